/* The settling region is clipped to the layers the board's window left plus the coefficients
 * that reach their equations (host/solve/gsolve_settle.c settle_clip_box): a window marching 2
 * coefficients at a time along x leaves regions of at most a third of the old box, and the clay
 * ends where the whole old box's settling puts it. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve.h"
#include "host/model/grid.h"
#include "tests/unit/sphere_grid.h"

#define N 48
#define H 1.25e-3f
#define R 0.020f
#define DT 0.01f
#define C (N / 2)
#define SY (C + 15) /* a sample just inside the sphere's top */
#define HALF_X 12   /* the window is 24 samples along x */
#define MOVES 3     /* steps of 2 coefficients after the push */
#define AFTER 30    /* steps with the window still after the last move */

enum { CLIPPED, WHOLE, RELOADED, RUNS }; /* RELOADED: WHOLE with one no-op window reload */

static grid_t *sphere_grid(void)
{
    grid_t *g = sphere_grid_new(N, H, R);
    g->material.plastic_rate_hz = 0.0f; /* elastic: the dent springs back for a long time */
    return g;
}

static int32_t box_coefs(const int32_t lo[3], const int32_t hi[3])
{
    return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

/* Largest |a - b| over n values. */
static float max_diff(const float *a, const float *b, size_t n)
{
    float m = 0.0f;
    for (size_t i = 0; i < n; i++) {
        const float d = fabsf(a[i] - b[i]);
        m = d > m ? d : m;
    }
    return m;
}

/* Pushes the sphere's top for 4 steps, then moves the window 2 coefficients (2 R samples)
 * along x on each of MOVES steps, then leaves it for AFTER steps: with the settling region
 * clipped (the default), the whole old box, and the whole old box with the main window
 * reloaded once during the push (re-reading p, v and d_fixed: nothing but round-off), all in
 * lockstep. */
static void check_march(int32_t ratio, double frac_bound)
{
    grid_t *g[RUNS];
    gsolve_t gs[RUNS];
    float *d[RUNS], *p[RUNS];
    int32_t clo[3], chi[3], cn[3];
    const int32_t zero[3] = {0, 0, 0}, dims[3] = {N, N, N};
    const size_t ns = (size_t)N * N * N;
    for (int r = 0; r < RUNS; r++) {
        g[r] = sphere_grid();
        assert_int_equal(gsolve_init_ratio(&gs[r], g[r], ratio), ARGIL_OK);
        assert_true(gs[r].settle_enabled && gs[r].settle_clip); /* the defaults */
        gs[r].settle_clip = r == CLIPPED;
        d[r] = malloc(sizeof(float) * ns);
        assert_non_null(d[r]);
        sparse_read_box(&gs[r].field.samp, FS_D, zero, dims, d[r]);
    }
    field_coefs_of_samples(&gs[0].field, zero, dims, clo, chi);
    for (int a = 0; a < 3; a++)
        cn[a] = chi[a] - clo[a];
    const size_t nc = (size_t)cn[0] * cn[1] * cn[2];
    for (int r = 0; r < RUNS; r++) {
        p[r] = malloc(sizeof(float) * nc);
        assert_non_null(p[r]);
    }
    float *d0 = malloc(sizeof(float) * ns);
    assert_non_null(d0);
    memcpy(d0, d[0], sizeof(float) * ns);
    double frac_max = 0.0;
    int regions = 0;
    float early_dd = 0.0f, early_dp = 0.0f;
    for (int k = 0; k < 4 + MOVES + AFTER; k++) {
        const int32_t shift = 2 * ratio * (k < 4 ? 0 : (k - 3 < MOVES ? k - 3 : MOVES));
        const int32_t lo[3] = {C - HALF_X + shift, SY - 8, C - 8};
        const int32_t hi[3] = {C + HALF_X + shift, SY + 8, C + 8};
        const uint32_t before = gs[CLIPPED].stats.settle_steps;
        for (int r = 0; r < RUNS; r++) {
            if (k < 4)
                for (int32_t dx = -1; dx <= 1; dx++)
                    for (int32_t dz = -1; dz <= 1; dz++)
                        assert_true(grid_add_force(g[r], C + dx, SY, C + dz, -20.0f));
            if (r == RELOADED && k == 2)
                gs[r].stale = true; /* as after a tool edit: the window is read again */
            int32_t dlo[3], dhi[3];
            float change;
            assert_int_equal(gsolve_step(&gs[r], g[r], lo, hi, DT, dlo, dhi, &change), ARGIL_OK);
            sparse_read_box(&gs[r].field.samp, FS_D, zero, dims, d[r]);
            sparse_read_box(&gs[r].field.coef, FC_P, clo, cn, p[r]);
        }
        const gsolve_t *c = &gs[CLIPPED];
        assert_int_equal(c->stats.settle_steps, gs[WHOLE].stats.settle_steps);
        if (c->stats.settle_steps == before)
            continue;
        int32_t olo[3], ohi[3];
        const physwin_t *w = &c->settle.win;
        for (int a = 0; a < 3; a++) { /* the old box in coefficients (coef_box) */
            olo[a] = c->settle.box_lo[a] / ratio;
            ohi[a] = (c->settle.box_hi[a] - 1) / ratio + 1;
        }
        const double frac = (double)box_coefs(w->clo, w->chi) / box_coefs(olo, ohi);
        frac_max = frac > frac_max ? frac : frac_max;
        /* the left layers (x below the window) are in the region; the unclipped is the box */
        assert_true(w->clo[0] == olo[0] && w->chi[0] > c->win.clo[0]);
        assert_int_equal(box_coefs(gs[WHOLE].settle.win.clo, gs[WHOLE].settle.win.chi),
                         box_coefs(olo, ohi));
        if (++regions <= 3) {
            const float dd = max_diff(d[CLIPPED], d[WHOLE], ns);
            const float dp = max_diff(p[CLIPPED], p[WHOLE], nc);
            early_dd = dd > early_dd ? dd : early_dd;
            early_dp = dp > early_dp ? dp : early_dp;
        }
    }
    const float moved = max_diff(d0, d[WHOLE], ns), diff = max_diff(d[CLIPPED], d[WHOLE], ns),
                noise = max_diff(d[RELOADED], d[WHOLE], ns);
    const double cost =
        (double)gs[CLIPPED].stats.settle_coefs / (double)gs[WHOLE].stats.settle_coefs;
    print_message("# R = %d: settling region <= %.3f of the old box, coefficients stepped %.3f "
                  "of the whole box's (%d steps); clipped vs whole, first 3 steps: density "
                  "%.2e, coefficient %.2e; at the end: density %.2e (one no-op reload of the "
                  "window: %.2e; the clay moved %.2e)\n",
                  (int)ratio, frac_max, cost, regions, (double)early_dd, (double)early_dp,
                  (double)diff, (double)noise, (double)moved);
    assert_true(regions >= 3);
    assert_true(frac_max <= frac_bound);
    assert_true(cost <= frac_bound);
    /* The same solve for the free coefficients: equal to round-off while the region settles
     * (measured 0 / 1.9e-9 on coefficients, 1.2e-7 on densities at R = 1 / 2; with a margin
     * of 2 instead of GSOLVE_SETTLE_MARGIN: 6.4e-6 / 4.9e-6 and 1.0e-6 / 8.9e-7) ... */
    assert_true(early_dp <= 1e-7f);
    assert_true(early_dd <= 2.4e-7f);
    /* ... and at the end within what one no-op reload of the window makes of the same run
     * (the main window's 8 CG iterations amplify round-off: ~3e-5 here), 1 % of the motion. */
    assert_true(moved > 5e-3f);
    assert_true(diff <= 1e-4f);
    assert_true(noise > 1e-6f); /* the yardstick itself measures something */
    for (int r = 0; r < RUNS; r++) {
        gsolve_free(&gs[r]);
        sphere_grid_free(g[r]);
        free(d[r]);
        free(p[r]);
    }
    free(d0);
}

/* R = 1: 24 coefficients along x, 2 left + 3 held = 5 (0.21). */
static void test_window_moving_two_coefficients_along_x(void **st)
{
    (void)st;
    check_march(1, 1.0 / 3.0);
}

/* R = 2: the 24-sample box is 12 coefficients, 2 left + 3 held = 5 (0.42, half the cost). */
static void test_window_moving_two_coefficients_along_x_at_r2(void **st)
{
    (void)st;
    check_march(2, 0.5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_moving_two_coefficients_along_x),
        cmocka_unit_test(test_window_moving_two_coefficients_along_x_at_r2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
