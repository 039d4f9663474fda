/* The stylus velocity by adaptive windowing (firmware/core/velocity.c), on positions quantised
 * like an encoder's: an even motion is read to a fraction of a count per window, a stylus at
 * rest dithering by one count reads almost still, a change of speed is followed within a few
 * ticks, and ticks without a new position count as time. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "firmware/core/velocity.h"

#define T_S 0.001f
#define COUNT_M 0.00002f   /* one encoder count at the tip, about the default arm's */

static float quantised(float x_m)
{
    return COUNT_M * floorf(x_m / COUNT_M);
}

/* 5 mm/s along x is a quarter count per tick: the backward difference reads 0 or 20 mm/s
 * tick by tick; the window reads 5 mm/s within one count over its span. */
static void test_even_motion_is_read_to_a_fraction_of_a_count(void **st)
{
    (void)st;
    velocity_window_t w;
    velocity_window_reset(&w);
    float worst = 0.0f, worst_bd = 0.0f, prev = 0.0f;
    for (uint32_t k = 0; k < 200; k++) {
        const float x = quantised(0.005f * (float)k * T_S + 0.3f * COUNT_M);
        const vec3_t v = velocity_window_add(&w, vec3(x, 0, 0), k, T_S, COUNT_M);
        if (k >= VELOCITY_WINDOW_MAX) {
            worst = fmaxf(worst, fabsf(v.x - 0.005f));
            worst_bd = fmaxf(worst_bd, fabsf((x - prev) / T_S - 0.005f));
        }
        assert_true(v.y == 0.0f && v.z == 0.0f);
        prev = x;
    }
    assert_true(worst_bd >= 0.005f);                                  /* what a difference reads */
    assert_true(worst <= 2.0f * COUNT_M / ((VELOCITY_WINDOW_MAX - 1) * T_S / 2.0f));
    assert_true(worst < 0.2f * worst_bd);
}

/* At rest on a count boundary the position flips between two counts: almost still. */
static void test_dither_at_rest_reads_almost_still(void **st)
{
    (void)st;
    velocity_window_t w;
    velocity_window_reset(&w);
    uint32_t seed = 12345u;
    float worst = 0.0f;
    for (uint32_t k = 0; k < 500; k++) {
        seed = seed * 1664525u + 1013904223u;
        const float x = (seed >> 31) ? COUNT_M : 0.0f;
        const vec3_t v = velocity_window_add(&w, vec3(0, 0, x), k, T_S, COUNT_M);
        if (k >= VELOCITY_WINDOW_MAX)
            worst = fmaxf(worst, fabsf(v.z));
    }
    /* one count over the longest window, not one count over one tick (20 mm/s) */
    assert_true(worst <= COUNT_M / ((VELOCITY_WINDOW_MAX - 1) * T_S) * 1.0001f);
}

/* The stylus stops dead (a wall) from 100 mm/s: the estimate falls below a tenth within 4
 * ticks, where a 16-tick average would still read half the speed after 8. */
static void test_a_stop_is_followed_within_a_few_ticks(void **st)
{
    (void)st;
    velocity_window_t w;
    velocity_window_reset(&w);
    float x = 0.0f;
    vec3_t v = vec3(0, 0, 0);
    for (uint32_t k = 0; k < 50; k++) {
        x = quantised(0.1f * (float)k * T_S);
        v = velocity_window_add(&w, vec3(x, 0, 0), k, T_S, COUNT_M);
    }
    assert_true(fabsf(v.x - 0.1f) < 0.005f);
    for (uint32_t k = 50; k < 54; k++)
        v = velocity_window_add(&w, vec3(x, 0, 0), k, T_S, COUNT_M);
    assert_true(fabsf(v.x) < 0.01f);
}

/* Positions arrive on ticks 0, 1, 4, 5, 8, … (a late bus): the slope is over the ticks they
 * were read at, not over their number. */
static void test_gaps_between_positions_count_as_time(void **st)
{
    (void)st;
    velocity_window_t w;
    velocity_window_reset(&w);
    vec3_t v = vec3(0, 0, 0);
    for (uint32_t k = 0; k < 64; k++) {
        if (k % 4 >= 2)
            continue;
        v = velocity_window_add(&w, vec3(0, 0.02f * (float)k * T_S, 0), k, T_S, COUNT_M);
    }
    assert_true(fabsf(v.y - 0.02f) < 1e-4f);
    /* and the first position alone says nothing */
    velocity_window_reset(&w);
    v = velocity_window_add(&w, vec3(1, 2, 3), 7, T_S, COUNT_M);
    assert_true(v.x == 0.0f && v.y == 0.0f && v.z == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_even_motion_is_read_to_a_fraction_of_a_count),
        cmocka_unit_test(test_dither_at_rest_reads_almost_still),
        cmocka_unit_test(test_a_stop_is_followed_within_a_few_ticks),
        cmocka_unit_test(test_gaps_between_positions_count_as_time),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
