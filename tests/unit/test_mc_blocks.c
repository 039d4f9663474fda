/* Incremental block meshing: after an edit only the dirty blocks are meshed again and the result
 * equals a from-scratch mesh array for array; the mesh is closed, manifold, shares every vertex
 * across blocks, matches the whole-grid mesher, carries painted colours, and meshes any region
 * at any iso. The block tables follow the surface: memory does not grow with the box, and a box
 * grown by clay written outside it re-meshes only the blocks the new clay touches. */
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
    assert_int_equal(all_blocks, mc_blocks_box_blocks(&inc)); /* 97 padded cells: 7^3 blocks */
    assert_int_equal(all_blocks, 343);
    assert_true(inc.blocks.count * 2 < all_blocks); /* only the blocks the surface crosses keep a slot */
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

/* Writes a ball of clay (the grid's density profile, max with what is there) and returns its
 * sample box [lo, hi). */
static void add_ball(grid_t *g, vec3_t c_m, float r_m, int32_t lo[3], int32_t hi[3])
{
    const float cc[3] = {c_m.x, c_m.y, c_m.z}, o[3] = {g->origin_m.x, g->origin_m.y, g->origin_m.z};
    int32_t n[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (int32_t)floorf((cc[a] - r_m - g->band_m - o[a]) / g->spacing_m) - 1;
        hi[a] = (int32_t)ceilf((cc[a] + r_m + g->band_m - o[a]) / g->spacing_m) + 2;
        n[a] = hi[a] - lo[a];
    }
    const size_t cnt = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    float *d = malloc(cnt * sizeof(float));
    assert_non_null(d);
    grid_read_box(g, GRID_DENSITY, lo, n, d);
    size_t i = 0;
    for (int32_t z = 0; z < n[2]; z++)
        for (int32_t y = 0; y < n[1]; y++)
            for (int32_t x = 0; x < n[0]; x++, i++) {
                const vec3_t p = vec3(o[0] + g->spacing_m * (float)(lo[0] + x),
                                      o[1] + g->spacing_m * (float)(lo[1] + y),
                                      o[2] + g->spacing_m * (float)(lo[2] + z));
                const float v = grid_profile(r_m - vec3_norm(vec3_sub(p, c_m)), g->band_m);
                d[i] = v > d[i] ? v : d[i];
            }
    assert_int_equal(grid_write_box(g, GRID_DENSITY, lo, n, d), ARGIL_OK);
    free(d);
}

/* A sphere of r = 30 mm in a 176^3 box: the mesher holds slots only where the surface is, far
 * below per-block tables over the box; clay written outside the box (past +x and past -z, so
 * block keys go negative) grows the mesher without a rebuild, re-meshes only the blocks the new
 * clay touches, and the result is the from-scratch mesh of the grown grid, array for array. */
static void test_memory_follows_surface_and_growth(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 176, 1e-3f, 0.030f);
    mc_blocks_t inc;
    grid_mesh_view_t view;
    assert_int_equal(grid_mesh_blocks_init(&inc, &view, &g, 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
    const size_t box_blocks = mc_blocks_box_blocks(&inc);
    assert_int_equal(box_blocks, 12 * 12 * 12); /* 177 padded cells per axis */
    assert_int_equal(inc.blocks_meshed, box_blocks);
    /* Blocks of empty space (grid blocks not held or uniform 0) are skipped unread: 81 read. */
    assert_true(inc.blocks_read * 10 < box_blocks);
    /* The tables over the box as they were: one block record and one dirty flag per block. */
    const size_t dense_tables = box_blocks * (sizeof(mc_block_mesh_t) + 1);
    const size_t table = block_table_bytes(&inc.blocks);
    assert_true(inc.blocks.count >= 50 && inc.blocks.count <= 120); /* the blocks the shell crosses: 74 */
    assert_true(table * 4 < dense_tables); /* 18 KB against 98 KB */
    /* Everything it holds, the sphere's triangles (≈ 1.6 MB of the 1.8) included. */
    const size_t bytes0 = mc_blocks_bytes(&inc);
    assert_true(bytes0 < 2200 * 1024);
    mesh_t a, b;
    mesh_init(&a);
    mesh_init(&b);
    assert_int_equal(mc_blocks_assemble(&inc, &a), ARGIL_OK);
    const size_t tri0 = a.n_tri;
    assert_true(tri0 > 15000);

    /* Clay outside the box: a 6 mm ball 40 mm past +x and one 30 mm past -z. */
    int32_t lo1[3], hi1[3], lo2[3], hi2[3];
    add_ball(&g, vec3(0.1275f, 0.0f, 0.0f), 0.006f, lo1, hi1);
    add_ball(&g, vec3(0.0f, 0.01f, -0.1175f), 0.006f, lo2, hi2);
    assert_true(grid_mesh_view_stale(&view, &g));
    const size_t slots_before = inc.blocks.count;
    assert_int_equal(grid_mesh_grow(&inc, &view, &g), ARGIL_OK);
    assert_false(grid_mesh_view_stale(&view, &g));
    assert_true(view.lo[2] < -20 && view.hi[0] > 210);
    grid_mesh_mark(&inc, &view, lo1, hi1);
    grid_mesh_mark(&inc, &view, lo2, hi2);
    assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
    /* Each ball's box (25 samples + the normals' halo) spans at most 3 blocks per axis (45 of
     * the 2700 blocks are meshed). */
    assert_true(inc.blocks_meshed >= 2 && inc.blocks_meshed <= 2 * 27);
    const size_t grown_blocks = mc_blocks_box_blocks(&inc);
    assert_true(grown_blocks * 3 > 4 * box_blocks); /* 225 x 176 x 215 samples: 2700 blocks */
    assert_true(inc.blocks_meshed * 50 < grown_blocks);
    assert_true(inc.blocks.count > slots_before && inc.blocks.count <= slots_before + 2 * 27);
    /* Memory grew by the balls' surfaces only, not with the box (the tables alone would double). */
    assert_true(mc_blocks_bytes(&inc) < bytes0 + 300 * 1024);
    assert_true(block_table_bytes(&inc.blocks) * 4 < grown_blocks * (sizeof(mc_block_mesh_t) + 1));
    assert_int_equal(mc_blocks_assemble(&inc, &a), ARGIL_OK);
    assert_true(a.n_tri > tri0 + 2000);

    /* From scratch over the grown bounds: the same arrays. */
    mc_blocks_t full;
    grid_mesh_view_t fview;
    assert_int_equal(grid_mesh_blocks_init(&full, &fview, &g, 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update_read(&full, grid_mesh_read, &fview), ARGIL_OK);
    assert_int_equal(full.blocks_meshed, grown_blocks);
    assert_int_equal(mc_blocks_assemble(&full, &b), ARGIL_OK);
    assert_same_mesh(&a, &b);
    assert_closed(&a);
    /* and the whole-grid mesher on a dense copy sees the same surface */
    mesh_t w;
    mesh_init(&w);
    assert_int_equal(grid_mesh_extract(&g, 0.5f, &w), ARGIL_OK);
    assert_int_equal(w.n_tri, a.n_tri);
    assert_int_equal(w.n_vert, a.n_vert);
    assert_float_equal(mesh_volume_m3(&w), mesh_volume_m3(&a), 1e-12);
    mesh_free(&w);
    mesh_free(&a);
    mesh_free(&b);
    mc_blocks_free(&inc);
    mc_blocks_free(&full);
    grid_free(&g);
}

/* A block whose surface is carved away gives its slot back; growth past the edge-id span, an
 * empty box and the dense array after growth are refused; with iso < 0 growth re-meshes all. */
static void test_slots_released_and_grow_errors(void **state)
{
    (void)state;
    grid_t g;
    make_grid(&g, 40, 1e-3f, 0.010f);
    mc_blocks_t inc;
    grid_mesh_view_t view;
    assert_int_equal(grid_mesh_blocks_init(&inc, &view, &g, 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
    assert_int_equal(inc.blocks.count, 8); /* 41 padded cells: the sphere's 8 blocks round the centre */
    int32_t lo[3], hi[3];
    grid_carve_sphere(&g, vec3(0, 0, 0), 0.019f, lo, hi);
    grid_mesh_mark(&inc, &view, lo, hi);
    assert_int_equal(mc_blocks_update_read(&inc, grid_mesh_read, &view), ARGIL_OK);
    assert_int_equal(inc.blocks_meshed, 27);
    assert_int_equal(inc.blocks.count, 0);
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mc_blocks_assemble(&inc, &m), ARGIL_OK);
    assert_int_equal(m.n_tri, 0);
    const int32_t far_lo[3] = {0, 0, 0}, far_hi[3] = {MC_BLOCKS_SPAN_MAX + 1, 1, 1};
    assert_int_equal(mc_blocks_grow(&inc, far_lo, far_hi), ARGIL_ERR_FULL);
    assert_int_equal(inc.hi[0], 40); /* kept */
    const int32_t empty_hi[3] = {0, 5, 5};
    assert_int_equal(mc_blocks_grow(&inc, far_lo, empty_hi), ARGIL_ERR_ARG);
    mc_blocks_free(&inc);

    const int32_t dims[3] = {4, 4, 4}, glo[3] = {-3, 0, 0}, ghi[3] = {4, 4, 4};
    float d[64] = {0};
    d[21] = 1.0f;
    assert_int_equal(mc_blocks_init(&inc, dims, 1.0f, vec3(0, 0, 0), 0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&inc, d, NULL), ARGIL_OK);
    assert_int_equal(mc_blocks_grow(&inc, glo, ghi), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&inc, d, NULL), ARGIL_ERR_ARG); /* d holds [0, dims) only */
    mc_blocks_free(&inc);
    assert_int_equal(mc_blocks_init(&inc, dims, 1.0f, vec3(0, 0, 0), -0.5f), ARGIL_OK);
    assert_int_equal(mc_blocks_update(&inc, d, NULL), ARGIL_OK);
    assert_false(inc.all_dirty);
    assert_int_equal(mc_blocks_grow(&inc, glo, ghi), ARGIL_OK);
    assert_true(inc.all_dirty); /* 0 counts as inside: the box's faces moved */
    mc_blocks_free(&inc);
    mesh_free(&m);
    grid_free(&g);
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
        cmocka_unit_test(test_memory_follows_surface_and_growth),
        cmocka_unit_test(test_slots_released_and_grow_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
