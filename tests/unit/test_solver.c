/* Density-spring dynamics on coefficients: explicit vs implicit equilibrium, implicit stability
 * at 10x the explicit limit, CG residual, adaptive step, constraints, window, painted material,
 * and the banded x passes of A and Aᵀ against the taps. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/constraints.h"
#include "host/model/material.h"
#include "host/model/physwin.h"
#include "host/model/solver.h"

static void make_region(solver_t *s, bspline_t *b, const solver_cfg_t *cfg)
{
    const int32_t n[3] = {8, 8, 8}, ns[3] = {12, 12, 12};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    assert_int_equal(bspline_init_uniform(b, n, lo, hi), ARGIL_OK);
    for (int i = 0; i < 512; i++)
        b->coef[i] = 0.3f;
    assert_int_equal(solver_init_patch(s, b, ns, cfg), ARGIL_OK);
    /* a constant load on a few samples */
    for (int32_t z = 4; z < 7; z++)
        for (int32_t y = 5; y < 8; y++)
            s->force_n[5 + 12 * (y + 12 * z)] = 0.5f;
}

static double disp_norm(const float *a, const float *b, size_t n)
{
    double v = 0.0;
    for (size_t i = 0; i < n; i++)
        v += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(v);
}

static void test_explicit_and_implicit_agree_at_equilibrium(void **state)
{
    (void)state;
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    cfg.acc_threshold = INFINITY;
    bspline_t b;
    solver_t ex, im;
    make_region(&ex, &b, &cfg);
    const float dtmax = solver_explicit_dt_max_s(&ex);
    assert_true(dtmax > 0.0f && isfinite(dtmax));
    ex.cfg.dt_s = ex.dt_prev_s = 0.8f * dtmax;
    for (int i = 0; i < 1500; i++)
        assert_int_equal(solver_step_explicit(&ex), ARGIL_OK);
    cfg.dt_s = 0.1f;
    cfg.cg_tol = 1e-8f; /* converge fully: this test compares equilibria */
    bspline_free(&b);
    make_region(&im, &b, &cfg);
    bspline_free(&b);
    for (int i = 0; i < 300; i++) {
        assert_int_equal(solver_step_implicit(&im), ARGIL_OK);
        assert_true(im.stats.cg_iters <= SOLVER_CG_ITERS_MAX);
    }
    assert_true(im.stats.residual < 1e-4f);
    float *p0 = calloc(im.ncoef, sizeof(float));
    for (size_t i = 0; i < im.ncoef; i++)
        p0[i] = 0.3f;
    const double d = disp_norm(ex.p, im.p, im.ncoef), m = disp_norm(im.p, p0, im.ncoef);
    assert_true(m > 1e-3);          /* the load moved the clay */
    assert_true(d / m < 0.01);      /* same static equilibrium within 1 % */
    free(p0);
    solver_free(&ex);
    solver_free(&im);
}

static double max_abs_dev(const solver_t *s)
{
    double m = 0.0;
    for (size_t i = 0; i < s->ncoef; i++)
        m = fmax(m, fabs((double)s->p[i] - 0.3));
    return m;
}

static void test_implicit_stable_at_ten_times_explicit_limit(void **state)
{
    (void)state;
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    cfg.acc_threshold = INFINITY;
    bspline_t b;
    solver_t s;
    make_region(&s, &b, &cfg);
    const float dtmax = solver_explicit_dt_max_s(&s);
    s.cfg.dt_s = s.dt_prev_s = 2.0f * dtmax; /* the explicit solver blows up beyond its limit */
    for (int i = 0; i < 300 && max_abs_dev(&s) < 1e3; i++)
        if (solver_step_explicit(&s) != ARGIL_OK)
            break;
    assert_true(!(max_abs_dev(&s) < 1e3));
    solver_free(&s);
    bspline_free(&b);
    make_region(&s, &b, &cfg);
    s.cfg.dt_s = s.dt_prev_s = 10.0f * dtmax;
    double last = 0.0;
    for (int i = 0; i < 300; i++) {
        assert_int_equal(solver_step_implicit(&s), ARGIL_OK);
        last = max_abs_dev(&s);
        assert_true(last < 1.0);
    }
    assert_true(last > 1e-3);
    solver_free(&s);
    bspline_free(&b);
}

static void test_adaptive_step_halves(void **state)
{
    (void)state;
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    cfg.dt_s = 0.01f;
    cfg.acc_threshold = 1.0f; /* tiny: forces halving */
    bspline_t b;
    solver_t s;
    make_region(&s, &b, &cfg);
    assert_int_equal(solver_step_implicit(&s), ARGIL_OK);
    assert_true(s.stats.halvings > 0);
    assert_true(s.cfg.dt_s < 0.01f);
    assert_true(s.stats.max_acc <= 1.0f || s.cfg.dt_s * 0.5f < s.cfg.dt_min_s);
    solver_free(&s);
    bspline_free(&b);
    cfg.dt_s = 0.0f;
    assert_int_equal(solver_init_patch(&s, &b, (const int32_t[3]){4, 4, 4}, &cfg), ARGIL_ERR_ARG);
}

static float sd_ball(void *ctx, vec3_t x)
{
    (void)ctx;
    return 0.06f - vec3_norm(x);
}

static void make_ball(field_t *f)
{
    assert_int_equal(field_init(f, 0.01f, 2, vec3(0, 0, 0)), ARGIL_OK);
    assert_int_equal(field_fill(f, sd_ball, NULL, vec3(-0.12f, -0.12f, -0.12f), vec3(0.12f, 0.12f, 0.12f)), ARGIL_OK);
}

static double inside_volume(const field_t *f)
{
    const int32_t lo[3] = {-22, -22, -22}, dims[3] = {45, 45, 45};
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *d = malloc(n * sizeof(float));
    sparse_read_box(&f->samp, FS_D, lo, dims, d);
    double v = 0.0;
    for (size_t i = 0; i < n; i++)
        v += d[i] > f->iso ? 1.0 : 0.0;
    free(d);
    return v * pow(f->sample_spacing_m, 3);
}

static const int32_t whole_lo[3] = {-9, -9, -9}, whole_hi[3] = {10, 10, 10};

static void run_window_box(field_t *f, int steps, const int32_t clo[3], const int32_t chi[3])
{
    physwin_t w;
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    cfg.dt_s = 0.05f;
    assert_int_equal(physwin_open(&w, f, clo, chi, &cfg), ARGIL_OK);
    for (int i = 0; i < steps; i++)
        assert_int_equal(solver_step_implicit(&w.solver), ARGIL_OK);
    assert_int_equal(physwin_store(&w, f), ARGIL_OK);
    physwin_close(&w);
}

static void run_window(field_t *f, int steps)
{
    run_window_box(f, steps, whole_lo, whole_hi);
}

static void test_window_at_rest_stays_and_outside_is_fixed(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f);
    const float out_before = sparse_get(&f.coef, FC_P, 11, 0, 0);
    const float d_before = sparse_get(&f.samp, FS_D, 0, 0, 12);
    run_window(&f, 20);
    assert_float_equal(sparse_get(&f.samp, FS_D, 0, 0, 12), d_before, 1e-4); /* at rest: no motion */
    assert_true(sparse_get(&f.coef, FC_P, 11, 0, 0) == out_before);
    field_free(&f);
}

static void test_inflate_increases_volume(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f);
    const double v0 = inside_volume(&f);
    undo_t u;
    undo_init(&u, 1u << 24);
    assert_int_equal(material_paint(&f, FS_RESTLEN, vec3(0, 0, 0), 0.1f, 0.3f, MATERIAL_ADD, &u), ARGIL_OK);
    run_window(&f, 15);
    const double v1 = inside_volume(&f);
    assert_true(v1 > v0 * 1.05);
    /* deflate the other way */
    field_t g;
    make_ball(&g);
    assert_int_equal(material_paint(&g, FS_RESTLEN, vec3(0, 0, 0), 0.1f, -0.3f, MATERIAL_ADD, NULL), ARGIL_OK);
    run_window(&g, 15);
    assert_true(inside_volume(&g) < v0 * 0.95);
    /* reset rest shape: the inflated shape becomes permanent and stays */
    const int32_t slo[3] = {-30, -30, -30}, shi[3] = {30, 30, 30};
    assert_int_equal(material_reset_rest(&f, slo, shi, &u), ARGIL_OK);
    run_window(&f, 10);
    assert_float_equal(inside_volume(&f), v1, 0.02 * v1);
    assert_int_equal(material_paint(&f, FS_D, vec3(0, 0, 0), 0.1f, 1.0f, MATERIAL_ADD, NULL), ARGIL_ERR_ARG);
    undo_free(&u);
    field_free(&f);
    field_free(&g);
}

/* Surface displacement (m) along +x at y = z = 0 after pushing inward with a constant force. */
static float push_displacement(float stiff_scale)
{
    field_t f;
    make_ball(&f);
    if (stiff_scale != 1.0f) { /* exactly stiff_scale on every sample the window below sees */
        const int32_t slo[3] = {-8, -20, -20}, sdims[3] = {40, 40, 40};
        float *k = malloc(sizeof(float) * 40 * 40 * 40);
        for (size_t i = 0; i < 40 * 40 * 40; i++)
            k[i] = stiff_scale;
        assert_int_equal(sparse_write_box(&f.samp, FS_STIFF, slo, sdims, k), ARGIL_OK);
        free(k);
    }
    float x0 = 0.0f;
    for (float x = 0.0f; x < 0.1f; x += 0.0002f)
        if (field_eval(&f, vec3(x, 0, 0), NULL) < f.iso) {
            x0 = x;
            break;
        }
    for (int32_t z = -1; z <= 1; z++)
        for (int32_t y = -1; y <= 1; y++)
            for (int32_t x = 10; x <= 13; x++)
                assert_int_equal(sparse_set(&f.samp, FS_FORCE, x, y, z, -0.2f), ARGIL_OK);
    const int32_t lo[3] = {1, -5, -5}, hi[3] = {11, 6, 6}; /* a physical window round the push */
    run_window_box(&f, 40, lo, hi);
    float x1 = 0.0f;
    for (float x = 0.0f; x < 0.1f; x += 0.0002f)
        if (field_eval(&f, vec3(x, 0, 0), NULL) < f.iso) {
            x1 = x;
            break;
        }
    field_free(&f);
    return x0 - x1;
}

static void test_stiffness_four_times_moves_a_third(void **state)
{
    (void)state;
    const float soft = push_displacement(1.0f), hard = push_displacement(4.0f);
    assert_true(soft > 0.002f); /* the push dents the surface by > 2 mm */
    assert_true(hard <= soft / 3.0f);
}

static void test_constraints_hold(void **state)
{
    (void)state;
    field_t f;
    make_ball(&f);
    physwin_t w;
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    cfg.dt_s = 0.05f;
    const int32_t clo[3] = {-9, -9, -9}, chi[3] = {10, 10, 10};
    assert_int_equal(physwin_open(&w, &f, clo, chi, &cfg), ARGIL_OK);
    for (size_t i = 0; i < w.solver.nsamp; i++)
        w.solver.force_n[i] = 0.3f; /* everything swells */
    const vec3_t hard_at = vec3(0.065f, 0.0f, 0.0f), soft_at = vec3(0.0f, 0.065f, 0.0f);
    assert_int_equal(constraint_hard_point(&w, &f, hard_at, f.iso), ARGIL_OK);
    assert_int_equal(constraint_point(&w, &f, soft_at, f.iso, 2000.0f), ARGIL_OK);
    const vec3_t curve[2] = {vec3(-0.02f, 0.0f, 0.064f), vec3(0.02f, 0.0f, 0.064f)};
    assert_int_equal(constraint_curve(&w, &f, curve, 2, f.iso, 2000.0f, 0.005f), ARGIL_OK);
    assert_int_equal(constraint_hard_point(&w, &f, hard_at, f.iso), ARGIL_ERR_ARG); /* same pivot */
    for (int i = 0; i < 40; i++)
        assert_int_equal(solver_step_implicit(&w.solver), ARGIL_OK);
    assert_int_equal(physwin_store(&w, &f), ARGIL_OK);
    assert_float_equal(field_eval(&f, hard_at, NULL), f.iso, 1e-4);
    const float free_pt = field_eval(&f, vec3(0.0f, -0.065f, 0.0f), NULL);
    assert_true(free_pt > f.iso + 0.05f); /* unconstrained side swelled */
    assert_true(fabsf(field_eval(&f, soft_at, NULL) - f.iso) < 0.3f * (free_pt - f.iso));
    assert_true(fabsf(field_eval(&f, vec3(0.0f, 0.0f, 0.064f), NULL) - f.iso) < 0.3f * (free_pt - f.iso));
    physwin_close(&w);
    /* fixed points do not move */
    assert_int_equal(material_fix(&f, vec3(0.06f, 0.0f, 0.0f), 0.015f, true, NULL), ARGIL_OK);
    const float fixed_p = sparse_get(&f.coef, FC_P, 6, 0, 0);
    assert_true(sparse_get(&f.coef, FC_FIXED, 6, 0, 0) == 1.0f);
    for (int32_t x = 0; x < 20; x++)
        assert_int_equal(sparse_set(&f.samp, FS_FORCE, x, 0, 0, 0.2f), ARGIL_OK);
    run_window(&f, 10);
    assert_true(sparse_get(&f.coef, FC_P, 6, 0, 0) == fixed_p);
    field_free(&f);
}

/* Reference A x along the taps, the 4-tap sum in the order the solver documents, axis by axis. */
static void ref_A(const solver_t *s, const float *x, float *d)
{
    const int32_t *nc = s->nc, *ns = s->ns;
    float *t1 = malloc(sizeof(float) * (size_t)ns[0] * nc[1] * nc[2]);
    float *t2 = malloc(sizeof(float) * (size_t)ns[0] * ns[1] * nc[2]);
    assert_non_null(t1);
    assert_non_null(t2);
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t y = 0; y < nc[1]; y++)
            for (int32_t i = 0; i < ns[0]; i++) {
                const float *w = s->tap_w[0] + 4 * i, *q = x + nc[0] * (y + nc[1] * z) + s->tap_first[0][i];
                t1[i + ns[0] * (y + nc[1] * z)] = w[0] * q[0] + w[1] * q[1] + w[2] * q[2] + w[3] * q[3];
            }
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t j = 0; j < ns[1]; j++)
            for (int32_t i = 0; i < ns[0]; i++) {
                const float *w = s->tap_w[1] + 4 * j;
                const float *q = t1 + i + ns[0] * (s->tap_first[1][j] + nc[1] * z);
                t2[i + ns[0] * (j + ns[1] * z)] = w[0] * q[0] + w[1] * q[ns[0]] + w[2] * q[2 * ns[0]] + w[3] * q[3 * ns[0]];
            }
    const size_t plane = (size_t)ns[0] * ns[1];
    for (int32_t k = 0; k < ns[2]; k++)
        for (size_t i = 0; i < plane; i++) {
            const float *w = s->tap_w[2] + 4 * k, *q = t2 + i + plane * s->tap_first[2][k];
            d[i + plane * k] = w[0] * q[0] + w[1] * q[plane] + w[2] * q[2 * plane] + w[3] * q[3 * plane];
        }
    free(t1);
    free(t2);
}

/* The x passes of A and Aᵀ run as banded blocks of 8 outputs: on a patch with non-uniform knots
 * and sample counts that are not multiples of 8, A p equals the 4-tap sums bit for bit (and the
 * fallback without bands equals it too), and the lumped mass Aᵀ(m ⊙ A1) built with the band of Aᵀ
 * matches a double-precision reference to 1e-6. */
static void test_banded_passes_equal_the_taps(void **state)
{
    (void)state;
    const int32_t n[3] = {9, 7, 10}, ns[3] = {21, 13, 11};
    double kx[13], ky[11], kz[14];
    double *kn[3] = {kx, ky, kz};
    for (int a = 0; a < 3; a++)
        for (int32_t i = 0; i < n[a] + 4; i++) /* clamped ends, uneven inner spans */
            kn[a][i] = i < 4 ? 0.0 : (i >= n[a] ? 1.0 : pow((double)(i - 3) / (double)(n[a] - 3), 1.4));
    bspline_t b;
    assert_int_equal(bspline_init(&b, n, (const double *const *)kn), ARGIL_OK);
    uint32_t r = 7u;
    for (int32_t i = 0; i < n[0] * n[1] * n[2]; i++) {
        r = r * 1664525u + 1013904223u;
        b.coef[i] = (float)(r >> 8) / 16777216.0f;
    }
    solver_cfg_t cfg;
    solver_cfg_default(&cfg);
    solver_t s;
    assert_int_equal(solver_init_patch(&s, &b, ns, &cfg), ARGIL_OK);
    assert_true(s.band_a.nchunk == 3 && s.band_at.nchunk == 2); /* 21 samples, 9 coefficients */
    float *d = malloc(sizeof(float) * s.nsamp), *ref = malloc(sizeof(float) * s.nsamp);
    assert_non_null(d);
    assert_non_null(ref);
    solver_densities(&s, d);
    ref_A(&s, s.p, ref);
    assert_memory_equal(d, ref, sizeof(float) * s.nsamp);
    /* and it is the patch: d at the sample parameters */
    const double uvw[3] = {kx[3] + (kx[9] - kx[3]) * 5.0 / 20.0, ky[3] + (ky[7] - ky[3]) * 4.0 / 12.0,
                           kz[3] + (kz[10] - kz[3]) * 7.0 / 10.0};
    assert_float_equal(d[5 + 21 * (4 + 13 * 7)], bspline_eval(&b, uvw, NULL), 1e-5);
    s.band_a.nchunk = s.band_at.nchunk = 0; /* the gather loops, as after a failed allocation */
    solver_densities(&s, d);
    assert_memory_equal(d, ref, sizeof(float) * s.nsamp);
    /* Aᵀ(m ⊙ A1) by its definition, in double */
    float *one = malloc(sizeof(float) * s.ncoef);
    assert_non_null(one);
    for (size_t i = 0; i < s.ncoef; i++)
        one[i] = 1.0f;
    ref_A(&s, one, ref);
    double worst = 0.0;
    for (int32_t z = 0; z < n[2]; z++)
        for (int32_t y = 0; y < n[1]; y++)
            for (int32_t x = 0; x < n[0]; x++) {
                double m = 0.0;
                for (int32_t k = 0; k < ns[2]; k++)
                    for (int32_t j = 0; j < ns[1]; j++)
                        for (int32_t i = 0; i < ns[0]; i++) {
                            const int32_t t[3] = {x - s.tap_first[0][i], y - s.tap_first[1][j], z - s.tap_first[2][k]};
                            if (t[0] < 0 || t[0] > 3 || t[1] < 0 || t[1] > 3 || t[2] < 0 || t[2] > 3)
                                continue;
                            const size_t si = (size_t)i + (size_t)ns[0] * ((size_t)j + (size_t)ns[1] * k);
                            m += (double)s.tap_w[0][4 * i + t[0]] * s.tap_w[1][4 * j + t[1]] * s.tap_w[2][4 * k + t[2]] *
                                 ref[si] * s.mass_kg[si];
                        }
                const float got = s.mlump[(size_t)x + (size_t)n[0] * ((size_t)y + (size_t)n[1] * z)];
                worst = fmax(worst, fabs(got - fmax(m, 1e-12)) / fmax(m, 1e-12));
            }
    assert_true(worst < 1e-6);
    free(one);
    free(d);
    free(ref);
    solver_free(&s);
    bspline_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_explicit_and_implicit_agree_at_equilibrium),
        cmocka_unit_test(test_implicit_stable_at_ten_times_explicit_limit),
        cmocka_unit_test(test_adaptive_step_halves),
        cmocka_unit_test(test_window_at_rest_stays_and_outside_is_fixed),
        cmocka_unit_test(test_inflate_increases_volume),
        cmocka_unit_test(test_stiffness_four_times_moves_a_third),
        cmocka_unit_test(test_constraints_hold),
        cmocka_unit_test(test_banded_passes_equal_the_taps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
