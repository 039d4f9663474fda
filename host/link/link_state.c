/* Link state machine: WAITING → CONNECTED on the first frame; CONNECTED → LOST on silence or a
 * lost transport; LOST → CONNECTED (a reconnection: resync due) when frames flow again. */
#include "link_state.h"

void link_fsm_init(link_fsm_t *f, uint32_t silence_us, bool transport_up)
{
    f->state = LINK_WAITING;
    f->silence_us = silence_us;
    f->last_rx_us = 0;
    f->ever_connected = false;
    f->transport_up = transport_up;
    f->resync_due = false;
    f->reconnects = 0;
    f->losses = 0;
    f->transport_drops = 0;
}

void link_fsm_frame(link_fsm_t *f, uint64_t now_us)
{
    f->last_rx_us = now_us;
    if (!f->transport_up || f->state == LINK_CONNECTED)
        return;
    if (f->ever_connected) {
        f->reconnects++;
        f->resync_due = true;
    }
    f->ever_connected = true;
    f->state = LINK_CONNECTED;
}

void link_fsm_transport_down(link_fsm_t *f)
{
    if (f->state == LINK_CONNECTED)
        f->losses++;
    if (f->transport_up)
        f->transport_drops++;
    f->transport_up = false;
    /* Before the first connection there is nothing to lose: keep waiting. */
    f->state = f->ever_connected ? LINK_LOST : LINK_WAITING;
}

void link_fsm_transport_up(link_fsm_t *f)
{
    f->transport_up = true;
    if (f->state == LINK_CONNECTED)
        return;
    /* Still LOST to the person until the board speaks; a never-connected link keeps waiting. */
}

void link_fsm_tick(link_fsm_t *f, uint64_t now_us)
{
    if (f->state == LINK_CONNECTED && now_us - f->last_rx_us > f->silence_us) {
        f->state = LINK_LOST;
        f->losses++;
    }
}

bool link_fsm_take_resync(link_fsm_t *f)
{
    const bool due = f->resync_due;
    f->resync_due = false;
    return due;
}

const char *link_state_name(link_state_t s)
{
    switch (s) {
    case LINK_WAITING: return "waiting";
    case LINK_CONNECTED: return "connected";
    case LINK_LOST: return "lost";
    }
    return "?";
}
