/* The session's undo (host/app/session_undo.h) on the B-spline model as the session drives it:
 * strokes of host tools, paint and implicit steps with external force (the clay moving and
 * settling), then undo gives back every coefficient and sample bit for bit, redo likewise; the
 * solver's round-off after an undo does not spoil the next undo or redo; a new stroke clears
 * redo; a small budget drops the oldest strokes; a knot insertion cuts the history; undo off
 * refuses. A press in the air (nothing touched) is no step: undo after it takes back the last
 * real stroke with its settling. The diff spread over slices between the solver's writes gives
 * the same journal bytes as the whole diff at once, and an undo asked for in the middle of it is
 * exact. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve.h"
#include "host/app/session_undo.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"
#include "tests/unit/sphere_grid.h"

#define N 32
#define H 1.25e-3f
#define R 0.012f
#define DT 0.01f
#define PAD 8                     /* samples / coefficients compared beyond the grid */
#define NS (N + 2 * PAD)
#define NBOX ((size_t)NS * NS * NS)

typedef struct {
    grid_t g;
    gsolve_t gs;
    session_undo_t su;
} rig_t;

/* The model's state (FC_P and the sample channels a state holds) over the grid and PAD around. */
typedef struct {
    float *p, *s[SESSION_UNDO_SAMP_CH];
    float *grid_d;
} state_t;

static void rig_init(rig_t *r, int32_t ratio, size_t budget)
{
    sphere_grid_init(&r->g, N, H, R);
    assert_int_equal(gsolve_init_ratio(&r->gs, &r->g, ratio), ARGIL_OK);
    assert_int_equal(session_undo_init(&r->su, &r->gs.field, budget), ARGIL_OK);
    assert_true(r->su.on);
}

static void rig_free(rig_t *r)
{
    session_undo_free(&r->su);
    gsolve_free(&r->gs);
    grid_free(&r->g);
}

static void state_take(const rig_t *r, state_t *st)
{
    const int32_t lo[3] = {-PAD, -PAD, -PAD}, dims[3] = {NS, NS, NS};
    st->p = malloc(NBOX * sizeof(float));
    assert_non_null(st->p);
    sparse_read_box(&r->gs.field.coef, FC_P, lo, dims, st->p);
    for (int c = 0; c < SESSION_UNDO_SAMP_CH; c++) {
        st->s[c] = malloc(NBOX * sizeof(float));
        assert_non_null(st->s[c]);
        sparse_read_box(&r->gs.field.samp, c, lo, dims, st->s[c]);
    }
    st->grid_d = malloc((size_t)N * N * N * sizeof(float));
    assert_non_null(st->grid_d);
    gv_copy(&r->g, GRID_DENSITY, st->grid_d);
}

static void state_free(state_t *st)
{
    free(st->p);
    for (int c = 0; c < SESSION_UNDO_SAMP_CH; c++)
        free(st->s[c]);
    free(st->grid_d);
}

/* Values of the model that differ (bit for bit) from st. */
static size_t state_diff(const rig_t *r, const state_t *st)
{
    state_t now;
    state_take(r, &now);
    size_t n = 0;
    for (size_t i = 0; i < NBOX; i++) {
        n += memcmp(&now.p[i], &st->p[i], sizeof(float)) != 0;
        for (int c = 0; c < SESSION_UNDO_SAMP_CH; c++)
            n += memcmp(&now.s[c][i], &st->s[c][i], sizeof(float)) != 0;
    }
    state_free(&now);
    return n;
}

/* The largest |grid density - st's|: the grid view follows the field only past
 * GSOLVE_VIEW_EPS, so a restored view is within twice that of the one it had. */
static float grid_diff(const rig_t *r, const state_t *st)
{
    float m = 0.0f;
    for (size_t i = 0; i < (size_t)N * N * N; i++) {
        const float d = fabsf(gv_get(&r->g, GRID_DENSITY, i) - st->grid_d[i]);
        m = d > m ? d : m;
    }
    return m;
}

static bool velocities_zero(const rig_t *r)
{
    const sparse_t *c = &r->gs.field.coef;
    size_t slot = 0;
    for (const sparse_block_t *b; (b = sparse_next(c, &slot)) != NULL;)
        for (int k = 0; k < SPARSE_BN; k++)
            if (b->data[FC_V * SPARSE_BN + k] != 0.0f)
                return false;
    return true;
}

/* Implicit steps of the window round the model point at, pushing inward there with force_n on
 * the samples of a small cube (0: none, the clay only moves on). */
static void dynamics(rig_t *r, vec3_t at, float force_n, int steps)
{
    grid_t *g = &r->g;
    int32_t c[3], lo[3], hi[3];
    const float pos[3] = {at.x, at.y, at.z}, org[3] = {g->origin_m.x, g->origin_m.y, g->origin_m.z};
    for (int a = 0; a < 3; a++) {
        c[a] = (int32_t)lroundf((pos[a] - org[a]) / g->spacing_m);
        lo[a] = c[a] - 8;
        hi[a] = c[a] + 8;
    }
    for (int k = 0; k < steps; k++) {
        if (force_n != 0.0f)
            for (int32_t z = c[2] - 1; z <= c[2] + 1; z++)
                for (int32_t y = c[1] - 1; y <= c[1] + 1; y++)
                    for (int32_t x = c[0] - 1; x <= c[0] + 1; x++)
                        assert_true(grid_add_force(g, x, y, z, force_n));
        int32_t dlo[3], dhi[3];
        float change = 0.0f;
        assert_int_equal(gsolve_step(&r->gs, g, lo, hi, DT, dlo, dhi, &change), ARGIL_OK);
        for (int32_t z = c[2] - 1; z <= c[2] + 1; z++)
            for (int32_t y = c[1] - 1; y <= c[1] + 1; y++)
                for (int32_t x = c[0] - 1; x <= c[0] + 1; x++)
                    assert_int_equal(grid_set(g, GRID_FORCE, x, y, z, 0.0f), ARGIL_OK);
    }
}

static void tool(rig_t *r, host_action_t a, vec3_t at, float radius_m)
{
    host_tool_t t;
    host_tool_default(&t);
    t.action = a;
    t.strength = host_action_has_strength(a) ? host_action_default_strength(a) : 0.0f;
    int32_t lo[3], hi[3];
    assert_int_equal(gsolve_apply_tool(&r->gs, &r->g, &t, radius_m, vec3(0, 0, 1), &at, 1, DT,
                                       lo, hi),
                     ARGIL_OK);
}

/* One stroke: a tool (and a paint) and the clay moving, pushed, then left to settle a little. */
static void stroke(rig_t *r, int k)
{
    assert_int_equal(session_undo_edit_start(&r->su, &r->gs.field), ARGIL_OK);
    const float ang = 1.3f * (float)k;
    const vec3_t at = vec3(R * cosf(ang), R * sinf(ang), 0.3f * R);
    static const host_action_t acts[] = {HOST_ACT_CARVE, HOST_ACT_ADD, HOST_ACT_SMOOTH,
                                         HOST_ACT_PAINT, HOST_ACT_STAMP};
    tool(r, acts[k % 5], at, 3e-3f);
    if (k % 2 == 1)
        assert_int_equal(gsolve_paint(&r->gs, GSOLVE_MAT_STIFFNESS, at, 4e-3f, 3.0f), ARGIL_OK);
    dynamics(r, at, -2.0f, 4);
    dynamics(r, at, 0.0f, 4);
}

/* Undo or redo as the session does it: the field, then the grid view. */
static argil_err_t step(rig_t *r, bool redo)
{
    int32_t lo[3], hi[3], glo[3], ghi[3];
    const argil_err_t e = session_undo_step(&r->su, &r->gs.field, redo, lo, hi);
    if (e == ARGIL_OK)
        assert_int_equal(gsolve_restored(&r->gs, &r->g, lo, hi, glo, ghi), ARGIL_OK);
    return e;
}

static void test_undo_redo_bit_exact(void **st_)
{
    (void)st_;
    rig_t r;
    rig_init(&r, 1, 16u << 20);
    enum { K = 4 };
    state_t s[K + 1];
    state_take(&r, &s[0]);
    for (int k = 0; k < K; k++) {
        stroke(&r, k);
        state_take(&r, &s[k + 1]);
        assert_true(state_diff(&r, &s[k]) > 100); /* each stroke changed something visible */
    }
    /* the last stroke is still open: undo records it, then goes back before it */
    for (int k = K; k > 0; k--) {
        assert_int_equal(step(&r, false), ARGIL_OK);
        assert_int_equal(state_diff(&r, &s[k - 1]), 0);
        assert_true(grid_diff(&r, &s[k - 1]) <= 2.0f * GSOLVE_VIEW_EPS);
        assert_true(velocities_zero(&r));
        assert_int_equal(session_undo_undo_count(&r.su), (size_t)(k - 1));
        assert_int_equal(session_undo_redo_count(&r.su), (size_t)(K - k + 1));
    }
    assert_int_equal(step(&r, false), ARGIL_ERR_EMPTY);
    assert_int_equal(state_diff(&r, &s[0]), 0);
    for (int k = 1; k <= K; k++) {
        /* the solver's round-off while the window reopens is dropped by the redo */
        dynamics(&r, vec3(R, 0, 0), 0.0f, 2);
        assert_int_equal(step(&r, true), ARGIL_OK);
        assert_int_equal(state_diff(&r, &s[k]), 0);
        assert_true(grid_diff(&r, &s[k]) <= 2.0f * GSOLVE_VIEW_EPS);
    }
    assert_int_equal(step(&r, true), ARGIL_ERR_EMPTY);
    printf("# %u steps, largest %zu B (%zu values), %zu B held, shadow %zu B\n",
           r.su.stats.steps, r.su.stats.max_step_bytes, r.su.stats.last_step_changes,
           session_undo_bytes(&r.su), session_undo_shadow_bytes(&r.su));
    assert_int_equal(r.su.stats.steps, K);
    /* undo twice, then a new stroke: redo is gone at once, and the new stroke undoes to s[2]
     * (the drift after the undo joined it) */
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s[K - 2]), 0);
    dynamics(&r, vec3(R, 0, 0), 0.0f, 2);
    stroke(&r, 7);
    assert_int_equal(session_undo_redo_count(&r.su), 0);
    assert_int_equal(step(&r, true), ARGIL_ERR_EMPTY);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s[K - 2]), 0);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s[K - 3]), 0);
    for (int k = 0; k <= K; k++)
        state_free(&s[k]);
    rig_free(&r);
}

static void test_budget_drops_oldest(void **st_)
{
    (void)st_;
    rig_t r;
    rig_init(&r, 1, 64u << 20);
    stroke(&r, 0);
    assert_int_equal(session_undo_edit_start(&r.su, &r.gs.field), ARGIL_OK);
    assert_int_equal(session_undo_finish(&r.su, &r.gs.field), ARGIL_OK);
    const size_t one = r.su.stats.last_step_bytes;
    assert_true(one > 1000);
    rig_free(&r);
    /* a budget of about 2.5 strokes: 6 strokes leave 2 or 3, the newest */
    rig_init(&r, 1, one * 5 / 2);
    enum { K = 6 };
    state_t s[K + 1];
    state_take(&r, &s[0]);
    for (int k = 0; k < K; k++) {
        stroke(&r, k);
        state_take(&r, &s[k + 1]);
    }
    assert_int_equal(session_undo_edit_start(&r.su, &r.gs.field), ARGIL_OK);
    assert_int_equal(session_undo_finish(&r.su, &r.gs.field), ARGIL_OK);
    const size_t held = r.su.u.done; /* steps recorded (a new empty stroke is open) */
    printf("# budget %zu B: %zu of %d strokes kept, %zu B held\n", one * 5 / 2, held, K,
           session_undo_bytes(&r.su));
    assert_true(held >= 1 && held < (size_t)K);
    assert_true(session_undo_bytes(&r.su) <= one * 5 / 2 || held == 1);
    for (size_t k = 0; k < held; k++) {
        assert_int_equal(step(&r, false), ARGIL_OK);
        assert_int_equal(state_diff(&r, &s[K - 1 - k]), 0);
    }
    assert_int_equal(step(&r, false), ARGIL_ERR_EMPTY);
    for (int k = 0; k <= K; k++)
        state_free(&s[k]);
    rig_free(&r);
}

static void test_knot_insertion_cuts_history(void **st_)
{
    (void)st_;
    rig_t r;
    rig_init(&r, 2, 16u << 20);
    stroke(&r, 0);
    float dd = 0.0f;
    int32_t lo[3], hi[3];
    /* the session records the open stroke first (session_undo_peer_edit_start) */
    assert_int_equal(session_undo_edit_start(&r.su, &r.gs.field), ARGIL_OK);
    assert_int_equal(gsolve_refine(&r.gs, &r.g, &dd, lo, hi), ARGIL_OK);
    state_t s1;
    state_take(&r, &s1);
    assert_int_equal(step(&r, false), ARGIL_ERR_STATE); /* the stroke before the refinement */
    assert_int_equal(state_diff(&r, &s1), 0);
    stroke(&r, 1);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s1), 0);
    assert_int_equal(step(&r, false), ARGIL_ERR_STATE);
    assert_int_equal(step(&r, true), ARGIL_OK);
    state_free(&s1);
    rig_free(&r);
}

/* As the session drives it: implicit steps (force_n inward at `at`, 0: the clay moves on by
 * itself), each after one slice of the pending diff (when slice) and the copy aside that comes
 * before any write. */
static void steps_sliced(rig_t *r, vec3_t at, float force_n, int steps, bool slice)
{
    for (int k = 0; k < steps; k++) {
        if (slice)
            (void)session_undo_slice(&r->su, &r->gs.field);
        session_undo_before_write(&r->su, &r->gs.field);
        dynamics(r, at, force_n, 1);
    }
}

/* A press of button 1 (not an edit) whose stroke touches the clay (touch) or not. */
static void press_stroke(rig_t *r, int k, bool touch, bool slice)
{
    assert_int_equal(session_undo_press(&r->su, &r->gs.field), ARGIL_OK);
    const float ang = 0.9f * (float)k;
    const vec3_t at = vec3(R * cosf(ang), R * sinf(ang), -0.2f * R);
    if (touch) {
        session_undo_touched(&r->su);
        session_undo_before_write(&r->su, &r->gs.field);
        tool(r, k % 2 ? HOST_ACT_ADD : HOST_ACT_CARVE, at, 3e-3f);
        steps_sliced(r, at, -2.0f, 3, slice);
    }
    steps_sliced(r, at, 0.0f, 3, slice);
}

static void test_air_press_is_no_step(void **st_)
{
    (void)st_;
    rig_t r;
    rig_init(&r, 1, 16u << 20);
    state_t s0, s1;
    state_take(&r, &s0);
    press_stroke(&r, 0, true, true);
    state_take(&r, &s1);
    assert_true(state_diff(&r, &s0) > 100);
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    /* a press in the air: the clay settles on (the last stroke's), nothing more to undo */
    press_stroke(&r, 1, false, true);
    assert_true(state_diff(&r, &s1) > 0); /* the clay did move on */
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    press_stroke(&r, 2, false, true); /* the air press is sealed: joined to the stroke */
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    assert_int_equal(session_undo_finish(&r.su, &r.gs.field), ARGIL_OK);
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    printf("# after a stroke and 2 presses in the air: %zu step to undo, %u recorded, %u air\n",
           session_undo_undo_count(&r.su), r.su.stats.steps, r.su.stats.air_presses);
    assert_int_equal(r.su.stats.air_presses, 1); /* the second is still open */
    assert_int_equal(r.su.stats.steps, 1);
    state_t s2;
    state_take(&r, &s2);
    /* undo takes back the stroke and everything after it: the start */
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s0), 0);
    assert_int_equal(session_undo_undo_count(&r.su), 0);
    assert_int_equal(session_undo_redo_count(&r.su), 1);
    assert_int_equal(step(&r, false), ARGIL_ERR_EMPTY);
    /* redo brings back the stroke with its settling, to the last boundary */
    assert_int_equal(step(&r, true), ARGIL_OK);
    assert_int_equal(session_undo_redo_count(&r.su), 0);
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s0), 0);
    /* a press in the air after an undo: still nothing to undo; the next real stroke is one */
    press_stroke(&r, 3, false, true);
    press_stroke(&r, 4, false, true);
    assert_int_equal(session_undo_undo_count(&r.su), 0);
    assert_int_equal(step(&r, false), ARGIL_ERR_EMPTY);
    press_stroke(&r, 5, false, true);
    press_stroke(&r, 6, true, true);
    assert_int_equal(session_undo_undo_count(&r.su), 1);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s0), 0);
    state_free(&s0);
    state_free(&s1);
    state_free(&s2);
    rig_free(&r);
}

/* The journal bytes of every step held. */
static size_t journal_bytes(const rig_t *r, uint8_t *out, size_t cap)
{
    const undo_t *u = &r->su.u;
    size_t n = 0;
    for (size_t i = 0; i < u->nsteps; i++) {
        const undo_step_t *st = &u->steps[i];
        assert_true(n + st->len <= cap);
        for (size_t b = 0; b < st->len; b++)
            out[n + b] = u->ring[(st->off + b) % u->ring_cap];
        n += st->len;
    }
    return n;
}

static void test_sliced_diff_is_the_whole_diff(void **st_)
{
    (void)st_;
    enum { K = 4 };
    rig_t a, b;
    rig_init(&a, 1, 16u << 20);
    rig_init(&b, 1, 16u << 20);
    uint32_t max_slices = 0;
    for (int k = 0; k < K; k++) {
        /* a: the whole diff at the press; b: a slice before each implicit step */
        press_stroke(&a, k, true, false);
        assert_int_equal(session_undo_finish(&a.su, &a.gs.field), ARGIL_OK);
        const uint32_t s0 = b.su.stats.slices;
        press_stroke(&b, k, true, true);
        if (b.su.stats.slices - s0 > max_slices)
            max_slices = b.su.stats.slices - s0;
    }
    assert_int_equal(session_undo_press(&a.su, &a.gs.field), ARGIL_OK);
    assert_int_equal(session_undo_finish(&a.su, &a.gs.field), ARGIL_OK);
    assert_int_equal(session_undo_press(&b.su, &b.gs.field), ARGIL_OK);
    uint32_t tail = 0;
    while (session_undo_slice(&b.su, &b.gs.field))
        tail++;
    printf("# %u steps, %zu B; sliced: up to %u slices a stroke, the last step %u more, %u blocks "
           "copied aside\n", b.su.stats.steps, b.su.u.bytes, max_slices, tail + 1,
           b.su.stats.copied_blocks);
    assert_int_equal(a.su.stats.steps, K);
    assert_int_equal(b.su.stats.steps, K);
    assert_true(b.su.stats.copied_blocks > 0); /* writes came while the diff was pending */
    assert_true(tail > 0);                     /* and it took several slices */
    const size_t cap = 16u << 20;
    uint8_t *ja = malloc(cap), *jb = malloc(cap);
    assert_non_null(ja);
    assert_non_null(jb);
    const size_t na = journal_bytes(&a, ja, cap), nb = journal_bytes(&b, jb, cap);
    assert_int_equal(na, nb);
    assert_true(na > 10000);
    assert_memory_equal(ja, jb, na);
    free(ja);
    free(jb);
    rig_free(&a);
    rig_free(&b);
}

static void test_undo_in_the_middle_of_the_slices(void **st_)
{
    (void)st_;
    rig_t r;
    rig_init(&r, 1, 16u << 20);
    state_t s0, s1;
    state_take(&r, &s0);
    press_stroke(&r, 0, true, false);
    state_take(&r, &s1);
    /* the next press seals stroke 0: one slice, then the clay is written again */
    assert_int_equal(session_undo_press(&r.su, &r.gs.field), ARGIL_OK);
    session_undo_touched(&r.su);
    assert_true(session_undo_slice(&r.su, &r.gs.field));
    assert_true(r.su.pend_open && r.su.pend_next < r.su.npend);
    steps_sliced(&r, vec3(0, R, 0), -2.0f, 2, false);
    assert_true(r.su.pend_open); /* still pending: the undo finishes it first */
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s1), 0);
    assert_int_equal(step(&r, false), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s0), 0);
    assert_int_equal(step(&r, true), ARGIL_OK);
    assert_int_equal(state_diff(&r, &s1), 0);
    state_free(&s0);
    state_free(&s1);
    rig_free(&r);
}

static void test_off(void **st_)
{
    (void)st_;
    session_undo_t su;
    int32_t lo[3], hi[3];
    assert_int_equal(session_undo_init(&su, NULL, 1u << 20), ARGIL_OK);
    assert_false(su.on);
    assert_non_null(strstr(su.note, "B-spline"));
    session_undo_free(&su);
    rig_t r;
    const int32_t dims[3] = {N, N, N};
    assert_int_equal(grid_init(&r.g, dims, H, vec3(0, 0, 0)), ARGIL_OK);
    assert_int_equal(gsolve_init(&r.gs, &r.g), ARGIL_OK);
    assert_int_equal(session_undo_init(&r.su, &r.gs.field, 0), ARGIL_OK);
    assert_false(r.su.on);
    assert_non_null(strstr(r.su.note, "--undo-mb 0"));
    assert_int_equal(session_undo_step(&r.su, &r.gs.field, false, lo, hi), ARGIL_ERR_ARG);
    assert_int_equal(session_undo_undo_count(&r.su), 0);
    rig_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_undo_redo_bit_exact),
        cmocka_unit_test(test_budget_drops_oldest),
        cmocka_unit_test(test_knot_insertion_cuts_history),
        cmocka_unit_test(test_air_press_is_no_step),
        cmocka_unit_test(test_sliced_diff_is_the_whole_diff),
        cmocka_unit_test(test_undo_in_the_middle_of_the_slices),
        cmocka_unit_test(test_off),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
