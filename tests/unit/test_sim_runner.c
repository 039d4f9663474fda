/* The device side of a scenario: the CAN fault layer (sim/can_faults.c) drops, delays,
 * silences and rewrites frames as told, and sim_runner (sim/sim_runner.c) applies a scenario's
 * steps on time, logs them, and cuts the drives' power when the watchdog kick stops. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "shared/gpio_lines.h"
#include "sim/can_faults.h"
#include "sim/sim_runner.h"

static can_batch_t batch_of(uint32_t id, int n)
{
    can_batch_t b = {0};
    for (int i = 0; i < n; i++) {
        can_frame_t f = {id, 1, {(uint8_t)i}};
        (void)can_batch_push(&b, &f);
    }
    return b;
}

static void test_drop_rate_follows_the_percentage(void **st)
{
    (void)st;
    static can_faults_t cf;
    can_faults_init(&cf);
    can_faults_set_drop(&cf, 10000u, 11u); /* 1 % */
    const can_batch_t in = batch_of(0x181, 20);
    uint32_t passed = 0;
    for (int k = 0; k < 10000; k++) { /* 200 000 frames */
        can_batch_t out;
        can_faults_to_board(&cf, &in, &out, k * 1000);
        passed += out.n;
    }
    assert_int_equal(passed + cf.dropped_to_board, 200000u);
    assert_in_range(cf.dropped_to_board, 1800u, 2200u); /* 1 % ± 10 % */
    /* the same seed gives the same losses */
    static can_faults_t again;
    can_faults_init(&again);
    can_faults_set_drop(&again, 10000u, 11u);
    for (int k = 0; k < 10000; k++) {
        can_batch_t out;
        can_faults_to_board(&again, &in, &out, k * 1000);
    }
    assert_int_equal(again.dropped_to_board, cf.dropped_to_board);
    can_faults_set_drop(&cf, 100000u, 7u); /* 10 % */
    const uint32_t before = cf.dropped_from_board;
    for (int k = 0; k < 10000; k++) {
        can_batch_t out;
        can_faults_from_board(&cf, &in, &out, k * 1000);
    }
    assert_in_range(cf.dropped_from_board - before, 19000u, 21000u);
}

/* Which frames a seed loses does not depend on how the two directions' frames interleave, nor
 * on other ids' traffic: the n-th heartbeat of drive 2 is lost, or not, in SIL and on a bus
 * alike. */
static void test_drop_is_per_frame_not_per_draw(void **st)
{
    (void)st;
    static can_faults_t a, b;
    can_faults_init(&a);
    can_faults_init(&b);
    can_faults_set_drop(&a, 100000u, 7u);
    can_faults_set_drop(&b, 100000u, 7u);
    const can_batch_t hb = batch_of(0x702, 1), tpdo = batch_of(0x182, 3), rpdo = batch_of(0x202, 2);
    bool lost_a[400], lost_b[400];
    uint32_t lost = 0;
    for (int k = 0; k < 400; k++) {
        can_batch_t out;
        /* a: only heartbeats; b: heartbeats among TPDOs one way and RPDOs the other */
        can_faults_to_board(&a, &hb, &out, k * 1000);
        lost_a[k] = out.n == 0;
        can_faults_from_board(&b, &rpdo, &out, k * 1000);
        if (k % 3 == 0)
            can_faults_to_board(&b, &tpdo, &out, k * 1000);
        can_faults_to_board(&b, &hb, &out, k * 1000);
        lost_b[k] = out.n == 0;
        lost += lost_a[k];
    }
    assert_memory_equal(lost_a, lost_b, sizeof(lost_a));
    assert_in_range(lost, 20u, 60u); /* 10 % of 400 */
}

static void test_delay_holds_frames_in_order(void **st)
{
    (void)st;
    static can_faults_t cf;
    can_faults_init(&cf);
    can_faults_set_delay(&cf, 2500);
    can_batch_t out;
    for (int k = 0; k < 3; k++) {
        can_batch_t in = batch_of(0x201 + (uint32_t)k, 1);
        can_faults_from_board(&cf, &in, &out, k * 1000);
        assert_int_equal(out.n, 0); /* held: due at 2.5, 3.5, 4.5 ms */
    }
    can_faults_from_board(&cf, NULL, &out, 3000);
    assert_int_equal(out.n, 1);
    assert_int_equal(out.f[0].id, 0x201);
    can_faults_set_delay(&cf, 0); /* off: the rest at once, in order */
    can_batch_t in = batch_of(0x300, 1);
    can_faults_from_board(&cf, &in, &out, 3100);
    assert_int_equal(out.n, 3);
    assert_int_equal(out.f[0].id, 0x202);
    assert_int_equal(out.f[1].id, 0x203);
    assert_int_equal(out.f[2].id, 0x300);
}

static void test_bus_off_heartbeat_and_encoder(void **st)
{
    (void)st;
    static can_faults_t cf;
    can_faults_init(&cf);
    can_batch_t in = {0}, out;
    can_frame_t f;
    canopen_heartbeat_encode(&f, 2, NMT_STATE_OPERATIONAL);
    (void)can_batch_push(&in, &f);
    canopen_tpdo_encode(&f, 1, 0x0627, 1000, 5);
    (void)can_batch_push(&in, &f);
    can_faults_heartbeat(&cf, 2, false);
    can_faults_encoder_jump(&cf, 1, -250);
    can_faults_to_board(&cf, &in, &out, 0);
    assert_int_equal(out.n, 1); /* the heartbeat is gone */
    uint8_t node;
    uint16_t sw;
    int32_t pos;
    int16_t tq;
    assert_true(canopen_tpdo_decode(&out.f[0], &node, &sw, &pos, &tq));
    assert_int_equal(pos, 750);
    assert_int_equal(sw, 0x0627);
    assert_int_equal(tq, 5);
    can_faults_bus_off(&cf);
    can_faults_to_board(&cf, &in, &out, 1000);
    assert_int_equal(out.n, 1); /* only the bus-off error frame */
    assert_int_equal(out.f[0].id, 0x20000040u);
    can_faults_from_board(&cf, &in, &out, 1000);
    assert_int_equal(out.n, 0);
    can_faults_to_board(&cf, &in, &out, 2000);
    assert_int_equal(out.n, 0); /* silent */
    can_faults_bus_restart(&cf);
    can_faults_heartbeat(&cf, 2, true);
    can_faults_to_board(&cf, &in, &out, 3000);
    assert_int_equal(out.n, 3);
    assert_int_equal(out.f[0].id, 0x20000100u); /* restarted */
    assert_int_equal(out.f[1].id, 0x702);
    assert_int_equal(cf.silenced, 6u); /* 2 + 2 + 2 frames while off */
}

typedef struct {
    char lines[16][96];
    int n;
} log_t;

static void log_fn(void *ctx, int64_t t_us, const char *event)
{
    log_t *l = ctx;
    if (l->n < 16)
        snprintf(l->lines[l->n++], sizeof(l->lines[0]), "%lld %s", (long long)t_us, event);
}

static void test_runner_applies_steps_on_time(void **st)
{
    (void)st;
    static const char text[] = "name r\nduration 1s\n"
                               "at 0.010 estop press\n"
                               "at 0.010 rearm\n"
                               "at 0.020 drive_fault_line low\n"
                               "at 0.030 hand 0 0 -10 over 100ms\n";
    static scenario_t s;
    scn_error_t err;
    assert_int_equal(scenario_parse(&s, text, sizeof(text) - 1, &err), SCN_OK);
    static sim_runner_t r;
    static log_t log;
    sim_params_t p;
    sim_params_default(&p);
    sim_runner_init(&r, &p, &s, false, log_fn, &log);
    can_batch_t out;
    for (int ms = 0; ms < 10; ms++)
        sim_runner_tick(&r, NULL, 0, &out, 1000);
    assert_true(sim_runner_gpio_in(&r) & GPIO_IN_ESTOP_N);
    sim_runner_tick(&r, NULL, 0, &out, 1000); /* t = 10 ms */
    assert_false(sim_runner_gpio_in(&r) & GPIO_IN_ESTOP_N);
    assert_int_equal(log.n, 1); /* the rearm is the host side's: not applied, not logged */
    assert_string_equal(log.lines[0], "10000 inject line=3 at 0.010 estop press");
    for (int ms = 11; ms <= 20; ms++)
        sim_runner_tick(&r, NULL, 0, &out, 1000);
    assert_false(sim_runner_gpio_in(&r) & GPIO_IN_DRIVE_FAULT_N);
    for (int ms = 21; ms < 200; ms++)
        sim_runner_tick(&r, NULL, 0, &out, 1000);
    /* the hand's target went 10 mm down; the unpowered arm followed it */
    const vec3_t d = vec3_sub(sim_device_tip_m(&r.dev), r.home_tip_m);
    assert_float_equal(d.z, -0.010f, 0.002f);
    assert_false(sim_runner_done(&r));
}

/* Held before its start, the device answers (the drives boot and send heartbeats) while the
 * scenario waits at time 0; released, its steps apply on the scenario's own clock. */
static void test_runner_holds_the_scenario_until_released(void **st)
{
    (void)st;
    static const char text[] = "name h\nduration 1s\n"
                               "at 0.000 hand 0 0 0\n"
                               "at 0.010 estop press\n";
    static scenario_t s;
    scn_error_t err;
    assert_int_equal(scenario_parse(&s, text, sizeof(text) - 1, &err), SCN_OK);
    static sim_runner_t r;
    static log_t log;
    sim_params_t p;
    sim_params_default(&p);
    sim_runner_init(&r, &p, &s, false, log_fn, &log);
    sim_runner_hold(&r, true);
    can_batch_t out;
    uint32_t frames = 0;
    for (int ms = 0; ms < 300; ms++) {
        sim_runner_tick(&r, NULL, 0, &out, 1000);
        frames += out.n;
    }
    assert_true(frames >= 3u);                   /* boot-up and heartbeats of three drives */
    assert_int_equal(r.now_us, 0);               /* the scenario waits at 0 */
    assert_int_equal(r.device_us, 300000);
    assert_int_equal(log.n, 0);                  /* no step applied */
    assert_true(sim_runner_gpio_in(&r) & GPIO_IN_ESTOP_N);
    sim_runner_hold(&r, false);
    for (int ms = 0; ms <= 10; ms++)
        sim_runner_tick(&r, NULL, 0, &out, 1000);
    assert_false(sim_runner_gpio_in(&r) & GPIO_IN_ESTOP_N);
    assert_int_equal(log.n, 2);
    assert_string_equal(log.lines[1], "10000 inject line=4 at 0.010 estop press");
}

static void test_watchdog_cuts_power_when_the_kick_stops(void **st)
{
    (void)st;
    static sim_runner_t r;
    static log_t log;
    sim_params_t p;
    sim_params_default(&p);
    sim_runner_init(&r, &p, NULL, true, log_fn, &log);
    can_batch_t out;
    uint32_t kick = 0;
    for (int ms = 0; ms < 50; ms++) { /* kicked every tick: fine */
        kick ^= GPIO_OUT_WDOG_KICK;
        sim_runner_tick(&r, NULL, GPIO_OUT_DRIVE_ENABLE | kick, &out, 1000);
    }
    assert_false(r.wdog_expired);
    int ms = 0;
    while (!r.wdog_expired && ms < 100) { /* the kick stops, DRIVE_ENABLE stays high */
        sim_runner_tick(&r, NULL, GPIO_OUT_DRIVE_ENABLE | kick, &out, 1000);
        ms++;
    }
    assert_in_range(ms, 21, 23); /* 20 ms without a kick */
    assert_non_null(strstr(log.lines[log.n - 1], "watchdog expired"));
    assert_string_equal(log.lines[0], "0 gpio_out DRIVE_ENABLE=1");
    /* sampled every 5 ms, a kick cannot be judged: no trip */
    sim_runner_init(&r, &p, NULL, true, log_fn, &log);
    for (int k = 0; k < 40; k++)
        sim_runner_tick(&r, NULL, GPIO_OUT_DRIVE_ENABLE, &out, 5000);
    assert_false(r.wdog_expired);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drop_rate_follows_the_percentage),
        cmocka_unit_test(test_drop_is_per_frame_not_per_draw),
        cmocka_unit_test(test_delay_holds_frames_in_order),
        cmocka_unit_test(test_bus_off_heartbeat_and_encoder),
        cmocka_unit_test(test_runner_applies_steps_on_time),
        cmocka_unit_test(test_runner_holds_the_scenario_until_released),
        cmocka_unit_test(test_watchdog_cuts_power_when_the_kick_stops),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
