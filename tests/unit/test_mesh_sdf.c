/* Mesh -> signed distance grid: a closed icosphere gives the sphere's distance within one grid
 * spacing and the right sign everywhere; an axis-aligned cube (rays along its edges) keeps its
 * sign; open, non-manifold and broken input is refused with the counts. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "host/io/mesh_sdf.h"
#include "host/mesh/mc.h"

/* An icosahedron subdivided `level` times, projected onto the sphere of radius r (CCW outside). */
static void icosphere(mesh_t *m, int level, float r)
{
    mesh_init(m);
    const float g = (1.0f + sqrtf(5.0f)) / 2.0f;
    const float v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                            {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    static const uint32_t f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                      {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                      {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                      {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int i = 0; i < 12; i++) {
        const vec3_t p = vec3(v[i][0], v[i][1], v[i][2]);
        const vec3_t n = vec3_scale(p, 1.0f / vec3_norm(p));
        assert_int_equal(mesh_add_vertex(m, vec3_scale(n, r), n, NULL), ARGIL_OK);
    }
    for (int i = 0; i < 20; i++)
        assert_int_equal(mesh_add_triangle(m, f[i][0], f[i][1], f[i][2]), ARGIL_OK);
    for (int l = 0; l < level; l++) {
        mesh_t n;
        mesh_init(&n);
        for (size_t i = 0; i < m->n_vert; i++)
            mesh_add_vertex(&n, vec3(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]),
                            vec3(m->normal[3 * i], m->normal[3 * i + 1], m->normal[3 * i + 2]), NULL);
        /* midpoints are shared through a per-edge lookup (quadratic but small) */
        const size_t ne_max = 3 * m->n_tri;
        uint32_t(*key)[3] = malloc(ne_max * sizeof(*key));
        size_t ne = 0;
        for (size_t t = 0; t < m->n_tri; t++) {
            uint32_t mid[3];
            for (int k = 0; k < 3; k++) {
                uint32_t a = m->tri[3 * t + (size_t)k], b = m->tri[3 * t + (size_t)(k + 1) % 3];
                if (a > b) {
                    const uint32_t s = a;
                    a = b;
                    b = s;
                }
                size_t j = 0;
                while (j < ne && !(key[j][0] == a && key[j][1] == b))
                    j++;
                if (j == ne) {
                    const vec3_t p = vec3_add(vec3(m->pos[3 * a], m->pos[3 * a + 1], m->pos[3 * a + 2]),
                                              vec3(m->pos[3 * b], m->pos[3 * b + 1], m->pos[3 * b + 2]));
                    const vec3_t nn = vec3_scale(p, 1.0f / vec3_norm(p));
                    key[ne][0] = a;
                    key[ne][1] = b;
                    assert_int_equal(mesh_add_vertex(&n, vec3_scale(nn, r), nn, &key[ne][2]), ARGIL_OK);
                    ne++;
                }
                mid[k] = key[j][2];
            }
            const uint32_t *c = m->tri + 3 * t;
            mesh_add_triangle(&n, c[0], mid[0], mid[2]);
            mesh_add_triangle(&n, c[1], mid[1], mid[0]);
            mesh_add_triangle(&n, c[2], mid[2], mid[1]);
            mesh_add_triangle(&n, mid[0], mid[1], mid[2]);
        }
        free(key);
        mesh_free(m);
        *m = n;
    }
}

static void test_sphere(void **state)
{
    (void)state;
    mesh_t m;
    icosphere(&m, 3, 0.03f);
    enum { N = 40 };
    const int32_t dims[3] = {N, N, N};
    const float h = 0.08f / (N - 1), band = 3 * h;
    const vec3_t org = vec3(-0.04f, -0.04f, -0.04f);
    float *sd = malloc(N * N * N * sizeof(float));
    mesh_sdf_report_t rep;
    assert_int_equal(mesh_sdf(&m, dims, h, org, band, sd, &rep), ARGIL_OK);
    assert_int_equal(rep.boundary_edges, 0);
    double worst = 0;
    size_t i = 0, banded = 0;
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++, i++) {
                const vec3_t p = vec3(org.x + h * x, org.y + h * y, org.z + h * z);
                const float truth = 0.03f - vec3_norm(p);
                if (fabsf(truth) < band - h) {
                    worst = fmax(worst, fabs(sd[i] - truth));
                    banded++;
                } else if (fabsf(truth) > band + h) {
                    assert_float_equal(sd[i], truth > 0 ? band : -band, 0.0f);
                }
                if (fabsf(truth) > h)
                    assert_true((sd[i] > 0) == (truth > 0));
            }
    assert_true(banded > 1000);
    assert_true(worst < h); /* within one grid spacing (the facets are within 0.2 mm) */
    free(sd);
    mesh_free(&m);
}

static void test_cube_on_rows(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    for (int i = 0; i < 8; i++) /* corners on grid rows: rays run along faces and edges */
        mesh_add_vertex(&m, vec3(i & 1 ? 0.01f : -0.01f, i & 2 ? 0.01f : -0.01f, i & 4 ? 0.01f : -0.01f),
                        vec3(0, 0, 1), NULL);
    static const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        mesh_add_triangle(&m, q[f][0], q[f][1], q[f][2]);
        mesh_add_triangle(&m, q[f][0], q[f][2], q[f][3]);
    }
    const int32_t dims[3] = {21, 21, 21};
    const float h = 0.002f;
    float sd[21 * 21 * 21];
    assert_int_equal(mesh_sdf(&m, dims, h, vec3(-0.02f, -0.02f, -0.02f), 0.003f, sd, NULL), ARGIL_OK);
    size_t i = 0;
    for (int z = 0; z < 21; z++)
        for (int y = 0; y < 21; y++)
            for (int x = 0; x < 21; x++, i++) {
                const float p[3] = {-0.02f + h * x, -0.02f + h * y, -0.02f + h * z};
                const float mx = fmaxf(fabsf(p[0]), fmaxf(fabsf(p[1]), fabsf(p[2])));
                if (mx < 0.0095f)
                    assert_true(sd[i] > 0);
                else if (mx > 0.0105f)
                    assert_true(sd[i] < 0);
                if (mx < 0.0095f || (fabsf(p[0]) < 0.01f && fabsf(p[1]) < 0.01f))
                    assert_float_equal(sd[i], fmaxf(fminf(0.01f - mx, 0.003f), -0.003f), 1e-5f);
            }
    mesh_free(&m);
}

static void test_refused(void **state)
{
    (void)state;
    mesh_t m;
    icosphere(&m, 1, 0.03f);
    const int32_t dims[3] = {8, 8, 8};
    float sd[512];
    mesh_sdf_report_t rep;
    m.n_tri--; /* a hole: three boundary edges */
    assert_int_equal(mesh_sdf(&m, dims, 0.01f, vec3(-0.04f, -0.04f, -0.04f), 0.02f, sd, &rep),
                     ARGIL_ERR_STATE);
    assert_int_equal(rep.boundary_edges, 3);
    m.n_tri++;
    const uint32_t t0[3] = {m.tri[0], m.tri[1], m.tri[2]};
    assert_int_equal(mesh_add_triangle(&m, t0[0], t0[1], t0[2]), ARGIL_OK); /* doubled face */
    assert_int_equal(mesh_sdf(&m, dims, 0.01f, vec3(-0.04f, -0.04f, -0.04f), 0.02f, sd, &rep),
                     ARGIL_ERR_STATE);
    assert_true(rep.nonmanifold_edges > 0);
    m.n_tri--;
    assert_int_equal(mesh_sdf(&m, dims, 0.0f, vec3(0, 0, 0), 0.02f, sd, NULL), ARGIL_ERR_ARG);
    assert_int_equal(mesh_sdf(&m, dims, 0.01f, vec3(0, 0, 0), -1.0f, sd, NULL), ARGIL_ERR_ARG);
    m.pos[0] = NAN;
    assert_int_equal(mesh_sdf(&m, dims, 0.01f, vec3(0, 0, 0), 0.02f, sd, NULL), ARGIL_ERR_ARG);
    const size_t nt = m.n_tri;
    m.n_tri = 0;
    assert_int_equal(mesh_sdf(&m, dims, 0.01f, vec3(0, 0, 0), 0.02f, sd, NULL), ARGIL_ERR_ARG);
    m.n_tri = nt;
    mesh_free(&m);
}

/* Grids of 1 to 2^30 samples are counted; a side below 1 or a larger count is refused. */
static void test_grid_samples(void **state)
{
    (void)state;
    uint64_t n = 0;
    assert_true(mc_grid_samples((const int32_t[3]){2, 3, 4}, &n));
    assert_int_equal(n, 24);
    assert_true(mc_grid_samples((const int32_t[3]){1024, 1024, 1024}, &n));
    assert_int_equal(n, (uint64_t)1 << 30);
    assert_false(mc_grid_samples((const int32_t[3]){1024, 1024, 1025}, &n));
    assert_false(mc_grid_samples((const int32_t[3]){4, 0, 4}, &n));
    assert_false(mc_grid_samples((const int32_t[3]){4, 4, -1}, &n));
    assert_false(mc_grid_samples((const int32_t[3]){INT32_MAX, INT32_MAX, 2}, &n));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_cube_on_rows),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_grid_samples),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
