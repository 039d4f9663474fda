/* The in-process simulation backend of the HAL: queues that the lockstep session fills and
 * drains from the other side (the simulated device and the host). */
#ifndef ARGIL_HAL_SIM_H
#define ARGIL_HAL_SIM_H

#include <stdbool.h>

#include "hal.h"
#include "link_bind.h"

#define HAL_SIM_LINK_BYTES 65536u   /* each direction */

typedef struct {
    uint8_t bytes[HAL_SIM_LINK_BYTES];
    uint32_t head;                 /* next byte to read */
    uint32_t tail;                 /* next byte to write */
} hal_sim_fifo_t;

struct hal {
    can_batch_t to_board;          /* drives → board */
    can_batch_t from_board;        /* board → drives */
    uint32_t gpio_in;
    uint32_t gpio_out;
    hal_sim_fifo_t link_to_board;  /* records: u16 length + frame bytes */
    hal_sim_fifo_t link_from_board;
    uint32_t link_dropped;         /* frames refused because a FIFO was full */
    link_bind_t bind;              /* which sender reaches the board, as over UDP */
    uint64_t link_now_us;          /* the binding's clock: one board tick per board tick */
    uint32_t tick_us;              /* … of this length (1000 until hal_sim_set_tick_us) */
};

#define HAL_SIM_HOST 1u            /* the sender key of hal_sim_host_send */

void hal_sim_init(hal_t *h);

/* The board's loop period, so the link binding's clock keeps real time at 2 and 4 kHz. */
void hal_sim_set_tick_us(hal_t *h, uint32_t tick_us);

/* Device side: the frames the board sent this tick (cleared by the call) and those to deliver. */
void hal_sim_take_from_board(hal_t *h, can_batch_t *out);
void hal_sim_put_to_board(hal_t *h, const can_batch_t *in);
void hal_sim_set_gpio_in(hal_t *h, uint32_t levels);
uint32_t hal_sim_gpio_out(const hal_t *h);

/* Host side of the link: one whole frame in (a datagram from sender HAL_SIM_HOST); whole
 * frames out. A datagram the binding refuses is dropped and counted, as by the UDP link. */
argil_err_t hal_sim_host_send(hal_t *h, const uint8_t *frame, size_t len);
/* The same from another sender (a second host or a stranger on the network). */
argil_err_t hal_sim_host_send_from(hal_t *h, uint64_t sender, const uint8_t *frame, size_t len);
size_t hal_sim_host_receive(hal_t *h, uint8_t *buf, size_t cap);

#endif
