/* Non-uniform cubic B-spline patch: partition of unity, analytic gradient, Boehm insertion. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "host/model/bspline.h"

static double rnd(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / 16777216.0;
}

/* A patch with non-uniform knots on every axis and random coefficients in [0, 1]. */
static void make_patch(bspline_t *b, uint32_t *seed)
{
    const int32_t n[3] = {8, 7, 9};
    double k0[12] = {0, 0.1, 0.15, 0.3, 0.35, 0.5, 0.55, 0.8, 1.0, 1.1, 1.3, 1.4};
    double k1[11] = {-1, -0.6, -0.5, -0.2, 0.0, 0.05, 0.4, 0.9, 1.0, 1.2, 1.5};
    double k2[13] = {2, 2.1, 2.2, 2.3, 2.5, 2.6, 2.6, 2.9, 3.0, 3.3, 3.4, 3.5, 3.9};
    const double *const k[3] = {k0, k1, k2};
    assert_int_equal(bspline_init(b, n, k), ARGIL_OK);
    for (int i = 0; i < n[0] * n[1] * n[2]; i++)
        b->coef[i] = (float)rnd(seed);
}

static void random_point(const bspline_t *b, uint32_t *s, double u[3])
{
    for (int a = 0; a < 3; a++) {
        const double lo = b->knots[a][3], hi = b->knots[a][b->n[a]];
        u[a] = lo + (hi - lo) * rnd(s);
    }
}

static void test_partition_of_unity(void **state)
{
    (void)state;
    uint32_t seed = 1;
    bspline_t b;
    make_patch(&b, &seed);
    for (int i = 0; i < b.n[0] * b.n[1] * b.n[2]; i++)
        b.coef[i] = 1.0f;
    for (int i = 0; i < 1000; i++) {
        double u[3], g[3];
        random_point(&b, &seed, u);
        assert_float_equal(bspline_eval(&b, u, g), 1.0, 1e-6);
        assert_float_equal(g[0], 0.0, 1e-5);
        assert_float_equal(g[2], 0.0, 1e-5);
    }
    const double out[3] = {-5.0, 0.0, 3.0};
    assert_float_equal(bspline_eval(&b, out, NULL), 0.0, 0.0);
    bspline_free(&b);
}

static void test_gradient_matches_finite_differences(void **state)
{
    (void)state;
    uint32_t seed = 7;
    bspline_t b;
    make_patch(&b, &seed);
    double worst = 0.0;
    for (int i = 0; i < 2000; i++) {
        double u[3], g[3];
        random_point(&b, &seed, u);
        bspline_eval(&b, u, g);
        for (int a = 0; a < 3; a++) {
            const double h = 1e-6;
            double up[3] = {u[0], u[1], u[2]}, um[3] = {u[0], u[1], u[2]};
            up[a] += h;
            um[a] -= h;
            if (bspline_span(b.knots[a], b.n[a], up[a]) != bspline_span(b.knots[a], b.n[a], um[a]))
                continue; /* C2 across knots, but FD straddling a double knot is only C1 */
            const double fd = (bspline_eval(&b, up, NULL) - bspline_eval(&b, um, NULL)) / (2 * h);
            const double err = fabs(fd - g[a]) / (1.0 + fabs(g[a]));
            worst = err > worst ? err : worst;
        }
    }
    assert_true(worst < 1e-5);
    bspline_free(&b);
}

static void test_knot_insertion_keeps_the_field(void **state)
{
    (void)state;
    uint32_t seed = 42;
    bspline_t b;
    make_patch(&b, &seed);
    enum { NPTS = 10000 };
    double *pts = malloc(sizeof(double) * 3 * NPTS), *before = malloc(sizeof(double) * NPTS);
    assert_non_null(pts);
    assert_non_null(before);
    for (int i = 0; i < NPTS; i++) {
        random_point(&b, &seed, pts + 3 * i);
        before[i] = bspline_eval(&b, pts + 3 * i, NULL);
    }
    /* several knots per axis, one of them repeated (multiplicity 2) */
    assert_int_equal(bspline_insert_knot(&b, 0, 0.42), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 0, 0.42), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 0, 0.77), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 1, 0.3), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 2, 2.95), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 2, 3.1), ARGIL_OK);
    assert_int_equal(b.n[0], 11);
    assert_int_equal(b.n[1], 8);
    assert_int_equal(b.n[2], 11);
    double worst = 0.0;
    for (int i = 0; i < NPTS; i++) {
        const double v = bspline_eval(&b, pts + 3 * i, NULL);
        const double rel = fabs(v - before[i]) / fmax(fabs(before[i]), 1e-2);
        worst = rel > worst ? rel : worst;
    }
    assert_true(worst < 1e-5);
    free(pts);
    free(before);
    bspline_free(&b);
}

static void test_rejects_bad_input(void **state)
{
    (void)state;
    bspline_t b;
    const int32_t n[3] = {4, 4, 4}, small[3] = {3, 4, 4};
    double k[8] = {0, 1, 2, 3, 4, 5, 6, 7}, dec[8] = {0, 1, 2, 3, 2, 5, 6, 7}, flat[8] = {0, 0, 0, 1, 1, 1, 1, 1};
    double nanv[8] = {0, 1, 2, 3, NAN, 5, 6, 7};
    const double *const ok[3] = {k, k, k}, *const bad[3] = {k, dec, k}, *const nn[3] = {nanv, k, k};
    const double *const fl[3] = {k, k, flat};
    assert_int_equal(bspline_init(&b, small, ok), ARGIL_ERR_ARG);
    assert_int_equal(bspline_init(&b, n, bad), ARGIL_ERR_ARG);
    assert_int_equal(bspline_init(&b, n, nn), ARGIL_ERR_ARG);
    assert_int_equal(bspline_init(&b, n, fl), ARGIL_ERR_ARG); /* empty domain [1, 1] */
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    assert_int_equal(bspline_init_uniform(&b, n, lo, hi), ARGIL_ERR_ARG);
    const double hi2[3] = {1, 1, 1};
    assert_int_equal(bspline_init_uniform(&b, n, lo, hi2), ARGIL_OK);
    assert_int_equal(bspline_insert_knot(&b, 3, 0.5), ARGIL_ERR_ARG);
    assert_int_equal(bspline_insert_knot(&b, 0, 1.5), ARGIL_ERR_ARG);
    assert_int_equal(bspline_insert_knot(&b, 0, NAN), ARGIL_ERR_ARG);
    assert_int_equal(bspline_span(b.knots[0], b.n[0], 2.0), -1);
    assert_int_equal(bspline_span(b.knots[0], b.n[0], 1.0), 3);
    bspline_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_partition_of_unity),
        cmocka_unit_test(test_gradient_matches_finite_differences),
        cmocka_unit_test(test_knot_insertion_keeps_the_field),
        cmocka_unit_test(test_rejects_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
