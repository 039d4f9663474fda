/* The in-process simulation backend of the HAL: queues that the lockstep session fills and
 * drains from the other side (the simulated device and the host). */
#ifndef ARGIL_HAL_SIM_H
#define ARGIL_HAL_SIM_H

#include <stdbool.h>

#include "hal.h"

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
};

void hal_sim_init(hal_t *h);

/* Device side: the frames the board sent this tick (cleared by the call) and those to deliver. */
void hal_sim_take_from_board(hal_t *h, can_batch_t *out);
void hal_sim_put_to_board(hal_t *h, const can_batch_t *in);
void hal_sim_set_gpio_in(hal_t *h, uint32_t levels);
uint32_t hal_sim_gpio_out(const hal_t *h);

/* Host side of the link: one whole frame in; whole frames out. */
argil_err_t hal_sim_host_send(hal_t *h, const uint8_t *frame, size_t len);
size_t hal_sim_host_receive(hal_t *h, uint8_t *buf, size_t cap);

#endif
