/* SIL: the seam carries a session. argil's peer sculpts a representation it knows only through
 * host/model/rep.h (an analytic sphere that dents where it is pushed, tests/sil/rep_dent_sphere.h):
 * the board is handed its windows and feels it, the board's impulses dent it, and it is meshed
 * through the seam. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "host/mesh/mesh_check.h"
#include "tests/sil/rep_dent_sphere.h"
#include "tests/sil/rig.h"

#define RADIUS_M 0.030f

/* The highest surface point within 2 mm of the z axis, from the seam's mesh (m; -1: none). */
static float top_z_m(const rep_t *rep, bool *watertight)
{
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(rep->ops->surface(rep->st, &m), ARGIL_OK);
    assert_true(m.n_tri > 1000);
    size_t open_edges = 0, nonmanifold = 0;
    *watertight = mesh_watertight(&m, &open_edges, &nonmanifold);
    float top = -1.0f;
    for (size_t i = 0; i < m.n_vert; i++) {
        const float *p = &m.pos[3 * i];
        if (p[0] * p[0] + p[1] * p[1] < 4e-6f && p[2] > top)
            top = p[2];
    }
    mesh_free(&m);
    return top;
}

static void test_peer_drives_a_second_representation(void **st)
{
    (void)st;
    dent_sphere_t ds;
    rep_t rep;
    assert_true(dent_sphere_init(&ds, 72, 0.00125f, RADIUS_M, &rep));
    bool closed = false;
    const float z_before = top_z_m(&rep, &closed);
    assert_true(closed);
    assert_true(fabsf(z_before - RADIUS_M) < 0.5e-3f);

    rig_t *r = rig_new_host(1.0f, false, &rep);
    assert_ptr_equal(r->peer.grid, &ds.grid);
    assert_true(rig_until_active(r, 1000) > 0);
    /* Touch: 2 mm into the top of the sphere, the arm pushes back. */
    const float r_tool = r->tool.radius_m;
    rig_move(r, vec3(0, 0, z_before + r_tool + 0.002f), 500);
    rig_move(r, vec3(0, 0, z_before + r_tool - 0.002f), 200);
    for (int i = 0; i < 300; i++)
        rig_tick(r);
    const float touch_n = r->rig.board.force_n.z;
    const float touch_pen_m = z_before + r_tool - rig_tip_model(r).z;
    rig_move(r, vec3(0, 0, z_before + r_tool + 0.002f), 200);

    /* Push: the board yields the clay and sends impulses; the host's step dents the sphere. */
    const msg_tool_t push = rig_tool(r, TOOL_PUSH, 1.0f);
    rig_set_tool(r, &push);
    rig_move(r, r->hand_model_m, 50);
    r->btn1 = true;
    rig_move(r, vec3(0, 0, z_before + r_tool - 0.005f), 140);
    for (int i = 0; i < 600; i++)
        rig_tick(r);
    r->btn1 = false;
    rig_move(r, vec3(0, 0, 0.060f), 600);
    for (int i = 0; i < 500; i++)
        rig_tick(r);
    const float z_after = top_z_m(&rep, &closed);
    const peer_stats_t ps = r->peer.stats;
    const board_stats_t bs = r->rig.board.stats;
    printf("# seam: touch %.2f N at %.2f mm in; push: top %.2f -> %.2f mm, %u impulse frames, "
           "%u windows sent, %u swapped\n",
           touch_n, touch_pen_m * 1e3, z_before * 1e3, z_after * 1e3, ps.impulse_frames,
           ps.windows_sent, bs.windows_swapped);
    rig_free(r);
    rep.ops->free(rep.st);

    assert_true(touch_pen_m > 0.0005f);   /* the stylus was in the clay's surface */
    assert_true(touch_n > 0.5f);          /* and the hand felt it push back */
    assert_true(touch_n <= 3.3f + 1e-4f); /* never past the tool's force limit */
    assert_true(ps.impulse_frames > 5);
    assert_int_equal(ps.impulses_unmapped, 0);
    assert_true(z_before - z_after > 0.002f); /* a dent of more than 2 mm, seen in the mesh */
    assert_true(closed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_peer_drives_a_second_representation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
