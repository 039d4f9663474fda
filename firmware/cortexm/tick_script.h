/* A fixed, deterministic tick sequence for the board core: scripted host frames (HELLO, TOOL,
 * a 16³ window, heartbeats with ARM), three minimal CiA 402 drives answering the board's
 * frames, a scripted joint trajectory into the clay, an e-stop press and a host silence.
 * Built for the host and for the Cortex-M image; both print the same lines, compared by
 * tests/sys/test_cross.sh. Freestanding: the caller prints. */
#ifndef ARGIL_TICK_SCRIPT_H
#define ARGIL_TICK_SCRIPT_H

#include <stdint.h>

#include "firmware/core/board.h"

#define TICK_SCRIPT_TICKS 1000u

typedef struct {
    uint32_t tick;
    uint8_t state;
    uint8_t fault;
    uint8_t can_tx;
    uint32_t gpio_out;
    int16_t torque_permille[ARGIL_DRIVES];
    float force_n[3];
    uint32_t link_tx_bytes;
} tick_result_t;

typedef struct {
    board_t board;
    board_out_t out;
    can_batch_t to_board;
    uint8_t link[4096];
    float window[16 * 16 * 16];
    struct {
        uint8_t power;             /* cia402_state_t */
        uint8_t operational;
        int16_t torque;
    } drive[ARGIL_DRIVES];
    uint32_t tick;
    uint32_t seq;
} tick_script_t;

/* Prepares the board and the script; ARGIL_OK or the board's refusal. */
argil_err_t tick_script_init(tick_script_t *s);

/* Runs the next tick and describes it in r. */
void tick_script_step(tick_script_t *s, tick_result_t *r);

#endif
