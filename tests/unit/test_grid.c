/* The host density grid: sphere profile, trilinear sampling and gradient, hard carving, board
 * windows, external forces and the density-spring view. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/grid.h"
#include "tests/unit/grid_view.h"
#include "tests/unit/sphere_grid.h"

#define N 64
#define H 1.25e-3f
#define R 0.030f

/* A 64³ grid at 1.25 mm, centred on the origin, holding a 30 mm sphere. */
static grid_t *sphere_grid(void)
{
    return sphere_grid_new(N, H, R);
}

static vec3_t sample_pos(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return vec3(g->origin_m.x + H * (float)x, g->origin_m.y + H * (float)y,
                g->origin_m.z + H * (float)z);
}

/* Some directions that avoid the grid axes. */
static vec3_t direction(int k)
{
    const float a = 0.37f + 0.91f * (float)k, b = 0.23f + 0.53f * (float)k;
    return vec3(cosf(a) * sinf(b + 0.4f), sinf(a) * sinf(b + 0.4f), cosf(b + 0.4f));
}

static void test_init_defaults_and_errors(void **state)
{
    (void)state;
    grid_t g;
    const int32_t dims[3] = {4, 5, 6};
    assert_int_equal(grid_init(&g, dims, 0.002f, vec3(1, 2, 3)), ARGIL_OK);
    assert_float_equal(g.iso, 0.5f, 0.0f);
    assert_float_equal(g.band_m, 0.008f, 1e-9f);
    assert_true(spring_material_valid(&g.material));
    for (size_t i = 0; i < 120; i++)
        assert_true(gv_get(&g, GRID_DENSITY, i) == 0.0f && gv_get(&g, GRID_REST, i) == 0.0f &&
                    gv_get(&g, GRID_VELOCITY, i) == 0.0f && gv_get(&g, GRID_FORCE, i) == 0.0f);
    int32_t lo[3], hi[3];
    grid_bounds(&g, lo, hi);
    assert_int_equal(lo[0], 0);
    assert_int_equal(hi[0], 4);
    assert_int_equal(hi[2], 6);
    assert_int_equal(grid_count(&g), 120);
    grid_free(&g);
    grid_free(&g); /* twice is harmless */

    const int32_t zero[3] = {4, 0, 6};
    const int32_t huge[3] = {2048, 2048, 2048};
    assert_int_equal(grid_init(&g, zero, 0.002f, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(grid_init(&g, huge, 0.002f, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(grid_init(&g, dims, 0.0f, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(grid_init(&g, dims, NAN, vec3(0, 0, 0)), ARGIL_ERR_ARG);
    assert_int_equal(grid_init(&g, dims, 0.002f, vec3(NAN, 0, 0)), ARGIL_ERR_NONFINITE);
    grid_free(&g);
}

static void test_sphere_profile(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    assert_float_equal(grid_density_at(g, vec3(0, 0, 0)), 1.0f, 1e-6f);
    assert_float_equal(grid_profile(0.0f, 1.0f), 0.5f, 0.0f);
    for (int k = 0; k < 20; k++) {
        const vec3_t dir = direction(k);
        const vec3_t p = vec3_scale(dir, R);
        assert_float_equal(grid_density_at(g, p), 0.5f, 0.01f);
        /* Deep inside and well outside the band. */
        assert_float_equal(grid_density_at(g, vec3_scale(dir, R - 2.0f * g->band_m)), 1.0f, 1e-6f);
        assert_float_equal(grid_density_at(g, vec3_scale(dir, R + 2.0f * g->band_m)), 0.0f, 1e-6f);

        const vec3_t grad = grid_gradient_at(g, p);
        const float mag = vec3_norm(grad);
        assert_float_equal(mag, 0.5f / g->band_m, 0.05f * 0.5f / g->band_m);
        assert_true(vec3_dot(grad, dir) / mag < -0.99f); /* points inward */
    }
    /* Outside the grid the field is 0 and flat. */
    assert_float_equal(grid_density_at(g, vec3(1.0f, 0, 0)), 0.0f, 0.0f);
    assert_float_equal(grid_density_at(g, vec3(NAN, 0, 0)), 0.0f, 0.0f);
    assert_float_equal(vec3_norm(grid_gradient_at(g, vec3(0, -1.0f, 0))), 0.0f, 0.0f);
    sphere_grid_free(g);
}

static void test_gradient_matches_finite_differences(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    const float step = 1e-3f * H;
    for (int k = 0; k < 200; k++) {
        /* Points in the band, kept away from cell faces so the difference stays in one cell. */
        const vec3_t dir = direction(k);
        vec3_t p = vec3_scale(dir, R + (float)(k % 7 - 3) * 1.0e-3f);
        float c[3] = {p.x, p.y, p.z};
        const float o[3] = {g->origin_m.x, g->origin_m.y, g->origin_m.z};
        for (int a = 0; a < 3; a++) {
            const float u = (c[a] - o[a]) / H;
            const float fr = u - floorf(u);
            if (fr < 0.05f || fr > 0.95f)
                c[a] = o[a] + (floorf(u) + 0.5f) * H;
        }
        p = vec3(c[0], c[1], c[2]);
        const vec3_t grad = grid_gradient_at(g, p);
        const vec3_t ex = vec3(step, 0, 0), ey = vec3(0, step, 0), ez = vec3(0, 0, step);
        const vec3_t fd = vec3(
            (grid_density_at(g, vec3_add(p, ex)) - grid_density_at(g, vec3_sub(p, ex))) / (2 * step),
            (grid_density_at(g, vec3_add(p, ey)) - grid_density_at(g, vec3_sub(p, ey))) / (2 * step),
            (grid_density_at(g, vec3_add(p, ez)) - grid_density_at(g, vec3_sub(p, ez))) / (2 * step));
        /* |grad| is 100 /m; float differences over 1.25 µm carry ~1 /m of rounding. */
        assert_true(vec3_norm(vec3_sub(grad, fd)) < 2.0f);
    }
    sphere_grid_free(g);
}

static void test_carve_sphere(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    const size_t n = (size_t)N * N * N;
    float *before = malloc(n * sizeof(float));
    float *rest_before = malloc(n * sizeof(float));
    assert_non_null(before);
    assert_non_null(rest_before);
    gv_copy(g, GRID_DENSITY, before);
    gv_copy(g, GRID_REST, rest_before);

    const vec3_t c = vec3(R, 0.0f, 0.0f);
    const float rc = 0.008f;
    int32_t lo[3], hi[3];
    grid_carve_sphere(g, c, rc, lo, hi);

    int32_t want_lo[3] = {N, N, N}, want_hi[3] = {0, 0, 0};
    size_t changed = 0;
    for (int32_t z = 0; z < N; z++)
        for (int32_t y = 0; y < N; y++)
            for (int32_t x = 0; x < N; x++) {
                const size_t i = gv_idx(g, x, y, z);
                const float dist = vec3_norm(vec3_sub(sample_pos(g, x, y, z), c));
                if (dist < rc - g->band_m)
                    assert_true(gv_get(g, GRID_DENSITY, i) == 0.0f &&
                                gv_get(g, GRID_REST, i) == 0.0f);
                if (dist < rc)
                    assert_true(gv_get(g, GRID_DENSITY, i) < 0.5f);
                if (dist > rc + g->band_m + H) {
                    assert_true(gv_bits(gv_get(g, GRID_DENSITY, i), before[i]));
                    assert_true(gv_bits(gv_get(g, GRID_REST, i), rest_before[i]));
                }
                assert_true(gv_get(g, GRID_DENSITY, i) <= before[i]);
                if (gv_get(g, GRID_DENSITY, i) != before[i] ||
                    gv_get(g, GRID_REST, i) != rest_before[i]) {
                    changed++;
                    const int32_t s[3] = {x, y, z};
                    for (int a = 0; a < 3; a++) {
                        want_lo[a] = s[a] < want_lo[a] ? s[a] : want_lo[a];
                        want_hi[a] = s[a] + 1 > want_hi[a] ? s[a] + 1 : want_hi[a];
                    }
                }
            }
    assert_true(changed > 1000);
    for (int a = 0; a < 3; a++) {
        assert_int_equal(lo[a], want_lo[a]);
        assert_int_equal(hi[a], want_hi[a]);
    }
    /* The carve centre sits on the old surface; the box reaches about rc + band around it. */
    assert_true(hi[0] - lo[0] <= (int32_t)(2.0f * (rc + g->band_m) / H) + 2);
    assert_float_equal(grid_density_at(g, c), 0.0f, 0.0f);

    /* The same carve again changes nothing; one far outside the solid neither. */
    grid_carve_sphere(g, c, rc, lo, hi);
    for (int a = 0; a < 3; a++)
        assert_true(lo[a] == 0 && hi[a] == 0);
    grid_carve_sphere(g, vec3(0.035f, 0.035f, 0.035f), 0.002f, lo, hi);
    for (int a = 0; a < 3; a++)
        assert_true(lo[a] == 0 && hi[a] == 0);
    grid_carve_sphere(g, vec3(NAN, 0, 0), 0.01f, lo, hi);
    for (int a = 0; a < 3; a++)
        assert_true(lo[a] == 0 && hi[a] == 0);
    free(before);
    free(rest_before);
    sphere_grid_free(g);
}

static void test_window_corner_and_extract(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    const int32_t win[3] = {32, 5, 8};
    /* p at sample index (10.2, 20.0, 60.7). */
    const vec3_t p = vec3(g->origin_m.x + 10.2f * H, g->origin_m.y + 20.0f * H,
                          g->origin_m.z + 60.7f * H);
    int32_t corner[3];
    grid_window_corner(g, p, win, corner);
    assert_int_equal(corner[0], -5); /* centre at 10.5 */
    assert_int_equal(corner[1], 18); /* centre at 20 */
    assert_int_equal(corner[2], 57); /* centre at 60.5 */

    float *out = malloc(32 * 5 * 8 * sizeof(float));
    assert_non_null(out);
    grid_extract(g, corner, win, out);
    size_t o = 0, zeros_outside = 0;
    for (int32_t z = 0; z < 8; z++)
        for (int32_t y = 0; y < 5; y++)
            for (int32_t x = 0; x < 32; x++, o++) {
                const int32_t gx = corner[0] + x, gy = corner[1] + y, gz = corner[2] + z;
                if (gx < 0 || gz >= N) {
                    assert_true(out[o] == 0.0f);
                    zeros_outside++;
                } else {
                    assert_true(gv_bits(out[o], gv_get(g, GRID_DENSITY, gv_idx(g, gx, gy, gz))));
                }
            }
    assert_int_equal(zeros_outside, 32 * 5 * 8 - 27 * 5 * 7);

    /* A window entirely beyond the grid reads zeros. */
    const int32_t far[3] = {1000, -1000, 5};
    grid_extract(g, far, win, out);
    for (size_t i = 0; i < 32 * 5 * 8; i++)
        assert_true(out[i] == 0.0f);
    free(out);

    grid_window_corner(g, vec3(INFINITY, 0, 0), win, corner);
    assert_int_equal(corner[0], 0);
    sphere_grid_free(g);
}

static void test_add_force(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    /* Beyond the nominal box the sparse grid still holds samples; only the index limit refuses. */
    assert_true(grid_add_force(g, -1, 0, 0, 1.0f));
    assert_float_equal(grid_get(g, GRID_FORCE, -1, 0, 0), 1.0f, 0.0f);
    assert_false(grid_add_force(g, -GRID_INDEX_MAX - 1, 0, 0, 1.0f));
    assert_false(grid_add_force(g, 0, GRID_INDEX_MAX, 0, 1.0f));
    assert_false(grid_add_force(g, 1, 1, 1, NAN));
    assert_false(grid_add_force(g, 1, 1, 1, INFINITY));
    assert_true(grid_add_force(g, 1, 2, 3, 1.5f));
    assert_true(grid_add_force(g, 1, 2, 3, 1.0f));
    assert_float_equal(gv_get(g, GRID_FORCE, gv_idx(g, 1, 2, 3)), 2.5f, 0.0f);
    sphere_grid_free(g);
}

static void test_springs_push_lowers_density(void **state)
{
    (void)state;
    grid_t *g = sphere_grid();
    /* The sample on the +x surface of the sphere: 30 mm = 24 spacings from the centre. */
    const int32_t x = 31 + 24, y = 31, z = 31;
    const size_t i = gv_idx(g, x, y, z);
    const float d0 = gv_get(g, GRID_DENSITY, i);
    assert_true(d0 > 0.2f && d0 < 0.8f);
    const float far0 = gv_get(g, GRID_DENSITY, gv_idx(g, 5, 5, 5));
    assert_true(grid_add_force(g, x, y, z, -50.0f));

    const int32_t lo[3] = {0, 0, 0}, hi[3] = {N, N, N};
    const float dt = springs_stable_dt_s(&g->material);
    grid_springs_step(g, lo, hi, dt);
    /* a = F/m = -50 /s²; after one step of ~21 ms the density falls by a*dt² ≈ 0.02. */
    assert_true(gv_get(g, GRID_DENSITY, i) < d0 - 0.01f);
    assert_float_equal(gv_get(g, GRID_FORCE, i), 0.0f, 0.0f); /* consumed */
    assert_float_equal(gv_get(g, GRID_DENSITY, gv_idx(g, 5, 5, 5)), far0, 0.0f);
    sphere_grid_free(g);
}


/* Painted channels: absent until allocated, defaults 1 / 0, the value rules, freed with the grid,
 * and equality bit for bit (an absent channel equals one holding only defaults, not one with -0). */
static void test_painted_channels(void **state)
{
    (void)state;
    grid_t a, b;
    const int32_t dims[3] = {3, 2, 2};
    assert_int_equal(grid_init(&a, dims, 0.001f, vec3(0, 0, 0)), ARGIL_OK);
    assert_int_equal(grid_init(&b, dims, 0.001f, vec3(0, 0, 0)), ARGIL_OK);
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        assert_false(grid_mat_painted(&a, ch));
    assert_float_equal(gv_mat(&a, GRID_MAT_STIFFNESS, 5), 1.0f, 0);
    assert_float_equal(gv_mat(&a, GRID_MAT_RESTLEN, 5), 0.0f, 0);
    assert_true(grid_mat_valid(GRID_MAT_MASS, 1e-6f));
    assert_false(grid_mat_valid(GRID_MAT_MASS, 0.0f));
    assert_true(grid_mat_valid(GRID_MAT_STIFFNESS, 0.0f));
    assert_false(grid_mat_valid(GRID_MAT_DAMPING, -0.5f));
    assert_true(grid_mat_valid(GRID_MAT_RESTLEN, -0.5f));
    assert_false(grid_mat_valid(GRID_MAT_STIFFNESS, INFINITY));
    assert_false(grid_mat_valid(GRID_MAT_N, 1.0f));
    assert_int_equal(grid_mat_set(&a, GRID_MAT_MASS, 0, 0, 0, 1.0f), ARGIL_OK);
    assert_true(grid_mat_painted(&a, GRID_MAT_MASS));
    assert_int_equal(grid_mat_set(&a, GRID_MAT_N, 0, 0, 0, 1.0f), ARGIL_ERR_ARG);
    assert_int_equal(grid_mat_set(&a, GRID_MAT_MASS, GRID_INDEX_MAX, 0, 0, 1.0f), ARGIL_ERR_ARG);
    for (int i = 0; i < 12; i++)
        assert_float_equal(gv_mat(&a, GRID_MAT_MASS, (size_t)i), 1.0f, 0);
    assert_true(grid_mat_equal(&a, &b, GRID_MAT_MASS)); /* all default = absent */
    gv_mat_set(&a, GRID_MAT_MASS, 7, 0.5f);
    assert_false(grid_mat_equal(&a, &b, GRID_MAT_MASS));
    assert_false(grid_mat_equal(&b, &a, GRID_MAT_MASS));
    gv_mat_set(&b, GRID_MAT_RESTLEN, 0, -0.0f); /* == 0, other bits */
    assert_false(grid_mat_equal(&a, &b, GRID_MAT_RESTLEN));
    grid_free(&a);
    grid_free(&b);
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        assert_false(grid_mat_painted(&a, ch));
}

/* Sparse storage: blocks wholly outside (0) or inside (1) the sphere hold no sample arrays, so
 * memory follows the surface: a sphere of twice the radius takes ~4x, not 8x (a dense grid:
 * 16 bytes per sample of the box whatever the clay). */
static size_t sphere_bytes(int32_t n, float radius_m)
{
    grid_t g;
    const int32_t dims[3] = {n, n, n};
    const float o = -0.5f * (float)(n - 1) * H;
    assert_int_equal(grid_init(&g, dims, H, vec3(o, o, o)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0, 0, 0), radius_m);
    const size_t bytes = grid_bytes(&g);
    /* Every block holding arrays lies on the surface's band. */
    assert_true(g.data_blocks > 0);
    grid_free(&g);
    return bytes;
}

static void test_memory_follows_the_surface(void **state)
{
    (void)state;
    /* The session's clay (r 30 mm in 88^3 at 1.25 mm) and one of twice the radius. */
    const size_t small = sphere_bytes(88, 0.030f), big = sphere_bytes(176, 0.060f);
    const double dense_small = 88.0 * 88 * 88 * GRID_CH_N * sizeof(float);
    print_message("# sphere r 30 mm in 88^3: %zu bytes (dense %.0f); r 60 mm in 176^3: %zu bytes "
                  "(dense %.0f), ratio %.2f\n", small, dense_small, big, 8.0 * dense_small,
                  (double)big / (double)small);
    assert_true((double)small < 0.3 * dense_small); /* measured 0.19 */
    const double ratio = (double)big / (double)small;
    assert_true(ratio > 3.0 && ratio < 5.0); /* the surface's 4x, not the volume's 8x */
}

/* The clay can be written anywhere (negative indices too); bounds grow to hold it, reading
 * beyond them is empty clay, compaction gives back blocks that came to rest uniform. */
static void test_grows_in_every_direction(void **state)
{
    (void)state;
    grid_t g;
    const int32_t dims[3] = {16, 16, 16};
    assert_int_equal(grid_init(&g, dims, H, vec3(0, 0, 0)), ARGIL_OK);
    int32_t lo[3], hi[3];
    grid_bounds(&g, lo, hi);
    assert_true(lo[0] == 0 && hi[0] == 16 && grid_bytes(&g) < 4096); /* no sample arrays */
    assert_int_equal(grid_set(&g, GRID_DENSITY, -20, 3, 40, 0.75f), ARGIL_OK);
    grid_bounds(&g, lo, hi);
    assert_int_equal(lo[0], -20);
    assert_int_equal(hi[2], 41);
    assert_int_equal(lo[1], 0);
    assert_float_equal(grid_get(&g, GRID_DENSITY, -20, 3, 40), 0.75f, 0.0f);
    assert_float_equal(grid_density_at(&g, vec3(-20 * H, 3 * H, 40 * H)), 0.75f, 1e-5f);
    /* A box across old and new ground reads back what was written, 0 elsewhere. */
    float box[27];
    const int32_t b0[3] = {-21, 2, 39}, bn[3] = {3, 3, 3};
    grid_read_box(&g, GRID_DENSITY, b0, bn, box);
    for (int i = 0; i < 27; i++)
        assert_float_equal(box[i], i == 13 ? 0.75f : 0.0f, 0.0f);
    assert_int_equal(g.data_blocks, 1);
    /* Writing empty clay over empty space allocates nothing. */
    for (int i = 0; i < 27; i++)
        box[i] = 0.0f;
    const int32_t far[3] = {100, 100, 100};
    assert_int_equal(grid_write_box(&g, GRID_DENSITY, far, bn, box), ARGIL_OK);
    assert_int_equal(g.data_blocks, 1);
    /* Back to empty: compaction frees the block and the bounds shrink to the nominal box. */
    assert_int_equal(grid_set(&g, GRID_DENSITY, -20, 3, 40, 0.0f), ARGIL_OK);
    grid_compact(&g);
    assert_int_equal(g.data_blocks, 0);
    grid_bounds(&g, lo, hi);
    assert_true(lo[0] == 0 && hi[0] == 16 && lo[2] == 0 && hi[2] == 16);
    grid_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_defaults_and_errors),
        cmocka_unit_test(test_sphere_profile),
        cmocka_unit_test(test_gradient_matches_finite_differences),
        cmocka_unit_test(test_carve_sphere),
        cmocka_unit_test(test_window_corner_and_extract),
        cmocka_unit_test(test_add_force),
        cmocka_unit_test(test_springs_push_lowers_density),
        cmocka_unit_test(test_painted_channels),
        cmocka_unit_test(test_memory_follows_the_surface),
        cmocka_unit_test(test_grows_in_every_direction),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
