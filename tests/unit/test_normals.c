/* Normals for clouds without them: PCA + MST orientation gives outward normals within a few
 * degrees on a sphere, a torus (genus 1) and a box (away from its edges), two separate spheres
 * are oriented each on its own, and unusable input is refused. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/fit/normals.h"

/* Fraction of points whose estimate is within acos(min_dot) of the truth (true normals are
 * passed in m->normal and replaced by the estimate). */
static double agreement(mesh_t *m, float min_dot, uint32_t *parts)
{
    float *truth = malloc(3 * m->n_vert * sizeof(float));
    assert_non_null(truth);
    memcpy(truth, m->normal, 3 * m->n_vert * sizeof(float));
    for (size_t i = 0; i < 3 * m->n_vert; i++)
        m->normal[i] = 0.0f;
    assert_int_equal(normals_estimate(m, NULL, parts), ARGIL_OK);
    size_t good = 0;
    for (size_t i = 0; i < m->n_vert; i++) {
        const float *a = m->normal + 3 * i, *b = truth + 3 * i;
        assert_float_equal(a[0] * a[0] + a[1] * a[1] + a[2] * a[2], 1.0f, 1e-4f);
        good += a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= min_dot;
    }
    free(truth);
    return (double)good / (double)m->n_vert;
}

static void sphere(mesh_t *m, int n, vec3_t c, float r)
{
    for (int i = 0; i < n; i++) {
        const double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), t = i * M_PI * (3 - sqrt(5));
        const vec3_t nn = vec3((float)(rr * cos(t)), (float)(rr * sin(t)), (float)z);
        assert_int_equal(mesh_add_vertex(m, vec3_add(c, vec3_scale(nn, r)), nn, NULL), ARGIL_OK);
    }
}

static void test_sphere_and_two(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    sphere(&m, 3000, vec3(0, 0, 0), 0.03f);
    uint32_t parts;
    assert_true(agreement(&m, 0.996f, &parts) == 1.0); /* every normal within 5 degrees */
    assert_int_equal(parts, 1);
    mesh_free(&m);
    mesh_init(&m);
    sphere(&m, 1500, vec3(-0.05f, 0, 0), 0.02f);
    sphere(&m, 1500, vec3(0.05f, 0, 0), 0.02f);
    assert_true(agreement(&m, 0.99f, &parts) == 1.0);
    assert_int_equal(parts, 2);
    mesh_free(&m);
}

static void test_torus(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    for (int i = 0; i < 120; i++)
        for (int j = 0; j < 40; j++) {
            const double u = 2 * M_PI * (i + 0.5 * (j & 1)) / 120, v = 2 * M_PI * j / 40;
            const vec3_t n = vec3((float)(cos(v) * cos(u)), (float)(cos(v) * sin(u)), (float)sin(v));
            const vec3_t p = vec3((float)((0.03 + 0.01 * cos(v)) * cos(u)),
                                  (float)((0.03 + 0.01 * cos(v)) * sin(u)), (float)(0.01 * sin(v)));
            assert_int_equal(mesh_add_vertex(&m, p, n, NULL), ARGIL_OK);
        }
    uint32_t parts;
    const double ok = agreement(&m, 0.985f, &parts); /* within 10 degrees */
    assert_true(ok == 1.0);
    mesh_free(&m);
}

static void test_box(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    const float h = 0.01f, s = 0.0005f;
    for (int a = 0; a < 3; a++)
        for (int sg = -1; sg <= 1; sg += 2)
            for (int i = 0; i <= 40; i++)
                for (int j = 0; j <= 40; j++) {
                    float p[3], n[3] = {0, 0, 0};
                    p[a] = sg * h;
                    p[(a + 1) % 3] = -h + s * (float)i;
                    p[(a + 2) % 3] = -h + s * (float)j;
                    n[a] = (float)sg;
                    assert_int_equal(mesh_add_vertex(&m, vec3(p[0], p[1], p[2]), vec3(n[0], n[1], n[2]), NULL),
                                     ARGIL_OK);
                }
    uint32_t parts;
    /* points more than 2 spacings from an edge are exact; all are at least on the right side */
    float *truth = malloc(3 * m.n_vert * sizeof(float));
    memcpy(truth, m.normal, 3 * m.n_vert * sizeof(float));
    assert_int_equal(normals_estimate(&m, NULL, &parts), ARGIL_OK);
    for (size_t i = 0; i < m.n_vert; i++) {
        const float *p = m.pos + 3 * i, *a = m.normal + 3 * i, *b = truth + 3 * i;
        int near_edge = 0;
        for (int k = 0; k < 3; k++)
            near_edge += fabsf(p[k]) > h - 2.5f * s;
        const float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        if (near_edge < 2)
            assert_true(d > 0.999f);
        else
            assert_true(d > 0.0f);
    }
    free(truth);
    mesh_free(&m);
}

static volatile int g_stop = 1;

static void test_errors(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    sphere(&m, 3, vec3(0, 0, 0), 0.01f);
    assert_int_equal(normals_estimate(&m, NULL, NULL), ARGIL_ERR_ARG);
    mesh_free(&m);
    mesh_init(&m);
    sphere(&m, 100, vec3(0, 0, 0), 0.01f);
    normals_opts_t o = {3, NULL, NULL, NULL};
    assert_int_equal(normals_estimate(&m, &o, NULL), ARGIL_ERR_ARG); /* k below 4 */
    o.k = 8;
    o.stop = &g_stop;
    assert_int_equal(normals_estimate(&m, &o, NULL), ARGIL_ERR_STATE);
    m.pos[7] = INFINITY;
    assert_int_equal(normals_estimate(&m, NULL, NULL), ARGIL_ERR_ARG);
    mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_and_two),
        cmocka_unit_test(test_torus),
        cmocka_unit_test(test_box),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
