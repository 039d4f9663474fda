/* RBF implicit (Zhang et al. §5): fits a sphere and a torus from oriented samples with a small
 * error, is positive inside and negative outside, has a size set by its centres, and refuses
 * unusable input. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "host/fit/rbf.h"

static void sphere_points(mesh_t *m, int n, float r)
{
    mesh_init(m);
    for (int i = 0; i < n; i++) {
        const double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), t = i * M_PI * (3 - sqrt(5));
        const vec3_t nn = vec3((float)(rr * cos(t)), (float)(rr * sin(t)), (float)z);
        assert_int_equal(mesh_add_vertex(m, vec3_scale(nn, r), nn, NULL), ARGIL_OK);
    }
}

static void test_sphere(void **state)
{
    (void)state;
    mesh_t m;
    sphere_points(&m, 1000, 0.03f);
    rbf_opts_t o;
    rbf_opts_default(&o);
    o.max_surface_samples = 200;
    rbf_model_t r;
    assert_int_equal(rbf_fit(&m, &o, &r), ARGIL_OK);
    assert_int_equal(r.n, 600);
    assert_true(r.rms_err_m < 0.0005f * 0.06f); /* 0.05 % of the size */
    assert_true(r.max_err_m < 0.002f * 0.06f);
    assert_true(rbf_eval(&r, vec3(0, 0, 0)) > 0.0f);
    assert_true(rbf_eval(&r, vec3(0.05f, 0, 0)) < 0.0f);
    /* the zero crossing along +x sits at the radius */
    float lo = 0.0f, hi = 0.05f;
    for (int k = 0; k < 40; k++) {
        const float mid = 0.5f * (lo + hi);
        if (rbf_eval(&r, vec3(mid, 0.0f, 0.0f)) > 0.0f)
            lo = mid;
        else
            hi = mid;
    }
    assert_float_equal(lo, 0.03f, 0.0003f);
    rbf_free(&r);
    mesh_free(&m);
}

static void test_torus(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    const float R = 0.03f, a = 0.01f;
    for (int i = 0; i < 60; i++)
        for (int j = 0; j < 30; j++) {
            const float u = 2.0f * (float)M_PI * (float)i / 60.0f, v = 2.0f * (float)M_PI * (float)j / 30.0f;
            const vec3_t n = vec3(cosf(v) * cosf(u), cosf(v) * sinf(u), sinf(v));
            const vec3_t p = vec3((R + a * cosf(v)) * cosf(u), (R + a * cosf(v)) * sinf(u), a * sinf(v));
            assert_int_equal(mesh_add_vertex(&m, p, n, NULL), ARGIL_OK);
        }
    rbf_opts_t o;
    rbf_opts_default(&o);
    o.max_surface_samples = 360;
    rbf_model_t r;
    assert_int_equal(rbf_fit(&m, &o, &r), ARGIL_OK);
    assert_true(r.rms_err_m < 0.002f * 0.08f);
    assert_true(rbf_eval(&r, vec3(0.03f, 0, 0)) > 0.0f);  /* inside the tube */
    assert_true(rbf_eval(&r, vec3(0, 0, 0)) < 0.0f);      /* the hole */
    rbf_free(&r);
    mesh_free(&m);
}

static volatile int g_stop = 1;

static void test_errors(void **state)
{
    (void)state;
    mesh_t m;
    sphere_points(&m, 3, 0.01f);
    rbf_opts_t o;
    rbf_opts_default(&o);
    rbf_model_t r;
    assert_int_equal(rbf_fit(&m, &o, &r), ARGIL_ERR_ARG); /* fewer than 4 points */
    mesh_free(&m);
    sphere_points(&m, 50, 0.01f);
    m.pos[4] = NAN;
    assert_int_equal(rbf_fit(&m, &o, &r), ARGIL_ERR_ARG);
    m.pos[4] = 0.0f;
    o.stop = (const volatile int *)&g_stop;
    assert_int_equal(rbf_fit(&m, &o, &r), ARGIL_ERR_STATE); /* stopped */
    assert_null(r.weight);
    assert_int_equal(rbf_alloc(&r, RBF_CENTRES_MAX + 1), ARGIL_ERR_ARG);
    mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_torus),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
