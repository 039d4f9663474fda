/* Mouse sculpting's hand: the cursor ray finds the clay's surface to within a fraction of a
 * sample, misses what it should miss, and the hand hovers over the surface when the button is
 * up, presses in (push) or draws out (pull) from the touched point when it is held, never
 * faster than its speed limit; the camera's pixel ray goes through what the view centres. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>

#include "host/app/live_hand.h"
#include "host/render/camera.h"

enum { EDGE = 56 };
#define SPACING_M 0.00125f
#define RADIUS_M 0.025f

static void make_clay(grid_t *g)
{
    const int32_t dims[3] = {EDGE, EDGE, EDGE};
    const float half = 0.5f * (float)(EDGE - 1) * SPACING_M;
    assert_int_equal(grid_init(g, dims, SPACING_M, vec3(-half, -half, -half)), ARGIL_OK);
    grid_fill_sphere(g, vec3(0, 0, 0), RADIUS_M);
}

static void test_raycast(void **state)
{
    (void)state;
    grid_t g;
    make_clay(&g);
    vec3_t hit;
    /* Straight down the z axis from outside the grid: the sphere's pole at z = +25 mm. */
    assert_true(live_hand_raycast(&g, vec3(0, 0, 0.2f), vec3(0, 0, -1), &hit));
    assert_float_equal(hit.z, RADIUS_M, 0.25f * SPACING_M);
    assert_float_equal(hit.x, 0.0f, 1e-6);
    /* Off-axis, 15 mm to the side: z = sqrt(25² − 15²) = 20 mm. */
    assert_true(live_hand_raycast(&g, vec3(0.015f, 0, 0.2f), vec3(0, 0, -1), &hit));
    assert_float_equal(hit.z, 0.020f, 0.5f * SPACING_M);
    /* Misses: beside the sphere, pointing away, not finite. */
    assert_false(live_hand_raycast(&g, vec3(0.03f, 0, 0.2f), vec3(0, 0, -1), &hit));
    assert_false(live_hand_raycast(&g, vec3(0, 0, 0.2f), vec3(0, 0, 1), &hit));
    assert_false(live_hand_raycast(&g, vec3(NAN, 0, 0.2f), vec3(0, 0, -1), &hit));
    assert_false(live_hand_raycast(&g, vec3(0, 0, 0.2f), vec3(0, 0, 0), &hit));
    grid_free(&g);
}

static void test_hand_hover_press_pull(void **state)
{
    (void)state;
    grid_t g;
    make_clay(&g);
    live_hand_cfg_t cfg;
    live_hand_cfg_default(&cfg);
    live_hand_t h;
    live_hand_init(&h);
    const float tool_r = 0.004f, dt = 0.001f;
    vec3_t pos = vec3(0, 0, 0.06f), vel;
    int buttons = -1;
    const vec3_t o = vec3(0, 0, 0.2f), d = vec3(0, 0, -1);
    /* Button up: the hand travels to hover over the pole at its speed limit. */
    float fastest = 0.0f;
    for (int i = 0; i < 1000; i++) {
        live_hand_step(&h, &cfg, &g, o, d, false, false, tool_r, dt, &pos, &vel, &buttons);
        fastest = fmaxf(fastest, vec3_norm(vel));
    }
    assert_int_equal(buttons, 0);
    assert_float_equal(pos.z, RADIUS_M + tool_r + cfg.hover_m, 0.5f * SPACING_M);
    assert_true(fastest <= cfg.max_speed_m_s * 1.001f);
    assert_true(fastest > 0.5f * cfg.max_speed_m_s);
    /* Button held (push): into the clay, down to radius + extra below the touched point. */
    for (int i = 0; i < 3000; i++)
        live_hand_step(&h, &cfg, &g, o, d, true, false, tool_r, dt, &pos, &vel, &buttons);
    assert_int_equal(buttons, 1);
    assert_float_equal(pos.z, RADIUS_M - (tool_r + cfg.press_extra_m), 0.5f * SPACING_M);
    /* Released: back out to hover. Held again as pull: drawn out above the touched point. */
    for (int i = 0; i < 1000; i++)
        live_hand_step(&h, &cfg, &g, o, d, false, false, tool_r, dt, &pos, &vel, &buttons);
    assert_int_equal(buttons, 0);
    for (int i = 0; i < 3000; i++)
        live_hand_step(&h, &cfg, &g, o, d, true, true, tool_r, dt, &pos, &vel, &buttons);
    assert_float_equal(pos.z, RADIUS_M + cfg.pull_m, 0.5f * SPACING_M);
    /* A drag while held moves across the plane of the first touch, not along the new ray. */
    for (int i = 0; i < 1000; i++)
        live_hand_step(&h, &cfg, &g, vec3(0.01f, 0, 0.2f), d, true, true, tool_r, dt, &pos,
                       &vel, &buttons);
    assert_float_equal(pos.x, 0.01f, 1e-4);
    assert_float_equal(pos.z, RADIUS_M + cfg.pull_m, 0.5f * SPACING_M);
    grid_free(&g);
}

static void test_camera_ray(void **state)
{
    (void)state;
    camera_t c;
    camera_frame(&c, vec3(-0.03f, -0.03f, -0.03f), vec3(0.03f, 0.03f, 0.03f));
    camera_orbit(&c, 0.4f, 0.3f);
    vec3_t o, d;
    /* The centre pixel's ray passes through the orbit centre. */
    camera_ray(&c, 320, 240, 640, 480, &o, &d);
    const vec3_t to_c = vec3_sub(c.center_m, o);
    const float along = vec3_dot(to_c, d);
    assert_float_equal(along, c.dist_m, 1e-5);
    assert_float_equal(vec3_norm(vec3_sub(to_c, vec3_scale(d, along))), 0.0f, 1e-6);
    /* A pixel right of centre looks to the view's right: +x turned by the camera. */
    vec3_t o2, d2;
    camera_ray(&c, 600, 240, 640, 480, &o2, &d2);
    const vec3_t right = vec3(c.rot[0], c.rot[1], c.rot[2]); /* first row: view x in model */
    assert_true(vec3_dot(vec3_sub(d2, d), right) > 0.1f);
    assert_float_equal(vec3_norm(d2), 1.0f, 1e-5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_raycast),
        cmocka_unit_test(test_hand_hover_press_pull),
        cmocka_unit_test(test_camera_ray),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
