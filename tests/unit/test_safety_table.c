/* The safety state machine as a complete table: every state (BOOT, IDLE, ARMED, ACTIVE, FAULT,
 * FAULT while the force fades after the host left, ESTOP) × every input event, with the next
 * state, the force scale and the fault recorded. Then the forbidden transitions, checked over
 * every combination of the inputs: no ACTIVE without a fresh window and a live host; no leaving
 * ESTOP while the line is low; FAULT latched until a re-arm with every cause gone. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "firmware/core/safety.h"

#define DT_US 1000u

static safety_cfg_t g_cfg;

static safety_inputs_t healthy(void)
{
    safety_inputs_t in;
    memset(&in, 0, sizeof(in));
    in.drives_enabled = true;
    in.window_ready = true;
    in.host_heartbeat = true;
    return in;
}

static float tick(safety_t *s, const safety_inputs_t *in)
{
    return safety_process(s, &g_cfg, in, DT_US);
}

/* ---- the states, each reached by legal inputs only ---- */

typedef enum {
    ST_BOOT,
    ST_IDLE,
    ST_ARMED,
    ST_ACTIVE,
    ST_FAULT,   /* latched after a drive EMCY, cause gone */
    ST_FADING,  /* FAULT (host lost) one tick into the 20 ms fade */
    ST_ESTOP,   /* latched, line released again */
    ST_COUNT
} row_t;

static const char *const row_name[ST_COUNT] = {"BOOT", "IDLE", "ARMED", "ACTIVE",
                                               "FAULT", "FADING", "ESTOP"};

static safety_t reach(row_t r)
{
    safety_t s;
    safety_init(&s);
    if (r == ST_BOOT)
        return s;
    safety_inputs_t in = healthy();
    (void)tick(&s, &in);
    assert_int_equal(s.state, SAFETY_IDLE);
    if (r == ST_IDLE)
        return s;
    in.arm_request = true;
    in.window_ready = false; /* hold ARMED: no window yet */
    (void)tick(&s, &in);
    assert_int_equal(s.state, SAFETY_ARMED);
    if (r == ST_ARMED)
        return s;
    in = healthy();
    assert_float_equal(tick(&s, &in), 1.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_ACTIVE);
    if (r == ST_ACTIVE)
        return s;
    if (r == ST_FAULT) {
        in.drive_emcy = true;
        assert_float_equal(tick(&s, &in), 0.0f, 0.0f);
        assert_int_equal(s.state, SAFETY_FAULT);
        assert_int_equal(s.fault, FAULT_DRIVE_EMCY);
        return s;
    }
    if (r == ST_ESTOP) {
        in.estop_pressed = true;
        assert_float_equal(tick(&s, &in), 0.0f, 0.0f);
        assert_int_equal(s.state, SAFETY_ESTOP);
        return s;
    }
    in.host_heartbeat = false;
    for (int i = 0; i < 100 && s.state == SAFETY_ACTIVE; i++)
        (void)tick(&s, &in);
    assert_int_equal(s.state, SAFETY_FAULT);
    assert_int_equal(s.fault, FAULT_HOST_LOST);
    assert_true(s.fade > 0.5f && s.fade < 1.0f);
    return s;
}

/* ---- the events: one tick's inputs, some with the history that makes them mean something ---- */

typedef enum {
    EV_HEALTHY,          /* heartbeat, window, drives enabled, nothing asked */
    EV_ARM,
    EV_DISARM,
    EV_ESTOP,
    EV_ESTOP_AND_ARM,    /* the host re-arms while the line is still low */
    EV_DRIVE_LINE,       /* DRIVE_FAULT_N low */
    EV_EMCY,
    EV_DRIVE_HB_LOST,
    EV_BUS,
    EV_NONFINITE,
    EV_FORCE_LIMIT,
    EV_VELOCITY,
    EV_OVERRUN_ONCE,
    EV_OVERRUN_STREAK,   /* the streak-th overrun in a row */
    EV_HOST_QUIET,       /* no heartbeat this tick, host still fresh */
    EV_HOST_TIMEOUT,     /* no heartbeat, and the silence reaches the timeout this tick */
    EV_NO_WINDOW,
    EV_DRIVES_OFF,
    EV_ARM_CAUSE_PRESENT, /* re-arm while DRIVE_FAULT_N is still low */
    EV_ARM_NO_HOST,      /* an arm request with the host timed out */
    EV_ARM_NO_WINDOW,
    EV_COUNT
} event_t;

static const char *const event_name[EV_COUNT] = {
    "healthy", "arm", "disarm", "estop", "estop+arm", "drive line", "emcy", "drive hb lost",
    "bus", "nonfinite", "force limit", "velocity", "overrun once", "overrun streak",
    "host quiet", "host timeout", "no window", "drives off", "arm, cause present",
    "arm, no host", "arm, no window"};

/* Applies the event's history to s and returns the event tick's inputs. */
static safety_inputs_t event_inputs(event_t e, safety_t *s)
{
    safety_inputs_t in = healthy();
    switch (e) {
    case EV_HEALTHY: break;
    case EV_ARM: in.arm_request = true; break;
    case EV_DISARM: in.disarm_request = true; break;
    case EV_ESTOP: in.estop_pressed = true; break;
    case EV_ESTOP_AND_ARM: in.estop_pressed = true; in.arm_request = true; break;
    case EV_DRIVE_LINE: in.drive_fault_line = true; break;
    case EV_EMCY: in.drive_emcy = true; break;
    case EV_DRIVE_HB_LOST: in.drive_heartbeat_lost = true; break;
    case EV_BUS: in.bus_error = true; break;
    case EV_NONFINITE: in.nonfinite = true; break;
    case EV_FORCE_LIMIT: in.force_limit_exceeded = true; break;
    case EV_VELOCITY: in.velocity_limit_exceeded = true; break;
    case EV_OVERRUN_ONCE: in.deadline_overrun = true; break;
    case EV_OVERRUN_STREAK:
        s->overruns_in_row = g_cfg.overrun_streak - 1u;
        in.deadline_overrun = true;
        break;
    case EV_HOST_QUIET: in.host_heartbeat = false; break;
    case EV_HOST_TIMEOUT:
        if (s->host_silence_us < g_cfg.host_timeout_us - DT_US)
            s->host_silence_us = g_cfg.host_timeout_us - DT_US;
        in.host_heartbeat = false;
        break;
    case EV_NO_WINDOW: in.window_ready = false; break;
    case EV_DRIVES_OFF: in.drives_enabled = false; break;
    case EV_ARM_CAUSE_PRESENT: in.arm_request = true; in.drive_fault_line = true; break;
    case EV_ARM_NO_HOST:
        if (s->host_silence_us < g_cfg.host_timeout_us - DT_US)
            s->host_silence_us = g_cfg.host_timeout_us - DT_US;
        in.host_heartbeat = false;
        in.arm_request = true;
        break;
    case EV_ARM_NO_WINDOW: in.arm_request = true; in.window_ready = false; break;
    case EV_COUNT: break;
    }
    return in;
}

/* ---- the table ---- */

typedef enum { K_ZERO, K_ONE, K_FADE } scale_t; /* K_FADE: 0 < k < the fade before the tick */

typedef struct {
    safety_state_t next;
    scale_t k;
    int fault; /* expected s.fault, or -1 where it does not apply (not FAULT/ESTOP) */
} cell_t;

#define BOOT0 {SAFETY_BOOT, K_ZERO, -1}
#define IDLE0 {SAFETY_IDLE, K_ZERO, -1}
#define ARMED0 {SAFETY_ARMED, K_ZERO, -1}
#define ACTIVE1 {SAFETY_ACTIVE, K_ONE, -1}
#define ESTOP0 {SAFETY_ESTOP, K_ZERO, FAULT_ESTOP}
#define FAULT0(code) {SAFETY_FAULT, K_ZERO, code}
#define FADE {SAFETY_FAULT, K_FADE, FAULT_HOST_LOST}

static const cell_t table[ST_COUNT][EV_COUNT] = {
    /* BOOT: the first tick always reaches IDLE (drives off) unless the e-stop is pressed. */
    [ST_BOOT] = {IDLE0, IDLE0, IDLE0, ESTOP0, ESTOP0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0,
                 IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0},
    /* IDLE: drives off; arming needs a live host and no fault cause, not yet a window. */
    [ST_IDLE] = {IDLE0, ARMED0, IDLE0, ESTOP0, ESTOP0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0,
                 IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, IDLE0, ARMED0},
    /* ARMED: ACTIVE as soon as window, drives and a fresh host are there. */
    [ST_ARMED] = {ACTIVE1, ACTIVE1, IDLE0, ESTOP0, ESTOP0, FAULT0(FAULT_DRIVE_LINE),
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_HEARTBEAT), FAULT0(FAULT_BUS),
                  FAULT0(FAULT_NONFINITE), FAULT0(FAULT_FORCE_LIMIT),
                  FAULT0(FAULT_VELOCITY_LIMIT), ACTIVE1, FAULT0(FAULT_DEADLINE), ACTIVE1,
                  FAULT0(FAULT_HOST_LOST), ARMED0, ARMED0, FAULT0(FAULT_DRIVE_LINE),
                  FAULT0(FAULT_HOST_LOST), ARMED0},
    /* ACTIVE: any fault cuts the force in the same tick; only host loss fades it. */
    [ST_ACTIVE] = {ACTIVE1, ACTIVE1, IDLE0, ESTOP0, ESTOP0, FAULT0(FAULT_DRIVE_LINE),
                   FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_HEARTBEAT), FAULT0(FAULT_BUS),
                   FAULT0(FAULT_NONFINITE), FAULT0(FAULT_FORCE_LIMIT),
                   FAULT0(FAULT_VELOCITY_LIMIT), ACTIVE1, FAULT0(FAULT_DEADLINE), ACTIVE1,
                   FADE, ARMED0, ARMED0, FAULT0(FAULT_DRIVE_LINE), FADE, ARMED0},
    /* FAULT: latched; only a re-arm with the cause gone and the host live leaves it. */
    [ST_FAULT] = {FAULT0(FAULT_DRIVE_EMCY), ARMED0, FAULT0(FAULT_DRIVE_EMCY), ESTOP0, ESTOP0,
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY),
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY),
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY),
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY),
                  FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_EMCY),
                  ARMED0},
    /* FADING: the fade goes on (a returning heartbeat alone does not stop it), but any hard
     * fault cuts the force to zero at once and becomes the recorded cause. */
    [ST_FADING] = {FADE, ARMED0, FADE, ESTOP0, ESTOP0, FAULT0(FAULT_DRIVE_LINE),
                   FAULT0(FAULT_DRIVE_EMCY), FAULT0(FAULT_DRIVE_HEARTBEAT), FAULT0(FAULT_BUS),
                   FAULT0(FAULT_NONFINITE), FAULT0(FAULT_FORCE_LIMIT),
                   FAULT0(FAULT_VELOCITY_LIMIT), FADE, FAULT0(FAULT_DEADLINE), FADE, FADE, FADE,
                   FADE, FAULT0(FAULT_DRIVE_LINE), FADE, ARMED0},
    /* ESTOP: latched until the line is high and the host re-arms. */
    [ST_ESTOP] = {ESTOP0, ARMED0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0,
                  ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0, ESTOP0,
                  ARMED0},
};

static void test_every_state_times_every_event(void **st)
{
    (void)st;
    int bad = 0;
    for (int r = 0; r < ST_COUNT; r++) {
        for (int e = 0; e < EV_COUNT; e++) {
            safety_t s = reach((row_t)r);
            const safety_inputs_t in = event_inputs((event_t)e, &s);
            const float before = s.fade;
            const float k = tick(&s, &in);
            const cell_t *c = &table[r][e];
            bool ok = s.state == c->next && (c->fault < 0 || (int)s.fault == c->fault);
            switch (c->k) {
            case K_ZERO: ok = ok && k == 0.0f; break;
            case K_ONE: ok = ok && k == 1.0f; break;
            case K_FADE: ok = ok && k > 0.0f && k < before; break;
            }
            /* what the rest of the board reads off the machine agrees with the state */
            ok = ok && safety_may_sculpt(&s) == (s.state == SAFETY_ACTIVE);
            ok = ok && safety_drives_on(&s) == (s.state == SAFETY_ARMED ||
                                                s.state == SAFETY_ACTIVE || k > 0.0f);
            if (!ok) {
                fprintf(stderr, "%s + %s: got %s (fault %s) k=%.3f, want %s (fault %d)\n",
                        row_name[r], event_name[e], safety_state_name(s.state),
                        safety_fault_name(s.fault), (double)k, safety_state_name(c->next),
                        c->fault);
                bad++;
            }
        }
    }
    assert_int_equal(bad, 0);
}

/* ---- the forbidden transitions, over every combination of the inputs ---- */

#define N_INPUTS 14u

static safety_inputs_t inputs_from_bits(uint32_t b)
{
    safety_inputs_t in;
    bool *const f[N_INPUTS] = {&in.estop_pressed, &in.drive_fault_line, &in.drives_enabled,
                               &in.drive_heartbeat_lost, &in.drive_emcy, &in.window_ready,
                               &in.host_heartbeat, &in.arm_request, &in.disarm_request,
                               &in.nonfinite, &in.force_limit_exceeded, &in.deadline_overrun,
                               &in.bus_error, &in.velocity_limit_exceeded};
    for (uint32_t i = 0; i < N_INPUTS; i++)
        *f[i] = (b >> i) & 1u;
    return in;
}

static bool any_fault_cause(const safety_inputs_t *in, const safety_t *before)
{
    const bool streak = in->deadline_overrun &&
                        before->overruns_in_row + 1u >= g_cfg.overrun_streak;
    return in->drive_fault_line || in->drive_heartbeat_lost || in->drive_emcy || in->nonfinite ||
           in->force_limit_exceeded || in->bus_error || in->velocity_limit_exceeded || streak;
}

static void test_forbidden_transitions_over_all_inputs(void **st)
{
    (void)st;
    uint32_t checked = 0, to_active = 0, rearmed = 0;
    for (int r = 0; r < ST_COUNT; r++) {
        for (int history = 0; history < 4; history++) {
            safety_t base = reach((row_t)r);
            if (history & 1) /* the host has been silent for the timeout but one tick */
                base.host_silence_us = g_cfg.host_timeout_us - DT_US;
            if (history & 2) /* one overrun short of the streak */
                base.overruns_in_row = g_cfg.overrun_streak - 1u;
            for (uint32_t b = 0; b < (1u << N_INPUTS); b++) {
                safety_t s = base;
                const safety_inputs_t in = inputs_from_bits(b);
                const bool host_fresh =
                    in.host_heartbeat ||
                    (base.host_seen && base.host_silence_us + DT_US < g_cfg.host_timeout_us);
                const float k = tick(&s, &in);
                checked++;
                assert_true(k >= 0.0f && k <= 1.0f);
                /* No ACTIVE without a window, enabled drives, a live host and no fault. */
                if (s.state == SAFETY_ACTIVE) {
                    to_active++;
                    if (!in.window_ready || !in.drives_enabled || !host_fresh ||
                        in.estop_pressed || any_fault_cause(&in, &base) ||
                        base.state == SAFETY_FAULT || base.state == SAFETY_ESTOP ||
                        base.state == SAFETY_IDLE || base.state == SAFETY_BOOT)
                        fail_msg("%s inputs 0x%04x (history %d): ACTIVE not allowed",
                                 row_name[r], b, history);
                }
                /* The e-stop line low: ESTOP, zero force, whatever else happens. */
                if (in.estop_pressed && (s.state != SAFETY_ESTOP || k != 0.0f))
                    fail_msg("%s inputs 0x%04x: e-stop low but %s k=%.3f", row_name[r], b,
                             safety_state_name(s.state), (double)k);
                /* Latched: FAULT and ESTOP leave only for ARMED, on a re-arm with every cause
                 * gone and the host live (or for ESTOP when the line goes low). */
                if (base.state == SAFETY_FAULT || base.state == SAFETY_ESTOP) {
                    const bool may_leave = in.arm_request && !in.estop_pressed &&
                                           !any_fault_cause(&in, &base) && host_fresh;
                    if (s.state == SAFETY_ARMED) {
                        rearmed++;
                        if (!may_leave)
                            fail_msg("%s inputs 0x%04x: left the latch without a valid re-arm",
                                     row_name[r], b);
                        assert_float_equal(k, 0.0f, 0.0f);
                    } else if (s.state != SAFETY_ESTOP) {
                        assert_int_equal(s.state, SAFETY_FAULT);
                        if (may_leave)
                            fail_msg("%s inputs 0x%04x: a valid re-arm was refused",
                                     row_name[r], b);
                    }
                    /* a new fault cause while the force fades cuts it at once */
                    if (any_fault_cause(&in, &base) && k != 0.0f)
                        fail_msg("%s inputs 0x%04x: force %.3f with a fault cause present",
                                 row_name[r], b, (double)k);
                }
                /* Non-zero force only in ACTIVE or while fading after the host left. */
                if (k > 0.0f && s.state != SAFETY_ACTIVE &&
                    !(s.state == SAFETY_FAULT && s.fault == FAULT_HOST_LOST))
                    fail_msg("%s inputs 0x%04x: force %.3f in %s", row_name[r], b, (double)k,
                             safety_state_name(s.state));
                /* Any fault cause with the force on ends in zero force this very tick. */
                if (any_fault_cause(&in, &base) && k != 0.0f)
                    fail_msg("%s inputs 0x%04x: fault cause present, force %.3f",
                             row_name[r], b, (double)k);
            }
        }
    }
    assert_int_equal(checked, ST_COUNT * 4u * (1u << N_INPUTS));
    assert_true(to_active > 0 && rearmed > 0); /* the checks above did see both */
}

/* The fade after host loss reaches zero within host_fade_us and stays there; the state stays
 * FAULT (host lost) through it, heartbeats or not. */
static void test_fade_completes_within_fade_time(void **st)
{
    (void)st;
    safety_t s = reach(ST_FADING);
    safety_inputs_t in = healthy();
    float prev = s.fade;
    uint32_t t_us = DT_US; /* one tick of the fade is already behind */
    while (prev > 0.0f) {
        in.host_heartbeat = (t_us / DT_US) % 2u == 0u;
        const float k = tick(&s, &in);
        assert_true(k < prev);
        assert_int_equal(s.state, SAFETY_FAULT);
        prev = k;
        t_us += DT_US;
        assert_true(t_us <= g_cfg.host_fade_us + DT_US);
    }
    assert_false(safety_drives_on(&s));
    for (int i = 0; i < 50; i++)
        assert_float_equal(tick(&s, &in), 0.0f, 0.0f);
}

static int setup(void **st)
{
    (void)st;
    safety_cfg_default(&g_cfg);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_state_times_every_event),
        cmocka_unit_test(test_forbidden_transitions_over_all_inputs),
        cmocka_unit_test(test_fade_completes_within_fade_time),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
