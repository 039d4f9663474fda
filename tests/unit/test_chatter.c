/* The chatter figure on synthetic telemetry rows: a steady force has none, a 100 Hz square
 * wave is all high-pass, a first contact's step is forgiven but the same step in contact is
 * not, and the moving average spans 20 ms whatever the loop rate. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "host/render/chatter.h"
#include "host/render/telemetry_log.h"

/* n rows at rate_hz, time_s rounded to the millisecond as session.c prints it, force 0,
 * contact column 0 (absent when with_contact is false). */
static telemetry_log_t rows(size_t n, double rate_hz, bool with_contact)
{
    telemetry_log_t log;
    memset(&log, 0, sizeof(log));
    log.n = n;
    log.time_s = calloc(n, sizeof(double));
    log.pos_mm = calloc(3 * n, sizeof(float));
    log.force_n = calloc(3 * n, sizeof(float));
    log.force_mag_n = calloc(n, sizeof(float));
    log.state = calloc(n, 1);
    log.contact = with_contact ? calloc(n, 1) : NULL;
    assert_non_null(log.time_s);
    assert_non_null(log.force_n);
    assert_true(!with_contact || log.contact != NULL);
    for (size_t i = 0; i < n; i++)
        log.time_s[i] = round((double)(i + 1) / rate_hz * 1e3) * 1e-3;
    log.n_states = 1;
    return log;
}

static void set_force(telemetry_log_t *log, size_t i, float fx, float fy, float fz)
{
    log->force_n[3 * i] = fx;
    log->force_n[3 * i + 1] = fy;
    log->force_n[3 * i + 2] = fz;
    log->force_mag_n[i] = sqrtf(fx * fx + fy * fy + fz * fz);
}

static void test_steady_force_has_no_chatter(void **state)
{
    (void)state;
    telemetry_log_t log = rows(2000, 1000.0, true);
    for (size_t i = 0; i < log.n; i++) {
        set_force(&log, i, 0.3f, -0.4f, 1.2f);
        log.contact[i] = 1;
    }
    chatter_t ch;
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.contact_ticks, 2000);
    assert_true(ch.rms_n < 1e-6);
    assert_int_equal(ch.steps, 0);
    assert_true(chatter_goal_met(&ch));
    telemetry_log_free(&log);
}

/* A 100 Hz square wave of ±0.5 N on x over a steady 1 N on z, at rate_hz: the 20 ms mean is
 * the 1 N, so the high-pass is the whole 0.5 N; every edge (1 N) is a step in contact. */
static void square_wave(double rate_hz, chatter_t *ch)
{
    const size_t n = (size_t)(2.0 * rate_hz), half = (size_t)(rate_hz / 200.0);
    telemetry_log_t log = rows(n, rate_hz, true);
    for (size_t i = 0; i < n; i++) {
        set_force(&log, i, (i / half) % 2 ? -0.5f : 0.5f, 0.0f, 1.0f);
        log.contact[i] = 1;
    }
    float *hp = calloc(n, sizeof(float));
    uint8_t *step = calloc(n, 1);
    assert_non_null(hp);
    assert_non_null(step);
    const chatter_trace_t tr = {hp, step};
    assert_int_equal(chatter_measure(&log, ch, &tr), ARGIL_OK);
    size_t marked = 0;
    for (size_t i = 0; i < n; i++)
        marked += step[i];
    assert_int_equal(marked, ch->steps);
    assert_true(fabsf(hp[n / 2] - 0.5f) < 0.01f);
    free(hp);
    free(step);
    telemetry_log_free(&log);
}

static void test_square_wave_is_all_high_pass(void **state)
{
    (void)state;
    chatter_t ch;
    square_wave(1000.0, &ch);
    assert_int_equal(ch.rows_per_window, 20);
    assert_int_equal(ch.contact_ticks, 2000);
    if (fabs(ch.rms_n - 0.5) > 0.02)
        fail_msg("RMS %.4f N, not 0.5 N", ch.rms_n);
    assert_int_equal(ch.steps, 2 * 100 * 2 - 1); /* 2 s of 100 Hz, two edges a period */
    assert_true(fabs(ch.worst_step_n - 1.0) < 1e-6);
    assert_true(fabs(ch.stretch_rms_n - 0.5) < 0.02);
    assert_false(chatter_goal_met(&ch));
    char line[256];
    chatter_format(&ch, line, sizeof(line));
    if (strstr(line, "0.500 N RMS over 2000 ticks in contact, 399 steps > 0.2 N") == NULL)
        fail_msg("figure line '%s'", line);
}

/* At 4 kHz the window is 80 rows (time_s repeats, 4 rows a millisecond); a 20-row window
 * there would average half a period of the wave and miss most of it. */
static void test_window_is_20_ms_at_any_rate(void **state)
{
    (void)state;
    chatter_t ch;
    square_wave(4000.0, &ch);
    assert_int_equal(ch.rows_per_window, 80);
    if (fabs(ch.rms_n - 0.5) > 0.02)
        fail_msg("RMS %.4f N at 4 kHz, not 0.5 N", ch.rms_n);
    square_wave(2000.0, &ch);
    assert_int_equal(ch.rows_per_window, 40);
}

/* 0 N out of contact, then 1 N on z from row 100; contact_from is where the flag rises. */
static telemetry_log_t one_step(float before_n, size_t contact_from, bool with_contact)
{
    telemetry_log_t log = rows(400, 1000.0, with_contact);
    for (size_t i = 0; i < log.n; i++) {
        set_force(&log, i, 0.0f, 0.0f, i < 100 ? before_n : before_n + 1.0f);
        if (with_contact)
            log.contact[i] = i >= contact_from;
    }
    return log;
}

static void test_first_contact_step_is_forgiven(void **state)
{
    (void)state;
    telemetry_log_t log = one_step(0.0f, 100, true);
    chatter_t ch;
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.steps, 0);
    assert_int_equal(ch.first_contact_steps, 1);
    assert_int_equal(ch.contact_ticks, 300);
    telemetry_log_free(&log);
}

static void test_step_in_contact_counts(void **state)
{
    (void)state;
    /* Already touching (0.1 N, flag up from the start): the 1 N jump is a step. */
    telemetry_log_t log = one_step(0.1f, 0, true);
    chatter_t ch;
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.steps, 1);
    assert_int_equal(ch.first_contact_steps, 0);
    assert_true(fabs(ch.worst_step_n - 1.0) < 1e-6);
    assert_true(fabs(ch.worst_step_time_s - 0.101) < 1e-9);
    assert_false(chatter_goal_met(&ch));
    telemetry_log_free(&log);
    /* The flag rising a row late does not excuse the step either. */
    log = one_step(0.0f, 101, true);
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.steps, 1);
    telemetry_log_free(&log);
    /* Without a contact column nothing is a first contact. */
    log = one_step(0.0f, 0, false);
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.steps, 1);
    telemetry_log_free(&log);
}

static void test_quiet_contact_meets_the_goal(void **state)
{
    (void)state;
    /* 0.5 N with ±0.02 N of 100 Hz ripple: 0.02 N RMS, no step. */
    telemetry_log_t log = rows(1000, 1000.0, true);
    for (size_t i = 0; i < log.n; i++) {
        set_force(&log, i, 0.0f, (i / 5) % 2 ? -0.02f : 0.02f, 0.5f);
        log.contact[i] = 1;
    }
    chatter_t ch;
    assert_int_equal(chatter_measure(&log, &ch, NULL), ARGIL_OK);
    assert_int_equal(ch.contact_ticks, 1000);
    assert_true(fabs(ch.rms_n - 0.02) < 0.002);
    assert_int_equal(ch.steps, 0);
    assert_true(chatter_goal_met(&ch));
    telemetry_log_free(&log);
    telemetry_log_t empty;
    memset(&empty, 0, sizeof(empty));
    assert_int_equal(chatter_measure(&empty, &ch, NULL), ARGIL_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_steady_force_has_no_chatter),
        cmocka_unit_test(test_square_wave_is_all_high_pass),
        cmocka_unit_test(test_window_is_20_ms_at_any_rate),
        cmocka_unit_test(test_first_contact_step_is_forgiven),
        cmocka_unit_test(test_step_in_contact_counts),
        cmocka_unit_test(test_quiet_contact_meets_the_goal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
