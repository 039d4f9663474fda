/* The board's one window on the world: CAN, GPIO, the host link and a clock. Each backend is
 * its own .c file chosen at link time (hal_sim.c today; hal_linux.c and hal_cortexm.c come with
 * the board issue). Every call returns at once: nothing here may block the 1 kHz tick. */
#ifndef ARGIL_HAL_H
#define ARGIL_HAL_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"
#include "shared/canopen.h"

typedef struct hal hal_t;  /* defined by the backend */

/* Moves the frames the drives sent since the last call into rx (at most CAN_BATCH_MAX). */
argil_err_t hal_can_receive(hal_t *h, can_batch_t *rx);
/* Queues the tick's frames for the bus; ARGIL_ERR_FULL when the bus cannot take them. */
argil_err_t hal_can_send(hal_t *h, const can_batch_t *tx);
/* Input line levels as GPIO_IN_* bits (shared/gpio_lines.h). */
uint32_t hal_gpio_read(hal_t *h);
/* Drives the output lines to GPIO_OUT_* levels. */
void hal_gpio_write(hal_t *h, uint32_t levels);
/* Copies whole frames from the host into buf, back to back; returns the bytes copied. */
size_t hal_link_receive(hal_t *h, uint8_t *buf, size_t cap);
/* Queues bytes of whole frames for the host; ARGIL_ERR_FULL when the link cannot take them. */
argil_err_t hal_link_send(hal_t *h, const uint8_t *buf, size_t len);
/* The core's host session, as the transport is told it after every tick (hal_link_session). */
typedef enum {
    HAL_SESSION_NONE = 0,   /* no host: the transport lets only a host's HELLO through */
    HAL_SESSION_LIVE = 1,   /* serving the host that said HELLO: no one else gets through */
    HAL_SESSION_LAPSED = 2  /* its host went quiet: another host's HELLO may take over */
} hal_session_state_t;
/* Tells the transport the core's host session; epoch counts the sessions started. */
void hal_link_session(hal_t *h, hal_session_state_t state, uint32_t epoch);
/* The transport's own refusals so far (datagrams it kept from the core), by reason. All 0 when
 * it has one host (USB); bad_mac and bad_nonce only on an authenticated link (keyed UDP). */
typedef struct {
    uint32_t wrong_source;  /* from another sender than the session's host */
    uint32_t no_session;    /* with no session to belong to */
    uint32_t bad_mac;       /* whose tag did not verify */
    uint32_t bad_nonce;     /* with a valid tag but another session's nonce */
} hal_link_refusals_t;
void hal_link_refusals(hal_t *h, hal_link_refusals_t *r);
/* A monotonic nanosecond clock for measuring the tick's compute time. */
uint64_t hal_compute_clock_ns(hal_t *h);
/* How many times the platform has taken the core from the calling thread against its will so
 * far. Where the compute clock is the thread's CPU time (the simulated HAL), a tick during which
 * this changed was not timed: on a virtual machine that does not report stolen time, the time
 * the hypervisor held the vCPU is charged to the thread that was running, and that thread is
 * then preempted for having used its slice (docs/realtime.md, "Timing a simulated tick"). Always
 * 0 where the compute clock is wall time (a board): there, being preempted is part of the
 * deadline. */
uint64_t hal_compute_preemptions(hal_t *h);

#endif
