/* Safety state machine: BOOT → IDLE → ARMED → ACTIVE, FAULT and ESTOP latched. */
#include "safety.h"

void safety_cfg_default(safety_cfg_t *cfg)
{
    cfg->host_timeout_us = 50000u;
    cfg->host_fade_us = 20000u;
    cfg->overrun_streak = 3u;
}

void safety_init(safety_t *s)
{
    s->state = SAFETY_BOOT;
    s->fault = FAULT_NONE;
    s->host_silence_us = 0;
    s->overruns_in_row = 0;
    s->fade = 0.0f;
    s->host_seen = false;
    s->entered = true;
}

static void enter(safety_t *s, safety_state_t st, fault_code_t why)
{
    if (s->state != st)
        s->entered = true;
    s->state = st;
    if (st == SAFETY_FAULT || st == SAFETY_ESTOP)
        s->fault = why;
}

/* The first fault the inputs report, in order of severity; FAULT_NONE when healthy. */
static fault_code_t input_fault(const safety_inputs_t *in, const safety_t *s,
                                const safety_cfg_t *cfg)
{
    if (in->nonfinite)
        return FAULT_NONFINITE;
    if (in->drive_fault_line)
        return FAULT_DRIVE_LINE;
    if (in->drive_emcy)
        return FAULT_DRIVE_EMCY;
    if (in->drive_heartbeat_lost)
        return FAULT_DRIVE_HEARTBEAT;
    if (in->bus_error)
        return FAULT_BUS;
    if (cfg->overrun_streak > 0 && s->overruns_in_row >= cfg->overrun_streak)
        return FAULT_DEADLINE;
    if (in->force_limit_exceeded)
        return FAULT_FORCE_LIMIT;
    if (in->velocity_limit_exceeded)
        return FAULT_VELOCITY_LIMIT;
    return FAULT_NONE;
}

float safety_process(safety_t *s, const safety_cfg_t *cfg, const safety_inputs_t *in,
                     uint32_t dt_us)
{
    s->entered = false;
    s->overruns_in_row = in->deadline_overrun ? s->overruns_in_row + 1u : 0u;
    if (in->host_heartbeat) {
        s->host_silence_us = 0;
        s->host_seen = true;
    } else if (s->host_silence_us < 0xFFFFFFFFu - dt_us) {
        s->host_silence_us += dt_us;
    }
    const bool host_fresh = s->host_seen && s->host_silence_us < cfg->host_timeout_us;

    /* E-stop wins over everything, in the same tick. */
    if (in->estop_pressed) {
        enter(s, SAFETY_ESTOP, FAULT_ESTOP);
        s->fade = 0.0f;
        return 0.0f;
    }
    const fault_code_t f = input_fault(in, s, cfg);

    switch (s->state) {
    case SAFETY_BOOT:
        enter(s, SAFETY_IDLE, FAULT_NONE);
        break;
    case SAFETY_IDLE:
        /* ARM is the host's command: only from a live host, never with a fault cause present. */
        if (in->arm_request && f == FAULT_NONE && host_fresh)
            enter(s, SAFETY_ARMED, FAULT_NONE);
        break;
    case SAFETY_ARMED:
    case SAFETY_ACTIVE:
        if (f != FAULT_NONE) {
            enter(s, SAFETY_FAULT, f);
            s->fade = 0.0f;
        } else if (in->disarm_request) {
            enter(s, SAFETY_IDLE, FAULT_NONE);
        } else if (s->host_seen && !host_fresh) {
            /* Host gone: stop sculpting now, fade the force out, then latch the fault. */
            const bool was_active = s->state == SAFETY_ACTIVE;
            enter(s, SAFETY_FAULT, FAULT_HOST_LOST);
            s->fade = was_active ? 1.0f : 0.0f;
        } else if (s->state == SAFETY_ARMED && in->drives_enabled && in->window_ready &&
                   host_fresh) {
            enter(s, SAFETY_ACTIVE, FAULT_NONE);
            s->fade = 1.0f;
        } else if (s->state == SAFETY_ACTIVE && (!in->drives_enabled || !in->window_ready)) {
            enter(s, SAFETY_ARMED, FAULT_NONE);
        }
        break;
    case SAFETY_FAULT:
    case SAFETY_ESTOP:
        /* A hard fault while the force still fades after host loss: torque off now, and that
         * fault becomes the recorded cause. */
        if (s->state == SAFETY_FAULT && s->fade > 0.0f && f != FAULT_NONE) {
            s->fault = f;
            s->fade = 0.0f;
        }
        /* Latched: leave only on the host's re-arm with every cause gone. */
        if (in->arm_request && f == FAULT_NONE && host_fresh) {
            enter(s, SAFETY_ARMED, FAULT_NONE);
            s->fade = 0.0f;
        }
        break;
    }

    if (s->state == SAFETY_ACTIVE) {
        s->fade = 1.0f;
        return 1.0f;
    }
    if (s->state == SAFETY_FAULT && s->fault == FAULT_HOST_LOST && s->fade > 0.0f) {
        const float step = cfg->host_fade_us > 0 ? (float)dt_us / (float)cfg->host_fade_us : 1.0f;
        s->fade = s->fade > step ? s->fade - step : 0.0f;
        return s->fade;
    }
    s->fade = 0.0f;
    return 0.0f;
}

bool safety_drives_on(const safety_t *s)
{
    return s->state == SAFETY_ARMED || s->state == SAFETY_ACTIVE ||
           (s->state == SAFETY_FAULT && s->fade > 0.0f);
}

bool safety_may_sculpt(const safety_t *s)
{
    return s->state == SAFETY_ACTIVE;
}
