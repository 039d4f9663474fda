/* The Linux board backend of the HAL: SocketCAN for the drives, libgpiod lines, and the host
 * link handed over through two lock-free SPSC rings that the link thread serves (the fast loop
 * never makes a link system call). A "sim" bus replaces CAN and GPIO with the in-process
 * simulated arm (hal_sim_bus.h: the only part that includes sim/), so the real daemon runs and
 * is tested on a machine with neither. */
#ifndef ARGIL_HAL_LINUX_H
#define ARGIL_HAL_LINUX_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "bus/can_socket.h"
#include "gpio_port.h"
#include "hal.h"
#include "shared/spsc_ring.h"

#define HAL_LINUX_RX_RING_BYTES (1u << 17)   /* host → board frames waiting for the tick */
#define HAL_LINUX_TX_RING_BYTES (1u << 19)   /* board → host, about 50 ticks of output */

typedef enum { HAL_BUS_SOCKETCAN = 0, HAL_BUS_SIM = 1 } hal_bus_t;

struct sim_device; /* the simulated arm of the sim bus (hal_sim_bus.c) */

struct hal {
    hal_bus_t bus;
    int can_fd;
    can_socket_stats_t can;
    can_rx_queue_t can_rx;
    gpio_port_t gpio;
    /* sim bus */
    struct sim_device *sim;
    can_batch_t sim_from_board;    /* frames the board sent, delivered at the next step */
    uint32_t sim_gpio_out;
    uint32_t tick_us;
    /* host link */
    spsc_ring_t link_rx;           /* producer: link thread; consumer: fast loop */
    spsc_ring_t link_tx;           /* producer: fast loop; consumer: link thread */
    _Atomic uint32_t link_session; /* the core's host session: state | epoch << 2 (fast loop) */
    _Atomic uint32_t link_refused_source;     /* the link thread's refusals (link thread) */
    _Atomic uint32_t link_refused_no_session;
    _Atomic uint32_t link_refused_bad_mac;
    _Atomic uint32_t link_refused_bad_nonce;
    uint8_t link_rx_mem[HAL_LINUX_RX_RING_BYTES];
    uint8_t link_tx_mem[HAL_LINUX_TX_RING_BYTES];
    uint32_t link_rx_too_big;      /* records larger than the tick's buffer (dropped) */
};

/* Opens the SocketCAN interface and the GPIO lines (the sim bus: hal_linux_open_sim in
 * hal_sim_bus.h). One line into err on failure. */
argil_err_t hal_linux_open(hal_t *h, const char *can_if, const gpio_names_t *names,
                           char *err, size_t err_len);

/* Clears h for a backend on bus and sets up its link rings (both opens start here). */
argil_err_t hal_linux_reset(hal_t *h, hal_bus_t bus);

void hal_linux_close(hal_t *h);

/* The link thread's side of the session hand-over: the core's session as last told, and the
 * transport's refusal counts for the core. */
void hal_linux_link_session_get(hal_t *h, hal_session_state_t *state, uint32_t *epoch);
void hal_linux_link_refusals_set(hal_t *h, const hal_link_refusals_t *r);

/* Sends the frames in tx straight away (shutdown: quick stop / NMT stop). */
argil_err_t hal_linux_can_flush(hal_t *h, const can_batch_t *tx);

#endif
