/* Incremental block meshing: after an edit only the dirty blocks are meshed again and the result
 * equals a from-scratch mesh array for array; the mesh is closed, manifold, shares every vertex
 * across blocks, matches the whole-grid mesher, carries painted colours, and meshes any region
 * at any iso. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc_blocks.h"
#include "host/mesh/mesh_check.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"

static void make_grid(grid_t *g, int32_t n, float spacing_m, float radius_m)
{
    const int32_t dims[3] = {n, n, n};
    const float half = 0.5f * (float)(n - 1) * spacing_m;
    assert_int_equal(grid_init(g, dims, spacing_m, vec3(-half, -half, -half)), ARGIL_OK);
    grid_fill_sphere(g, vec3(0, 0, 0), radius_m);
}

static void assert_same_mesh(const mesh_t *a, const mesh_t *b)
{
    assert_int_equal(a->n_vert, b->n_vert);
    assert_int_equal(a->n_tri, b->n_tri);
    assert_memory_equal(a->pos, b->pos, 3 * sizeof(float) * a->n_vert);
    assert_memory_equal(a->normal, b->normal, 3 * sizeof(float) * a->n_vert);
    assert_memory_equal(a->tri, b->tri, 3 * sizeof(uint32_t) * a->n_tri);
    assert_int_equal(a->has_rgb, b->has_rgb);
    if (a->has_rgb)
        assert_memory_equal(a->rgb, b->rgb, 3 * a->n_vert);
}

static void assert_closed(const mesh_t *m)
{
    size_t boundary = 9, nonmanifold = 9;
    assert_true(mesh_watertight(m, &boundary, &nonmanifold));
    assert_int_equal(boundary, 0);
    assert_int_equal(nonmanifold, 0);
}

static int cmp_pos(const void *a, const void *b)
{
    return memcmp(a, b, 3 * sizeof(float));
}

/* The sorted vertex positions of a mesh (caller frees). */
static float *sorted_positions(const mesh_t *m)
{
    float *p = malloc(3 * sizeof(float) * (m->n_vert + 1));
    assert_non_null(p);
    memcpy(p, m->pos, 3 * sizeof(float) * m->n_vert);
    qsort(p, m->n_vert, 3 * sizeof(float), cmp_pos);
    return p;
}

static void test_matches_whole_grid_mesher(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 56, 1e-3f, 0.021f);
    mesh_t whole, blk;
    mesh_init(&whole);
    mesh_init(&blk);
    assert_int_equal(mc_extract(gv_dense(&g), g.dims, g.spacing_m, g.origin_m, 0.5f, &whole), ARGIL_OK);
    assert_int_equal(mc_extract_region(gv_dense(&g), NULL, g.dims, g.spacing_m, g.origin_m, 0.5f,
                                       NULL, NULL, &blk),
                     ARGIL_OK);
    assert_true(blk.n_tri > 10000);
    assert_int_equal(blk.n_vert, whole.n_vert);
    assert_int_equal(blk.n_tri, whole.n_tri);
    float *pa = sorted_positions(&whole), *pb = sorted_positions(&blk);
    assert_memory_equal(pa, pb, 3 * sizeof(float) * blk.n_vert); /* same vertices, bit for bit */
    free(pa);
    free(pb);
    assert_closed(&blk);
    const double v = mesh_volume_m3(&blk), want = 4.0 / 3.0 * M_PI * pow(0.021, 3);
    assert_true(fabs(v - want) / want < 0.01);
    assert_float_equal(v, mesh_volume_m3(&whole), 1e-12);
    mesh_free(&whole);
    mesh_free(&blk);
    grid_free(&g);
}

static void test_incremental_equals_full(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 96, 1e-3f, 0.035f);
    mc_blocks_t inc;
    grid_mesh_view_t view;
    assert_int_equal(grid_mesh_blocks_init(&inc, &view, &g, 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
    const size_t all_blocks = inc.blocks_meshed;
    assert_int_equal(all_blocks, inc.n_blocks);
    mesh_t a, b;
    mesh_init(&a);
    mesh_init(&b);
    /* Five carves around the sphere, each followed by an incremental update. */
    for (int k = 0; k < 5; k++) {
        const float ang = (float)k * 1.3f;
        int32_t lo[3], hi[3];
        grid_carve_sphere(&g, vec3(0.035f * cosf(ang), 0.035f * sinf(ang), 0.01f * (float)(k - 2)),
                          0.008f, lo, hi);
        assert_true(hi[0] > lo[0]);
        grid_mesh_mark(&inc, &view, lo, hi);
        assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
        /* A 16 mm carve touches at most 3 blocks per axis (plus the normal halo: 4). */
        assert_true(inc.blocks_meshed <= 64);
        assert_true(inc.blocks_meshed * 8 < all_blocks);
    }
    assert_int_equal(mc_blocks_assemble(&inc, &a), ARGIL_OK);
    mc_blocks_t full;
    assert_int_equal(mc_blocks_init(&full, g.dims, g.spacing_m, g.origin_m, 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&full, gv_dense(&g), NULL), ARGIL_OK);
    assert_int_equal(mc_blocks_assemble(&full, &b), ARGIL_OK);
    assert_same_mesh(&a, &b);
    assert_closed(&a);
    /* and the whole-grid mesher sees the same surface */
    mesh_t w;
    mesh_init(&w);
    assert_int_equal(mc_extract(gv_dense(&g), g.dims, g.spacing_m, g.origin_m, 0.5f, &w), ARGIL_OK);
    assert_int_equal(w.n_tri, a.n_tri);
    assert_float_equal(mesh_volume_m3(&w), mesh_volume_m3(&a), 1e-12);
    mesh_free(&w);
    mesh_free(&a);
    mesh_free(&b);
    mc_blocks_free(&inc);
    mc_blocks_free(&full);
    grid_free(&g);
}

static uint32_t xorshift(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return *s = x;
}

/* Saddle-heavy random fields, edited in random boxes: incremental stays identical to full. */
static void test_random_edits_identical(void **state)
{
    (void)state;
    const int32_t dims[3] = {37, 29, 41};
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *d = malloc(n * sizeof(float));
    uint8_t *rgb = malloc(3 * n);
    assert_non_null(d);
    assert_non_null(rgb);
    uint32_t s = 12345;
    for (size_t i = 0; i < n; i++) {
        d[i] = (float)(xorshift(&s) % 5) / 4.0f;
        rgb[3 * i] = (uint8_t)i;
        rgb[3 * i + 1] = (uint8_t)(i >> 8);
        rgb[3 * i + 2] = 7;
    }
    mc_blocks_t inc;
    assert_int_equal(mc_blocks_init(&inc, dims, 0.5f, vec3(1, 2, 3), 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&inc, d, rgb), ARGIL_OK);
    mesh_t a, b;
    mesh_init(&a);
    mesh_init(&b);
    for (int k = 0; k < 10; k++) {
        int32_t lo[3], hi[3];
        for (int ax = 0; ax < 3; ax++) {
            lo[ax] = (int32_t)(xorshift(&s) % (uint32_t)dims[ax]);
            hi[ax] = lo[ax] + 1 + (int32_t)(xorshift(&s) % 4u);
            if (hi[ax] > dims[ax])
                hi[ax] = dims[ax];
        }
        for (int32_t z = lo[2]; z < hi[2]; z++)
            for (int32_t y = lo[1]; y < hi[1]; y++)
                for (int32_t x = lo[0]; x < hi[0]; x++) {
                    const size_t i = (size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                    d[i] = (float)(xorshift(&s) % 5) / 4.0f;
                    rgb[3 * i + 2] = (uint8_t)k;
                }
        mc_blocks_mark(&inc, lo, hi);
        assert_int_equal(mc_blocks_update(&inc, d, rgb), ARGIL_OK);
        assert_int_equal(mc_blocks_assemble(&inc, &a), ARGIL_OK);
        assert_int_equal(mc_extract_region(d, rgb, dims, 0.5f, vec3(1, 2, 3), 0.5f, NULL, NULL, &b),
                         ARGIL_OK);
        assert_same_mesh(&a, &b);
        assert_closed(&a);
    }
    mesh_free(&a);
    mesh_free(&b);
    mc_blocks_free(&inc);
    free(d);
    free(rgb);
}

static void test_painted_colours(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 40, 1e-3f, 0.015f);
    const size_t n = (size_t)40 * 40 * 40;
    uint8_t *rgb = malloc(3 * n);
    assert_non_null(rgb);
    for (size_t i = 0; i < n; i++) {
        const int32_t x = (int32_t)(i % 40);
        rgb[3 * i] = x < 20 ? 200 : 10; /* left half painted red, right half blue */
        rgb[3 * i + 1] = 30;
        rgb[3 * i + 2] = x < 20 ? 10 : 220;
    }
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mc_extract_region(gv_dense(&g), rgb, g.dims, g.spacing_m, g.origin_m, 0.5f, NULL,
                                       NULL, &m),
                     ARGIL_OK);
    assert_true(m.has_rgb);
    size_t red = 0, blue = 0;
    for (size_t v = 0; v < m.n_vert; v++) {
        const float x = m.pos[3 * v];
        const uint8_t *c = m.rgb + 3 * v;
        if (x < -0.002f) {
            assert_int_equal(c[0], 200);
            red++;
        } else if (x > 0.002f) {
            assert_int_equal(c[2], 220);
            blue++;
        }
    }
    assert_true(red > 500 && blue > 500);
    assert_closed(&m);
    mesh_free(&m);
    free(rgb);
    grid_free(&g);
}

static void test_region_and_iso(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 48, 1e-3f, 0.018f);
    mesh_t m;
    mesh_init(&m);
    /* The x < 24 half of the sphere: closed at the cut, about half the volume. */
    const int32_t lo[3] = {0, 0, 0}, hi[3] = {24, 48, 48};
    assert_int_equal(mc_extract_region(gv_dense(&g), NULL, g.dims, g.spacing_m, g.origin_m, 0.5f, lo,
                                       hi, &m),
                     ARGIL_OK);
    assert_closed(&m);
    const double full = 4.0 / 3.0 * M_PI * pow(0.018, 3);
    const double v = mesh_volume_m3(&m);
    assert_true(v > 0.40 * full && v < 0.55 * full);
    for (size_t i = 0; i < m.n_vert; i++)
        assert_true(m.pos[3 * i] <= g.origin_m.x + 24.0f * g.spacing_m);
    /* Other iso-values: a higher iso gives a smaller solid (band 4 mm: iso 0.75 = 2 mm in). */
    double vol[3];
    const float iso[3] = {0.25f, 0.5f, 0.75f};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(mc_extract_region(gv_dense(&g), NULL, g.dims, g.spacing_m, g.origin_m, iso[k],
                                           NULL, NULL, &m),
                         ARGIL_OK);
        assert_closed(&m);
        vol[k] = mesh_volume_m3(&m);
    }
    const double r75 = cbrt(vol[2] / (4.0 / 3.0 * M_PI)), r25 = cbrt(vol[0] / (4.0 / 3.0 * M_PI));
    assert_float_equal(r75, 0.016, 0.0003);
    assert_float_equal(r25, 0.020, 0.0003);
    assert_true(vol[0] > vol[1] && vol[1] > vol[2]);
    mesh_free(&m);
    grid_free(&g);
}

static void test_errors(void **state)
{
    (void)state;
    mc_blocks_t b;
    const int32_t bad[3] = {0, 4, 4}, dims[3] = {4, 4, 4};
    assert_int_equal(mc_blocks_init(&b, bad, 1.0f, vec3(0, 0, 0), 0.5f), ARGIL_ERR_ARG);
    assert_int_equal(mc_blocks_init(&b, dims, NAN, vec3(0, 0, 0), 0.5f), ARGIL_ERR_ARG);
    assert_int_equal(mc_blocks_init(&b, dims, 1.0f, vec3(0, 0, 0), INFINITY), ARGIL_ERR_ARG);
    float d[64] = {0};
    d[21] = NAN;
    assert_int_equal(mc_blocks_init(&b, dims, 1.0f, vec3(0, 0, 0), 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&b, d, NULL), ARGIL_ERR_NONFINITE);
    d[21] = 1.0f;
    assert_int_equal(mc_blocks_update(&b, d, NULL), ARGIL_OK);
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mc_blocks_assemble(&b, &m), ARGIL_OK);
    assert_int_equal(m.n_vert, 6); /* one inside sample: an octahedron */
    assert_int_equal(m.n_tri, 8);
    mc_blocks_free(&b);
    const int32_t lo[3] = {2, 0, 0}, hi[3] = {2, 4, 4}, hi2[3] = {5, 4, 4};
    assert_int_equal(mc_extract_region(d, NULL, dims, 1.0f, vec3(0, 0, 0), 0.5f, lo, hi, &m),
                     ARGIL_ERR_ARG);
    assert_int_equal(mc_extract_region(d, NULL, dims, 1.0f, vec3(0, 0, 0), 0.5f, lo, hi2, &m),
                     ARGIL_ERR_ARG);
    mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_whole_grid_mesher),
        cmocka_unit_test(test_incremental_equals_full),
        cmocka_unit_test(test_random_edits_identical),
        cmocka_unit_test(test_painted_colours),
        cmocka_unit_test(test_region_and_iso),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
