/* Safety state machine: every transition of DESIGN.md, and the ones that must not happen. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "firmware/core/safety.h"

static safety_cfg_t cfg;

static safety_inputs_t healthy(void)
{
    safety_inputs_t in = {0};
    in.drives_enabled = true;
    in.window_ready = true;
    in.host_heartbeat = true;
    return in;
}

/* Drives a fresh machine to ACTIVE. */
static void to_active(safety_t *s)
{
    safety_cfg_default(&cfg);
    safety_init(s);
    safety_inputs_t in = healthy();
    (void)safety_process(s, &cfg, &in, 1000);
    assert_int_equal(s->state, SAFETY_IDLE);
    in.arm_request = true;
    (void)safety_process(s, &cfg, &in, 1000);
    assert_int_equal(s->state, SAFETY_ARMED);
    in.arm_request = false;
    float k = safety_process(s, &cfg, &in, 1000);
    assert_int_equal(s->state, SAFETY_ACTIVE);
    assert_float_equal(k, 1.0f, 0.0f);
}

static void test_boot_idle_armed_active(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    assert_true(safety_drives_on(&s));
    assert_true(safety_may_sculpt(&s));
}

static void test_no_active_without_window_or_host(void **st)
{
    (void)st;
    safety_t s;
    safety_cfg_default(&cfg);
    safety_init(&s);
    safety_inputs_t in = healthy();
    in.window_ready = false;
    (void)safety_process(&s, &cfg, &in, 1000);
    in.arm_request = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    in.arm_request = false;
    for (int i = 0; i < 100; i++)
        assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_ARMED);

    /* A window but no host heartbeat ever: stays ARMED, zero force. */
    safety_init(&s);
    in = healthy();
    in.host_heartbeat = false;
    (void)safety_process(&s, &cfg, &in, 1000);
    in.arm_request = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    in.arm_request = false;
    for (int i = 0; i < 10; i++)
        assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_not_equal(s.state, SAFETY_ACTIVE);
}

static void test_estop_same_tick_and_latched(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.estop_pressed = true;
    assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_ESTOP);
    assert_false(safety_drives_on(&s));
    /* Re-arm while the line is still low: refused. */
    in.arm_request = true;
    assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_ESTOP);
    /* Released but not re-armed: still latched. */
    in.estop_pressed = false;
    in.arm_request = false;
    for (int i = 0; i < 50; i++)
        (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_ESTOP);
    /* Released and re-armed: ARMED, then ACTIVE. */
    in.arm_request = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_ARMED);
    in.arm_request = false;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_ACTIVE);
}

static void test_host_lost_fades_within_20ms(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.host_heartbeat = false;
    int t_fault_ms = -1, t_zero_ms = -1;
    float at_half = -1.0f;
    for (int ms = 1; ms <= 100; ms++) {
        const float k = safety_process(&s, &cfg, &in, 1000);
        if (t_fault_ms < 0 && s.state == SAFETY_FAULT)
            t_fault_ms = ms;
        if (t_fault_ms > 0 && ms == t_fault_ms + 10)
            at_half = k;
        if (t_fault_ms > 0 && t_zero_ms < 0 && k == 0.0f)
            t_zero_ms = ms;
        if (t_fault_ms < 0)
            assert_float_equal(k, 1.0f, 0.0f);
    }
    assert_int_equal(s.fault, FAULT_HOST_LOST);
    assert_in_range(t_fault_ms, 50, 51);              /* the 50 ms timeout */
    assert_true(t_zero_ms - t_fault_ms <= 20);        /* zero force within 20 ms */
    assert_true(at_half > 0.3f && at_half < 0.7f);    /* a fade, not a step */
    assert_false(safety_may_sculpt(&s));
}

static void test_nonfinite_is_fault_in_same_tick(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.nonfinite = true;
    assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_FAULT);
    assert_int_equal(s.fault, FAULT_NONFINITE);
}

static void test_fault_latched_until_rearm_with_cause_gone(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.drive_fault_line = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_FAULT);
    assert_int_equal(s.fault, FAULT_DRIVE_LINE);
    in.arm_request = true; /* cause still present */
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_FAULT);
    in.drive_fault_line = false;
    in.arm_request = false;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_FAULT);
    in.arm_request = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_ARMED);
}

static void test_overrun_streak(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.deadline_overrun = true;
    (void)safety_process(&s, &cfg, &in, 1000);
    (void)safety_process(&s, &cfg, &in, 1000);
    in.deadline_overrun = false;
    (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_ACTIVE); /* two in a row, then fine: tolerated */
    in.deadline_overrun = true;
    for (int i = 0; i < 3; i++)
        (void)safety_process(&s, &cfg, &in, 1000);
    assert_int_equal(s.state, SAFETY_FAULT);
    assert_int_equal(s.fault, FAULT_DEADLINE);
}

static void test_disarm_and_drive_events(void **st)
{
    (void)st;
    safety_t s;
    to_active(&s);
    safety_inputs_t in = healthy();
    in.disarm_request = true;
    assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_IDLE);
    assert_false(safety_drives_on(&s));

    const struct { int field; fault_code_t code; } cases[] = {
        {0, FAULT_DRIVE_EMCY}, {1, FAULT_DRIVE_HEARTBEAT}, {2, FAULT_BUS}, {3, FAULT_FORCE_LIMIT}};
    for (unsigned c = 0; c < sizeof(cases) / sizeof(cases[0]); c++) {
        to_active(&s);
        in = healthy();
        if (cases[c].field == 0) in.drive_emcy = true;
        if (cases[c].field == 1) in.drive_heartbeat_lost = true;
        if (cases[c].field == 2) in.bus_error = true;
        if (cases[c].field == 3) in.force_limit_exceeded = true;
        assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
        assert_int_equal(s.state, SAFETY_FAULT);
        assert_int_equal(s.fault, cases[c].code);
        assert_string_not_equal(safety_fault_name(s.fault), "?");
    }
    /* Losing the drives' enable in ACTIVE drops back to ARMED with zero force. */
    to_active(&s);
    in = healthy();
    in.drives_enabled = false;
    assert_float_equal(safety_process(&s, &cfg, &in, 1000), 0.0f, 0.0f);
    assert_int_equal(s.state, SAFETY_ARMED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_boot_idle_armed_active),
        cmocka_unit_test(test_no_active_without_window_or_host),
        cmocka_unit_test(test_estop_same_tick_and_latched),
        cmocka_unit_test(test_host_lost_fades_within_20ms),
        cmocka_unit_test(test_nonfinite_is_fault_in_same_tick),
        cmocka_unit_test(test_fault_latched_until_rearm_with_cause_gone),
        cmocka_unit_test(test_overrun_streak),
        cmocka_unit_test(test_disarm_and_drive_events),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
