/* The scenario clock of argil-sim and hil-host (sim/scn_clock.h): board ticks while SYNCs come,
 * the wall clock when the bus is silent for longer than 400 ms. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sim/scn_clock.h"

/* A board at 250 ticks/s: 4 ms of wall time per SYNC, yet 1 ms of scenario time each. */
static void test_ticks_follow_syncs(void **st)
{
    (void)st;
    scn_clock_t c;
    scn_clock_init(&c, true, 1000000);
    int64_t wall = 1000000;
    for (int i = 0; i < 250; i++) {
        wall += 4000;
        assert_int_equal(scn_clock_idle(&c, wall - 1000), 0); /* between SYNCs: no step */
        assert_int_equal(scn_clock_sync(&c, wall), SCN_CLOCK_TICK_US);
    }
    assert_int_equal(c.now_us, 250000);   /* one wall second = 250 ms of scenario time */
    assert_int_equal(c.syncs, 250);
    assert_int_equal(c.wall_steps, 0);
    /* A 390 ms stall of the board: still waits. */
    assert_int_equal(scn_clock_idle(&c, wall + 390000), 0);
    assert_int_equal(c.now_us, 250000);
}

/* The board goes silent (bus-off) for 0.8 s: after 400 ms the clock runs on the wall clock,
 * catching up the whole silence in steps of at most 20 ms; the next SYNC brings it back to
 * ticks. */
static void test_silence_falls_back_to_wall_clock(void **st)
{
    (void)st;
    scn_clock_t c;
    scn_clock_init(&c, true, 0);
    assert_int_equal(scn_clock_sync(&c, 1000), 1000u);
    assert_int_equal(scn_clock_idle(&c, 401000), 0);              /* exactly 400 ms: waits */
    assert_false(c.silent);
    uint32_t caught = 0, steps = 0;
    for (uint32_t d; (d = scn_clock_idle(&c, 401001)) > 0; steps++) {
        assert_true(d <= SCN_CLOCK_MAX_STEP_US);
        caught += d;
    }
    assert_true(c.silent);
    assert_int_equal(caught, 400001);                             /* the whole silence */
    assert_int_equal(steps, 21);                                  /* 20 x 20 ms + 1 us */
    assert_int_equal(scn_clock_idle(&c, 402001), 1000u);          /* then at wall rate */
    assert_int_equal(scn_clock_idle(&c, 402001), 0u);             /* no time passed */
    int64_t wall = 402001;
    for (int i = 0; i < 398; i++)
        assert_int_equal(scn_clock_idle(&c, wall += 1000), 1000u);
    assert_int_equal(c.now_us, 1000 + 400001 + 1000 + 398000);
    assert_int_equal(scn_clock_sync(&c, wall + 500), 1000u);
    assert_false(c.silent);
    assert_int_equal(scn_clock_idle(&c, wall + 350500), 0);       /* waits for SYNCs again */
    assert_int_equal(c.wall_steps, 21 + 1 + 398);
}

/* A bus-off the scenario makes: scenario time is wall time from the last SYNC at once, and the
 * SYNCs the board still sends before it sees the bus-off do not restart a wait; so a restart
 * 300 ms later comes 300 ms later. After it, SYNCs drive the clock again. */
static void test_bus_off_follows_the_wall_clock_at_once(void **st)
{
    (void)st;
    scn_clock_t c;
    scn_clock_init(&c, true, 0);
    assert_int_equal(scn_clock_sync(&c, 1000), 1000u);
    scn_clock_wall_while_bus_off(&c, true);
    assert_int_equal(scn_clock_sync(&c, 3000), 0u);               /* a late SYNC: no step */
    uint32_t caught = 0;
    for (uint32_t d; (d = scn_clock_idle(&c, 301000)) > 0;)
        caught += d;
    assert_int_equal(caught, 300000);                             /* the whole 300 ms */
    assert_int_equal(c.now_us, 301000);
    scn_clock_wall_while_bus_off(&c, false);
    assert_int_equal(scn_clock_sync(&c, 302000), 1000u);          /* the bus is back */
    assert_false(c.silent);
    assert_int_equal(scn_clock_idle(&c, 650000), 0);              /* waits for SYNCs again */
    assert_int_equal(c.now_us, 302000);
}

/* A wall-clock-only clock ignores SYNCs and steps by the time passed (at most 20 ms a step). */
static void test_wall_clock_only(void **st)
{
    (void)st;
    scn_clock_t c;
    scn_clock_init(&c, false, 0);
    assert_int_equal(scn_clock_sync(&c, 500), 0u);
    assert_int_equal(scn_clock_idle(&c, 1000), 1000u);
    assert_int_equal(scn_clock_idle(&c, 61000), SCN_CLOCK_MAX_STEP_US); /* then catches up */
    assert_int_equal(scn_clock_idle(&c, 61000), SCN_CLOCK_MAX_STEP_US);
    assert_int_equal(scn_clock_idle(&c, 61000), SCN_CLOCK_MAX_STEP_US);
    assert_int_equal(scn_clock_idle(&c, 61000), 0u);
    assert_int_equal(c.now_us, 61000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ticks_follow_syncs),
        cmocka_unit_test(test_silence_falls_back_to_wall_clock),
        cmocka_unit_test(test_bus_off_follows_the_wall_clock_at_once),
        cmocka_unit_test(test_wall_clock_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
