/* Host session and sequence-number window (host_session.h). */
#include "host_session.h"

void host_session_init(host_session_t *s)
{
    s->state = HOST_SESSION_NONE;
    s->epoch = 0;
    s->newest_seq = 0;
    s->seen = 0;
    s->silence_us = 0;
}

/* Records seq in the window; the verdict on it. Newer means (seq − newest) mod 2³² in
 * 1 … 2³¹ − 1 (RFC 1982 serial numbers), so the counter may wrap. */
static host_frame_verdict_t window_check(host_session_t *s, uint32_t seq)
{
    const uint32_t ahead = seq - s->newest_seq;
    if (ahead != 0u && ahead < 0x80000000u) {
        s->seen = ahead >= HOST_SESSION_WINDOW ? 0u : s->seen << ahead;
        s->seen |= 1u;
        s->newest_seq = seq;
        return HOST_FRAME_ACCEPT;
    }
    const uint32_t behind = s->newest_seq - seq;
    if (behind >= HOST_SESSION_WINDOW)
        return HOST_FRAME_STALE;
    const uint64_t bit = (uint64_t)1u << behind;
    if (s->seen & bit)
        return HOST_FRAME_DUPLICATE;
    s->seen |= bit;
    return HOST_FRAME_ACCEPT;
}

host_frame_verdict_t host_session_admit(host_session_t *s, bool hello, bool alive, uint32_t seq)
{
    if (hello && s->state != HOST_SESSION_LIVE) {
        /* A new session, maybe of a new host whose numbers start anywhere. */
        s->state = HOST_SESSION_LIVE;
        s->epoch++;
        s->newest_seq = seq;
        s->seen = 1u;
        s->silence_us = 0;
        return HOST_FRAME_NEW_SESSION;
    }
    if (s->state == HOST_SESSION_NONE)
        return HOST_FRAME_NO_SESSION;
    const host_frame_verdict_t v = window_check(s, seq);
    if (v != HOST_FRAME_ACCEPT)
        return v;
    if (alive) {
        s->silence_us = 0;
        s->state = HOST_SESSION_LIVE;
    }
    if (hello) {
        s->epoch++; /* the live host starts over (a reconnection): its numbers carry on */
        return HOST_FRAME_NEW_SESSION;
    }
    return HOST_FRAME_ACCEPT;
}

void host_session_end(host_session_t *s)
{
    s->state = HOST_SESSION_NONE;
    s->seen = 0;
    s->silence_us = 0;
}

bool host_session_process(host_session_t *s, uint32_t dt_us, uint32_t timeout_us)
{
    if (s->state != HOST_SESSION_LIVE)
        return false;
    s->silence_us = s->silence_us > 0xFFFFFFFFu - dt_us ? 0xFFFFFFFFu : s->silence_us + dt_us;
    if (s->silence_us < timeout_us)
        return false;
    s->state = HOST_SESSION_LAPSED;
    return true;
}
