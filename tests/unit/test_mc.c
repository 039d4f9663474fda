/* Marching cubes and mesh checks: closed, manifold, accurate surfaces on spheres, a torus,
 * saddle-heavy random fields and fields that touch the block's border. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/mesh/mesh.h"
#include "host/mesh/mesh_check.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"

#define PI_D 3.14159265358979323846

/* The 64³ test block: 1.25 mm spacing, centred on the origin (±39.4 mm). */
#define N64 64
#define H64 1.25e-3f

typedef struct {
    int32_t dims[3];
    float spacing_m;
    vec3_t origin_m;
    float *d;
} field_t;

static void field_alloc(field_t *f, int32_t nx, int32_t ny, int32_t nz, float spacing_m)
{
    f->dims[0] = nx;
    f->dims[1] = ny;
    f->dims[2] = nz;
    f->spacing_m = spacing_m;
    f->origin_m = vec3(-0.5f * (float)(nx - 1) * spacing_m, -0.5f * (float)(ny - 1) * spacing_m,
                       -0.5f * (float)(nz - 1) * spacing_m);
    f->d = calloc((size_t)nx * (size_t)ny * (size_t)nz, sizeof(float));
    assert_non_null(f->d);
}

static vec3_t field_pos(const field_t *f, int32_t x, int32_t y, int32_t z)
{
    return vec3(f->origin_m.x + f->spacing_m * (float)x, f->origin_m.y + f->spacing_m * (float)y,
                f->origin_m.z + f->spacing_m * (float)z);
}

static float profile(float sd_m, float band_m)
{
    float d = 0.5f + 0.5f * sd_m / band_m;
    return d < 0.0f ? 0.0f : (d > 1.0f ? 1.0f : d);
}

static void field_sphere(field_t *f, vec3_t c, float r_m)
{
    const float band = 4.0f * f->spacing_m;
    size_t i = 0;
    for (int32_t z = 0; z < f->dims[2]; z++)
        for (int32_t y = 0; y < f->dims[1]; y++)
            for (int32_t x = 0; x < f->dims[0]; x++, i++) {
                float v = profile(r_m - vec3_norm(vec3_sub(field_pos(f, x, y, z), c)), band);
                if (v > f->d[i])
                    f->d[i] = v; /* union with what is there */
            }
}

static void field_torus(field_t *f, float big_r_m, float small_r_m)
{
    const float band = 4.0f * f->spacing_m;
    size_t i = 0;
    for (int32_t z = 0; z < f->dims[2]; z++)
        for (int32_t y = 0; y < f->dims[1]; y++)
            for (int32_t x = 0; x < f->dims[0]; x++, i++) {
                vec3_t p = field_pos(f, x, y, z);
                float q = sqrtf(p.x * p.x + p.y * p.y) - big_r_m;
                f->d[i] = profile(small_r_m - sqrtf(q * q + p.z * p.z), band);
            }
}

static uint32_t rng_next(uint32_t *s)
{
    /* xorshift32 */
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

static void field_random(field_t *f, uint32_t seed, int levels)
{
    const size_t n = (size_t)f->dims[0] * (size_t)f->dims[1] * (size_t)f->dims[2];
    for (size_t i = 0; i < n; i++) {
        uint32_t r = rng_next(&seed);
        if (levels > 0)
            f->d[i] = (float)(r % (uint32_t)levels) / (float)(levels - 1);
        else
            f->d[i] = (float)(r >> 8) / 16777216.0f;
    }
}

static void extract(const field_t *f, mesh_t *m)
{
    mesh_init(m);
    assert_int_equal(mc_extract(f->d, f->dims, f->spacing_m, f->origin_m, 0.5f, m), ARGIL_OK);
}

static int cmp_pos(const void *a, const void *b)
{
    return memcmp(a, b, 3 * sizeof(float));
}

/* Asserts a closed, edge-manifold mesh with no sliver triangles and no duplicated vertices,
 * every vertex used, unit normals; returns its Euler characteristic V - E + F. */
static long assert_closed_manifold(const mesh_t *m, float min_area_m2)
{
    size_t boundary = 99, nonmanifold = 99;
    assert_true(mesh_watertight(m, &boundary, &nonmanifold));
    assert_int_equal(boundary, 0);
    assert_int_equal(nonmanifold, 0);
    assert_int_equal(mesh_degenerate_triangles(m, min_area_m2), 0);
    const size_t e = mesh_edge_count(m);
    assert_int_equal(2 * e, 3 * m->n_tri);

    unsigned char *used = calloc(m->n_vert + 1, 1);
    assert_non_null(used);
    for (size_t i = 0; i < 3 * m->n_tri; i++)
        used[m->tri[i]] = 1;
    for (size_t v = 0; v < m->n_vert; v++) {
        assert_true(used[v]);
        const float *n = m->normal + 3 * v;
        assert_float_equal(sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0f, 1e-4f);
    }
    free(used);

    float *p = malloc(3 * sizeof(float) * (m->n_vert + 1));
    assert_non_null(p);
    memcpy(p, m->pos, 3 * sizeof(float) * m->n_vert);
    qsort(p, m->n_vert, 3 * sizeof(float), cmp_pos);
    for (size_t v = 1; v < m->n_vert; v++)
        assert_true(memcmp(p + 3 * (v - 1), p + 3 * v, 3 * sizeof(float)) != 0);
    free(p);
    return (long)m->n_vert - (long)e + (long)m->n_tri;
}

static void test_sphere_r30mm(void **state)
{
    (void)state;
    field_t f;
    field_alloc(&f, N64, N64, N64, H64);
    const float r = 0.030f;
    field_sphere(&f, vec3(0.0f, 0.0f, 0.0f), r);
    mesh_t m;
    extract(&f, &m);
    assert_true(m.n_tri > 10000);
    assert_int_equal(assert_closed_manifold(&m, 1e-12f), 2); /* a sphere: genus 0 */

    const double v_exact = 4.0 / 3.0 * PI_D * 0.030 * 0.030 * 0.030;
    const double v = mesh_volume_m3(&m);
    assert_true(fabs(v - v_exact) < 0.015 * v_exact);

    float worst_r = 0.0f, worst_dot = 1.0f;
    for (size_t i = 0; i < m.n_vert; i++) {
        const vec3_t p = vec3(m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]);
        const vec3_t n = vec3(m.normal[3 * i], m.normal[3 * i + 1], m.normal[3 * i + 2]);
        const float len = vec3_norm(p);
        const float dr = fabsf(len - r);
        const float dot = vec3_dot(n, vec3_scale(p, 1.0f / len));
        worst_r = dr > worst_r ? dr : worst_r;
        worst_dot = dot < worst_dot ? dot : worst_dot;
    }
    assert_true(worst_r < 0.5f * H64);
    assert_true(worst_dot > 0.9f);

    /* Triangles face outward: their geometric normal agrees with the radial direction. */
    for (size_t t = 0; t < m.n_tri; t++) {
        const float *a = m.pos + 3 * m.tri[3 * t], *b = m.pos + 3 * m.tri[3 * t + 1],
                    *c = m.pos + 3 * m.tri[3 * t + 2];
        const vec3_t u = vec3(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
        const vec3_t w = vec3(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
        const vec3_t centre = vec3((a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3,
                                   (a[2] + b[2] + c[2]) / 3);
        assert_true(vec3_dot(vec3_cross(u, w), centre) > 0.0f);
    }
    mesh_free(&m);
    free(f.d);
}

static void test_carved_grid_stays_closed(void **state)
{
    (void)state;
    /* The grid's own sphere, bitten by the eraser at its surface and drilled through. */
    grid_t g;
    const int32_t dims[3] = {N64, N64, N64};
    const float o = -0.5f * (float)(N64 - 1) * H64;
    assert_int_equal(grid_init(&g, dims, H64, vec3(o, o, o)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0, 0, 0), 0.030f);
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mc_extract(gv_dense(&g), g.dims, g.spacing_m, g.origin_m, g.iso, &m), ARGIL_OK);
    const double v_full = mesh_volume_m3(&m);
    int32_t lo[3], hi[3];
    grid_carve_sphere(&g, vec3(0.030f, 0, 0), 0.010f, lo, hi);
    for (int k = -6; k <= 6; k++)
        grid_carve_sphere(&g, vec3(0, 0, 0.005f * (float)k), 0.006f, lo, hi);
    assert_int_equal(mc_extract(gv_dense(&g), g.dims, g.spacing_m, g.origin_m, g.iso, &m), ARGIL_OK);
    assert_int_equal(assert_closed_manifold(&m, 1e-12f), 0); /* drilled through: genus 1 */
    const double v = mesh_volume_m3(&m);
    assert_true(v < v_full - 0.5 * PI_D * 0.006 * 0.006 * 0.060);
    assert_true(v > 0.5 * v_full);
    mesh_free(&m);
    grid_free(&g);
}

static void test_torus_genus_one(void **state)
{
    (void)state;
    field_t f;
    field_alloc(&f, N64, N64, 32, H64);
    const double big_r = 0.020, small_r = 0.007;
    field_torus(&f, (float)big_r, (float)small_r);
    mesh_t m;
    extract(&f, &m);
    assert_int_equal(assert_closed_manifold(&m, 1e-12f), 0);
    const double v_exact = 2.0 * PI_D * PI_D * big_r * small_r * small_r;
    assert_true(fabs(mesh_volume_m3(&m) - v_exact) < 0.03 * v_exact);
    mesh_free(&m);
    free(f.d);
}

static void test_touching_spheres(void **state)
{
    (void)state;
    /* Two spheres whose surfaces meet at the origin, on a coarse grid: the neck is all saddles. */
    field_t f;
    field_alloc(&f, 24, 16, 16, 1.0e-3f);
    field_sphere(&f, vec3(-0.005f, 0.0f, 0.0f), 0.005f);
    field_sphere(&f, vec3(0.005f, 0.0f, 0.0f), 0.005f);
    mesh_t m;
    extract(&f, &m);
    const long chi = assert_closed_manifold(&m, 1e-14f);
    assert_int_equal(chi % 2, 0);
    assert_true(mesh_volume_m3(&m) > 0.0);
    mesh_free(&m);
    free(f.d);
}

static void test_random_fields(void **state)
{
    (void)state;
    static const uint32_t seeds[] = {1u, 12345u, 0xC0FFEEu, 777u};
    for (size_t s = 0; s < sizeof(seeds) / sizeof(seeds[0]); s++) {
        field_t f;
        field_alloc(&f, 16, 16, 16, 1.0e-3f);
        field_random(&f, seeds[s], 0);
        mesh_t m;
        extract(&f, &m);
        assert_true(m.n_tri > 1000);
        const long chi = assert_closed_manifold(&m, 1e-14f);
        assert_int_equal(chi % 2, 0); /* closed orientable surfaces only */
        assert_true(mesh_volume_m3(&m) > 0.0);
        mesh_free(&m);
        free(f.d);
    }
}

static void test_samples_exactly_on_iso(void **state)
{
    (void)state;
    /* Values from {0, 0.5, 1}: a third of the samples sit exactly on the iso-value. */
    field_t f;
    field_alloc(&f, 12, 12, 12, 1.0e-3f);
    field_random(&f, 99u, 3);
    mesh_t m;
    extract(&f, &m);
    assert_true(m.n_tri > 100);
    /* Vertices stay MC_T_MIN of a cell from any sample: areas well above 1e-5 of a cell face. */
    assert_closed_manifold(&m, 1e-5f * 1.0e-6f);
    mesh_free(&m);
    free(f.d);
}

static void test_checkerboard(void **state)
{
    (void)state;
    /* Alternating 0/1: every face of every cell is a saddle. */
    field_t f;
    field_alloc(&f, 9, 9, 9, 1.0e-3f);
    size_t i = 0;
    for (int32_t z = 0; z < 9; z++)
        for (int32_t y = 0; y < 9; y++)
            for (int32_t x = 0; x < 9; x++, i++)
                f.d[i] = (float)((x + y + z) & 1);
    mesh_t m;
    extract(&f, &m);
    assert_closed_manifold(&m, 1e-14f);
    /* Separating inside corners: every inside sample becomes its own little octahedron. */
    assert_int_equal(m.n_tri, 8 * 364);
    mesh_free(&m);
    free(f.d);
}

static void test_full_block_closes_at_border(void **state)
{
    (void)state;
    field_t f;
    field_alloc(&f, 8, 8, 8, 1.0f);
    for (size_t i = 0; i < 512; i++)
        f.d[i] = 1.0f;
    mesh_t m;
    extract(&f, &m);
    assert_int_equal(assert_closed_manifold(&m, 1e-6f), 2);
    /* The surface runs half a cell outside the samples: an 8 x 8 x 8 box with cut corners. */
    const double v = mesh_volume_m3(&m);
    assert_true(v > 0.97 * 512.0 && v < 512.0);
    mesh_free(&m);
    free(f.d);
}

static void test_single_sample_is_octahedron(void **state)
{
    (void)state;
    const float d = 1.0f;
    const int32_t dims[3] = {1, 1, 1};
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mc_extract(&d, dims, 2.0f, vec3(1.0f, 2.0f, 3.0f), 0.5f, &m), ARGIL_OK);
    assert_int_equal(m.n_vert, 6);
    assert_int_equal(m.n_tri, 8);
    assert_int_equal(assert_closed_manifold(&m, 1e-3f), 2);
    /* Vertices at 0.5 cell (1 m) from the sample: volume of an octahedron of radius 1 = 4/3. */
    assert_float_equal(mesh_volume_m3(&m), 4.0 / 3.0, 1e-5);
    for (size_t v = 0; v < 6; v++) {
        const vec3_t p = vec3(m.pos[3 * v] - 1.0f, m.pos[3 * v + 1] - 2.0f, m.pos[3 * v + 2] - 3.0f);
        const vec3_t n = vec3(m.normal[3 * v], m.normal[3 * v + 1], m.normal[3 * v + 2]);
        assert_float_equal(vec3_norm(p), 1.0f, 1e-6f);
        assert_float_equal(vec3_dot(n, p), 1.0f, 1e-6f);
    }
    mesh_free(&m);
}

static void test_deterministic(void **state)
{
    (void)state;
    field_t f;
    field_alloc(&f, 16, 16, 16, 1.0e-3f);
    field_random(&f, 4242u, 0);
    mesh_t a, b;
    extract(&f, &a);
    extract(&f, &b);
    assert_int_equal(a.n_vert, b.n_vert);
    assert_int_equal(a.n_tri, b.n_tri);
    assert_memory_equal(a.pos, b.pos, 3 * sizeof(float) * a.n_vert);
    assert_memory_equal(a.normal, b.normal, 3 * sizeof(float) * a.n_vert);
    assert_memory_equal(a.tri, b.tri, 3 * sizeof(uint32_t) * a.n_tri);
    /* Reusing an output mesh gives the same arrays too. */
    assert_int_equal(mc_extract(f.d, f.dims, f.spacing_m, f.origin_m, 0.5f, &a), ARGIL_OK);
    assert_int_equal(a.n_tri, b.n_tri);
    assert_memory_equal(a.tri, b.tri, 3 * sizeof(uint32_t) * a.n_tri);
    mesh_free(&a);
    mesh_free(&b);
    free(f.d);
}

static void test_empty_field(void **state)
{
    (void)state;
    field_t f;
    field_alloc(&f, 10, 10, 10, 1.0e-3f);
    mesh_t m;
    extract(&f, &m);
    assert_int_equal(m.n_tri, 0);
    assert_int_equal(m.n_vert, 0);
    assert_true(mesh_watertight(&m, NULL, NULL));
    assert_float_equal(mesh_volume_m3(&m), 0.0, 0.0);
    mesh_free(&m);
    free(f.d);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    float d[8] = {0, 1, 0, 1, 0, 1, 0, 1};
    const int32_t dims[3] = {2, 2, 2};
    const int32_t zero[3] = {2, 0, 2};
    mesh_t m;
    mesh_init(&m);
    const vec3_t o = vec3(0, 0, 0);
    assert_int_equal(mc_extract(d, zero, 1.0f, o, 0.5f, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, 0.0f, o, 0.5f, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, NAN, o, 0.5f, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, 1.0f, vec3(INFINITY, 0, 0), 0.5f, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, 1.0f, o, NAN, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(NULL, dims, 1.0f, o, 0.5f, &m), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, 1.0f, o, 0.5f, NULL), ARGIL_ERR_ARG);
    assert_int_equal(mc_extract(d, dims, 1.0f, o, 0.5f, &m), ARGIL_OK);
    assert_true(m.n_tri > 0);
    d[5] = NAN;
    assert_int_equal(mc_extract(d, dims, 1.0f, o, 0.5f, &m), ARGIL_ERR_NONFINITE);
    assert_int_equal(m.n_tri, 0);
    assert_int_equal(m.n_vert, 0);
    mesh_free(&m);
}

static void add_vertex(mesh_t *m, float x, float y, float z)
{
    assert_int_equal(mesh_add_vertex(m, vec3(x, y, z), vec3(0, 0, 1), NULL), ARGIL_OK);
}

static void test_mesh_checks_on_tetrahedron(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    add_vertex(&m, 0, 0, 0);
    add_vertex(&m, 1, 0, 0);
    add_vertex(&m, 0, 1, 0);
    add_vertex(&m, 0, 0, 1);
    assert_int_equal(mesh_add_triangle(&m, 0, 2, 1), ARGIL_OK);
    assert_int_equal(mesh_add_triangle(&m, 0, 1, 3), ARGIL_OK);
    assert_int_equal(mesh_add_triangle(&m, 0, 3, 2), ARGIL_OK);
    assert_int_equal(mesh_add_triangle(&m, 1, 2, 3), ARGIL_OK);
    assert_int_equal(mesh_add_triangle(&m, 1, 2, 4), ARGIL_ERR_ARG);
    assert_float_equal(mesh_volume_m3(&m), 1.0 / 6.0, 1e-12);
    size_t b, nm;
    assert_true(mesh_watertight(&m, &b, &nm));
    assert_int_equal(mesh_edge_count(&m), 6);
    assert_int_equal(mesh_degenerate_triangles(&m, 0.49f), 0);
    assert_int_equal(mesh_degenerate_triangles(&m, 0.51f), 3); /* the three right triangles */

    /* Flip one triangle: its three edges now run twice in the same direction. */
    m.tri[9] = 2;
    m.tri[10] = 1;
    assert_false(mesh_watertight(&m, &b, &nm));
    assert_int_equal(b, 0);
    assert_int_equal(nm, 3);

    /* Drop it: three boundary edges. */
    m.n_tri = 3;
    assert_false(mesh_watertight(&m, &b, &nm));
    assert_int_equal(b, 3);
    assert_int_equal(nm, 0);

    /* A collinear triangle has zero area. */
    add_vertex(&m, 2, 0, 0);
    assert_int_equal(mesh_add_triangle(&m, 0, 1, 4), ARGIL_OK);
    assert_int_equal(mesh_degenerate_triangles(&m, 1e-20f), 1);
    mesh_free(&m);
    assert_null(m.pos);
    assert_int_equal(m.n_vert, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_r30mm),
        cmocka_unit_test(test_carved_grid_stays_closed),
        cmocka_unit_test(test_torus_genus_one),
        cmocka_unit_test(test_touching_spheres),
        cmocka_unit_test(test_random_fields),
        cmocka_unit_test(test_samples_exactly_on_iso),
        cmocka_unit_test(test_checkerboard),
        cmocka_unit_test(test_full_block_closes_at_border),
        cmocka_unit_test(test_single_sample_is_octahedron),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_empty_field),
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_mesh_checks_on_tetrahedron),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
