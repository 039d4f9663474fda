/* The session's host tool on the B-spline model (gsolve_apply_tool, peer_set_host_tool): each
 * action moves the surface the way a person would see it (add outward, carve inward, mirror on
 * both sides by the same amount, smooth lowers a bump, chisel by its depth per second, box
 * flat-bottomed where the sphere is round), the strength scales with the solve period, and bad
 * settings change nothing. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve.h"
#include "host/app/peer.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"
#include "tests/unit/sphere_grid.h"

#define N 48
#define H 1.25e-3f
#define R 0.020f
#define DT 0.01f

/* Where the density along the ray from the grid centre in direction dir (unit axis, sign)
 * crosses 0.5, offset `off` samples along the next axis: distance from the centre line, m. */
static float crossing_m(const grid_t *g, int axis, int sign, int32_t off)
{
    const int32_t c0 = N / 2 - 1, c1 = N / 2; /* the two samples either side of the centre */
    int32_t at[3] = {c1, c1, c1};
    at[(axis + 1) % 3] += off;
    const int32_t start = sign > 0 ? c1 : c0;
    for (int32_t k = 0; k + 1 < N / 2; k++) {
        at[axis] = start + sign * k;
        const float a = gv_get(g, GRID_DENSITY, gv_idx(g, at[0], at[1], at[2]));
        at[axis] = start + sign * (k + 1);
        const float b = gv_get(g, GRID_DENSITY, gv_idx(g, at[0], at[1], at[2]));
        if (a >= 0.5f && b < 0.5f) {
            const float pos = (float)(start + sign * k) + (float)sign * (a - 0.5f) / (a - b);
            return fabsf(pos - 0.5f * (float)(N - 1)) * H;
        }
    }
    return -1.0f;
}

static double volume_m3(const grid_t *g)
{
    double s = 0.0;
    for (size_t i = 0; i < (size_t)N * N * N; i++)
        s += gv_get(g, GRID_DENSITY, i);
    return s * (double)H * H * H;
}

static argil_err_t apply(gsolve_t *gs, grid_t *g, host_action_t a, host_shape_t sh,
                         uint32_t mirror, float strength, float radius, vec3_t at, float dt)
{
    host_tool_t t;
    host_tool_default(&t);
    t.action = a;
    t.shape = sh;
    t.mirror = mirror;
    t.strength = strength;
    int32_t lo[3], hi[3];
    return gsolve_apply_tool(gs, g, &t, radius, vec3(0, 0, 1), &at, 1, dt, lo, hi);
}

static void test_add_grows_the_clay_at_the_tool(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    const double v0 = volume_m3(g);
    const float x0 = crossing_m(g, 0, 1, 0);
    /* a 4 mm ball centred 2 mm outside the +x surface: the surface moves out to ~26 mm */
    assert_int_equal(apply(&gs, g, HOST_ACT_ADD, HOST_SHAPE_SPHERE, 0, 0.0f, 4e-3f,
                           vec3(R + 2e-3f, 0, 0), DT), ARGIL_OK);
    const float x1 = crossing_m(g, 0, 1, 0);
    const double dv = volume_m3(g) - v0;
    /* the ball's part outside the sphere: 268 mm³ less the 37 mm³ lens inside it, = 231 mm³;
     * max(p, φ) also fills the neck where the two density ramps overlap */
    print_message("# add: +x surface %.2f -> %.2f mm, volume +%.1f mm3; -x %.2f mm\n",
                  (double)x0 * 1e3, (double)x1 * 1e3, dv * 1e9,
                  (double)crossing_m(g, 0, -1, 0) * 1e3);
    assert_true(fabsf(x1 - (R + 6e-3f)) < 0.5e-3f);
    assert_true(dv > 231e-9 && dv < 400e-9);
    assert_true(fabsf(crossing_m(g, 0, -1, 0) - R) < 0.1e-3f); /* the far side untouched */
    sphere_model_free(&gs, g);
}

static void test_mirror_carves_both_sides_alike(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    assert_int_equal(apply(&gs, g, HOST_ACT_CARVE, HOST_SHAPE_SPHERE, HOST_MIRROR_X, 0.0f, 5e-3f,
                           vec3(R, 1e-3f, 0), DT), ARGIL_OK);
    const float px = crossing_m(g, 0, 1, 0), nx = crossing_m(g, 0, -1, 0);
    print_message("# mirror x: +x surface %.3f mm, -x %.3f mm (sphere %.1f); +y %.3f mm\n",
                  (double)px * 1e3, (double)nx * 1e3, (double)R * 1e3,
                  (double)crossing_m(g, 1, 1, 0) * 1e3);
    assert_true(px < R - 4e-3f);
    assert_true(fabsf(px - nx) < 0.1e-3f);
    assert_true(fabsf(crossing_m(g, 1, 1, 0) - R) < 0.1e-3f); /* y and z untouched */
    assert_true(fabsf(crossing_m(g, 2, -1, 0) - R) < 0.1e-3f);
    /* without the mirror only +x moves */
    gsolve_t gs2;
    grid_t *g2 = sphere_model_new(&gs2, N, H, R);
    assert_int_equal(apply(&gs2, g2, HOST_ACT_CARVE, HOST_SHAPE_SPHERE, 0, 0.0f, 5e-3f,
                           vec3(R, 1e-3f, 0), DT), ARGIL_OK);
    assert_true(fabsf(crossing_m(g2, 0, 1, 0) - px) < 1e-6f);
    assert_true(fabsf(crossing_m(g2, 0, -1, 0) - R) < 0.1e-3f);
    sphere_model_free(&gs2, g2);
    sphere_model_free(&gs, g);
}

/* A ridge made with add, then smoothed: its top comes down. */
static void test_smooth_lowers_a_bump(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    assert_int_equal(apply(&gs, g, HOST_ACT_ADD, HOST_SHAPE_SPHERE, 0, 0.0f, 2.5e-3f,
                           vec3(0, R + 1e-3f, 0), DT), ARGIL_OK);
    const float top0 = crossing_m(g, 1, 1, 0);
    for (int k = 0; k < 50; k++)
        assert_int_equal(apply(&gs, g, HOST_ACT_SMOOTH, HOST_SHAPE_SPHERE, 0,
                               host_action_default_strength(HOST_ACT_SMOOTH), 6e-3f,
                               vec3(0, R + 1e-3f, 0), DT), ARGIL_OK);
    const float top1 = crossing_m(g, 1, 1, 0);
    print_message("# smooth: bump top %.2f -> %.2f mm (sphere %.1f)\n", (double)top0 * 1e3,
                  (double)top1 * 1e3, (double)R * 1e3);
    assert_true(top0 > R + 3e-3f);
    assert_true(top1 < top0 - 1e-3f);
    assert_true(top1 > R - 1e-3f); /* smoothed, not carved */
    sphere_model_free(&gs, g);
}

/* Toothpaste's strength is per second: twice the period, twice the density per application. */
static void test_strength_is_per_second(void **st)
{
    (void)st;
    float rise[2];
    for (int k = 0; k < 2; k++) {
        gsolve_t gs;
        grid_t *g = sphere_model_new(&gs, N, H, R);
        const int32_t c = N / 2, x = N - 4; /* 5.6 mm beyond the surface: density 0 */
        const float before = gv_get(g, GRID_DENSITY, gv_idx(g, x, c, c));
        const float px = ((float)x - 0.5f * (float)(N - 1)) * H;
        assert_int_equal(apply(&gs, g, HOST_ACT_TOOTHPASTE, HOST_SHAPE_SPHERE, 0, 5.0f, 4e-3f,
                               vec3(px, ((float)c - 0.5f * (float)(N - 1)) * H,
                                    ((float)c - 0.5f * (float)(N - 1)) * H),
                               k == 0 ? DT : 2.0f * DT), ARGIL_OK);
        rise[k] = gv_get(g, GRID_DENSITY, gv_idx(g, x, c, c)) - before;
        sphere_model_free(&gs, g);
    }
    print_message("# toothpaste 5/s: density at the tool centre +%.4f (10 ms), +%.4f (20 ms)\n",
                  (double)rise[0], (double)rise[1]);
    assert_true(rise[0] > 0.035f && rise[0] <= 0.0501f); /* 0.05 at the coefficients */
    assert_true(fabsf(rise[1] - 2.0f * rise[0]) < 5e-4f);
}

static void test_chisel_moves_the_surface_by_its_depth(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    /* 2 mm/s for 0.5 s at 10 ms: 1 mm in along the normal, under a 6 mm ball on the surface */
    for (int k = 0; k < 50; k++)
        assert_int_equal(apply(&gs, g, HOST_ACT_CHISEL, HOST_SHAPE_SPHERE, 0, 2.0f, 6e-3f,
                               vec3(0, 0, R), DT), ARGIL_OK);
    const float z1 = crossing_m(g, 2, 1, 0);
    print_message("# chisel 2 mm/s x 0.5 s: +z surface %.3f mm (sphere %.1f)\n",
                  (double)z1 * 1e3, (double)R * 1e3);
    assert_true(fabsf((R - z1) - 1e-3f) < 0.25e-3f);
    sphere_model_free(&gs, g);
}

/* A box cuts as deep off-centre as on its axis; a sphere's cut is shallower off-centre. */
static void test_box_is_flat_bottomed(void **st)
{
    (void)st;
    float depth[2][2];
    for (int s = 0; s < 2; s++) {
        gsolve_t gs;
        grid_t *g = sphere_model_new(&gs, N, H, R);
        assert_int_equal(apply(&gs, g, HOST_ACT_CARVE, s ? HOST_SHAPE_BOX : HOST_SHAPE_SPHERE, 0,
                               0.0f, 5e-3f, vec3(0, 0, R + 1e-3f), DT), ARGIL_OK);
        depth[s][0] = R - crossing_m(g, 2, 1, 0);
        depth[s][1] = R - crossing_m(g, 2, 1, 3); /* 3.75 mm off the axis (along x) */
        sphere_model_free(&gs, g);
    }
    print_message("# cut depth on the axis / 3.75 mm off it: sphere %.2f / %.2f mm, box %.2f / "
                  "%.2f mm\n", (double)depth[0][0] * 1e3, (double)depth[0][1] * 1e3,
                  (double)depth[1][0] * 1e3, (double)depth[1][1] * 1e3);
    assert_true(depth[1][0] > 3.5e-3f && depth[0][0] > 3.5e-3f);
    assert_true(depth[1][1] > depth[0][1] + 1e-3f);
}

/* A stroke of two points cuts the whole segment between them, not only its ends. */
static void test_stroke_fills_the_gap(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    host_tool_t t;
    host_tool_default(&t);
    const vec3_t pts[2] = {vec3(-8e-3f, 0, R + 1e-3f), vec3(8e-3f, 0, R + 1e-3f)};
    int32_t lo[3], hi[3];
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 3e-3f, vec3(0, 0, 1), pts, 2, DT, lo, hi),
                     ARGIL_OK);
    const float mid = crossing_m(g, 2, 1, 0);
    print_message("# stroke from x -8 to +8 mm: +z surface mid-way %.2f mm\n", (double)mid * 1e3);
    assert_true(mid < R - 1.5e-3f);
    assert_true(hi[0] - lo[0] > 16); /* the box covers the stroke (> 20 mm of samples) */
    sphere_model_free(&gs, g);
}

static void test_bad_settings_change_nothing(void **st)
{
    (void)st;
    gsolve_t gs;
    grid_t *g = sphere_model_new(&gs, N, H, R);
    float *before = gv_dup(g, GRID_DENSITY);
    assert_non_null(before);
    host_tool_t t;
    host_tool_default(&t);
    const vec3_t at = vec3(0, R, 0);
    int32_t lo[3], hi[3];
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 0.0f, vec3(0, 0, 1), &at, 1, DT, lo, hi),
                     ARGIL_ERR_ARG);
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 0), &at, 1, DT, lo, hi),
                     ARGIL_ERR_ARG);
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &at, 0, DT, lo, hi),
                     ARGIL_ERR_ARG);
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &at, 1, 0.0f, lo, hi),
                     ARGIL_ERR_ARG);
    const vec3_t nan_at = vec3(NAN, 0, 0);
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &nan_at, 1, DT, lo, hi),
                     ARGIL_ERR_NONFINITE);
    t.mirror = 8;
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &at, 1, DT, lo, hi),
                     ARGIL_ERR_ARG);
    host_tool_default(&t);
    t.action = HOST_ACT_COUNT;
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &at, 1, DT, lo, hi),
                     ARGIL_ERR_ARG);
    host_tool_default(&t);
    t.strength = HOST_STRENGTH_MAX * 2.0f;
    assert_int_equal(gsolve_apply_tool(&gs, g, &t, 4e-3f, vec3(0, 0, 1), &at, 1, DT, lo, hi),
                     ARGIL_ERR_ARG);
    assert_int_equal(lo[0], 0);
    assert_int_equal(hi[0], 0);
    assert_true(gv_equal(g, GRID_DENSITY, before));
    free(before);
    sphere_model_free(&gs, g);
}

static bool send_nothing(void *ctx, const uint8_t *frame, size_t len)
{
    (void)ctx;
    (void)frame;
    (void)len;
    return true;
}

/* The springs carve the grid themselves: only the default setting; the B-spline takes any. */
static void test_peer_setter(void **st)
{
    (void)st;
    for (int k = 0; k < 2; k++) {
        grid_t g;
        const int32_t dims[3] = {24, 24, 24};
        assert_int_equal(grid_init(&g, dims, H, vec3(-0.015f, -0.015f, -0.015f)), ARGIL_OK);
        peer_cfg_t cfg;
        peer_cfg_default(&cfg);
        cfg.global_solve = k ? PEER_SOLVE_BSPLINE : PEER_SOLVE_SPRINGS;
        peer_t p;
        assert_int_equal(peer_init(&p, &cfg, &g, send_nothing, NULL, NULL), ARGIL_OK);
        assert_true(host_tool_is_default(&p.host_tool));
        host_tool_t t;
        host_tool_default(&t);
        t.action = HOST_ACT_ADD;
        t.mirror = HOST_MIRROR_X | HOST_MIRROR_Z;
        assert_int_equal(peer_set_host_tool(&p, &t), k ? ARGIL_OK : ARGIL_ERR_STATE);
        assert_int_equal(p.host_tool.action, k ? HOST_ACT_ADD : HOST_ACT_CARVE);
        t.shape = HOST_SHAPE_COUNT;
        assert_int_equal(peer_set_host_tool(&p, &t), ARGIL_ERR_ARG);
        assert_int_equal(p.host_tool.shape, HOST_SHAPE_SPHERE);
        host_tool_default(&t);
        assert_int_equal(peer_set_host_tool(&p, &t), ARGIL_OK);
        peer_free(&p);
        grid_free(&g);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_add_grows_the_clay_at_the_tool),
        cmocka_unit_test(test_mirror_carves_both_sides_alike),
        cmocka_unit_test(test_smooth_lowers_a_bump),
        cmocka_unit_test(test_strength_is_per_second),
        cmocka_unit_test(test_chisel_moves_the_surface_by_its_depth),
        cmocka_unit_test(test_box_is_flat_bottomed),
        cmocka_unit_test(test_stroke_fills_the_gap),
        cmocka_unit_test(test_bad_settings_change_nothing),
        cmocka_unit_test(test_peer_setter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
