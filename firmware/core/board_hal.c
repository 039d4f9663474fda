/* Glue between the pure tick and the HAL. */
#include "board_hal.h"

#include <string.h>

static hal_session_state_t session_state(const host_session_t *s)
{
    switch (s->state) {
    case HOST_SESSION_LIVE: return HAL_SESSION_LIVE;
    case HOST_SESSION_LAPSED: return HAL_SESSION_LAPSED;
    default: return HAL_SESSION_NONE;
    }
}

void board_io_init(board_io_t *io)
{
    memset(io, 0, sizeof(*io));
}

uint32_t board_run_tick(board_t *b, board_io_t *io, hal_t *hal)
{
    const uint64_t preemptions0 = hal_compute_preemptions(hal);
    const uint64_t t0 = hal_compute_clock_ns(hal);
    board_in_t in;
    (void)hal_can_receive(hal, &io->can_rx);
    in.can_rx = &io->can_rx;
    in.gpio_in = hal_gpio_read(hal);
    in.link_rx = io->link_rx;
    in.link_rx_len = hal_link_receive(hal, io->link_rx, sizeof(io->link_rx));
    in.prev_compute_ns = io->prev_compute_ns;
    in.prev_wake_ns = io->prev_wake_ns;
    in.prev_compute_preempted = io->prev_compute_preempted;
    hal_link_refusals_t refused;
    hal_link_refusals(hal, &refused);
    in.link_refused_source = refused.wrong_source;
    in.link_refused_no_session = refused.no_session;
    in.link_refused_bad_mac = refused.bad_mac;
    in.link_refused_bad_nonce = refused.bad_nonce;
    board_tick(b, &in, &io->out);
    if (hal_can_send(hal, &io->out.can_tx) != ARGIL_OK)
        io->can_tx_errors++;
    hal_gpio_write(hal, io->out.gpio_out);
    if (io->out.link_tx_len > 0 &&
        hal_link_send(hal, io->out.link_tx, io->out.link_tx_len) != ARGIL_OK)
        io->link_tx_errors++;
    /* After this tick's frames are queued: a transport that unbinds on the session's end
     * still carries the frames that went with it. */
    hal_link_session(hal, session_state(&b->session), b->session.epoch);
    const uint64_t dt = hal_compute_clock_ns(hal) - t0;
    io->prev_compute_ns = dt > 0xFFFFFFFFu ? 0xFFFFFFFFu : (uint32_t)dt;
    io->prev_compute_preempted = hal_compute_preemptions(hal) != preemptions0;
    return io->prev_compute_ns;
}
