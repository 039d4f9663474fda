/* SIL: knot insertion in a live session. The same dent pushed into the clay (a) at R = 1 from
 * the start and (b) in a session started at R = 2 (--knot-ratio 2) whose script refines the
 * model while the stylus rests on the surface, just before the push: the refinement changes
 * no density by 1e-5, the solve goes on (the push after it dents the clay as deep as at R = 1),
 * the mesh is watertight and every change is journaled. A refine the session cannot do is
 * refused before the start with the script's line. */
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

static const char *const DENT_HEAD =
    "set radius_mm 4\nset stiffness_n_per_mm 0.8\nset max_force_n 3.3\nset alpha 30000\n"
    "tool touch\nmove 0 0 36 0.6\nmove 0 0 32 0.4\nwait 0.2\n";
static const char *const DENT_TAIL =
    "tool push\npress 1\nmove 0 0 22 1.5\nwait 0.3\nrelease 1\nmove 0 0 45 0.5\n";

static char dir[64];

static void write_script(const char *path, bool refine)
{
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(DENT_HEAD, fp);
    if (refine)
        fputs("refine\n", fp);
    fputs(DENT_TAIL, fp);
    assert_int_equal(fclose(fp), 0);
}

/* The +z extent of the final mesh near the z axis (the dent's floor), mm. */
static double dent_mm(const char *out)
{
    mesh_t m;
    sil_read_final(out, &m);
    const double best = sil_extent_mm(&m, 2, 1);
    mesh_free(&m);
    return best;
}

static argil_err_t run(const char *script, const char *out, int ratio, peer_global_solve_t solve,
                       session_summary_t *sum, char *err, size_t err_len)
{
    session_opts_t o;
    sil_opts(&o, script, out);
    o.knot_ratio = ratio;
    o.global_solve = solve;
    err[0] = '\0';
    return session_run(&o, sum, err, err_len);
}

static void test_dent_after_a_refinement(void **st)
{
    (void)st;
    strcpy(dir, "/tmp/argil-knots-XXXXXX");
    assert_non_null(mkdtemp(dir));
    char plain[128], refined[128], out_a[128], out_b[128], err[1024];
    snprintf(plain, sizeof(plain), "%s/dent.scn", dir);
    snprintf(refined, sizeof(refined), "%s/dent_refine.scn", dir);
    snprintf(out_a, sizeof(out_a), "%s/a", dir);
    snprintf(out_b, sizeof(out_b), "%s/b", dir);
    write_script(plain, false);
    write_script(refined, true);
    session_summary_t a, b;
    if (run(plain, out_a, 1, PEER_SOLVE_BSPLINE, &a, err, sizeof(err)) != ARGIL_OK)
        fail_msg("R = 1 session: %s", err);
    if (run(refined, out_b, 2, PEER_SOLVE_BSPLINE, &b, err, sizeof(err)) != ARGIL_OK)
        fail_msg("R = 2 + refine session: %s", err);
    const double da = dent_mm(out_a), db = dent_mm(out_b);
    printf("# dent floor: %.2f mm at R = 1, %.2f mm at R = 2 refined to 1 (sphere %.1f); "
           "refinement: max |dd| %.2e; volume %+.3f %% / %+.3f %%\n", da, db, CLAY_R_MM,
           (double)b.refine_max_dd,
           (a.volume_after_m3 - a.volume_before_m3) / a.volume_before_m3 * 100.0,
           (b.volume_after_m3 - b.volume_before_m3) / b.volume_before_m3 * 100.0);
    printf("# solve step CPU median %.2f / %.2f ms (ASan build)\n", a.solve_median_ms,
           b.solve_median_ms);
    assert_int_equal(a.refines, 0);
    assert_int_equal(a.knot_ratio_end, 1);
    assert_int_equal(b.refines, 1);
    assert_int_equal(b.knot_ratio_end, 1);
    assert_true(b.refine_max_dd < 1e-5f);
    sil_assert_clean(&b);
    /* the push after the refinement made the dent, as deep as at R = 1 */
    assert_true(da < CLAY_R_MM - 2.0);
    assert_true(db < CLAY_R_MM - 2.0);
    assert_true(fabs(db - da) < 0.5);
    (void)sil_remove_dir(out_a);
    (void)sil_remove_dir(out_b);

    /* R = 1 and the springs cannot refine: refused before anything starts, naming the line */
    session_summary_t c;
    assert_int_equal(run(refined, NULL, 1, PEER_SOLVE_BSPLINE, &c, err, sizeof(err)),
                     ARGIL_ERR_ARG);
    printf("# R = 1: %s\n", err);
    assert_non_null(strstr(err, "line 9: 'refine': already at one coefficient per sample"));
    assert_int_equal(c.board_ticks, 0);
    assert_int_equal(run(refined, NULL, 2, PEER_SOLVE_SPRINGS, &c, err, sizeof(err)),
                     ARGIL_ERR_ARG);
    assert_non_null(strstr(err, "line 9: 'refine' needs the B-spline model"));
    assert_int_equal(run(plain, NULL, 3, PEER_SOLVE_BSPLINE, &c, err, sizeof(err)),
                     ARGIL_ERR_ARG);
    assert_non_null(strstr(err, "knot ratio 3 refused"));
    (void)sil_remove_dir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dent_after_a_refinement),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
