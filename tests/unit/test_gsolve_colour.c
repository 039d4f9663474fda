/* Painted colour on the B-spline model and its grid view (gsolve_apply_tool with HOST_ACT_PAINT /
 * HOST_ACT_SOFT_PAINT, gsolve_colour_to_grid, gsolve_colour_from_grid): paint reaches exactly the
 * samples inside the tool (and their mirror images), changes no density and leaves the window
 * alone, soft paint blends in step by step, the grid holds no colour arrays until something is painted,
 * and the colour goes from grid to model and back byte for byte. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"
#include "tests/unit/sphere_grid.h"

#define N 40
#define H 1.25e-3f
#define R 0.018f
#define DT 0.01f

static vec3_t sample_pos(const grid_t *g, size_t i)
{
    const size_t x = i % N, y = i / N % N, z = i / ((size_t)N * N);
    return vec3(g->origin_m.x + H * (float)x, g->origin_m.y + H * (float)y,
                g->origin_m.z + H * (float)z);
}

static argil_err_t paint(gsolve_t *gs, grid_t *g, host_action_t a, uint32_t mirror, float strength,
                         const uint8_t rgb[3], float radius, vec3_t at, int32_t lo[3], int32_t hi[3])
{
    host_tool_t t;
    host_tool_default(&t);
    t.action = a;
    t.mirror = mirror;
    t.strength = strength;
    memcpy(t.rgb, rgb, 3);
    return gsolve_apply_tool(gs, g, &t, radius, vec3(0, 0, 1), &at, 1, DT, lo, hi);
}

static void test_paint_colours_the_ball_only(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    assert_false(grid_rgb_any(g));
    const size_t n = (size_t)N * N * N;
    float *d0 = malloc(n * sizeof(float)), *d1 = malloc(n * sizeof(float));
    uint8_t *col = malloc(3 * n);
    assert_true(d0 != NULL && d1 != NULL && col != NULL);
    gv_copy(g, GRID_DENSITY, d0);
    const uint32_t w0 = g->rgb_writes;
    const uint8_t red[3] = {230, 20, 20};
    const vec3_t at = vec3(R, 0, 0); /* on the +x surface, mirrored onto -x */
    int32_t lo[3], hi[3];
    assert_int_equal(paint(&gs, g, HOST_ACT_PAINT, HOST_MIRROR_X, 0.0f, red, 4e-3f, at, lo, hi),
                     ARGIL_OK);
    assert_true(grid_rgb_any(g));
    assert_true(g->rgb_writes > w0); /* once per mirror image that changed */
    const uint32_t w1 = g->rgb_writes;
    assert_true(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2]);
    assert_memory_equal(gv_copy(g, GRID_DENSITY, d1), d0, n * sizeof(float)); /* no clay moved */
    gv_rgb_copy(g, col);
    assert_false(gs.stale);                                /* nor the window reloaded */
    size_t in = 0, in_red = 0, out_red = 0, edge = 0;
    for (size_t i = 0; i < n; i++) {
        const vec3_t p = sample_pos(g, i);
        const float dp = vec3_norm(vec3_sub(p, at));
        const float dm = vec3_norm(vec3_sub(p, vec3(-R, 0, 0)));
        const float dist = dp < dm ? dp : dm;
        const bool is_red = memcmp(&col[3 * i], red, 3) == 0;
        const bool is_base = col[3 * i] == GRID_RGB_DEFAULT &&
                             col[3 * i + 1] == GRID_RGB_DEFAULT &&
                             col[3 * i + 2] == GRID_RGB_DEFAULT;
        assert_true(is_red || is_base); /* paint is all or nothing */
        if (dist < 4e-3f - 1e-5f) {
            in++;
            in_red += is_red;
        } else if (dist > 4e-3f + 1e-5f) {
            out_red += is_red;
        } else {
            edge++;
        }
        if (is_red) { /* inside the box the call reported */
            const int32_t s[3] = {(int32_t)(i % N), (int32_t)(i / N % N), (int32_t)(i / (N * N))};
            for (int a = 0; a < 3; a++)
                assert_true(s[a] >= lo[a] && s[a] < hi[a]);
        }
    }
    print_message("# paint: %zu of %zu samples within 4 mm red (both sides), %zu beyond, %zu on "
                  "the edge\n", in_red, in, out_red, edge);
    /* two 4 mm balls on the 1.25 mm lattice: 2 x 4/3 pi (3.2)^3 = ~275 samples */
    assert_true(in > 250 && in < 300);
    assert_int_equal(in_red, in);
    assert_int_equal(out_red, 0);
    /* painting the same again changes nothing: no write counted */
    assert_int_equal(paint(&gs, g, HOST_ACT_PAINT, HOST_MIRROR_X, 0.0f, red, 4e-3f, at, lo, hi),
                     ARGIL_OK);
    assert_int_equal(g->rgb_writes, w1);
    assert_true(lo[0] == hi[0]);
    free(d0);
    free(d1);
    free(col);
    sphere_model_free(&gs, g);
}

static void test_soft_paint_blends_in(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    const uint8_t blue[3] = {0, 0, 255};
    /* the sample at the tool centre, 10.6 mm inside the +x surface (density 1) */
    const size_t c = (size_t)(N / 2 + 8) + (size_t)N * ((size_t)(N / 2) + (size_t)N * (N / 2));
    const vec3_t at = sample_pos(g, c);
    assert_true(gv_get(g, GRID_DENSITY, c) == 1.0f);
    /* per step the colour moves by w = 20 /s x 10 ms x phi x d of the way, phi the tool's
     * profile at its centre: 0.5 + 0.5 x 4 mm / band (5 mm) = 0.9, so w = 0.18 */
    const float phi = 0.5f + 0.5f * 4e-3f / g->band_m;
    const double w = 20.0 * DT * phi;
    int32_t lo[3], hi[3];
    double r_want = GRID_RGB_DEFAULT, b_want = GRID_RGB_DEFAULT;
    uint8_t cc[3];
    for (int k = 0; k < 10; k++) {
        assert_int_equal(paint(&gs, g, HOST_ACT_SOFT_PAINT, 0, 20.0f, blue, 4e-3f, at, lo, hi),
                         ARGIL_OK);
        assert_true(grid_rgb_any(g));
        r_want += (0.0 - r_want) * w;
        b_want += (255.0 - b_want) * w;
        gv_rgb(g, c, cc);
        assert_true(fabs(cc[0] - r_want) <= 1.0 && fabs(cc[2] - b_want) <= 1.0);
    }
    print_message("# soft paint (w %.3f per step): centre after 10 steps %u %u %u (want %.1f, "
                  "%.1f)\n", w, cc[0], cc[1], cc[2], r_want, b_want);
    /* 0.82^10 = 0.137 of the way left */
    assert_true(cc[0] < 32 && cc[2] > 245);
    sphere_model_free(&gs, g);
}

static void test_carve_leaves_no_colour_and_round_trip(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    host_tool_t t;
    host_tool_default(&t);
    int32_t lo[3], hi[3];
    const vec3_t at = vec3(0, R, 0);
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 3e-3f, vec3(0, 0, 1), &at, 1, DT, lo, hi),
                     ARGIL_OK);
    assert_false(grid_rgb_any(g)); /* a carve paints nothing: unpainted sessions stay as before */
    const int32_t all_lo[3] = {0, 0, 0};
    assert_int_equal(gsolve_colour_to_grid(&gs, g, all_lo, g->dims), ARGIL_OK);
    assert_false(grid_rgb_any(g));
    /* every byte value survives grid -> model -> grid */
    const size_t n = (size_t)N * N * N;
    uint8_t *rgb = malloc(3 * n);
    assert_non_null(rgb);
    for (size_t i = 0; i < 3 * n; i++)
        rgb[i] = (uint8_t)(i * 7u + i / 3u);
    assert_int_equal(gv_rgb_store(g, rgb), ARGIL_OK);
    uint8_t *keep = malloc(3 * n);
    assert_non_null(keep);
    memcpy(keep, rgb, 3 * n);
    assert_int_equal(gsolve_colour_from_grid(&gs, g), ARGIL_OK);
    memset(rgb, (int)GRID_RGB_DEFAULT, 3 * n);
    assert_int_equal(gv_rgb_store(g, rgb), ARGIL_OK);
    const uint32_t w = g->rgb_writes;
    assert_int_equal(gsolve_colour_to_grid(&gs, g, all_lo, g->dims), ARGIL_OK);
    assert_memory_equal(gv_rgb_copy(g, rgb), keep, 3 * n);
    assert_int_equal(g->rgb_writes, w + 1);
    /* a box beyond the grid is clipped, not refused */
    const int32_t blo[3] = {-10, -10, -10}, bhi[3] = {N + 10, 3, 3};
    assert_int_equal(gsolve_colour_to_grid(&gs, g, blo, bhi), ARGIL_OK);
    assert_true(grid_rgb_painted(g));
    free(keep);
    free(rgb);
    sphere_model_free(&gs, g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paint_colours_the_ball_only),
        cmocka_unit_test(test_soft_paint_blends_in),
        cmocka_unit_test(test_carve_leaves_no_colour_and_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
