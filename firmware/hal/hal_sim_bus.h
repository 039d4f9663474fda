/* The sim bus of the Linux board backend: argil-board's `--bus sim` steps the in-process
 * simulated arm (sim/) where SocketCAN and libgpiod would be, so the real daemon runs and is
 * tested on a machine with neither. The lines still go through gpio_port with the board's
 * names, so a wrong line name fails as on a real chip. */
#ifndef ARGIL_HAL_SIM_BUS_H
#define ARGIL_HAL_SIM_BUS_H

#include "hal_linux.h"

/* Opens h on the simulated arm (sim_params_default) for CAN and GPIO, stepped tick_us per
 * tick. One line into err on failure. */
argil_err_t hal_linux_open_sim(hal_t *h, const gpio_names_t *names, uint32_t tick_us,
                               char *err, size_t err_len);

/* Frees the simulated arm (nothing when h is on SocketCAN). */
void hal_sim_bus_close(hal_t *h);

/* One tick of the simulated arm under the frames and lines of the last tick; its frames for
 * the board into rx. */
void hal_sim_bus_step(hal_t *h, can_batch_t *rx);

#endif
