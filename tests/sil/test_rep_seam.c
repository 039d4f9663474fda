/* SIL: the seam carries a session. argil's peer sculpts a representation it knows only through
 * host/model/rep.h (an analytic sphere that dents where it is pushed, tests/sil/rep_dent_sphere.h):
 * the board is handed its windows and feels it, the board's impulses dent it, it is meshed
 * through the seam, and the session's journal, cut off as by a crash, recovers it. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "host/app/peer_journal.h"
#include "host/io/argil_file.h"
#include "host/io/journal.h"
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

/* A scripted session over the rig: the peer's journal steps after every tick when journaling. */
typedef struct {
    rig_t *r;
    bool journaling;
    journal_t j;
    peer_journal_t pj;
} seam_run_t;

/* What the scripted push shows. */
typedef struct {
    float touch_n;        /* force on the hand resting 2 mm into the top */
    float touch_pen_m;    /* how far the stylus was in the surface then */
    float z_before_m;     /* top of the seam's mesh before and after the push */
    float z_after_m;
    bool closed;          /* the mesh after the push is watertight */
    peer_stats_t ps;
    board_stats_t bs;
} seam_figures_t;

/* One board tick, then, journaling, the journal's step as argil sculpt's session takes it (at
 * the session time of the host milliseconds run). */
static void run_tick(seam_run_t *s)
{
    rig_tick(s->r);
    if (!s->journaling)
        return;
    char err[256] = "";
    bool stop_now = false;
    const argil_err_t e = peer_journal_step(&s->j, &s->pj, &s->r->peer,
                                            (double)s->r->ms * 1e-3, &stop_now, err, sizeof(err));
    if (e != ARGIL_OK)
        fail_msg("journal step: %s", err);
    assert_false(stop_now);
}

/* Moves the hand in a straight line over ms milliseconds, a step each board tick (rig_move). */
static void run_move(seam_run_t *s, vec3_t to_m, int ms)
{
    const vec3_t from = s->r->hand_model_m;
    const int ticks = rig_ticks_in_ms(s->r, ms);
    for (int i = 1; i <= ticks; i++) {
        s->r->hand_model_m =
            vec3_add(from, vec3_scale(vec3_sub(to_m, from), (float)i / (float)ticks));
        run_tick(s);
    }
}

/* Runs ticks of nothing. */
static void run_ticks(seam_run_t *s, int ticks)
{
    for (int i = 0; i < ticks; i++)
        run_tick(s);
}

/* The script: arm, touch 2 mm into the top of the sphere, back off, push a dent with the
 * board's push tool, back away and wait; the figures go to f. */
static void run_push(seam_run_t *s, const rep_t *rep, float z_before_m, seam_figures_t *f)
{
    rig_t *r = s->r;
    bool active = false;
    for (int i = 0; i < rig_ticks_in_ms(r, 1000) && !active; i++) {
        run_tick(s);
        active = r->rig.board.safety.state == SAFETY_ACTIVE;
    }
    assert_true(active);
    /* Touch: 2 mm into the top of the sphere, the arm pushes back. */
    const float r_tool = r->tool.radius_m;
    run_move(s, vec3(0, 0, z_before_m + r_tool + 0.002f), 500);
    run_move(s, vec3(0, 0, z_before_m + r_tool - 0.002f), 200);
    run_ticks(s, 300);
    f->touch_n = r->rig.board.force_n.z;
    f->touch_pen_m = z_before_m + r_tool - rig_tip_model(r).z;
    run_move(s, vec3(0, 0, z_before_m + r_tool + 0.002f), 200);

    /* Push: the board yields the clay and sends impulses; the host's step dents the sphere. */
    const msg_tool_t push = rig_tool(r, TOOL_PUSH, 1.0f);
    rig_set_tool(r, &push);
    run_move(s, r->hand_model_m, 50);
    r->btn1 = true;
    run_move(s, vec3(0, 0, z_before_m + r_tool - 0.005f), 140);
    run_ticks(s, 600);
    r->btn1 = false;
    run_move(s, vec3(0, 0, 0.060f), 600);
    run_ticks(s, 500);
    f->z_before_m = z_before_m;
    f->z_after_m = top_z_m(rep, &f->closed);
    f->ps = r->peer.stats;
    f->bs = r->rig.board.stats;
}

/* The push's figures as a person checks them: felt, dented, still closed. */
static void check_push(const seam_figures_t *f)
{
    assert_true(f->touch_pen_m > 0.0005f);   /* the stylus was in the clay's surface */
    assert_true(f->touch_n > 0.5f);          /* and the hand felt it push back */
    assert_true(f->touch_n <= 3.3f + 1e-4f); /* never past the tool's force limit */
    assert_true(f->ps.impulse_frames > 5);
    assert_int_equal(f->ps.impulses_unmapped, 0);
    assert_true(f->z_before_m - f->z_after_m > 0.002f); /* a dent of more than 2 mm, in the mesh */
    assert_true(f->closed);
}

/* The sphere as the board and the mesher see it: every node's density (x fastest). */
static float *rep_densities(const dent_sphere_t *ds)
{
    float *d = malloc((size_t)ds->dims[0] * (size_t)ds->dims[1] * (size_t)ds->dims[2] *
                      sizeof(float));
    assert_non_null(d);
    const int32_t zero[3] = {0, 0, 0};
    (void)dent_sphere_ops.window_samples(ds, zero, ds->dims, d, NULL);
    return d;
}

/* The undented 30 mm sphere on 72³ nodes 1.25 mm apart, its mesh checked closed with its top at
 * the radius; returns that top (m). */
static float sphere_make(dent_sphere_t *ds, rep_t *rep)
{
    assert_true(dent_sphere_init(ds, 72, 0.00125f, RADIUS_M, rep));
    bool closed = false;
    const float z_top_m = top_z_m(rep, &closed);
    assert_true(closed);
    assert_true(fabsf(z_top_m - RADIUS_M) < 0.5e-3f);
    return z_top_m;
}

static void test_peer_drives_a_second_representation(void **st)
{
    (void)st;
    dent_sphere_t ds;
    rep_t rep;
    const float z_before = sphere_make(&ds, &rep);

    seam_run_t s = {.r = rig_new_host(1.0f, false, &rep)};
    assert_ptr_equal(s.r->peer.grid, &ds.grid); /* the peer holds the sphere's sample grid */
    seam_figures_t f;
    run_push(&s, &rep, z_before, &f);
    printf("# seam: touch %.2f N at %.2f mm in; push: top %.2f -> %.2f mm, %u impulse frames, "
           "%u windows sent, %u swapped\n",
           f.touch_n, f.touch_pen_m * 1e3, f.z_before_m * 1e3, f.z_after_m * 1e3,
           f.ps.impulse_frames, f.ps.windows_sent, f.bs.windows_swapped);
    rig_free(s.r);
    rep.ops->free(rep.st);
    check_push(&f);
}

/* The same push with the peer's journal open (autosave 0.25 s, far shorter than the 1.1 s the
 * script ends with after the last dent, so every record is on disk), the session then cut off as
 * by a crash (journal_close: no final write), and the model recovered as argil recover does. */
static void test_journal_recovers_a_second_representation(void **st)
{
    (void)st;
    dent_sphere_t ds;
    rep_t rep;
    const float z_before = sphere_make(&ds, &rep);
    float *before = rep_densities(&ds);
    char dir[] = "/tmp/argil-seam-XXXXXX";
    assert_non_null(mkdtemp(dir));

    seam_run_t s = {.r = rig_new_host(1.0f, false, &rep), .journaling = true};
    char err[256] = "";
    if (peer_journal_open(&s.j, dir, s.r->peer.grid, 0.25f, 60.0f, err, sizeof(err)) != ARGIL_OK)
        fail_msg("journal open in %s: %s", dir, err);
    seam_figures_t f;
    run_push(&s, &rep, z_before, &f);
    const journal_stats_t js = s.j.stats;
    const size_t unwritten = s.j.buf_len;
    const uint32_t strays = s.pj.stray_records;
    float *after = rep_densities(&ds);
    journal_close(&s.j);
    rig_free(s.r);

    argil_doc_t doc;
    journal_info_t info;
    const journal_err_t re = journal_recover(dir, &doc, &info, err, sizeof(err));
    const grid_t *g = &doc.grid;
    bool same_lattice = re == JOURNAL_OK && g->spacing_m == ds.lat.spacing_m &&
                        g->origin_m.x == ds.lat.origin_m.x && g->origin_m.y == ds.lat.origin_m.y &&
                        g->origin_m.z == ds.lat.origin_m.z;
    for (int a = 0; a < 3; a++)
        same_lattice = same_lattice && g->dims[a] == ds.dims[a];
    /* The journal stores the samples' float bits and recovery replays them: no tolerance. */
    float max_diff = same_lattice ? 0.0f : INFINITY, dent = 0.0f, far_diff = max_diff;
    size_t k = 0;
    for (int32_t z = 0; z < ds.dims[2] && same_lattice; z++)
        for (int32_t y = 0; y < ds.dims[1]; y++)
            for (int32_t x = 0; x < ds.dims[0]; x++, k++) {
                const float d = grid_get(g, GRID_DENSITY, x, y, z);
                max_diff = fmaxf(max_diff, fabsf(d - after[k]));
                const int32_t n[3] = {x, y, z};
                const vec3_t p = ds_pos_m(&ds, n);
                if (p.x * p.x + p.y * p.y < 25e-6f && p.z > 0.0f)
                    dent = fmaxf(dent, before[k] - d); /* within 5 mm of the push's axis */
                else if (p.z < 0.0f)
                    far_diff = fmaxf(far_diff, fabsf(d - before[k]));
            }
    printf("# seam journal: %u records, %u syncs; recovered %u records, %llu samples; "
           "|recovered - sphere| %.3g; dent %.3f density; lower half moved %.3g\n",
           js.records, js.syncs, info.records, (unsigned long long)info.samples,
           (double)max_diff, (double)dent, (double)far_diff);
    argil_doc_free(&doc);
    free(before);
    free(after);
    const argil_err_t de = journal_discard(dir, err, sizeof(err));
    const int rm = rmdir(dir);
    rep.ops->free(rep.st);

    check_push(&f);
    assert_true(js.records > 0);
    assert_true(js.syncs > 0);
    assert_int_equal(unwritten, 0); /* nothing was left for a final write */
    assert_int_equal(strays, 0);    /* every change was inside the box the step reported */
    assert_int_equal(re, JOURNAL_OK);
    assert_true(same_lattice);
    assert_int_equal(info.records, js.records);
    assert_true(max_diff == 0.0f);
    /* The mesh's top fell by more than 2 mm; across the 5 mm half-band the density falls by
     * 0.5 per band, so the samples there fell by more than 0.5 x 2 / 5 = 0.2. */
    assert_true(dent > 0.2f);
    assert_true(far_diff == 0.0f); /* the push did not reach the lower half */
    assert_int_equal(de, ARGIL_OK);
    assert_int_equal(rm, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_peer_drives_a_second_representation),
        cmocka_unit_test(test_journal_recovers_a_second_representation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
