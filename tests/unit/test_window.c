/* The board's local window and force mapping: reassembly, sampling, contact force, sculpting. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/haptics.h"
#include "firmware/core/window.h"

#define EDGE 16
#define H 0.00125f
#define BAND (4.0f * H)

static window_t *win;

/* A window of a sphere of radius r centred at c, in the density profile the host uses. */
static void sphere_head(msg_window_t *head, uint32_t version)
{
    memset(head, 0, sizeof(*head));
    head->version = version;
    head->dims[0] = head->dims[1] = head->dims[2] = EDGE;
    head->origin_m[0] = head->origin_m[1] = head->origin_m[2] = -0.5f * (EDGE - 1) * H;
    head->spacing_m = H;
    head->iso = 0.5f;
    head->node_mass = 1.0f;
    head->stiffness = 2.0f;
    head->damping = 40.0f;
    head->plastic_rate_hz = 20.0f;
    head->channels = 1;
    head->chunk_count = window_chunk_count(head->dims, head->channels);
}

static float profile(float sd)
{
    float d = 0.5f + 0.5f * sd / BAND;
    return d < 0 ? 0 : (d > 1 ? 1 : d);
}

/* A plane surface z = 0 (material below, z < 0), or a sphere of radius r at the origin. */
static void fill(float *s, int plane, float r)
{
    const float o = -0.5f * (EDGE - 1) * H;
    for (int z = 0; z < EDGE; z++)
        for (int y = 0; y < EDGE; y++)
            for (int x = 0; x < EDGE; x++) {
                const float px = o + x * H, py = o + y * H, pz = o + z * H;
                const float sd = plane ? -pz : r - sqrtf(px * px + py * py + pz * pz);
                s[x + EDGE * (y + EDGE * z)] = profile(sd);
            }
}

static void load(const float *samples, uint32_t version)
{
    msg_window_t head, chunk;
    sphere_head(&head, version);
    for (uint16_t i = 0; i < head.chunk_count; i++) {
        assert_int_equal(window_chunk_fill(&head, samples, i, &chunk), PROTO_OK);
        assert_int_equal(window_feed(win, &chunk), PROTO_OK);
    }
    assert_true(window_pending(win));
    window_swap(win);
}

static int setup(void **st)
{
    (void)st;
    win = calloc(1, sizeof(*win));
    window_init(win);
    return win ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    free(win);
    return 0;
}

static void test_window_arrives_whole_then_swaps(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    fill(s, 1, 0);
    msg_window_t head, chunk;
    sphere_head(&head, 1);
    assert_null(window_active(win));
    for (uint16_t i = 0; i + 1 < head.chunk_count; i++) {
        assert_int_equal(window_chunk_fill(&head, s, i, &chunk), PROTO_OK);
        assert_int_equal(window_feed(win, &chunk), PROTO_OK);
        assert_false(window_pending(win));
    }
    assert_int_equal(window_chunk_fill(&head, s, (uint16_t)(head.chunk_count - 1), &chunk), PROTO_OK);
    assert_int_equal(window_feed(win, &chunk), PROTO_OK);
    assert_true(window_pending(win));
    assert_null(window_active(win)); /* not before the tick boundary */
    window_swap(win);
    const window_buf_t *b = window_active(win);
    assert_non_null(b);
    assert_int_equal(b->version, 1);
    assert_memory_equal(b->density, s, sizeof(s));
    /* A stale version is refused. */
    assert_int_equal(window_chunk_fill(&head, s, 0, &chunk), PROTO_OK);
    assert_int_equal(window_feed(win, &chunk), PROTO_ERR_CHUNK);
}

static void test_nonfinite_window_refused(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    fill(s, 1, 0);
    s[1234] = NAN;
    msg_window_t head, chunk;
    sphere_head(&head, 7);
    proto_err_t last = PROTO_OK;
    for (uint16_t i = 0; i < head.chunk_count; i++) {
        window_chunk_fill(&head, s, i, &chunk);
        const proto_err_t e = window_feed(win, &chunk);
        if (e != PROTO_OK)
            last = e;
    }
    /* Either the decoder-level check or the window's own: never a pending NaN window. */
    assert_true(last == PROTO_ERR_VALUE || last == PROTO_ERR_CHUNK);
    assert_false(window_pending(win));
}

static void test_gradient_matches_finite_differences(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    fill(s, 0, 0.006f);
    load(s, 1);
    const window_buf_t *b = window_active(win);
    const float e = 1e-5f;
    for (int k = 0; k < 50; k++) {
        const vec3_t p = vec3(0.0031f * sinf((float)k), 0.0027f * cosf(1.3f * k), 0.004f * sinf(0.7f * k));
        float d, dx1, dx0;
        vec3_t g, gg;
        assert_true(window_sample(b, p, &d, &g));
        window_sample(b, vec3_add(p, vec3(e, 0, 0)), &dx1, &gg);
        window_sample(b, vec3_sub(p, vec3(e, 0, 0)), &dx0, &gg);
        assert_float_equal(g.x, (dx1 - dx0) / (2 * e), 2.0f);
    }
    float d;
    vec3_t g;
    assert_false(window_sample(b, vec3(1.0f, 0, 0), &d, &g));
    assert_false(window_sample(b, vec3(NAN, 0, 0), &d, &g));
}

static msg_tool_t tool_of(tool_kind_t k)
{
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = (uint8_t)k;
    t.shape = TOOL_SHAPE_POINT;
    t.filter = BETA_GAUSSIAN;
    t.axis[2] = 1.0f;
    t.iso = 0.5f;
    t.radius_m = 0.002f;
    t.alpha = 12000.0f;
    t.contact_stiffness_n_per_m = 800.0f;
    t.max_force_n = 3.3f;
    t.model_scale = 1.0f;
    return t;
}

static void test_contact_force_pushes_out_with_stiffness(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    static float imp[EDGE * EDGE * EDGE];
    fill(s, 1, 0); /* surface z = 0, material below */
    load(s, 1);
    window_buf_t *b = window_active_mut(win);
    haptics_t h;
    haptics_init(&h);
    msg_tool_t t = tool_of(TOOL_TOUCH);
    haptics_out_t out;
    /* Tool sphere clear of the surface: no force. */
    haptics_process(&h, &t, b, vec3(0, 0, 0.003f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_false(out.contact);
    assert_float_equal(vec3_norm(out.force_n), 0.0f, 0.0f);
    /* 1 mm into the surface with a 2 mm tool: penetration 3 mm → k * 3 mm = 2.4 N, along +z. */
    haptics_process(&h, &t, b, vec3(0.0003f, -0.0002f, -0.001f), vec3(0, 0, 0), false, true, 0.001f,
                    imp, &out);
    assert_true(out.contact);
    assert_float_equal(out.force_n.z, 800.0f * 0.003f, 0.05f);
    assert_float_equal(out.force_n.x, 0.0f, 1e-3f);
    assert_float_equal(out.force_n.y, 0.0f, 1e-3f);
    /* Deeper means more force (monotonic over the band). */
    float prev = 0.0f;
    for (int i = 0; i < 4; i++) {
        haptics_process(&h, &t, b, vec3(0, 0, -0.001f * i), vec3(0, 0, 0), false, true, 0.001f, imp,
                        &out);
        assert_true(out.force_n.z > prev);
        prev = out.force_n.z;
    }
}

static void test_swapped_window_starts_at_rest_over_a_used_buffer(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    const int32_t n = EDGE * EDGE * EDGE;
    fill(s, 0, 0.01f);
    load(s, 1);
    /* the first buffer is used: springs moved, forces pending */
    window_buf_t *b = window_active_mut(win);
    for (int32_t i = 0; i < n; i++) {
        b->rest[i] = 0.25f;
        b->velocity[i] = 3.0f;
        b->force[i] = -7.0f;
    }
    fill(s, 1, 0);
    load(s, 2);  /* into the other buffer */
    fill(s, 0, 0.008f);
    load(s, 3);  /* back into the used one: chunk by chunk it must be reset */
    b = window_active_mut(win);
    assert_int_equal(b->version, 3);
    assert_memory_equal(b->density, s, sizeof(s));
    assert_memory_equal(b->rest, s, sizeof(s));
    for (int32_t i = 0; i < n; i++) {
        assert_float_equal(b->velocity[i], 0.0f, 0.0f);
        assert_float_equal(b->force[i], 0.0f, 0.0f);
    }
}

static void test_density_alone_equals_the_sampled_density_bit_for_bit(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    fill(s, 0, 0.009f);
    load(s, 1);
    const window_buf_t *b = window_active(win);
    const float ext = (EDGE - 1) * H;
    int inside = 0;
    for (int k = 0; k < 4000; k++) {
        /* points over and a little beyond the window, on an irregular lattice */
        const vec3_t p = vec3(b->origin_m.x - 0.05f * ext + 1.1f * ext * (float)((k * 37) % 101) / 100.0f,
                              b->origin_m.y - 0.05f * ext + 1.1f * ext * (float)((k * 53) % 89) / 88.0f,
                              b->origin_m.z - 0.05f * ext + 1.1f * ext * (float)((k * 71) % 97) / 96.0f);
        float d1 = -1.0f, d2 = -2.0f;
        vec3_t g;
        const bool in1 = window_sample(b, p, &d1, &g);
        const bool in2 = window_density(b, p, &d2);
        assert_int_equal(in1, in2);
        if (in1) {
            assert_memory_equal(&d1, &d2, sizeof d1);
            inside++;
        }
    }
    assert_true(inside > 2000 && inside < 4000); /* both inside and outside were tried */
}

static void test_push_lowers_density_and_records_impulses(void **st)
{
    (void)st;
    static float s[EDGE * EDGE * EDGE];
    static float imp[EDGE * EDGE * EDGE];
    memset(imp, 0, sizeof(imp));
    fill(s, 1, 0);
    load(s, 1);
    window_buf_t *b = window_active_mut(win);
    haptics_t h;
    haptics_init(&h);
    msg_tool_t t = tool_of(TOOL_PUSH);
    haptics_out_t out;
    float d0, d1;
    vec3_t g;
    int32_t box_lo[3] = {EDGE, EDGE, EDGE}, box_hi[3] = {-1, -1, -1};
    window_sample(b, vec3(0, 0, -0.002f), &d0, &g);
    /* Press 3 mm into the clay over 60 ticks with the button held, stepping the springs. */
    for (int i = 0; i <= 60; i++) {
        haptics_process(&h, &t, b, vec3(0, 0, -0.00005f * i), vec3(0, 0, -0.05f), true, true, 0.001f,
                        imp, &out);
        if (i > 0)
            assert_true(out.sculpting); /* the first tick has no path yet */
        for (int a = 0; a < 3; a++) {
            box_lo[a] = out.touched_lo[a] < box_lo[a] ? out.touched_lo[a] : box_lo[a];
            box_hi[a] = out.touched_hi[a] > box_hi[a] ? out.touched_hi[a] : box_hi[a];
        }
        spring_field_t f = {{EDGE, EDGE, EDGE}, b->density, b->rest, b->velocity, b->force, NULL};
        const int32_t lo[3] = {0, 0, 0}, hi[3] = {EDGE, EDGE, EDGE};
        springs_step(&f, &b->material, lo, hi, 0.001f);
    }
    for (int i = 0; i < 50; i++) {
        spring_field_t f = {{EDGE, EDGE, EDGE}, b->density, b->rest, b->velocity, b->force, NULL};
        const int32_t lo[3] = {0, 0, 0}, hi[3] = {EDGE, EDGE, EDGE};
        springs_step(&f, &b->material, lo, hi, 0.001f);
    }
    window_sample(b, vec3(0, 0, -0.002f), &d1, &g);
    assert_true(d1 < d0 - 0.1f); /* the clay gave way under the tool */
    double total = 0.0;
    int touched = 0;
    for (int i = 0; i < EDGE * EDGE * EDGE; i++) {
        assert_true(imp[i] <= 0.0f); /* pushing only lowers density */
        total += imp[i];
        touched += imp[i] != 0.0f;
    }
    assert_true(total < 0.0);
    assert_true(touched > 8); /* spread by β over more than one cell's corners */
    /* every node that received an impulse lies in the reported box (the board flushes only
     * that box), and the box is not the whole window */
    for (int i = 0; i < EDGE * EDGE * EDGE; i++) {
        if (imp[i] == 0.0f)
            continue;
        const int x = i % EDGE, y = (i / EDGE) % EDGE, z = i / (EDGE * EDGE);
        assert_true(x >= box_lo[0] && x <= box_hi[0]);
        assert_true(y >= box_lo[1] && y <= box_hi[1]);
        assert_true(z >= box_lo[2] && z <= box_hi[2]);
    }
    assert_true((box_hi[0] - box_lo[0] + 1) * (box_hi[1] - box_lo[1] + 1) *
                    (box_hi[2] - box_lo[2] + 1) < EDGE * EDGE * EDGE / 2);
    /* Without the button nothing is sculpted. */
    memset(imp, 0, sizeof(imp));
    haptics_process(&h, &t, b, vec3(0, 0, -0.004f), vec3(0, 0, 0), false, true, 0.001f, imp, &out);
    assert_false(out.sculpting);
    for (int i = 0; i < EDGE * EDGE * EDGE; i++)
        assert_float_equal(imp[i], 0.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_window_arrives_whole_then_swaps, setup, teardown),
        cmocka_unit_test_setup_teardown(test_nonfinite_window_refused, setup, teardown),
        cmocka_unit_test_setup_teardown(test_gradient_matches_finite_differences, setup, teardown),
        cmocka_unit_test_setup_teardown(test_contact_force_pushes_out_with_stiffness, setup, teardown),
        cmocka_unit_test_setup_teardown(test_push_lowers_density_and_records_impulses, setup, teardown),
        cmocka_unit_test_setup_teardown(test_swapped_window_starts_at_rest_over_a_used_buffer, setup, teardown),
        cmocka_unit_test_setup_teardown(test_density_alone_equals_the_sampled_density_bit_for_bit, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
