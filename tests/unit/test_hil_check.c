/* The HIL log checker (sim/hil_check.c): candump and event-log readers refuse bad lines with a
 * reason and a line; each expectation kind passes on a log that shows it and fails, with a
 * latency, on one that does not. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "sim/hil_check.h"

static void test_candump_lines(void **st)
{
    (void)st;
    int64_t t;
    can_frame_t f;
    const char ok[] = "(1700000000.123456) vcan0 201#0F00E803";
    assert_int_equal(hil_candump_line(ok, strlen(ok), &t, &f), HIL_OK);
    assert_int_equal(t, 1700000000123456LL);
    assert_int_equal(f.id, 0x201);
    assert_int_equal(f.len, 4);
    assert_int_equal(f.data[2], 0xE8);
    const char sync[] = "(1.000001)  can0  080#\r";
    assert_int_equal(hil_candump_line(sync, strlen(sync), &t, &f), HIL_OK);
    assert_int_equal(f.len, 0);
    assert_int_equal(t, 1000001);
    const char errf[] = "(2.000000) vcan0 20000040#0000000000000000";
    assert_int_equal(hil_candump_line(errf, strlen(errf), &t, &f), HIL_OK);
    assert_int_equal(f.id, 0x20000040u);
    static const struct {
        const char *line;
        hil_err_t e;
    } bad[] = {
        {"1.000000 vcan0 201#00", HIL_ERR_SYNTAX},          /* no parentheses */
        {"(1.00000) vcan0 201#00", HIL_ERR_SYNTAX},         /* 5 decimals */
        {"(.000000) vcan0 201#00", HIL_ERR_SYNTAX},         /* no seconds */
        {"(1.000000 vcan0 201#00", HIL_ERR_SYNTAX},         /* no ')' */
        {"(1.000000)vcan0 201#00", HIL_ERR_SYNTAX},         /* no blank */
        {"(1.000000) vcan0", HIL_ERR_SYNTAX},               /* no frame */
        {"(1.000000) averyveryverylongname 201#00", HIL_ERR_SYNTAX},
        {"(1.000000) vcan0 2G1#00", HIL_ERR_FRAME},         /* not hex */
        {"(1.000000) vcan0 201", HIL_ERR_FRAME},            /* no '#' */
        {"(1.000000) vcan0 2010#00", HIL_ERR_FRAME},        /* 4 digits */
        {"(1.000000) vcan0 801#00", HIL_ERR_FRAME},         /* > 0x7FF */
        {"(1.000000) vcan0 12345678#00", HIL_ERR_FRAME},    /* extended, not an error frame */
        {"(1.000000) vcan0 201#R", HIL_ERR_FRAME},          /* remote */
        {"(1.000000) vcan0 201##100", HIL_ERR_FRAME},       /* CAN FD */
        {"(1.000000) vcan0 201#0", HIL_ERR_FRAME},          /* odd digits */
        {"(1.000000) vcan0 201#000000000000000000", HIL_ERR_FRAME}, /* 9 bytes */
        {"(1.000000) vcan0 201#0Z", HIL_ERR_FRAME},
        {"(1.000000) vcan0 123456789#00", HIL_ERR_FRAME},   /* 9 digits */
    };
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        const hil_err_t e = hil_candump_line(bad[i].line, strlen(bad[i].line), &t, &f);
        if (e != bad[i].e)
            fail_msg("'%s': got %d want %d", bad[i].line, e, bad[i].e);
    }
    hil_obs_t o;
    hil_obs_init(&o);
    uint32_t line = 0;
    const char order[] = "(2.000000) vcan0 080#\n\n(1.000000) vcan0 080#\n";
    assert_int_equal(hil_obs_add_candump(&o, order, strlen(order), &line), HIL_ERR_ORDER);
    assert_int_equal(line, 3);
    assert_string_equal(hil_err_name(HIL_ERR_ORDER), "timestamp earlier than the line before");
    hil_obs_free(&o);
}

static scenario_t scn;

static void load_scn(void)
{
    static const char text[] = "name t\nduration 3s\n"
                               "at 1.0 estop press\n"                 /* line 3 */
                               "at 2.0 rearm\n"                       /* line 4 */
                               "expect at 1.0 torque_zero within 1ms\n"
                               "expect at 1.0 quick_stop within 1ms\n"
                               "expect at 1.0 fault within 2ms\n"
                               "expect at 1.0 no_torque_frames until rearm\n"
                               "expect at 0.5 running until 0.9\n"
                               "expect at 1.0 safe until end\n"
                               "expect at 2.0 enabled within 300ms\n"
                               "expect at 0.0 torque_nonzero within 1s\n";
    scn_error_t err;
    assert_int_equal(scenario_parse(&scn, text, sizeof(text) - 1, &err), SCN_OK);
}

static void test_event_logs(void **st)
{
    (void)st;
    load_scn();
    static const struct {
        const char *text;
        hil_err_t e;
        uint32_t line;
    } cases[] = {
        {"(5.000000) start scenario t\n(5.5) end\n", HIL_ERR_SYNTAX, 2},
        {"(5.000000) start scenario t\n(4.000000) end\n", HIL_ERR_ORDER, 2},
        {"(5.000000) start scenario t\n(6.000000) dance\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) inject line=9 x\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) inject line=x\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=2\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=1x\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario other\n", HIL_ERR_SCENARIO, 1},
        {"(5.000000) start scenario tt\n", HIL_ERR_SCENARIO, 1},
        {"(5.000000) note hello\n", HIL_ERR_NO_START, 0},
        {"(5.000000)start\n", HIL_ERR_SYNTAX, 1},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.3\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark 1.300000\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark at x.000000\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.3000001\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark at 123456.000000\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.300000 t=1.300\n", HIL_OK, 0},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.300000 sync=1300 t=1.3\n", HIL_OK, 0},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.300000 sync=x\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) mark at 1.300000 sync=12x\n", HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=0 prev=(5.500000)\n",
         HIL_OK, 0},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=0 prev=(7.000000)\n",
         HIL_ERR_ORDER, 2},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=0 prev=5.5\n",
         HIL_ERR_EVENT, 2},
        {"(5.000000) start scenario t\n(6.000000) gpio_out DRIVE_ENABLE=0 prev=(5.500000)x\n",
         HIL_ERR_EVENT, 2},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        hil_obs_t o;
        hil_obs_init(&o);
        uint32_t line = 0;
        const hil_err_t e = hil_obs_add_events(&o, &scn, cases[i].text, strlen(cases[i].text),
                                               &line);
        if (e != cases[i].e || line != cases[i].line)
            fail_msg("case %zu: got %d line %u, want %d line %u", i, e, line, cases[i].e,
                     cases[i].line);
        assert_true(strlen(hil_err_name(e)) > 1);
        hil_obs_free(&o);
    }
}

/* A synthetic run at 1 kHz: RPDOs for 3 drives each ms at +0.5 ms; torque 100 ‰ and ENABLE_OP
 * until the e-stop at 1.0 s is seen `react_us` later, then QUICK_STOP with torque 0; DRIVE_ENABLE
 * falls at +1 ms; re-enabled at 2.050 s. */
static void synth(hil_obs_t *o, int64_t react_us, bool torque_after_off)
{
    hil_obs_init(o);
    const int64_t t0 = 10000000;
    const char ev[] = "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
                      "(11.001000) gpio_out DRIVE_ENABLE=0 t=1.001\n"
                      "(12.000000) inject line=4 rearm\n(12.050000) gpio_out DRIVE_ENABLE=1\n";
    uint32_t line;
    assert_int_equal(hil_obs_add_events(o, &scn, ev, strlen(ev), &line), HIL_OK);
    for (int64_t ms = 0; ms < 3000; ms++) {
        const int64_t t = t0 + ms * 1000 + 500;
        const bool off = t >= t0 + 1000000 + react_us && t < t0 + 2050000;
        for (uint8_t n = 1; n <= 3; n++) {
            can_frame_t f;
            int16_t tq = off ? 0 : 100;
            if (torque_after_off && ms == 1500)
                tq = 5;
            canopen_rpdo_encode(&f, n, off ? CIA402_CW_QUICK_STOP : CIA402_CW_ENABLE_OP, tq);
            assert_int_equal(hil_obs_push_frame(o, t, &f), HIL_OK);
        }
    }
}

static void test_expectations_pass_and_fail(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    hil_result_t r;
    synth(&o, 0, false); /* reacts in the same tick */
    for (uint32_t i = 0; i < scn.n_expects; i++) {
        hil_check_expect(&scn, &o, i, &r);
        if (!r.pass)
            fail_msg("expectation %u failed: %s", i, r.msg);
    }
    hil_check_expect(&scn, &o, 0, &r);
    assert_int_equal(r.observed_us, 0);      /* the board's first RPDO after it is zero */
    assert_non_null(strstr(r.msg, "first RPDO at +0.500 ms"));
    hil_check_expect(&scn, &o, 2, &r);
    assert_int_equal(r.observed_us, 1000);   /* DRIVE_ENABLE fell at +1 ms */
    hil_check_expect(&scn, &o, 6, &r);
    assert_int_equal(r.observed_us, 50500);  /* enabled again 50.5 ms after the rearm */
    hil_obs_free(&o);

    synth(&o, 5000, false); /* reacts 5 ms late: the 1 ms bounds fail, with the latency */
    hil_check_expect(&scn, &o, 0, &r);
    assert_false(r.pass);
    assert_int_equal(r.observed_us, 5500);
    hil_check_expect(&scn, &o, 1, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "no QUICK_STOP"));
    hil_check_expect(&scn, &o, 2, &r);
    assert_false(r.pass);
    hil_check_expect(&scn, &o, 3, &r);       /* torque frames after the e-stop */
    assert_false(r.pass);
    assert_int_equal(r.observed_us, 500);
    hil_obs_free(&o);

    synth(&o, 0, true); /* one torque frame in the middle of the fault */
    hil_check_expect(&scn, &o, 3, &r);
    assert_false(r.pass);
    assert_int_equal(r.observed_us, 500500);
    hil_check_expect(&scn, &o, 5, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "after the drives went off"));
    hil_check_expect(&scn, &o, 0, &r);       /* zero torque did not hold */
    assert_false(r.pass);
    hil_obs_free(&o);

    /* running fails when the drives go off inside its window */
    static const char text[] = "name t\nduration 3s\nat 1.0 estop press\nat 2.0 rearm\n"
                               "expect at 0.5 running until 1.5\n"
                               "expect at 1.0 fault within 2ms\n";
    scn_error_t err;
    scenario_t s2;
    assert_int_equal(scenario_parse(&s2, text, sizeof(text) - 1, &err), SCN_OK);
    synth(&o, 0, false);
    hil_check_expect(&s2, &o, 0, &r);
    assert_false(r.pass);
    assert_int_equal(r.observed_us, 500500);
    hil_obs_free(&o);
    /* fault fails when DRIVE_ENABLE never drops */
    hil_obs_init(&o);
    const char ev[] = "(10.000000) start scenario t\n(10.000100) gpio_out DRIVE_ENABLE=1\n";
    uint32_t line;
    assert_int_equal(hil_obs_add_events(&o, &s2, ev, strlen(ev), &line), HIL_OK);
    hil_check_expect(&s2, &o, 1, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "never went low"));
    hil_obs_free(&o);
}

/* A slow board, as under emulation: a tick every tick_us of wall time from 10 s + phase_us,
 * each the 3 drives' RPDOs then its SYNC 200 us later (as argil-board sends them). The first
 * tick after the e-stop at 1.0 s is in flight (inputs read before); the RPDOs go QUICK_STOP with
 * torque 0 react_ticks ticks after it, DRIVE_ENABLE low 100 us after them. After the rearm at
 * 2.0 s DRIVE_ENABLE rises and the drives come back on enable_ticks ticks after the first. */
static void synth_ticks(hil_obs_t *o, int64_t tick_us, int64_t phase_us, int react_ticks,
                        int enable_ticks)
{
    hil_obs_init(o);
    const int64_t t0 = 10000000, estop = t0 + 1000000, rearm = t0 + 2000000;
    int64_t t_off = -1, t_on = -1;
    int since_estop = 0, since_rearm = 0;
    for (int64_t t = t0 + phase_us; t < t0 + 3000000; t += tick_us) {
        since_estop += t > estop;
        since_rearm += t > rearm;
        if (since_estop == react_ticks + 1 && t_off < 0)
            t_off = t;
        if (since_rearm == enable_ticks + 1 && t_on < 0)
            t_on = t;
    }
    assert_true(t_off > 0 && t_on > 0);
    char ev[256];
    snprintf(ev, sizeof(ev),
             "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
             "(%lld.%06lld) gpio_out DRIVE_ENABLE=0\n(12.000000) inject line=4 rearm\n"
             "(%lld.%06lld) gpio_out DRIVE_ENABLE=1\n",
             (long long)((t_off + 100) / 1000000), (long long)((t_off + 100) % 1000000),
             (long long)((t_on - 100) / 1000000), (long long)((t_on - 100) % 1000000));
    uint32_t line;
    assert_int_equal(hil_obs_add_events(o, &scn, ev, strlen(ev), &line), HIL_OK);
    for (int64_t t = t0 + phase_us; t < t0 + 3000000; t += tick_us) {
        can_frame_t f;
        const bool off = t >= t_off && t < t_on;
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_rpdo_encode(&f, n, off ? CIA402_CW_QUICK_STOP : CIA402_CW_ENABLE_OP,
                                off ? 0 : 100);
            assert_int_equal(hil_obs_push_frame(o, t, &f), HIL_OK);
        }
        f = (can_frame_t){.id = CANOPEN_COB_SYNC, .len = 0};
        assert_int_equal(hil_obs_push_frame(o, t + 200, &f), HIL_OK);
    }
    assert_true(o->n_syncs > 0);
}

/* A rearm at 1 kHz with SYNCs: the board answers each drive statusword react_ticks later with
 * the next controlword (0x06, 0x07, 0x0F), each drive answers a controlword lag_ticks later with
 * its next state (TPDO after each SYNC). */
static void synth_enable(hil_obs_t *o, int react_ticks, int lag_ticks)
{
    hil_obs_init(o);
    const int64_t t0 = 10000000, rearm = t0 + 2000000;
    const char ev[] = "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
                      "(11.001000) gpio_out DRIVE_ENABLE=0\n(12.000000) inject line=4 rearm\n"
                      "(12.000900) gpio_out DRIVE_ENABLE=1\n";
    uint32_t line;
    assert_int_equal(hil_obs_add_events(o, &scn, ev, strlen(ev), &line), HIL_OK);
    static const uint16_t cws[4] = {CIA402_CW_DISABLE_VOLTAGE, 0x06u, 0x07u, CIA402_CW_ENABLE_OP};
    static const cia402_state_t states[4] = {CIA402_SWITCH_ON_DISABLED, CIA402_READY_TO_SWITCH_ON,
                                             CIA402_SWITCHED_ON, CIA402_OPERATION_ENABLED};
    int cw_step = 0, drive_step = 0;
    int64_t next_cw_tick = -1, next_state_tick = -1;
    for (int64_t tick = 0; tick < 3000; tick++) {
        const int64_t t = t0 + tick * 1000 + 500;
        if (t > rearm && next_cw_tick < 0 && cw_step == 0)
            next_cw_tick = tick + react_ticks;
        if (cw_step < 3 && tick == next_cw_tick) {
            cw_step++;
            next_state_tick = tick + lag_ticks;
        }
        if (drive_step < cw_step && tick == next_state_tick) {
            drive_step = cw_step;
            if (cw_step < 3)
                next_cw_tick = tick + react_ticks;
        }
        can_frame_t f;
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_rpdo_encode(&f, n, t < rearm ? CIA402_CW_QUICK_STOP : cws[cw_step], 0);
            assert_int_equal(hil_obs_push_frame(o, t, &f), HIL_OK);
        }
        f = (can_frame_t){.id = CANOPEN_COB_SYNC, .len = 0};
        assert_int_equal(hil_obs_push_frame(o, t + 200, &f), HIL_OK);
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_tpdo_encode(&f, n, cia402_statusword(states[drive_step]), 0, 0);
            assert_int_equal(hil_obs_push_frame(o, t + 300, &f), HIL_OK);
        }
    }
}

/* "enabled within" bounds the board's ticks: the ticks its controlwords waited for the drives'
 * answers are the drives' (a lagging arm stand-in), the rest the board's. */
static void test_enabled_counts_the_boards_ticks_not_the_drives(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    hil_result_t r;
    synth_enable(&o, 2, 200);  /* drives answer 200 ticks late: 406 ticks in all */
    hil_check_expect(&scn, &o, 6, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    assert_true(r.observed_ticks >= 2 && r.observed_ticks <= 9); /* 3 x 2, as SYNCs fall */
    assert_true(r.observed_us > 400000);
    assert_non_null(strstr(r.msg, "406 ticks: the drives answered in 402, the board took 4"));
    hil_obs_free(&o);

    synth_enable(&o, 110, 1);  /* the board waits 110 ticks after each answer: 332 of its own */
    hil_check_expect(&scn, &o, 6, &r);
    assert_false(r.pass);
    assert_true(r.observed_ticks > 300);
    hil_obs_free(&o);

    synth_enable(&o, 95, 30);  /* 285 of the board's, 60 of the drives': passes */
    hil_check_expect(&scn, &o, 6, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    hil_obs_free(&o);
}

/* A run whose step at 1.0 was logged 100 ticks late (the arm stand-in lagging) and whose
 * drives go off at off_ms after the start, at 1 kHz with a SYNC each tick. */
static void synth_lagged_end(hil_obs_t *o, const scenario_t *sc, int64_t off_ms)
{
    hil_obs_init(o);
    const char ev[] = "(10.000000) start scenario e\n(11.100000) inject line=3 at 1.0 can_drop\n";
    uint32_t line;
    assert_int_equal(hil_obs_add_events(o, sc, ev, strlen(ev), &line), HIL_OK);
    for (int64_t ms = 0; ms < 3300; ms++) {
        const int64_t t = 10000000 + ms * 1000 + 500;
        can_frame_t f;
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_rpdo_encode(&f, n, ms < off_ms ? CIA402_CW_ENABLE_OP : CIA402_CW_QUICK_STOP, 0);
            assert_int_equal(hil_obs_push_frame(o, t, &f), HIL_OK);
        }
        f = (can_frame_t){.id = CANOPEN_COB_SYNC, .len = 0};
        assert_int_equal(hil_obs_push_frame(o, t + 200, &f), HIL_OK);
    }
}

/* A window "until end" stops at the rig's end (its clock's last SYNC), not 100 ticks later
 * where a time counted from a lagged injection puts it: there the rig was shutting down. */
static void test_until_end_stops_at_the_rigs_end(void **st)
{
    (void)st;
    static const char text[] = "name e\nduration 3s\nat 1.0 can_drop 1% seed 1\n"
                               "expect at 1.0 running until end\n";
    static scenario_t sc;
    scn_error_t err;
    assert_int_equal(scenario_parse(&sc, text, sizeof(text) - 1, &err), SCN_OK);
    hil_obs_t o;
    hil_result_t r;
    synth_lagged_end(&o, &sc, 3050);   /* off 50 ticks after the end: not the board's doing */
    hil_check_expect(&sc, &o, 0, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    hil_obs_free(&o);
    synth_lagged_end(&o, &sc, 2950);   /* off 50 ticks before it: a failure */
    hil_check_expect(&sc, &o, 0, &r);
    assert_false(r.pass);
    hil_obs_free(&o);
}

/* With SYNCs in the log, bounds count board ticks: a board at 333 ticks/s that reacts one tick
 * after the one in flight meets "within 1ms" though 3 ms of wall time passed; one more fails. */
static void test_bounds_in_ticks(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    hil_result_t r;
    synth_ticks(&o, 3000, 1050, 1, 200);     /* tick in flight at 11.000050 */
    for (uint32_t i = 0; i < scn.n_expects; i++) {
        hil_check_expect(&scn, &o, i, &r);
        if (!r.pass)
            fail_msg("expectation %u failed: %s", i, r.msg);
    }
    hil_check_expect(&scn, &o, 0, &r);       /* torque_zero within 1ms */
    assert_int_equal(r.observed_ticks, 1);
    assert_int_equal(r.observed_us, 3050);   /* the next tick's RPDOs */
    assert_non_null(strstr(r.msg, "3.050 ms, 1 tick"));
    assert_non_null(strstr(r.msg, "bound 1 ticks = 1.000 ms at 1 kHz"));
    hil_check_expect(&scn, &o, 1, &r);       /* quick_stop within 1ms */
    assert_int_equal(r.observed_ticks, 1);
    hil_check_expect(&scn, &o, 2, &r);       /* fault within 2ms: DRIVE_ENABLE low in that tick */
    assert_int_equal(r.observed_ticks, 1);
    assert_int_equal(r.observed_us, 3150);
    hil_check_expect(&scn, &o, 6, &r);       /* enabled within 300ms: 200 ticks, 600 ms wall */
    assert_int_equal(r.observed_ticks, 200);
    assert_true(r.observed_us > 595000 && r.observed_us < 610000);
    hil_obs_free(&o);

    synth_ticks(&o, 3000, 1050, 2, 301);     /* one tick late; back on after 301 ticks */
    hil_check_expect(&scn, &o, 0, &r);
    assert_false(r.pass);
    assert_int_equal(r.observed_ticks, 2);
    hil_check_expect(&scn, &o, 1, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "no QUICK_STOP within 1 ticks"));
    hil_check_expect(&scn, &o, 2, &r);       /* 2 ticks meet "within 2ms" */
    assert_true(r.pass);
    assert_int_equal(r.observed_ticks, 2);
    hil_check_expect(&scn, &o, 3, &r);       /* no_torque_frames: the late tick had torque */
    assert_false(r.pass);
    hil_check_expect(&scn, &o, 6, &r);
    assert_false(r.pass);
    hil_obs_free(&o);

    /* At 1 kHz, ticks aligned with the injection, both measures agree: 1 tick = 1 ms. */
    synth_ticks(&o, 1000, 0, 0, 100);
    hil_check_expect(&scn, &o, 0, &r);
    assert_true(r.pass);
    assert_int_equal(r.observed_ticks, 1);
    assert_int_equal(r.observed_us, 1000);
    hil_obs_free(&o);
}

/* A rig whose scenario clock follows the board's ticks logs "mark at T" when it passes T: an
 * expectation at T with no step there is anchored at the mark, not at start + T. Here the
 * board ran at half speed: scenario time 0.5-0.9 s was wall time 11.2-11.5 s, after the e-stop
 * at 11.0 s, so "running" over that window fails; anchored at start + T it would pass. */
static void test_marks_anchor_expectations(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    hil_result_t r;
    synth(&o, 1000, false);
    hil_check_expect(&scn, &o, 4, &r);       /* running 0.5 until 0.9, at start + T */
    assert_true(r.pass);
    const char marks[] = "(11.200000) mark at 0.500000 t=0.500\n"
                         "(11.200500) mark at 0.500000 t=0.501\n" /* a repeat: first counts */
                         "(11.500000) mark at 0.900000 t=0.900\n";
    uint32_t line = 0;
    hil_obs_t m;
    hil_obs_init(&m);
    const char ev[] = "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
                      "(11.001000) gpio_out DRIVE_ENABLE=0 t=1.001\n";
    assert_int_equal(hil_obs_add_events(&m, &scn, ev, strlen(ev), &line), HIL_OK);
    assert_int_equal(hil_obs_add_events(&m, &scn, marks, strlen(marks), &line), HIL_OK);
    assert_int_equal(m.n_marks, 2);
    assert_int_equal(m.mark_us[0], 11200000);
    assert_int_equal(m.mark_t_us[1], 900000);
    for (size_t k = 0; k < o.n_frames; k++)
        assert_int_equal(hil_obs_push_frame(&m, o.frame[k].t_us, &o.frame[k].f), HIL_OK);
    hil_check_expect(&scn, &m, 4, &r);
    assert_false(r.pass);
    if (strstr(r.msg, "controlword 0x0002") == NULL)
        fail_msg("%s", r.msg);
    hil_obs_free(&m);
    hil_obs_free(&o);
}

/* At 333 ticks/s: a mark with sync=N is anchored at the N-th SYNC after the start line however
 * late the line itself was written; a DRIVE_ENABLE edge logged with the sample before it may
 * have happened just after that sample; a host-side step's bound gets the link's ticks. */
static void test_sync_marks_gpio_window_link_ticks(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    hil_result_t r;
    synth_ticks(&o, 3000, 1050, 2, 200);     /* reacts one tick late: fault in 2 ticks */
    /* SYNCs at 10.001250 + k * 3 ms: the 100th after the start is at 10.298250. Marks written
     * late (at 11.5 s, after the e-stop) with their SYNC anchor "running 0.5 until 0.9" there. */
    const char mark[] = "(11.500000) mark at 0.500000 sync=100 t=0.5\n"
                        "(11.500001) mark at 0.900000 sync=120 t=0.9\n";
    uint32_t line = 0;
    assert_int_equal(hil_obs_add_events(&o, &scn, mark, strlen(mark), &line), HIL_OK);
    assert_int_equal(o.mark_sync[0], 100);
    hil_check_expect(&scn, &o, 4, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    assert_non_null(strstr(r.msg, "held for 60.000 ms"));
    o.mark_sync[0] = o.mark_sync[1] = 0;     /* by the lines' own times: after the e-stop */
    hil_check_expect(&scn, &o, 4, &r);
    assert_false(r.pass);
    /* fault within 2ms passed with the edge at its sample; a sample taken a tick later with
     * the one before in the bound still passes, one without fails */
    hil_check_expect(&scn, &o, 2, &r);
    assert_true(r.pass);
    hil_obs_t g;
    hil_obs_init(&g);
    char ev[320];
    int64_t t_low = -1;
    for (size_t k = 0; k < o.n_gpio; k++)
        if (!o.gpio[k].drive_enable)
            t_low = o.gpio[k].t_us;
    assert_true(t_low > 0);
    const int64_t late = t_low + 6000;       /* seen two samples (6 ms, 2 ticks) later */
    snprintf(ev, sizeof(ev),
             "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
             "(%lld.%06lld) gpio_out DRIVE_ENABLE=0 prev=(%lld.%06lld)\n",
             (long long)(late / 1000000), (long long)(late % 1000000),
             (long long)((t_low - 100) / 1000000), (long long)((t_low - 100) % 1000000));
    assert_int_equal(hil_obs_add_events(&g, &scn, ev, strlen(ev), &line), HIL_OK);
    assert_int_equal(g.gpio[0].prev_us, t_low - 100);
    for (size_t k = 0; k < o.n_frames; k++)
        assert_int_equal(hil_obs_push_frame(&g, o.frame[k].t_us, &o.frame[k].f), HIL_OK);
    hil_check_expect(&scn, &g, 2, &r);
    assert_true(r.pass);
    g.gpio[0].prev_us = -1;                   /* without it the late sample fails the bound */
    hil_check_expect(&scn, &g, 2, &r);
    assert_false(r.pass);
    hil_obs_free(&g);
    /* The e-stop is device side: link ticks do not widen its bound ... */
    o.link_ticks = 6;
    hil_check_expect(&scn, &o, 0, &r);       /* torque_zero within 1ms, 2 ticks: fails */
    assert_false(r.pass);
    hil_obs_free(&o);
}

/* A tick writes DRIVE_ENABLE after its SYNC: a board whose RPDOs go off in the bound's last tick
 * and whose DRIVE_ENABLE falls right after that tick's SYNC meets "fault within 2ms"; one that
 * drops it a tick later does not. */
static void test_gpio_edge_of_the_last_tick_follows_its_sync(void **st)
{
    (void)st;
    load_scn();
    hil_obs_t o;
    synth_ticks(&o, 3000, 1050, 2, 200); /* 333 ticks/s; RPDOs off in the bound's last tick */
    int64_t t_low = -1;
    for (size_t k = 0; k < o.n_gpio; k++)
        if (!o.gpio[k].drive_enable)
            t_low = o.gpio[k].t_us - 100; /* synth_ticks logs it 100 us after the RPDOs */
    assert_true(t_low > 0);
    for (int late = 0; late < 2; late++) {
        hil_obs_t g;
        hil_obs_init(&g);
        /* the edge between two samples 50 us apart just after that tick's SYNC (+200 us), or
         * a tick (3 ms) later */
        const int64_t seen = t_low + 300 + late * 3000, prev = seen - 50;
        char ev[320];
        snprintf(ev, sizeof(ev),
                 "(10.000000) start scenario t\n(11.000000) inject line=3 estop\n"
                 "(%lld.%06lld) gpio_out DRIVE_ENABLE=0 prev=(%lld.%06lld)\n",
                 (long long)(seen / 1000000), (long long)(seen % 1000000),
                 (long long)(prev / 1000000), (long long)(prev % 1000000));
        uint32_t line = 0;
        assert_int_equal(hil_obs_add_events(&g, &scn, ev, strlen(ev), &line), HIL_OK);
        for (size_t k = 0; k < o.n_frames; k++)
            assert_int_equal(hil_obs_push_frame(&g, o.frame[k].t_us, &o.frame[k].f), HIL_OK);
        hil_result_t r;
        hil_check_expect(&scn, &g, 2, &r); /* fault within 2ms */
        if (late == 0 && !r.pass)
            fail_msg("%s", r.msg);
        if (late == 1)
            assert_false(r.pass);
        hil_obs_free(&g);
    }
    hil_obs_free(&o);
}

/* A 1 kHz log from 10 s: three drives beating every 100 ticks (drive 2 skips the beats in
 * skip[], as numbered from 1), RPDOs ENABLE_OP with torque until tick off_tick (0: never) and
 * QUICK_STOP with torque 0 after, or torque back on from tick on_again (0: never). */
static void synth_beats(hil_obs_t *o, const scenario_t *s, int ticks, const int *skip, int n_skip,
                        int off_tick, int on_again)
{
    hil_obs_init(o);
    uint32_t line;
    const char ev[] = "(10.000000) start scenario hb\n";
    assert_int_equal(hil_obs_add_events(o, s, ev, strlen(ev), &line), HIL_OK);
    for (int k = 1; k <= ticks; k++) {
        const int64_t t = 10000000 + (int64_t)k * 1000;
        can_frame_t f;
        if (k % 100 == 50) {
            bool skipped = false;
            for (int i = 0; i < n_skip; i++)
                skipped |= skip[i] == k / 100 + 1;
            for (uint8_t n = 1; n <= 3; n++) {
                canopen_heartbeat_encode(&f, n, NMT_STATE_OPERATIONAL);
                if (n != 2 || !skipped)
                    assert_int_equal(hil_obs_push_frame(o, t + 100, &f), HIL_OK);
            }
        }
        const bool off = off_tick > 0 && k >= off_tick && (on_again == 0 || k < on_again);
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_rpdo_encode(&f, n, off ? CIA402_CW_QUICK_STOP : CIA402_CW_ENABLE_OP,
                                off ? 0 : 100);
            assert_int_equal(hil_obs_push_frame(o, t + 300, &f), HIL_OK);
        }
        f = (can_frame_t){.id = CANOPEN_COB_SYNC, .len = 0};
        assert_int_equal(hil_obs_push_frame(o, t + 500, &f), HIL_OK);
    }
}

/* synth_beats' 2.5 s log judged by s's first expectation. */
static void judge_beats(const scenario_t *s, const int *skip, int n_skip, int off_tick,
                        int on_again, hil_result_t *r)
{
    hil_obs_t o;
    synth_beats(&o, s, 2500, skip, n_skip, off_tick, on_again);
    hil_check_expect(s, &o, 0, r);
    hil_obs_free(&o);
}

/* heartbeat_supervised holds the board to the consumer rule from what was on the bus: one lost
 * heartbeat ridden, two in a row off at 250 (+2) ticks, and off stays off. */
static void test_heartbeat_supervised(void **st)
{
    (void)st;
    static const char text[] = "name hb\nduration 3s\nat 0.5 can_drop 10% seed 7\n"
                               "expect at 0.5 heartbeat_supervised until end\n";
    static scenario_t s;
    scn_error_t err;
    assert_int_equal(scenario_parse(&s, text, sizeof(text) - 1, &err), SCN_OK);
    assert_int_equal(s.expect[0].kind, SCN_EXP_HEARTBEAT_SUPERVISED);
    hil_result_t r;
    /* beat 8 (tick 750) lost: a 200-tick gap, on throughout */
    static const int one[] = {8}, two[] = {8, 9};
    judge_beats(&s, one, 1, 0, 0, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    assert_int_equal(r.tolerated, 1);
    /* the same log with the board off at tick 900 (heartbeat 250 ticks old at most): spurious */
    judge_beats(&s, one, 1, 900, 0, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "under 250 ticks old"));
    /* beats 8 and 9 lost: the last drive-2 beat on the bus came in tick 650, read in it; the
     * board's age passes 250 in tick 901, whose RPDOs follow 251 SYNCs after the beat */
    judge_beats(&s, two, 2, 901, 0, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    assert_int_equal(r.observed_ticks, 251);
    /* ... off only at tick 905: 255 SYNCs, past the bound (251 + a late read + log order) */
    judge_beats(&s, two, 2, 905, 0, &r);
    assert_false(r.pass);
    assert_non_null(strstr(r.msg, "still on"));
    /* ... off at 901 but torque again at 1500: the fault must latch */
    judge_beats(&s, two, 2, 901, 1500, &r);
    assert_false(r.pass);
}

/* An expectation time after a step counts board ticks from that step's logged injection: a
 * host that performed "link lost" 30 ticks after argil-sim's clock passed it gets its 80 ticks
 * from when it did, not from argil-sim's mark. */
static void test_times_after_a_step_count_from_its_injection(void **st)
{
    (void)st;
    static const char text[] = "name lost\nduration 3s\nat 1.0 link lost\n"
                               "expect at 1.080 no_torque_frames until end\n";
    static scenario_t s;
    scn_error_t err;
    assert_int_equal(scenario_parse(&s, text, sizeof(text) - 1, &err), SCN_OK);
    hil_obs_t o;
    hil_obs_init(&o);
    o.link_ticks = 6;
    for (int k = 1; k <= 2000; k++) {
        const int64_t t = 10000000 + (int64_t)k * 1000;
        can_frame_t f;
        for (uint8_t n = 1; n <= 3; n++) {
            canopen_rpdo_encode(&f, n, CIA402_CW_ENABLE_OP, k < 1030 + 76 ? 100 : 0);
            assert_int_equal(hil_obs_push_frame(&o, t + 300, &f), HIL_OK);
        }
        f = (can_frame_t){.id = CANOPEN_COB_SYNC, .len = 0};
        assert_int_equal(hil_obs_push_frame(&o, t + 500, &f), HIL_OK);
    }
    /* hil-host's step just after the 1030th SYNC; argil-sim's mark at the 1080th */
    const char ev[] = "(10.000000) start scenario lost\n"
                      "(11.030600) inject line=3 link lost\n"
                      "(11.080600) mark at 1.080000 sync=1080\n";
    uint32_t line;
    assert_int_equal(hil_obs_add_events(&o, &s, ev, strlen(ev), &line), HIL_OK);
    hil_result_t r;
    hil_check_expect(&s, &o, 0, &r);
    if (!r.pass)
        fail_msg("%s", r.msg);
    /* torque until 5 ticks later than the board's 70 + link 6 after the step: caught */
    for (size_t k = 0; k < o.n_frames; k++) {
        uint8_t node;
        uint16_t cw;
        int16_t tq;
        if (canopen_rpdo_decode(&o.frame[k].f, &node, &cw, &tq) &&
            o.frame[k].t_us < 10000000 + (1030 + 80 + 6 + 5) * 1000)
            canopen_rpdo_encode(&o.frame[k].f, node, cw, 100);
    }
    hil_check_expect(&s, &o, 0, &r);
    assert_false(r.pass);
    hil_obs_free(&o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_candump_lines),
        cmocka_unit_test(test_event_logs),
        cmocka_unit_test(test_expectations_pass_and_fail),
        cmocka_unit_test(test_bounds_in_ticks),
        cmocka_unit_test(test_marks_anchor_expectations),
        cmocka_unit_test(test_sync_marks_gpio_window_link_ticks),
        cmocka_unit_test(test_gpio_edge_of_the_last_tick_follows_its_sync),
        cmocka_unit_test(test_heartbeat_supervised),
        cmocka_unit_test(test_times_after_a_step_count_from_its_injection),
        cmocka_unit_test(test_enabled_counts_the_boards_ticks_not_the_drives),
        cmocka_unit_test(test_until_end_stops_at_the_rigs_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
