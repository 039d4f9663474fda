/* Runs one board tick against a HAL: gathers inputs, ticks, emits outputs, measures compute. */
#ifndef ARGIL_BOARD_HAL_H
#define ARGIL_BOARD_HAL_H

#include "board.h"
#include "firmware/hal/hal.h"

/* Bytes of host frames taken per tick: two full WINDOW chunks and the small frames, so no tick
 * decodes more than two 1 KiB chunks; the rest waits in the link's queue. */
#define BOARD_LINK_RX_MAX 2304u

typedef struct {
    can_batch_t can_rx;
    uint8_t link_rx[BOARD_LINK_RX_MAX];
    board_out_t out;
    uint32_t prev_compute_ns;
    bool prev_compute_preempted;       /* see board_in_t */
    uint32_t prev_wake_ns;             /* set by a caller that sleeps on a clock (0 otherwise) */
    uint32_t can_tx_errors;
    uint32_t link_tx_errors;
} board_io_t;

void board_io_init(board_io_t *io);

/* One tick: HAL in → board_tick → HAL out. Returns the tick's compute time in ns. */
uint32_t board_run_tick(board_t *b, board_io_t *io, hal_t *hal);

#endif
