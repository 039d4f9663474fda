/* SIL: undo and redo in a scripted session (script verbs undo, redo; host/app/session_undo.h).
 * A dent pushed into the +z side and undone leaves the surface where the untouched -z side is
 * and the volume as it started; redo brings the dent back as deep as a run that never undid it;
 * the autosave journal recovers the undone model; refused requests (nothing to undo or redo,
 * button 1 held) are one line each with the script line and the session goes on; the default
 * session's files are the same bytes with undo on and off; the springs solve refuses the verbs
 * before the start; a press in the air after the dent is no step: the undo after it still takes
 * the dent away. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/session.h"
#include "host/io/argil_file.h"
#include "host/io/journal.h"
#include "host/io/ply.h"
#include "tests/sil/sil_runs.h"
#include "tests/unit/grid_view.h"

#define CLAY_R_MM 30.0

static const char *const HEAD =
    "set radius_mm 4\nset stiffness_n_per_mm 0.8\nset max_force_n 3.3\nset alpha 30000\n"
    "tool touch\nmove 0 0 36 0.6\nmove 0 0 32 0.4\nwait 0.2\n";
static const char *const DENT =
    "tool push\npress 1\nmove 0 0 22 1.5\nwait 0.3\nrelease 1\nmove 0 0 45 0.5\n";
/* The same stroke asking for an undo while button 1 is held (line 14 with ERRS_HEAD first). */
static const char *const DENT_UNDO_HELD =
    "tool push\npress 1\nmove 0 0 22 1.5\nundo\nwait 0.3\nrelease 1\nmove 0 0 45 0.5\n";
static const char *const ERRS_HEAD = "undo\nredo\n";

typedef struct {
    char dir[64];
    session_summary_t sum;
    mesh_t mesh;
    char notes[4][256];
    int n_notes;
    /* the journal as it stood after the undo (recovery check) */
    char copy_dir[96];
    bool copy;                    /* copy the journal 0.3 s after the undo */
    double undo_at_s;             /* when the session did it (< 0: not yet) */
    bool copied;
} run_t;

static run_t dent, undone, redone, errs, def_on, def_off, air;

static void on_note(void *ctx, const char *msg)
{
    run_t *r = ctx;
    if (r->n_notes < 4)
        snprintf(r->notes[r->n_notes], sizeof(r->notes[0]), "%s", msg);
    r->n_notes++;
}

static void copy_file(const char *from, const char *to)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    assert_non_null(in);
    assert_non_null(out);
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), in)) > 0)
        assert_int_equal(fwrite(buf, 1, n, out), n);
    fclose(in);
    assert_int_equal(fclose(out), 0);
}

/* Copies the session's journal files once, 0.3 s after the undo (autosave every 0.05 s): what
 * a crash then would leave. */
static void copy_hook(void *ctx, session_frame_t *f)
{
    run_t *r = ctx;
    if (r->undo_at_s < 0.0 && f->undo->stats.undos > 0)
        r->undo_at_s = f->t_s;
    if (r->copied || r->undo_at_s < 0.0 || f->t_s < r->undo_at_s + 0.3)
        return;
    r->copied = true;
    DIR *d = opendir(r->dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, "journal", 7) != 0)
            continue;
        char a[256], b[256];
        snprintf(a, sizeof(a), "%s/%s", r->dir, e->d_name);
        snprintf(b, sizeof(b), "%s/%s", r->copy_dir, e->d_name);
        copy_file(a, b);
    }
    closedir(d);
}

/* Runs a script made of the parts (NULL ends them) or the default script (parts NULL). */
static void run(run_t *r, const char *const *parts, uint32_t undo_mb, bool copy)
{
    static const char *const none[] = {NULL};
    char path[128];
    assert_int_equal(sil_script_dir(r->dir, "argil-undo", "s.scn", parts ? parts : none, path), 0);
    session_opts_t o;
    sil_opts(&o, parts ? path : NULL, r->dir);
    o.undo_mb = undo_mb;
    o.on_note = on_note;
    o.note_ctx = r;
    session_hook_t hook = {copy_hook, r, false};
    r->undo_at_s = -1.0;
    if (copy) {
        snprintf(r->copy_dir, sizeof(r->copy_dir), "%s/copy", r->dir);
        assert_int_equal(mkdir(r->copy_dir, 0777), 0);
        r->copy = true;
        o.autosave_s = 0.05f;
        o.hook = &hook;
    }
    sil_run(&o, &r->sum, "session failed");
    sil_assert_clean(&r->sum);
    sil_read_final(r->dir, &r->mesh);
}

static void cleanup(run_t *r)
{
    if (r->copy_dir[0])
        (void)sil_remove_dir(r->copy_dir);
    (void)sil_remove_dir(r->dir);
    mesh_free(&r->mesh);
}

static double dvol_pct(const run_t *r)
{
    return (r->sum.volume_after_m3 - r->sum.volume_before_m3) / r->sum.volume_before_m3 * 100.0;
}

static int setup(void **st)
{
    (void)st;
    const char *const p_dent[] = {HEAD, DENT, "wait 0.6\nwait 0.5\n", NULL};
    const char *const p_undone[] = {HEAD, DENT, "wait 0.6\nundo\nwait 0.5\n", NULL};
    const char *const p_redone[] = {HEAD, DENT, "wait 0.6\nundo\nwait 0.2\nredo\nwait 0.3\n", NULL};
    const char *const p_errs[] = {ERRS_HEAD, HEAD, DENT_UNDO_HELD, "wait 0.6\n", NULL};
    run(&dent, p_dent, SESSION_UNDO_MB_DEFAULT, false);
    run(&undone, p_undone, SESSION_UNDO_MB_DEFAULT, true);
    run(&redone, p_redone, SESSION_UNDO_MB_DEFAULT, false);
    run(&errs, p_errs, SESSION_UNDO_MB_DEFAULT, false);
    run(&def_on, NULL, SESSION_UNDO_MB_DEFAULT, false);
    run(&def_off, NULL, 0, false);
    /* the stylus 15 mm above the clay right after the dent, the clay still springing back:
     * button 1 pressed and released, nothing touched (the per-press boundary made this a step
     * of its own, the settling, and the undo took back only that: volume -0.47 %) */
    const char *const p_air[] = {HEAD, DENT, "press 1\nwait 0.2\nrelease 1\nwait 0.3\nundo\n"
                                             "wait 0.5\n", NULL};
    run(&air, p_air, SESSION_UNDO_MB_DEFAULT, false);
    return 0;
}

static int teardown(void **st)
{
    (void)st;
    run_t *const all[] = {&dent, &undone, &redone, &errs, &def_on, &def_off, &air};
    for (size_t k = 0; k < sizeof(all) / sizeof(all[0]); k++)
        cleanup(all[k]);
    return 0;
}

static void test_undo_takes_the_dent_away(void **st)
{
    (void)st;
    const double d = sil_extent_mm(&dent.mesh, 2, 1), u = sil_extent_mm(&undone.mesh, 2, 1);
    const double other = sil_extent_mm(&undone.mesh, 2, -1);
    printf("# dent: +z surface %.3f mm (volume %+.3f %%); undone: +z %.3f mm, -z %.3f mm, "
           "volume %+.4f %%; %u step(s), largest %.1f KiB\n",
           d, dvol_pct(&dent), u, other, dvol_pct(&undone), undone.sum.undo_steps,
           (double)undone.sum.undo_max_step_bytes / 1024.0);
    assert_true(d < CLAY_R_MM - 8.0);                 /* a dent a person sees */
    assert_true(fabs(u - other) < 0.05);              /* back where the untouched side is */
    assert_true(fabs(other - CLAY_R_MM) < 0.2);
    assert_true(fabs(dvol_pct(&undone)) < 0.1);       /* the volume as it started */
    assert_int_equal(undone.sum.undos, 1);
    assert_int_equal(undone.sum.undo_refused, 0);
    assert_int_equal(undone.n_notes, 0);
}

static void test_redo_brings_it_back(void **st)
{
    (void)st;
    const double d = sil_extent_mm(&dent.mesh, 2, 1), r = sil_extent_mm(&redone.mesh, 2, 1);
    printf("# redone: +z %.3f mm (never undone %.3f mm), volume %+.3f %% (%+.3f %%)\n", r, d,
           dvol_pct(&redone), dvol_pct(&dent));
    assert_true(fabs(r - d) < 0.05);
    assert_int_equal(redone.sum.undos, 1);
    assert_int_equal(redone.sum.redos, 1);
}

/* The journal copied after the undo recovers the undone model: no dent. */
static void test_recovery_after_undo(void **st)
{
    (void)st;
    assert_true(undone.copied);
    argil_doc_t doc, fin;
    journal_info_t info;
    char err[512] = "", path[128];
    assert_int_equal(journal_recover(undone.copy_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    snprintf(path, sizeof(path), "%s/model.argil", undone.dir);
    assert_int_equal(argil_file_read(path, &fin, err, sizeof(err)), ARGIL_OK);
    const grid_t *a = &doc.grid, *b = &fin.grid;
    assert_memory_equal(a->dims, b->dims, sizeof(a->dims));
    const size_t n = (size_t)a->dims[0] * a->dims[1] * a->dims[2];
    float dmax = 0.0f;
    for (size_t i = 0; i < n; i++) {
        const float dd = fabsf(gv_get(a, GRID_DENSITY, i) - gv_get(b, GRID_DENSITY, i));
        dmax = dd > dmax ? dd : dmax;
    }
    printf("# recovered after the undo: %u records, largest density difference to the final "
           "model %.2g\n", info.records, (double)dmax);
    assert_true(info.records > 0);
    assert_true(dmax < 1e-4f);
    argil_doc_free(&doc);
    argil_doc_free(&fin);
}

static void test_press_in_the_air_is_no_step(void **st)
{
    (void)st;
    const double u = sil_extent_mm(&air.mesh, 2, 1), other = sil_extent_mm(&air.mesh, 2, -1);
    printf("# dent, a press in the air, undo: +z %.3f mm, -z %.3f mm, volume %+.4f %%; %u "
           "step(s) recorded, %u undone\n", u, other, dvol_pct(&air), air.sum.undo_steps,
           air.sum.undos);
    assert_true(fabs(u - other) < 0.05); /* the dent went, not the air press */
    assert_true(fabs(dvol_pct(&air)) < 0.1);
    assert_int_equal(air.sum.undo_steps, 1);
    assert_int_equal(air.sum.undos, 1);
    assert_int_equal(air.sum.undo_refused, 0);
}

static void test_refusals_are_one_line_and_the_session_goes_on(void **st)
{
    (void)st;
    for (int k = 0; k < errs.n_notes && k < 4; k++)
        printf("# %s\n", errs.notes[k]);
    assert_int_equal(errs.n_notes, 3);
    assert_int_equal(errs.sum.undo_refused, 3);
    assert_non_null(strstr(errs.notes[0], "line 1: undo refused: nothing to undo"));
    assert_non_null(strstr(errs.notes[1], "line 2: redo refused: nothing to redo"));
    assert_non_null(strstr(errs.notes[2], "line 14: undo refused: button 1 is held"));
    for (int k = 0; k < 3; k++)
        assert_null(strchr(errs.notes[k], '\n'));
    /* the held undo changed nothing: the dent is there */
    assert_true(sil_extent_mm(&errs.mesh, 2, 1) < CLAY_R_MM - 8.0);
    assert_int_equal(errs.sum.undos, 0);
}

static void test_default_session_unchanged(void **st)
{
    (void)st;
    static const char *const names[] = {"final.ply", "model.argil"};
    for (int k = 0; k < 2; k++) {
        char a[128], b[128];
        snprintf(a, sizeof(a), "%s/%s", def_on.dir, names[k]);
        snprintf(b, sizeof(b), "%s/%s", def_off.dir, names[k]);
        FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
        assert_non_null(fa);
        assert_non_null(fb);
        int ca, cb;
        size_t n = 0;
        do {
            ca = fgetc(fa);
            cb = fgetc(fb);
            assert_int_equal(ca, cb);
            n++;
        } while (ca != EOF);
        fclose(fa);
        fclose(fb);
        printf("# %s: %zu bytes, the same with undo on and off\n", names[k], n - 1);
    }
    printf("# default session: %u steps (3 strokes: the last stays open), largest %.1f KiB, "
           "%.1f KiB held, shadow %.1f MiB\n",
           def_on.sum.undo_steps, (double)def_on.sum.undo_max_step_bytes / 1024.0,
           (double)def_on.sum.undo_bytes / 1024.0,
           (double)def_on.sum.undo_shadow_bytes / (1024.0 * 1024.0));
    assert_true(def_on.sum.undo_on);
    assert_int_equal(def_on.sum.undo_steps, 2);
    assert_false(def_off.sum.undo_on);
    assert_non_null(strstr(def_off.sum.undo_note, "--undo-mb 0"));
}

static void test_springs_refuse_before_the_start(void **st)
{
    (void)st;
    session_summary_t sum;
    char err[1024];
    sil_assert_refused("wait 0.1\nundo\n", PEER_SOLVE_SPRINGS, "springs", &sum, err, sizeof(err));
    assert_non_null(strstr(err, "line 2: 'undo' and 'redo' need the B-spline model"));
    assert_int_equal(sum.board_ticks, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_undo_takes_the_dent_away),
        cmocka_unit_test(test_redo_brings_it_back),
        cmocka_unit_test(test_recovery_after_undo),
        cmocka_unit_test(test_press_in_the_air_is_no_step),
        cmocka_unit_test(test_refusals_are_one_line_and_the_session_goes_on),
        cmocka_unit_test(test_default_session_unchanged),
        cmocka_unit_test(test_springs_refuse_before_the_start),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
