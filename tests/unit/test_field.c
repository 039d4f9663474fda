/* Uniform B-spline working space: value and gradient against finite differences, samples equal
 * to the spline (d = A p), partial refreshes equal to a full one, the influence boxes. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/field.h"

static float sd_ball(void *ctx, vec3_t x)
{
    (void)ctx;
    return 0.05f - vec3_norm(vec3_sub(x, vec3(0.003f, -0.002f, 0.001f)));
}

static void make_ball(field_t *f, int32_t ratio)
{
    assert_int_equal(field_init(f, 0.01f, ratio, vec3(-0.001f, 0.002f, 0.0005f)), ARGIL_OK);
    assert_int_equal(field_fill(f, sd_ball, NULL, vec3(-0.1f, -0.1f, -0.1f), vec3(0.1f, 0.1f, 0.1f)), ARGIL_OK);
}

static void test_init_rejects_bad_arguments(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.0f, 2, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(field_init(&f, NAN, 2, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(field_init(&f, 0.01f, 0, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(field_init(&f, 0.01f, FIELD_RATIO_MAX + 1, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(field_init(&f, 0.01f, 2, vec3(INFINITY, 0, 0)), ARGIL_ERR_NONFINITE);
    const int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 4, 4};
    assert_int_equal(field_init(&f, 0.01f, 2, vec3(0, 0, 0)), ARGIL_OK);
    assert_int_equal(field_refresh(&f, lo, hi), ARGIL_ERR_ARG);
    assert_int_equal(field_fill(&f, NULL, NULL, vec3(0, 0, 0), vec3(1, 1, 1)), ARGIL_ERR_ARG);
    field_free(&f);
}

static void test_gradient_matches_finite_differences(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f, 2);
    const float h = 1e-4f;
    double worst = 0.0;
    for (int k = 0; k < 200; k++) {
        /* points through the density ramp, where the gradient is large */
        const float t = 0.37f * (float)k, r = 0.03f + 0.04f * (float)((k * 7) % 13) / 13.0f;
        const vec3_t x = vec3(r * cosf(t) * sinf(0.3f * t + 0.2f), r * sinf(t) * sinf(0.3f * t + 0.2f),
                              r * cosf(0.3f * t + 0.2f));
        vec3_t g;
        const float v = field_eval(&f, x, &g);
        assert_true(v >= -1e-6f && v <= 1.0f + 1e-6f);
        const float fd[3] = {
            (field_eval(&f, vec3(x.x + h, x.y, x.z), NULL) - field_eval(&f, vec3(x.x - h, x.y, x.z), NULL)) / (2 * h),
            (field_eval(&f, vec3(x.x, x.y + h, x.z), NULL) - field_eval(&f, vec3(x.x, x.y - h, x.z), NULL)) / (2 * h),
            (field_eval(&f, vec3(x.x, x.y, x.z + h), NULL) - field_eval(&f, vec3(x.x, x.y, x.z - h), NULL)) / (2 * h)};
        const float an[3] = {g.x, g.y, g.z};
        for (int a = 0; a < 3; a++)
            worst = fmax(worst, fabs((double)an[a] - fd[a]));
    }
    /* |∇f| across the ramp is 0.5 / band = 16.7 per m; float differences at h = 0.1 mm */
    assert_true(worst < 0.05);
    vec3_t g;
    assert_true(field_eval(&f, vec3(NAN, 0, 0), &g) == 0.0f);
    assert_true(g.x == 0.0f && g.y == 0.0f && g.z == 0.0f);
    field_free(&f);
}

static void test_samples_are_the_spline(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f, 3);
    double worst = 0.0;
    for (int32_t z = -20; z <= 20; z += 3)
        for (int32_t y = -20; y <= 20; y += 5)
            for (int32_t x = -20; x <= 20; x++) {
                const int32_t s[3] = {x, y, z};
                const float d = sparse_get(&f.samp, FS_D, x, y, z);
                worst = fmax(worst, fabs((double)d - field_eval(&f, field_sample_pos(&f, s), NULL)));
            }
    assert_true(worst < 1e-5);
    assert_true(sparse_get(&f.samp, FS_D, 0, 0, 0) > 0.99f); /* inside */
    assert_true(sparse_get(&f.samp, FS_D, 40, 0, 0) == 0.0f); /* outside */
    /* the rest shape is the filled shape */
    assert_true(sparse_get(&f.samp, FS_REST, 5, 6, 7) == sparse_get(&f.samp, FS_D, 5, 6, 7));
    field_free(&f);
}

static void test_partial_refresh_equals_full(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f, 2);
    /* change a few coefficients, refresh two halves, compare with one full refresh */
    for (int32_t i = -3; i <= 3; i++)
        assert_int_equal(sparse_set(&f.coef, FC_P, i, 2 * i, -i, 0.3f + 0.05f * (float)i), ARGIL_OK);
    const int32_t lo[3] = {-16, -16, -16}, mid[3] = {1, 16, 16}, mid2[3] = {1, -16, -16},
                  hi[3] = {16, 16, 16};
    assert_int_equal(field_refresh(&f, lo, mid), ARGIL_OK);
    assert_int_equal(field_refresh(&f, mid2, hi), ARGIL_OK);
    const int32_t dims[3] = {32, 32, 32};
    float *a = malloc(sizeof(float) * 32768), *b = malloc(sizeof(float) * 32768);
    sparse_read_box(&f.samp, FS_D, lo, dims, a);
    assert_int_equal(field_refresh(&f, lo, hi), ARGIL_OK);
    sparse_read_box(&f.samp, FS_D, lo, dims, b);
    assert_memory_equal(a, b, sizeof(float) * 32768);
    free(a);
    free(b);
    field_free(&f);
}

static void test_influence_boxes(void **state)
{
    (void)state;
    for (int32_t ratio = 1; ratio <= 4; ratio++) {
        field_t f;
        assert_int_equal(field_init(&f, 0.01f, ratio, vec3(0, 0, 0)), ARGIL_OK);
        const int32_t c[3] = {-3, 2, 0}, c1[3] = {-2, 3, 1};
        assert_int_equal(sparse_set(&f.coef, FC_P, c[0], c[1], c[2], 1.0f), ARGIL_OK);
        int32_t slo[3], shi[3];
        field_samples_of_coefs(&f, c, c1, slo, shi);
        const int32_t blo[3] = {slo[0] - 5, slo[1] - 5, slo[2] - 5}, bhi[3] = {shi[0] + 5, shi[1] + 5, shi[2] + 5};
        assert_int_equal(field_refresh(&f, blo, bhi), ARGIL_OK);
        for (int32_t z = blo[2]; z < bhi[2]; z++)
            for (int32_t y = blo[1]; y < bhi[1]; y++)
                for (int32_t x = blo[0]; x < bhi[0]; x++) {
                    const bool in = x >= slo[0] && x < shi[0] && y >= slo[1] && y < shi[1] && z >= slo[2] && z < shi[2];
                    const float d = sparse_get(&f.samp, FS_D, x, y, z);
                    assert_true(in ? d > 0.0f : d == 0.0f); /* exactly the support, no more */
                    if (in) {
                        const int32_t s[3] = {x, y, z}, s1[3] = {x + 1, y + 1, z + 1};
                        int32_t clo[3], chi[3];
                        field_coefs_of_samples(&f, s, s1, clo, chi);
                        for (int a = 0; a < 3; a++)
                            assert_true(clo[a] <= c[a] && c[a] < chi[a]);
                    }
                }
        field_free(&f);
    }
}

static void test_partition_of_unity(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.02f, 2, vec3(0, 0, 0)), ARGIL_OK);
    const int32_t lo[3] = {-4, -4, -4}, dims[3] = {9, 9, 9};
    float one[729];
    for (int i = 0; i < 729; i++)
        one[i] = 1.0f;
    assert_int_equal(sparse_write_box(&f.coef, FC_P, lo, dims, one), ARGIL_OK);
    vec3_t g;
    assert_float_equal(field_eval(&f, vec3(0.013f, -0.007f, 0.021f), &g), 1.0f, 1e-6);
    assert_float_equal(g.x, 0.0f, 1e-4);
    assert_float_equal(g.y, 0.0f, 1e-4);
    assert_float_equal(g.z, 0.0f, 1e-4);
    field_free(&f);
}

/* field_coefs_from is the transpose of field_samples_from: <A x, y> = <x, Aᵀ y> for random x, y
 * (ratio 3, a box straddling the origin). */
static void test_transpose_is_adjoint(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.02f, 3, vec3(0, 0, 0)), ARGIL_OK);
    const int32_t slo[3] = {-7, -4, 2}, shi[3] = {9, 6, 13};
    int32_t clo[3], chi[3], cn[3], sn[3];
    field_coefs_of_samples(&f, slo, shi, clo, chi);
    size_t nc = 1, ns = 1, nt = 0;
    for (int a = 0; a < 3; a++) {
        cn[a] = chi[a] - clo[a];
        sn[a] = shi[a] - slo[a];
        nc *= (size_t)cn[a];
        ns *= (size_t)sn[a];
    }
    nt = (size_t)sn[0] * cn[1] * cn[2] + (size_t)sn[0] * sn[1] * cn[2] + (size_t)cn[0] * sn[1] * sn[2] +
         (size_t)cn[0] * cn[1] * sn[2];
    float *x = malloc(sizeof(float) * nc), *atx = malloc(sizeof(float) * nc);
    float *y = malloc(sizeof(float) * ns), *ax = malloc(sizeof(float) * ns), *tmp = malloc(sizeof(float) * nt);
    uint32_t r = 7u;
    for (size_t i = 0; i < nc; i++) {
        r = r * 1664525u + 1013904223u;
        x[i] = (float)(r >> 8) / 16777216.0f - 0.5f;
    }
    for (size_t i = 0; i < ns; i++) {
        r = r * 1664525u + 1013904223u;
        y[i] = (float)(r >> 8) / 16777216.0f - 0.5f;
    }
    field_samples_from(&f, x, clo, cn, slo, shi, ax, tmp);
    field_coefs_from(&f, y, slo, shi, clo, cn, atx, tmp);
    double l = 0.0, rr = 0.0, mag = 0.0;
    for (size_t i = 0; i < ns; i++) {
        l += (double)ax[i] * y[i];
        mag += fabs((double)ax[i] * y[i]);
    }
    for (size_t i = 0; i < nc; i++)
        rr += (double)x[i] * atx[i];
    assert_true(mag > 1.0);
    assert_true(fabs(l - rr) < 1e-5 * mag);
    free(x);
    free(atx);
    free(y);
    free(ax);
    free(tmp);
    field_free(&f);
}

static float sd_ball_refine(void *ctx, vec3_t x)
{
    (void)ctx;
    return 0.07f - vec3_norm(vec3_sub(x, vec3(0.01f, -0.02f, 0.005f)));
}

/* Knot insertion in the sparse field (every span halved): the field is unchanged to 1e-5 relative
 * at 10,000 random points, inside, outside and across the surface; samples and their lattice
 * stay; an odd ratio is refused. */
static void test_refine_keeps_the_field(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.02f, 4, vec3(0.003f, -0.001f, 0.002f)), ARGIL_OK);
    assert_int_equal(field_fill(&f, sd_ball_refine, NULL, vec3(-0.1f, -0.1f, -0.1f), vec3(0.1f, 0.1f, 0.1f)),
                     ARGIL_OK);
    uint32_t r = 99u;
    for (int k = 0; k < 200; k++) { /* rough the coefficients up so the test sees every term */
        r = r * 1664525u + 1013904223u;
        const int32_t c[3] = {(int32_t)(r >> 8) % 9 - 4, (int32_t)(r >> 12) % 9 - 4, (int32_t)(r >> 16) % 9 - 4};
        assert_int_equal(sparse_set(&f.coef, FC_P, c[0], c[1], c[2], (float)((r >> 20) % 1000) * 1e-3f), ARGIL_OK);
    }
    for (int32_t z = 0; z < 3; z++) /* coarse coefficients [0, 2]^3 fixed */
        for (int32_t y = 0; y < 3; y++)
            for (int32_t x = 0; x < 3; x++)
                assert_int_equal(sparse_set(&f.coef, FC_FIXED, x, y, z, 1.0f), ARGIL_OK);
    const int32_t slo[3] = {-24, -24, -24}, shi[3] = {24, 24, 24};
    assert_int_equal(field_refresh(&f, slo, shi), ARGIL_OK);
    enum { NPTS = 10000 };
    static vec3_t pts[NPTS];
    static float before[NPTS];
    for (int k = 0; k < NPTS; k++) {
        float u[3];
        for (int a = 0; a < 3; a++) {
            r = r * 1664525u + 1013904223u;
            u[a] = ((float)(r >> 8) / 16777216.0f - 0.5f) * 0.3f;
        }
        pts[k] = vec3(u[0], u[1], u[2]);
        before[k] = field_eval(&f, pts[k], NULL);
    }
    const float d_before = sparse_get(&f.samp, FS_D, 3, -5, 7);
    const size_t ncoef_before = f.coef.blocks.count;
    assert_int_equal(field_refine(&f), ARGIL_OK);
    assert_true(f.ratio == 2 && f.coef_spacing_m == 0.01f);
    assert_true(f.coef.blocks.count > 4 * ncoef_before);
    double worst = 0.0;
    int inside = 0;
    for (int k = 0; k < NPTS; k++) {
        const double v = field_eval(&f, pts[k], NULL), err = fabs(v - before[k]) / fmax(1.0, fabs(before[k]));
        worst = fmax(worst, err);
        inside += before[k] > 0.5f;
    }
    print_message("refine: worst relative change %.2e at %d points (%d inside)\n", worst, NPTS, inside);
    assert_true(worst < 1e-5);
    assert_true(inside > 300 && inside < NPTS - 300);
    assert_float_equal(sparse_get(&f.samp, FS_D, 3, -5, 7), d_before, 1e-5);
    /* a fine coefficient is fixed only where all its parents were: fine 2 has parents 0..2,
     * fine 3 has 1..2, fine 4 has 1..3 and fine 5 has 2..3 */
    assert_true(sparse_get(&f.coef, FC_FIXED, 2, 2, 2) == 1.0f && sparse_get(&f.coef, FC_FIXED, 3, 3, 3) == 1.0f);
    assert_true(sparse_get(&f.coef, FC_FIXED, 4, 2, 2) == 0.0f && sparse_get(&f.coef, FC_FIXED, 2, 5, 3) == 0.0f);
    assert_int_equal(field_refine(&f), ARGIL_OK); /* ratio 2 -> 1 */
    assert_int_equal(field_refine(&f), ARGIL_ERR_ARG);
    for (int k = 0; k < 100; k++)
        assert_float_equal(field_eval(&f, pts[k], NULL), before[k], 1e-5 * fmax(1.0, fabs(before[k])));
    field_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_rejects_bad_arguments),
        cmocka_unit_test(test_gradient_matches_finite_differences),
        cmocka_unit_test(test_samples_are_the_spline),
        cmocka_unit_test(test_partial_refresh_equals_full),
        cmocka_unit_test(test_influence_boxes),
        cmocka_unit_test(test_partition_of_unity),
        cmocka_unit_test(test_transpose_is_adjoint),
        cmocka_unit_test(test_refine_keeps_the_field),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
