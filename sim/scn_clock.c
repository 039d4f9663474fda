/* Scenario time from the board's SYNCs, or from the wall clock when the bus is silent (see
 * scn_clock.h). */
#include "scn_clock.h"

void scn_clock_init(scn_clock_t *c, bool ticks, int64_t wall_us)
{
    c->ticks = ticks;
    c->now_us = 0;
    c->last_wall_us = wall_us;
    c->silent = false;
    c->bus_off = false;
    c->syncs = 0;
    c->wall_steps = 0;
}

uint32_t scn_clock_sync(scn_clock_t *c, int64_t wall_us)
{
    if (!c->ticks || c->bus_off)
        return 0;
    c->silent = false;
    c->syncs++;
    c->now_us += SCN_CLOCK_TICK_US;
    c->last_wall_us = wall_us;
    return SCN_CLOCK_TICK_US;
}

uint32_t scn_clock_idle(scn_clock_t *c, int64_t wall_us)
{
    const int64_t since = wall_us - c->last_wall_us;
    if (c->ticks && !c->silent && !c->bus_off) {
        if (since <= SCN_CLOCK_SILENCE_US)
            return 0;
        c->silent = true;
    }
    if (since < 1)
        return 0;
    const uint32_t step = since > (int64_t)SCN_CLOCK_MAX_STEP_US ? SCN_CLOCK_MAX_STEP_US
                                                                 : (uint32_t)since;
    c->now_us += step;
    /* the wall time not taken yet is caught up by the next steps: the whole silence counts */
    c->last_wall_us += step;
    c->wall_steps++;
    return step;
}

void scn_clock_wall_while_bus_off(scn_clock_t *c, bool bus_off)
{
    c->bus_off = bus_off;
}

bool scn_clock_is_tick(const can_frame_t *f)
{
    return f->id == CANOPEN_COB_SYNC && f->len <= 1u;
}
