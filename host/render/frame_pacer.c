/* Frame pacing of the live window (see frame_pacer.h). */
#include "host/render/frame_pacer.h"

void frame_pacer_cfg_default(frame_pacer_cfg_t *c)
{
    c->display_period_ns = 16666667u;
    c->hold_ns = 12000000u;
    c->idle_period_ns = 250000000u;
}

void frame_pacer_init(frame_pacer_t *p)
{
    p->any = false;
    p->last_start_ns = 0;
    p->last_swap_ns = 0;
}

bool frame_pacer_due(const frame_pacer_t *p, const frame_pacer_cfg_t *c,
                     const frame_pacer_in_t *in, uint64_t now_ns, uint64_t *due_ns)
{
    uint64_t due = now_ns;
    if (p->any && !(in->undrawn && in->urgent) && !in->input) {
        if (in->undrawn) {
            due = p->last_start_ns + c->display_period_ns;
            const uint64_t hold = p->last_swap_ns + c->hold_ns;
            if (in->inflight && hold > due)
                due = hold;
        } else {
            due = p->last_swap_ns + c->idle_period_ns;
        }
    }
    *due_ns = due;
    return due <= now_ns;
}

void frame_pacer_drawn(frame_pacer_t *p, uint64_t start_ns, uint64_t swap_ns)
{
    p->any = true;
    p->last_start_ns = start_ns;
    p->last_swap_ns = swap_ns;
}
