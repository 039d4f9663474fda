/* The B-spline density model behind the seam (host/solve/rep_bspline.h): the window the board
 * gets is the grid's samples (with the painted stiffness channel), an impulse acts where it is
 * put and nowhere else, forces the implicit step does not take are dropped, and the springs
 * variant refuses what it cannot do without changing anything. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "host/solve/rep_bspline.h"
#include "tests/unit/sphere_grid.h"

#define N 32
#define H 1e-3f
#define EDGE 8

/* A 10 mm clay sphere on N³ samples behind the seam: implicit (the B-spline model, R = 1) or
 * the grid's springs; model_free frees both. */
static grid_t *model_new(rep_bspline_t *b, bool implicit)
{
    grid_t *g = sphere_grid_new(N, H, 0.010f);
    assert_int_equal(rep_bspline_init(b, g, implicit, 1), ARGIL_OK);
    return g;
}

static void model_free(rep_bspline_t *b, grid_t *g)
{
    rep_bspline(b).ops->free(b);
    sphere_grid_free(g);
}

static void test_window_is_the_grid_and_carries_painted_stiffness(void **st)
{
    (void)st;
    rep_bspline_t b;
    grid_t *g = model_new(&b, true);
    const rep_t rep = rep_bspline(&b);
    const int32_t dims[3] = {EDGE, EDGE, EDGE};
    int32_t corner[3], want[3];
    const vec3_t top = vec3(0, 0, 0.010f);
    rep.ops->window_corner(rep.st, top, dims, corner);
    grid_window_corner(g, top, dims, want);
    assert_memory_equal(corner, want, sizeof(corner));
    static float d[EDGE * EDGE * EDGE], k[EDGE * EDGE * EDGE], ref[EDGE * EDGE * EDGE];
    assert_false(rep.ops->window_samples(rep.st, corner, dims, d, k));
    grid_extract(g, corner, dims, ref);
    assert_memory_equal(d, ref, sizeof(d));
    rep_change_t c;
    assert_int_equal(rep.ops->paint(rep.st, REP_MAT_STIFFNESS, top, 0.003f, 4.0f, &c), ARGIL_OK);
    assert_true(c.felt && c.box.hi[0] > c.box.lo[0]);
    assert_true(rep.ops->window_samples(rep.st, corner, dims, d, k));
    /* Each node's spring is the base times the model's painted scale there: the board feels
     * the paint (up to 1 + 3 (1 - 0.87 / 3) = 3.1x at the nodes 0.87 mm from its centre). */
    float k_max = 0.0f;
    int i = 0;
    for (int32_t z = 0; z < EDGE; z++)
        for (int32_t y = 0; y < EDGE; y++)
            for (int32_t x = 0; x < EDGE; x++, i++) {
                const int32_t at[3] = {corner[0] + x, corner[1] + y, corner[2] + z};
                const float scale =
                    rep.ops->material_at(rep.st, REP_MAT_STIFFNESS, grid_box_origin(g, at));
                assert_float_equal(k[i], scale * g->material.stiffness, 1e-6f);
                k_max = k[i] > k_max ? k[i] : k_max;
            }
    assert_true(k_max > 3.0f * g->material.stiffness);
    model_free(&b, g);
}

/* A push on one surface node: the springs move that node's density within the step's region,
 * and the change box holds it; the same push outside the lattice is refused. */
static void test_impulse_moves_the_node_it_was_put_on(void **st)
{
    (void)st;
    rep_bspline_t b;
    grid_t *g = model_new(&b, false);
    const rep_t rep = rep_bspline(&b);
    const int32_t far[3] = {GRID_INDEX_MAX, 0, 0};
    assert_int_equal(rep.ops->add_node_force(rep.st, far, -50.0f), ARGIL_ERR_ARG);
    assert_int_equal(rep.ops->add_node_force(rep.st, far, NAN), ARGIL_ERR_NONFINITE);
    const int32_t node[3] = {N / 2, N / 2, N / 2 + 10};
    const float d0 = grid_get(g, GRID_DENSITY, node[0], node[1], node[2]);
    assert_int_equal(rep.ops->add_node_force(rep.st, node, -50.0f), ARGIL_OK);
    const rep_box_t region = {{N / 2 - 4, N / 2 - 4, N / 2 + 6}, {N / 2 + 4, N / 2 + 4, N / 2 + 14}};
    rep_change_t c;
    assert_int_equal(rep.ops->step(rep.st, &region, 0.01f, &c), ARGIL_OK);
    const float d1 = grid_get(g, GRID_DENSITY, node[0], node[1], node[2]);
    assert_true(d0 - d1 > 1e-3f);
    assert_true(c.felt);
    for (int a = 0; a < 3; a++)
        assert_true(c.box.lo[a] <= node[a] && node[a] < c.box.hi[a]);
    host_tool_t t;
    host_tool_default(&t);
    assert_true(rep.ops->tool_supported(rep.st, &t));
    t.action = HOST_ACT_ADD;
    assert_false(rep.ops->tool_supported(rep.st, &t));
    assert_int_equal(rep.ops->paint(rep.st, REP_MAT_MASS, vec3(0, 0, 0), 0.003f, 2.0f, &c),
                     ARGIL_ERR_STATE);
    float dd = 1.0f;
    assert_int_equal(rep.ops->refine(rep.st, &dd, &c), ARGIL_ERR_STATE);
    assert_true(dd == 0.0f && c.box.hi[0] <= c.box.lo[0]);
    model_free(&b, g);
}

/* The implicit step takes the forces in its region; one left outside it does not wait for a
 * later window there (it would act as a stale push): it is gone after the step. */
static void test_implicit_step_drops_forces_outside_its_region(void **st)
{
    (void)st;
    rep_bspline_t b;
    grid_t *g = model_new(&b, true);
    const rep_t rep = rep_bspline(&b);
    const int32_t outside[3] = {2, 2, 2};
    assert_int_equal(rep.ops->add_node_force(rep.st, outside, 30.0f), ARGIL_OK);
    assert_true(grid_get(g, GRID_FORCE, 2, 2, 2) != 0.0f);
    const rep_box_t region = {{12, 12, 20}, {20, 20, 28}};
    rep_change_t c;
    assert_int_equal(rep.ops->step(rep.st, &region, 0.01f, &c), ARGIL_OK);
    assert_true(grid_get(g, GRID_FORCE, 2, 2, 2) == 0.0f);
    model_free(&b, g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_is_the_grid_and_carries_painted_stiffness),
        cmocka_unit_test(test_impulse_moves_the_node_it_was_put_on),
        cmocka_unit_test(test_implicit_step_drops_forces_outside_its_region),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
