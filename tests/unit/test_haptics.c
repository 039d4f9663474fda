/* Force mapping pieces in isolation: β filters, point/curve/area paths, the virtual contact
 * point with friction, iso-surface rendering, the rope, and the passivity observer. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/haptics.h"
#include "firmware/core/passivity.h"

#define EDGE 16
#define H 0.00125f
#define BAND (4.0f * H)
#define N (EDGE * EDGE * EDGE)

static window_buf_t *win;
static float imp[N];

/* A window whose surface is the plane z = 0, material below. */
static int setup(void **st)
{
    (void)st;
    win = calloc(1, sizeof(*win));
    if (!win)
        return -1;
    win->valid = true;
    win->version = 1;
    for (int a = 0; a < 3; a++)
        win->dims[a] = EDGE;
    const float o = -0.5f * (EDGE - 1) * H;
    win->origin_m = vec3(o, o, o);
    win->spacing_m = H;
    win->iso = 0.5f;
    spring_material_default(&win->material);
    win->density = win->field;
    win->node_stiffness = NULL;
    win->max_stiffness = win->material.stiffness;
    for (int z = 0; z < EDGE; z++)
        for (int y = 0; y < EDGE; y++)
            for (int x = 0; x < EDGE; x++) {
                float d = 0.5f + 0.5f * (-(o + z * H)) / BAND;
                win->density[x + EDGE * (y + EDGE * z)] = d < 0 ? 0 : (d > 1 ? 1 : d);
            }
    memcpy(win->rest, win->density, sizeof(float) * N);
    memset(imp, 0, sizeof(imp));
    return 0;
}

static int teardown(void **st)
{
    (void)st;
    free(win);
    return 0;
}

static msg_tool_t tool_of(tool_kind_t k)
{
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = (uint8_t)k;
    t.filter = BETA_GAUSSIAN;
    t.axis[2] = 1.0f;
    t.radius_m = 0.002f;
    t.alpha = 1000.0f;
    t.contact_stiffness_n_per_m = 1000.0f;
    t.max_force_n = 3.3f;
    t.iso = 0.5f;
    t.model_scale = 1.0f;
    return t;
}

static void test_beta_filters_have_their_shapes(void **st)
{
    (void)st;
    const float r = 0.002f;
    for (int f = 0; f < BETA_FILTER_COUNT; f++) {
        assert_float_equal(haptics_beta((beta_filter_t)f, 0.0f, r), 1.0f, 1e-6f);
        assert_float_equal(haptics_beta((beta_filter_t)f, r * 1.01f, r), 0.0f, 0.0f);
        /* Never grows with distance. */
        float prev = 2.0f;
        for (int k = 0; k <= 20; k++) {
            const float b = haptics_beta((beta_filter_t)f, r * (float)k / 21.0f, r);
            assert_true(b <= prev + 1e-6f && b >= 0.0f);
            prev = b;
        }
    }
    assert_float_equal(haptics_beta(BETA_CONICAL, 0.5f * r, r), 0.5f, 1e-6f);
    assert_float_equal(haptics_beta(BETA_SPHERICAL, 0.6f * r, r), 0.8f, 1e-6f);
    assert_float_equal(haptics_beta(BETA_GAUSSIAN, 0.5f * r, r), expf(-0.5f), 1e-6f);
    assert_float_equal(haptics_beta(BETA_CONSTANT, 0.9f * r, r), 1.0f, 0.0f);
}

static void test_surface_distance_finds_the_plane(void **st)
{
    (void)st;
    float dist;
    vec3_t n;
    assert_true(haptics_surface_distance(win, vec3(0.0003f, 0.0001f, -0.002f), 0.5f, 0.005f, &dist, &n));
    /* Found to within the search's resolution, 1/64 cell = 20 µm. */
    assert_float_equal(dist, 0.002f, 2e-5f);      /* 2 mm inside */
    assert_float_equal(n.z, 1.0f, 1e-4f);         /* outward = +z */
    /* Inner shell at iso 0.75 lies 2.5 mm below the surface (half the band). */
    assert_true(haptics_surface_distance(win, vec3(0, 0, -0.001f), 0.75f, 0.005f, &dist, &n));
    assert_float_equal(dist, -0.0015f, 2e-5f);
}

static void test_iso_surface_rendering_feels_the_inner_shell(void **st)
{
    (void)st;
    haptics_t h;
    haptics_init(&h);
    msg_tool_t t = tool_of(TOOL_TOUCH);
    t.radius_m = 0.0005f;
    haptics_out_t out;
    /* 1.8 mm inside: the outer surface pushes hard; the iso 0.75 shell (z = -2.5 mm) not yet. */
    haptics_process(&h, &t, win, vec3(0, 0, -0.0018f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_float_equal(out.force_n.z, 1000.0f * 0.0023f, 0.01f);
    t.flags = TOOL_FLAG_ISO;
    t.iso = 0.75f;
    haptics_process(&h, &t, win, vec3(0, 0, -0.0018f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_false(out.contact);
    haptics_process(&h, &t, win, vec3(0, 0, -0.003f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_true(out.contact);
    assert_float_equal(out.force_n.z, 1000.0f * 0.001f, 0.01f); /* 0.5 mm + tool radius */
    assert_float_equal(out.potential_j, 0.5f * 1000.0f * 0.001f * 0.001f, 2e-5f * 1000.0f * 0.001f);
}

static void test_friction_holds_the_contact_point_until_the_cone(void **st)
{
    (void)st;
    haptics_t h;
    haptics_init(&h);
    msg_tool_t t = tool_of(TOOL_TOUCH);
    t.radius_m = 0.0005f;
    t.friction = 0.5f;
    haptics_out_t out;
    haptics_process(&h, &t, win, vec3(0, 0, -0.0015f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    /* pen = 2 mm; slide 0.5 mm sideways: within μ·pen = 1 mm, the contact point stays → the
     * force has a tangential part pulling back by k · 0.5 mm. */
    haptics_process(&h, &t, win, vec3(0.0005f, 0, -0.0015f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_float_equal(out.force_n.x, -0.5f, 0.01f);
    /* Slide 3 mm: the point follows at the edge of the cone: tangential force = μ · normal. */
    haptics_process(&h, &t, win, vec3(0.0035f, 0, -0.0015f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_float_equal(out.force_n.x, -0.5f * out.force_n.z, 0.01f);
    /* Without friction the force is normal only. */
    t.friction = 0.0f;
    haptics_process(&h, &t, win, vec3(0.005f, 0, -0.0015f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_float_equal(out.force_n.x, 0.0f, 1e-4f);
}

/* Sum and count of the impulses a tool deposited. */
static void impulse_stats(double *sum, int *count, float *x_min, float *x_max)
{
    *sum = 0.0;
    *count = 0;
    *x_min = 1.0f;
    *x_max = -1.0f;
    for (int i = 0; i < N; i++) {
        if (imp[i] == 0.0f)
            continue;
        *sum += imp[i];
        (*count)++;
        const float x = win->origin_m.x + (float)(i % EDGE) * H;
        if (x < *x_min) *x_min = x;
        if (x > *x_max) *x_max = x;
    }
}

static void test_point_curve_area_tools_cover_their_extent(void **st)
{
    (void)st;
    haptics_t h;
    haptics_out_t out;
    double sum;
    int count[3];
    float xmin, xmax;
    for (int shape = 0; shape < 3; shape++) {
        memset(imp, 0, sizeof(imp));
        memset(win->force, 0, sizeof(win->force));
        haptics_init(&h);
        msg_tool_t t = tool_of(TOOL_PUSH);
        t.shape = (uint8_t)shape;
        t.length_m = 0.008f;
        t.axis[0] = 1.0f; /* curve along x; area normal to x → spans y and z */
        t.axis[2] = 0.0f;
        t.radius_m = 0.001f;
        /* One 0.2 mm step down into the clay with the button held. */
        haptics_process(&h, &t, win, vec3(0, 0, -0.0010f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
        haptics_process(&h, &t, win, vec3(0, 0, -0.0012f), vec3(0, 0, -0.2f), true, true, 0.001f, imp, &out);
        assert_true(out.sculpting);
        impulse_stats(&sum, &count[shape], &xmin, &xmax);
        assert_true(sum < 0.0);                    /* push lowers density */
        if (shape == TOOL_SHAPE_CURVE)
            assert_true(xmax - xmin >= 0.008f - H); /* the whole 8 mm segment */
        else
            assert_true(xmax - xmin <= 0.002f + 2 * H); /* point and area stay narrow in x */
    }
    assert_true(count[1] > 3 * count[0]);          /* a curve touches many more nodes */
    assert_true(count[2] > 3 * count[0]);          /* and so does an area */
}

static void test_sculpting_force_follows_equation_7(void **st)
{
    (void)st;
    haptics_t h;
    haptics_out_t out;
    msg_tool_t t = tool_of(TOOL_PUSH);
    t.filter = BETA_CONSTANT;
    t.radius_m = 0.0004f; /* below a cell: only the corners of the cells crossed */
    double s1, s2;
    int c;
    float a, b;
    /* f = -α · l · s: doubling the path doubles the impulse; the density met scales it. */
    memset(imp, 0, sizeof(imp));
    haptics_init(&h);
    haptics_process(&h, &t, win, vec3(0.0001f, 0.0001f, -0.003f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    haptics_process(&h, &t, win, vec3(0.0001f, 0.0001f, -0.0031f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    impulse_stats(&s1, &c, &a, &b);
    memset(imp, 0, sizeof(imp));
    haptics_init(&h);
    haptics_process(&h, &t, win, vec3(0.0001f, 0.0001f, -0.003f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    haptics_process(&h, &t, win, vec3(0.0001f, 0.0001f, -0.0032f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    impulse_stats(&s2, &c, &a, &b);
    assert_true(s1 < 0.0);
    assert_float_equal(s2 / s1, 2.0, 0.1); /* within 5 %: s and β move with the path */
    assert_in_range(c, 8, 32); /* the corners of the cells the short path crosses, and a few
                                * nodes within √3 cells of it */
}

static void test_rope_pulls_back_and_draws_the_grabbed_nodes(void **st)
{
    (void)st;
    haptics_t h;
    haptics_init(&h);
    haptics_out_t out;
    msg_tool_t t = tool_of(TOOL_ROPE);
    t.rope_stiffness_n_per_m = 300.0f;
    memset(imp, 0, sizeof(imp));
    haptics_process(&h, &t, win, vec3(0, 0, -0.001f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    haptics_process(&h, &t, win, vec3(0, 0, 0.004f), vec3(0, 0, 0), true, true, 0.001f, imp, &out);
    assert_float_equal(out.force_n.z, -300.0f * 0.005f, 1e-3f); /* pulled back to the grab */
    assert_float_equal(out.potential_j, 0.5f * 300.0f * 0.005f * 0.005f, 1e-7f);
    double sum;
    int c;
    float a, b;
    impulse_stats(&sum, &c, &a, &b);
    assert_float_equal(sum > 0.0 ? 1.0 : 0.0, 1.0, 0.0); /* the grabbed clay is drawn (up) */
    /* Let go: nothing more. */
    memset(imp, 0, sizeof(imp));
    haptics_process(&h, &t, win, vec3(0, 0, 0.004f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    impulse_stats(&sum, &c, &a, &b);
    assert_int_equal(c, 0);
}

static void test_passivity_observer_counts_generated_energy(void **st)
{
    (void)st;
    passivity_t p;
    passivity_init(&p, 1);
    /* An ideal spring rendered continuously: held force = -k x at each sample, U = ½ k x². With
     * a zero-order hold the observer sees a small positive leak on release; the controller then
     * damps it away. */
    const float k = 1000.0f, dt = 0.001f;
    float x = 0.003f, v = -0.05f;
    vec3_t f = vec3(0, 0, 0);
    for (int i = 0; i < 200; i++) {
        const vec3_t pos = vec3(0, 0, x);
        const float u = x < 0 ? 0.5f * k * x * x : 0.0f;
        (void)passivity_process(&p, pos, vec3(0, 0, v), u, 7u, dt, false, 0.0f, 0.0f);
        f = vec3(0, 0, x < 0 ? -k * x : 0.0f);
        passivity_applied(&p, f);
        x += v * dt;
        if (x < -0.002f) v = 0.05f; /* bounce: in, then out */
    }
    /* Sampling made the wall slightly active — by about ½ k (v dt)² per step in contact
     * (80 steps here) — and no more. */
    const float leak_bound = 80.0f * 0.5f * k * (0.05f * dt) * (0.05f * dt) * 2.0f;
    assert_true(p.max_energy_j > 0.0f);
    assert_true(p.max_energy_j < leak_bound);
    /* The controller: a positive energy with motion gives a damping force against v. */
    passivity_t q;
    passivity_init(&q, 1);
    (void)passivity_process(&q, vec3(0, 0, 0), vec3(0, 0, 0), 0.0f, 1u, dt, true, 0.0f, 50.0f);
    passivity_applied(&q, vec3(0, 0, 1.0f));   /* 1 N pushing along +z… */
    const vec3_t pc =
        passivity_process(&q, vec3(0, 0, 0.0001f), vec3(0, 0, 0.1f), 0.0f, 1u, dt, true, 0.0f, 50.0f);
    assert_true(q.energy_j > 0.0f);            /* …that did 0.1 mJ of work from nothing */
    assert_true(pc.z < 0.0f);                  /* so the controller damps the motion */
    assert_float_equal(-pc.z * 0.1f * dt, q.energy_j, 1e-6f); /* exactly that energy */
    /* Within the dead band it stays out of the way. */
    passivity_t d;
    passivity_init(&d, 1);
    (void)passivity_process(&d, vec3(0, 0, 0), vec3(0, 0, 0), 0.0f, 1u, dt, true, 1e-3f, 50.0f);
    passivity_applied(&d, vec3(0, 0, 1.0f));
    const vec3_t none =
        passivity_process(&d, vec3(0, 0, 0.0001f), vec3(0, 0, 0.1f), 0.0f, 1u, dt, true, 1e-3f, 50.0f);
    assert_float_equal(vec3_norm(none), 0.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_beta_filters_have_their_shapes),
        cmocka_unit_test_setup_teardown(test_surface_distance_finds_the_plane, setup, teardown),
        cmocka_unit_test_setup_teardown(test_iso_surface_rendering_feels_the_inner_shell, setup, teardown),
        cmocka_unit_test_setup_teardown(test_friction_holds_the_contact_point_until_the_cone, setup, teardown),
        cmocka_unit_test_setup_teardown(test_point_curve_area_tools_cover_their_extent, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sculpting_force_follows_equation_7, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rope_pulls_back_and_draws_the_grabbed_nodes, setup, teardown),
        cmocka_unit_test(test_passivity_observer_counts_generated_energy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
