/* Material colour maps: the ramp runs blue → pale → red and is clamped, names parse, and a mesh
 * coloured from a non-uniform material gets colours that follow the material — the stiffest
 * vertex reddest, the softest bluest, logarithmic about the default (1.0, the pale middle), grey
 * for a non-finite value, the ramp's middle for a uniform default material. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "host/render/colour_map.h"

/* Stiffness rising along x: 0.5 at x = 0 to 2.5 at x = 0.02 m. */
static float ramp_x(const void *ctx, vec3_t x_m)
{
    (void)ctx;
    return 0.5f + 100.0f * x_m.x;
}

static float uniform(const void *ctx, vec3_t x_m)
{
    (void)x_m;
    return *(const float *)ctx;
}

static float nan_above(const void *ctx, vec3_t x_m)
{
    (void)ctx;
    return x_m.y > 0.5f ? NAN : 1.2f;
}

static int redness(const uint8_t *c) { return (int)c[0] - (int)c[2]; }

static void test_ramp_ends_and_clamping(void **state)
{
    (void)state;
    uint8_t lo[3], mid[3], hi[3], below[3], above[3], bad[3];
    colour_ramp_rgb(0.0f, lo);
    colour_ramp_rgb(0.5f, mid);
    colour_ramp_rgb(1.0f, hi);
    colour_ramp_rgb(-3.0f, below);
    colour_ramp_rgb(7.0f, above);
    colour_ramp_rgb(NAN, bad);
    assert_true(lo[2] > lo[0] + 100);              /* low end: blue */
    assert_true(hi[0] > hi[2] + 100);              /* high end: red */
    assert_true(mid[0] > 200 && mid[1] > 200 && mid[2] > 200); /* middle: pale */
    assert_memory_equal(below, lo, 3);
    assert_memory_equal(above, hi, 3);
    assert_int_equal(bad[0], 128);
    assert_int_equal(bad[1], 128);
    assert_int_equal(bad[2], 128);
    /* Redness rises monotonically along the ramp. */
    int prev = -1000;
    for (int i = 0; i <= 20; i++) {
        uint8_t c[3];
        colour_ramp_rgb((float)i / 20.0f, c);
        assert_true(redness(c) >= prev);
        prev = redness(c);
    }
}

static void test_names(void **state)
{
    (void)state;
    colour_map_t c = COLOUR_MAP_NONE;
    assert_true(colour_map_parse("stiffness", &c));
    assert_int_equal(c, COLOUR_MAP_STIFFNESS);
    assert_true(colour_map_parse("mass", &c));
    assert_int_equal(c, COLOUR_MAP_MASS);
    assert_true(colour_map_parse("none", &c));
    assert_int_equal(c, COLOUR_MAP_NONE);
    assert_false(colour_map_parse("Stiffness", &c));
    assert_false(colour_map_parse("", &c));
    assert_string_equal(colour_map_name(COLOUR_MAP_MASS), "mass");
}

static void make_row(mesh_t *m, int n)
{
    mesh_init(m);
    for (int i = 0; i < n; i++)
        assert_int_equal(mesh_add_vertex(m, vec3(0.02f * (float)i / (float)(n - 1), 0, 0),
                                         vec3(0, 0, 1), NULL),
                         ARGIL_OK);
}

static void test_colours_follow_the_material(void **state)
{
    (void)state;
    mesh_t m;
    make_row(&m, 21); /* stiffness 0.5, 0.6, ... 2.5 */
    float lo = 0, hi = 0;
    assert_int_equal(colour_map_mesh(&m, ramp_x, NULL, &lo, &hi), ARGIL_OK);
    assert_true(m.has_rgb);
    /* Logarithmic about the default: the ends are 1/2.5 .. 2.5. */
    assert_float_equal(lo, 0.4f, 1e-5f);
    assert_float_equal(hi, 2.5f, 1e-5f);
    /* Softest vertex blue, stiffest red, and redness never falls with stiffness. */
    assert_true(m.rgb[2] > m.rgb[0] + 100);
    assert_true(m.rgb[60] > m.rgb[62] + 100);
    for (int i = 1; i < 21; i++)
        assert_true(redness(m.rgb + 3 * i) >= redness(m.rgb + 3 * (i - 1)));
    /* The vertex at the default stiffness 1.0 (x = 5 mm) sits at the ramp's pale middle; half
     * as stiff (0.5) is as far below it as twice as stiff (2.0) is above. */
    uint8_t c[3];
    colour_ramp_rgb(0.5f, c);
    assert_memory_equal(m.rgb + 15, c, 3);
    colour_ramp_rgb(0.5f - 0.5f * logf(2.0f) / logf(2.5f), c);
    assert_memory_equal(m.rgb + 0, c, 3);
    colour_ramp_rgb(0.5f + 0.5f * logf(2.0f) / logf(2.5f), c);
    assert_memory_equal(m.rgb + 45, c, 3);
    mesh_free(&m);
}

static void test_range_includes_the_default_and_uniform_is_middle(void **state)
{
    (void)state;
    mesh_t m;
    make_row(&m, 4);
    const float stiff = 1.8f;
    float lo = 0, hi = 0;
    assert_int_equal(colour_map_mesh(&m, uniform, &stiff, &lo, &hi), ARGIL_OK);
    assert_float_equal(lo, 1.0f / 1.8f, 1e-6f); /* widened to the default, then mirrored */
    assert_float_equal(hi, 1.8f, 1e-6f);
    for (int i = 0; i < 4; i++)
        assert_true(m.rgb[3 * i] > m.rgb[3 * i + 2] + 100); /* all at the top: red */
    const float one = 1.0f;
    assert_int_equal(colour_map_mesh(&m, uniform, &one, &lo, &hi), ARGIL_OK);
    assert_float_equal(lo, 1.0f, 1e-6f);
    assert_float_equal(hi, 1.0f, 1e-6f);
    uint8_t mid[3];
    colour_ramp_rgb(0.5f, mid);
    for (int i = 0; i < 4; i++)
        assert_memory_equal(m.rgb + 3 * i, mid, 3);
    mesh_free(&m);
}

static void test_non_finite_values_are_grey(void **state)
{
    (void)state;
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(mesh_add_vertex(&m, vec3(0, 0, 0), vec3(0, 0, 1), NULL), ARGIL_OK);
    assert_int_equal(mesh_add_vertex(&m, vec3(0, 1, 0), vec3(0, 0, 1), NULL), ARGIL_OK);
    float lo = 0, hi = 0;
    assert_int_equal(colour_map_mesh(&m, nan_above, NULL, &lo, &hi), ARGIL_OK);
    assert_float_equal(hi, 1.2f, 1e-6f); /* the NaN is left out of the range */
    assert_int_equal(m.rgb[3], 128);
    assert_int_equal(m.rgb[4], 128);
    assert_int_equal(m.rgb[5], 128);
    assert_true(m.rgb[0] > m.rgb[2] + 100);
    mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ramp_ends_and_clamping),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_colours_follow_the_material),
        cmocka_unit_test(test_range_includes_the_default_and_uniform_is_middle),
        cmocka_unit_test(test_non_finite_values_are_grey),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
