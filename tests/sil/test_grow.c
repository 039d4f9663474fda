/* SIL: the clay grows past the grid's old box (Ferley §3.1 sparse working space). A
 * 4 mm `action add` ball dragged from the sphere's +x side (30 mm) out to 72 mm leaves a rod of
 * clay reaching ~75 mm, far past the 88³ grid's old edge at +54.4 mm, where the dense grid
 * clipped every add. The mesh follows, the file keeps it, the journal rebased onto a box that
 * holds it, and the grid's memory stays a fraction of a dense grid of its bounds. */
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
#include "host/io/argil_file.h"
#include "host/io/ply.h"
#include "host/mesh/grid_mesh.h"
#include "tests/sil/sil_runs.h"

#define OLD_EDGE_MM 54.375 /* (88 - 1) / 2 samples of 1.25 mm from the centre */

static const char *const STROKE =
    "set radius_mm 4\ntool touch\nmove 45 0 45 0.5\nmove 45 0 0 0.5\nmove 36 0 0 0.3\n"
    "tool carve\naction add\npress 1\nmove 28 0 0 0.2\nmove 72 0 0 2.0\nrelease 1\n"
    "move 80 0 0 0.3\n";

static char g_dir[64];

/* The largest vertex x of m, mm. */
static double max_x_mm(const mesh_t *m)
{
    double best = -1e9;
    for (size_t i = 0; i < m->n_vert; i++)
        best = fmax(best, (double)m->pos[3 * i] * 1e3);
    return best;
}

static void test_add_past_the_old_edge(void **st)
{
    (void)st;
    const char *const parts[] = {STROKE, NULL};
    char path[128];
    assert_int_equal(sil_script_dir(g_dir, "argil-grow", "s.scn", parts, path), 0);
    session_opts_t o;
    sil_opts(&o, path, g_dir);
    session_summary_t sum;
    char err[1024] = "";
    sil_run(&o, &sum, "session failed");
    sil_assert_clean(&sum);
    assert_true(sum.journal_checkpoints >= 1); /* rebased onto a box holding the grown clay */

    /* The grid grew along +x only. */
    printf("# grid bounds x %d..%d (was 0..88), y %d..%d; memory %zu KiB at the start, %zu KiB "
           "at the end, a dense grid of the bounds %zu KiB; volume %+.3f cm3\n",
           sum.grid_lo[0], sum.grid_hi[0], sum.grid_lo[1], sum.grid_hi[1],
           sum.grid_bytes_start / 1024, sum.grid_bytes_end / 1024,
           sum.grid_dense_bytes_end / 1024,
           (sum.volume_after_m3 - sum.volume_before_m3) * 1e6);
    assert_int_equal(sum.grid_lo[0], 0);
    assert_true(sum.grid_hi[0] > 100); /* measured 110 */
    assert_true(sum.grid_lo[1] == 0 && sum.grid_hi[1] == 88);
    assert_true((double)sum.grid_bytes_end < 0.4 * (double)sum.grid_dense_bytes_end);
    /* A rod of 4 mm radius over 40 mm: about 2 cm3 more clay (measured +2.14). */
    assert_true((sum.volume_after_m3 - sum.volume_before_m3) * 1e6 > 1.0);

    /* The mesh follows the clay past the old edge. */
    mesh_t m;
    sil_read_final(g_dir, &m);
    const double x_mm = max_x_mm(&m);
    printf("# final.ply reaches x = %.2f mm (the old grid's edge: %.2f mm)\n", x_mm, OLD_EDGE_MM);
    assert_true(x_mm > OLD_EDGE_MM + 15.0); /* measured 75.5 */
    assert_true(x_mm < 80.0);               /* the ball went to 72 mm, radius 4 */

    /* The file holds the grown box (a dense box over the bounds) and meshes the same. */
    argil_doc_t d;
    snprintf(path, sizeof(path), "%s/model.argil", g_dir);
    assert_int_equal(argil_file_read(path, &d, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(d.grid.dims[0], sum.grid_hi[0] - sum.grid_lo[0]);
    mesh_t fm;
    mesh_init(&fm);
    assert_int_equal(grid_mesh_extract(&d.grid, d.grid.iso, &fm), ARGIL_OK);
    assert_int_equal(fm.n_tri, m.n_tri);
    assert_float_equal(max_x_mm(&fm), x_mm, 1e-3);
    mesh_free(&fm);
    argil_doc_free(&d);
    mesh_free(&m);
    (void)sil_remove_dir(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_add_past_the_old_edge),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
