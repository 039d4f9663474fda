/* How a tick is timed: the board core counts a tick past its period as a deadline miss unless
 * the platform says it could not time it (preempted on a CPU-time clock), and the simulated
 * HAL says so when the machine took the core from the ticking thread. */
#define _GNU_SOURCE /* sched_setaffinity, CPU_SET */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <string.h>
#include <time.h>

#include "firmware/core/board.h"
#include "firmware/hal/hal_sim.h"
#include "shared/gpio_lines.h"

static board_t g_board;
static board_out_t g_out;

static void tick(uint32_t prev_compute_ns, bool preempted)
{
    board_in_t in;
    memset(&in, 0, sizeof(in));
    in.gpio_in = GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N;
    in.prev_compute_ns = prev_compute_ns;
    in.prev_compute_preempted = preempted;
    board_tick(&g_board, &in, &g_out);
}

static void test_a_timed_tick_past_its_period_is_a_miss_a_preempted_one_is_not(void **st)
{
    (void)st;
    board_cfg_t cfg;
    board_cfg_default(&cfg); /* 1 kHz: a 1 ms period */
    assert_int_equal(board_init(&g_board, &cfg), ARGIL_OK);
    tick(0, false);
    tick(5000, false);      /* 5 µs: on time */
    tick(1500000, false);   /* 1.5 ms, timed: a miss */
    assert_int_equal(g_board.stats.deadline_misses, 1);
    assert_int_equal(g_board.stats.worst_compute_ns, 1500000);
    assert_int_equal(g_board.rt.overruns, 1);
    tick(2500000, true);    /* 2.5 ms charged while preempted: not timed */
    assert_int_equal(g_board.stats.deadline_miss_tick[0], 2); /* the 1.5 ms one, by number */
    tick(2500000, true);
    tick(2500000, true);    /* three in a row would fault the board if they counted */
    tick(200000, true);     /* preempted, but within the period */
    assert_int_equal(g_board.stats.deadline_misses, 1);
    assert_int_equal(g_board.stats.preempted_ticks, 4);
    /* … the ones charged past the period are kept by tick number, for a rerun to compare */
    assert_int_equal(g_board.stats.preempted_over_period, 3);
    assert_int_equal(g_board.stats.preempted_over_tick[0], 3);
    assert_int_equal(g_board.stats.preempted_over_tick[2], 5);
    assert_int_equal(g_board.stats.worst_compute_ns, 1500000);
    assert_int_equal(g_board.rt.overruns, 1);
    assert_int_equal(g_board.rt.worst_streak, 1);
    tick(1200000, false);   /* timed again: counted again */
    assert_int_equal(g_board.stats.deadline_misses, 2);
    assert_int_equal(g_board.stats.deadline_miss_tick[1], 7);
    assert_int_equal(g_board.stats.preempted_ticks, 4);
    for (uint32_t i = 0; i < 2u * BOARD_PREEMPTED_KEPT; i++) /* more than it keeps: counted */
        tick(3000000, true);
    assert_int_equal(g_board.stats.preempted_over_period, 3 + 2 * BOARD_PREEMPTED_KEPT);
    assert_int_equal(g_board.stats.preempted_over_tick[BOARD_PREEMPTED_KEPT - 1], 12);
}

static atomic_bool g_spin;

static void *spinner(void *arg)
{
    (void)arg;
    while (atomic_load(&g_spin)) {
    }
    return NULL;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Two busy threads on one CPU: the scheduler must take the core from this one within 200 ms
 * (its slices are a few ms), and the simulated HAL must see it. */
static void test_the_simulated_hal_sees_the_machine_take_the_core(void **st)
{
    (void)st;
    static hal_t hal;
    hal_sim_init(&hal);
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(sched_getcpu() < 0 ? 0 : sched_getcpu(), &one);
    assert_int_equal(pthread_setaffinity_np(pthread_self(), sizeof(one), &one), 0);
    atomic_store(&g_spin, true);
    pthread_t t;
    pthread_attr_t attr;
    assert_int_equal(pthread_attr_init(&attr), 0);
    assert_int_equal(pthread_attr_setaffinity_np(&attr, sizeof(one), &one), 0);
    assert_int_equal(pthread_create(&t, &attr, spinner, NULL), 0);
    const uint64_t before = hal_compute_preemptions(&hal);
    const double t0 = now_s();
    while (now_s() - t0 < 0.2) {
    }
    const uint64_t after = hal_compute_preemptions(&hal);
    atomic_store(&g_spin, false);
    assert_int_equal(pthread_join(t, NULL), 0);
    (void)pthread_attr_destroy(&attr);
    assert_true(after > before);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_timed_tick_past_its_period_is_a_miss_a_preempted_one_is_not),
        cmocka_unit_test(test_the_simulated_hal_sees_the_machine_take_the_core),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
