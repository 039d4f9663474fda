/* SIL: the host model's tools in a scripted session (script verbs action, action_shape, mirror;
 * docs/script.md). With the board's carve tool held in the clay: the default setting carves as
 * every session did (the explicit `action carve / action_shape sphere / mirror none` gives the
 * same mesh, byte for byte), `mirror x` carves the -x side by as much as the +x side, `action
 * add` grows a ridge where the stylus went, `action smooth` brings that ridge down again, and
 * the springs solve refuses host settings before the session starts. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/session.h"
#include "host/io/ply.h"
#include "tests/sil/sil_runs.h"

#define CLAY_R_MM 30.0

/* Round the clay to its +x side, then carve 3 mm into it with a 4 mm ball (the host lines go
 * between the approach and the press). */
static const char *const CARVE_HEAD =
    "set radius_mm 4\ntool touch\nmove 45 0 45 0.5\nmove 45 0 0 0.5\nmove 36 0 0 0.3\n"
    "tool carve\n";
static const char *const CARVE_TAIL =
    "press 1\nmove 27 0 0 0.6\nwait 0.2\nrelease 1\nmove 45 0 0 0.3\n";
/* A 2 mm ball drawn along the top (y = 31 mm, z from -10 to 10 mm) with `action add`. */
static const char *const RIDGE =
    "set radius_mm 2\ntool touch\nmove 0 45 -10 0.5\nmove 0 36 -10 0.3\ntool carve\n"
    "action add\npress 1\nmove 0 31 -10 0.2\nmove 0 31 10 1.0\nrelease 1\nmove 0 45 10 0.3\n";
/* Then a 6 mm smoothing ball run along the ridge top and back. */
static const char *const SMOOTH =
    "set radius_mm 6\naction smooth\nmove 0 33 12 0.3\npress 1\nmove 0 33 -12 1.0\n"
    "move 0 33 12 1.0\nrelease 1\nmove 0 45 12 0.3\n";

typedef struct {
    char dir[64];
    session_summary_t sum;
    mesh_t mesh;
} run_t;

static run_t plain, explicit_default, mirrored, ridge, smoothed;

static void run_script(run_t *r, const char *a, const char *b, const char *c)
{
    const char *const parts[] = {a, b, c, NULL};
    char path[128];
    assert_int_equal(sil_script_dir(r->dir, "argil-hosttool", "s.scn", parts, path), 0);
    session_opts_t o;
    sil_opts(&o, path, r->dir);
    sil_run(&o, &r->sum, "session failed");
    sil_assert_clean(&r->sum);
    sil_read_final(r->dir, &r->mesh);
}

static void cleanup(run_t *r)
{
    (void)sil_remove_dir(r->dir);
    mesh_free(&r->mesh);
}

static double dvol_cm3(const run_t *r)
{
    return (r->sum.volume_after_m3 - r->sum.volume_before_m3) * 1e6;
}

static int setup(void **st)
{
    (void)st;
    run_script(&plain, CARVE_HEAD, "", CARVE_TAIL);
    run_script(&explicit_default, CARVE_HEAD, "action carve\naction_shape sphere\nmirror none\n",
               CARVE_TAIL);
    run_script(&mirrored, CARVE_HEAD, "mirror x\n", CARVE_TAIL);
    run_script(&ridge, RIDGE, "", "");
    run_script(&smoothed, RIDGE, SMOOTH, "");
    return 0;
}

static int teardown(void **st)
{
    (void)st;
    run_t *const all[] = {&plain, &explicit_default, &mirrored, &ridge, &smoothed};
    for (size_t k = 0; k < sizeof(all) / sizeof(all[0]); k++)
        cleanup(all[k]);
    return 0;
}

static void test_default_setting_carves_as_before(void **st)
{
    (void)st;
    const double x = sil_extent_mm(&plain.mesh, 0, 1);
    printf("# carve (default): +x surface %.2f mm, -x %.2f mm, volume %+.3f cm3\n", x,
           sil_extent_mm(&plain.mesh, 0, -1), dvol_cm3(&plain));
    assert_true(x < CLAY_R_MM - 5.0 && x > CLAY_R_MM - 9.0); /* 3 mm in with a 4 mm ball */
    assert_true(fabs(sil_extent_mm(&plain.mesh, 0, -1) - CLAY_R_MM) < 0.2);
    /* spelling the default out changes nothing: the same mesh, vertex for vertex */
    assert_int_equal(explicit_default.mesh.n_vert, plain.mesh.n_vert);
    assert_memory_equal(explicit_default.mesh.pos, plain.mesh.pos,
                        plain.mesh.n_vert * 3 * sizeof(float));
    assert_true(explicit_default.sum.volume_after_m3 == plain.sum.volume_after_m3);
}

static void test_mirror_x_carves_both_sides(void **st)
{
    (void)st;
    const double px = sil_extent_mm(&mirrored.mesh, 0, 1);
    const double nx = sil_extent_mm(&mirrored.mesh, 0, -1);
    printf("# mirror x: +x surface %.3f mm, -x %.3f mm (unmirrored +x %.3f); volume %+.3f cm3 "
           "(unmirrored %+.3f)\n", px, nx, sil_extent_mm(&plain.mesh, 0, 1), dvol_cm3(&mirrored),
           dvol_cm3(&plain));
    assert_true(nx < CLAY_R_MM - 5.0);
    assert_true(fabs(px - nx) < 0.1);
    assert_true(fabs(px - sil_extent_mm(&plain.mesh, 0, 1)) < 0.1);
    /* twice the material gone, within 10 % */
    assert_true(fabs(dvol_cm3(&mirrored) - 2.0 * dvol_cm3(&plain)) < 0.1 * fabs(dvol_cm3(&plain)));
    /* the top untouched */
    assert_true(fabs(sil_extent_mm(&mirrored.mesh, 1, 1) - CLAY_R_MM) < 0.2);
}

static void test_add_grows_a_ridge(void **st)
{
    (void)st;
    const double top = sil_extent_mm(&ridge.mesh, 1, 1), dv = dvol_cm3(&ridge);
    printf("# add: ridge top %.2f mm (clay %.1f), volume %+.3f cm3 (%.2f %%)\n", top, CLAY_R_MM,
           dv, dv * 1e-6 / ridge.sum.volume_before_m3 * 100.0);
    /* a 2 mm ball centred ~1 mm above the surface: the top rises ~3 mm */
    assert_true(top > CLAY_R_MM + 2.0 && top < CLAY_R_MM + 4.0);
    /* the ridge's part above the sphere: ~10 mm² across x 20 mm long, plus its ends and the
     * neck the overlapping ramps fill: 0.2 … 0.6 cm³ */
    assert_true(dv > 0.15 && dv < 0.6);
    assert_true(fabs(sil_extent_mm(&ridge.mesh, 0, 1) - CLAY_R_MM) < 0.2); /* the side untouched */
}

static void test_smooth_lowers_the_ridge(void **st)
{
    (void)st;
    const double before = sil_extent_mm(&ridge.mesh, 1, 1);
    const double after = sil_extent_mm(&smoothed.mesh, 1, 1);
    printf("# smooth: ridge top %.2f -> %.2f mm (clay %.1f), volume %+.3f -> %+.3f cm3\n", before,
           after, CLAY_R_MM, dvol_cm3(&ridge), dvol_cm3(&smoothed));
    assert_true(after < before - 1.0);
    assert_true(after > CLAY_R_MM - 1.0); /* smoothed, not carved away */
}

static void test_springs_refuse_host_settings(void **st)
{
    (void)st;
    session_summary_t sum;
    char err[1024];
    sil_assert_refused("tool carve\nwait 0.1\nmirror y\n", PEER_SOLVE_SPRINGS, "springs", &sum,
                       err, sizeof(err));
    assert_non_null(strstr(err, "line 3: host tool settings need the B-spline model"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_setting_carves_as_before),
        cmocka_unit_test(test_mirror_x_carves_both_sides),
        cmocka_unit_test(test_add_grows_a_ridge),
        cmocka_unit_test(test_smooth_lowers_the_ridge),
        cmocka_unit_test(test_springs_refuse_host_settings),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
