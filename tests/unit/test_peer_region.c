/* A solver that falls behind lowers its region, never the board's rate: with
 * adaptive_region, solve steps over 80 % of their period shrink the margin around the board's
 * window a sample at a time down to the window itself, 50 fast steps in a row grow it back, and
 * the solve's physical window follows the margin; without it the margin never moves. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>

#include "host/app/peer.h"
#include "host/model/grid.h"

typedef struct {
    grid_t grid;
    peer_t peer;
} rig_t;

/* The board's end of the link is not needed here: frames are taken and dropped. */
static bool discard(void *ctx, const uint8_t *frame, size_t len)
{
    (void)ctx;
    (void)frame;
    (void)len;
    return true;
}

static rig_t *rig_new(bool adaptive)
{
    rig_t *r = calloc(1, sizeof(*r));
    assert_non_null(r);
    const int32_t dims[3] = {40, 40, 40};
    assert_int_equal(grid_init(&r->grid, dims, 1e-3f, vec3(-0.02f, -0.02f, -0.02f)), ARGIL_OK);
    grid_fill_sphere(&r->grid, vec3(0, 0, 0), 0.012f);
    peer_cfg_t cfg;
    peer_cfg_default(&cfg);
    cfg.adaptive_region = adaptive;
    assert_int_equal(peer_init(&r->peer, &cfg, &r->grid, discard, NULL, NULL), ARGIL_OK);
    return r;
}

static void rig_free(rig_t *r)
{
    peer_free(&r->peer);
    grid_free(&r->grid);
    free(r);
}

static void test_slow_steps_shrink_fast_steps_grow(void **st)
{
    (void)st;
    rig_t *r = rig_new(true);
    peer_t *p = &r->peer; /* solve period 10 ms: budget 8 ms, fast below 4 ms */
    assert_int_equal(p->sched.margin, SOLVE_MARGIN_MAX);
    solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 7.9);
    assert_int_equal(p->sched.margin, 4); /* within budget: unchanged */
    for (int i = 0; i < 3; i++)
        solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 12.0);
    assert_int_equal(p->sched.margin, 1);
    for (int i = 0; i < 5; i++)
        solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 30.0);
    assert_int_equal(p->sched.margin, 0); /* never below the board's own window */
    assert_int_equal(p->sched.shrinks, 4);
    assert_int_equal(p->sched.margin_min, 0);
    for (uint32_t i = 0; i + 1 < SOLVE_MARGIN_GROW_STEPS; i++)
        solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 1.0);
    assert_int_equal(p->sched.margin, 0); /* 49 fast steps: not yet */
    solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 5.0); /* a middling step breaks the run */
    for (uint32_t i = 0; i + 1 < SOLVE_MARGIN_GROW_STEPS; i++)
        solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 1.0);
    assert_int_equal(p->sched.margin, 0);
    solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 1.0);
    assert_int_equal(p->sched.margin, 1); /* the 50th fast step in a row */
    for (uint32_t i = 0; i < 10 * SOLVE_MARGIN_GROW_STEPS; i++)
        solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 1.0);
    assert_int_equal(p->sched.margin, SOLVE_MARGIN_MAX); /* and no further */
    rig_free(r);
}

static void test_the_solve_box_follows_the_margin(void **st)
{
    (void)st;
    for (int adaptive = 0; adaptive < 2; adaptive++) {
        rig_t *r = rig_new(adaptive);
        peer_t *p = &r->peer;
        p->current = (peer_window_ref_t){.version = 1, .corner = {10, 12, 14}, .dims = {16, 16, 16}};
        p->have_current = true;
        p->board_seen = true; /* as after the board's HELLO */
        peer_tick(p, p->cfg.solve_period_us);
        assert_int_equal(p->box.lo[0], 10 - SOLVE_MARGIN_MAX);
        assert_int_equal(p->box.hi[2], 14 + 16 + SOLVE_MARGIN_MAX);
        /* Four steps far over budget: with adaptive_region the next solve is the window alone;
         * without it the peer never calls the rule and keeps its margin. */
        if (adaptive)
            for (int i = 0; i < 4; i++)
                solve_sched_adapt(&p->sched, p->cfg.solve_period_us, 100.0);
        peer_tick(p, p->cfg.solve_period_us);
        const int32_t m = adaptive ? 0 : SOLVE_MARGIN_MAX;
        assert_int_equal(p->box.lo[0], 10 - m);
        assert_int_equal(p->box.lo[1], 12 - m);
        assert_int_equal(p->box.hi[0], 10 + 16 + m);
        assert_int_equal(p->box.hi[2], 14 + 16 + m);
        rig_free(r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slow_steps_shrink_fast_steps_grow),
        cmocka_unit_test(test_the_solve_box_follows_the_margin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
