/* Lockstep session: script → virtual hand → simulated arm ⇄ board core ⇄ host field. */
#define _POSIX_C_SOURCE 200809L
#include "session.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "host/solve/histogram.h"
#include "host/app/peer.h"
#include "host/app/peer_journal.h"
#include "host/app/script.h"
#include "host/app/session_files.h"
#include "host/app/session_undo.h"
#include "host/io/journal.h"
#include "host/mesh/mc.h"
#include "host/mesh/mesh_check.h"
#include "host/mesh/grid_mesh.h"
#include "host/model/grid.h"
#include "sim/rig/rig.h"

#define SESSION_CLAY_RADIUS_M 0.030f
#define SESSION_GRID_EDGE 88
#define SESSION_SPACING_M 0.00125f
#define SESSION_COMPACT_SOLVES 100u /* grid_compact every this many solves (1 s) */
#define SESSION_TAIL_S 0.3f            /* simulated time after the script, to let the clay settle */
#define SESSION_START_Z_M 0.060f       /* the workspace centre sits 60 mm in front of the clay */
#define COMPUTE_HIST_BINS 2001u        /* 0 … 2000 µs; the last bin holds everything slower */

void session_opts_default(session_opts_t *o)
{
    o->script_path = "scripts/default.scn";
    o->out_dir = "out";
    o->window_edge = 16;
    o->tick_us = 1000u;
    o->global_solve = PEER_SOLVE_BSPLINE;
    o->knot_ratio = 1;
    o->progress = false;
    o->settle_s = 2.0f;
    o->deadline_faults = true;
    o->stop = NULL;
    o->hook = NULL;
    o->journal = true;
    o->autosave_s = 1.0f;
    o->checkpoint_s = 60.0f;
    o->debug_dump_record = 0;
    o->debug_dump_path = NULL;
    o->undo_mb = SESSION_UNDO_MB_DEFAULT;
    o->on_note = NULL;
    o->note_ctx = NULL;
}

/* Everything a session owns; large, so it lives on the heap. */
typedef struct {
    sim_rig_t rig;                     /* the simulated arm and the board, in lockstep */
    grid_t grid;
    peer_t peer;
    script_t script;
    script_player_t player;
    FILE *csv;                         /* telemetry, written to csv_tmp until the end */
    char csv_tmp[4096];
    char csv_path[4096];
    uint32_t csv_rows;
    uint8_t rx[SIM_RIG_LINK_BYTES];
    vec3_t model_offset_m;             /* model = device + offset (scale 1) */
    uint32_t compute_hist_us[COMPUTE_HIST_BINS]; /* tick compute times, 1 µs bins */
    session_undo_t undo;               /* undo / redo of strokes (B-spline model) */
    uint32_t undo_solves;              /* peer solves seen by the undo */
    bool undo_script_queued;           /* the player's undo / redo is queued */
    journal_t journal;                 /* autosave journal (when journaling) */
    bool journaling;
    peer_journal_t journal_steps;      /* what the journal has looked at, and its costs */
    uint32_t compact_solves;           /* peer solves at the last grid_compact */
    uint8_t *final_rgb;                /* painted colour over the final grid's bounds, or NULL */
    bool paint_chosen;                 /* a paint action ran or a colour was picked */
    uint8_t paint_rgb[3];              /* the paint colour chosen last (model.argil TOOL) */
    float soft_paint_per_s;            /* the soft-paint rate chosen last (model.argil PNTS) */
    mesh_t mesh;                       /* the clay's surface: at the start, then at the end */
} session_t;

/* The lockstep loop's clock, and how far the session has come in it. */
typedef struct {
    uint32_t dt_us;                    /* the board's tick */
    float dt_s;
    double total_s;                    /* settle + script + tail: the progress line's end */
    bool hold_open;                    /* the hook keeps the session running after the script */
    uint64_t max_ticks;
    uint64_t tick;                     /* the tick running, or the ticks run once the loop ends */
    bool started;                      /* the board became ACTIVE: the script plays */
    bool finished;                     /* every script command has finished … */
    double finished_at_s;              /* … at this simulated time */
} lockstep_t;

static bool link_send(void *ctx, const uint8_t *frame, size_t len)
{
    session_t *s = ctx;
    return sim_rig_host_send(&s->rig, frame, len) == ARGIL_OK;
}

static void on_telemetry(void *ctx, const msg_telemetry_t *t)
{
    session_t *s = ctx;
    if (!s->csv)
        return;
    const double fn = sqrt((double)t->force_n[0] * t->force_n[0] +
                           (double)t->force_n[1] * t->force_n[1] +
                           (double)t->force_n[2] * t->force_n[2]);
    fprintf(s->csv, "%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%s,%u,%u,%u,%u\n",
            (double)t->time_us * 1e-6, (double)t->pos_m[0] * 1e3, (double)t->pos_m[1] * 1e3,
            (double)t->pos_m[2] * 1e3, (double)t->force_n[0], (double)t->force_n[1],
            (double)t->force_n[2], fn, safety_state_name((safety_state_t)t->state),
            t->tool_kind, t->buttons, t->flags & 1u, (t->flags >> 1) & 1u);
    s->csv_rows++;
}

static void tool_from_player(const session_t *s, msg_tool_t *tool)
{
    const script_player_t *p = &s->player;
    memset(tool, 0, sizeof(*tool));
    tool->kind = (uint8_t)p->tool;
    tool->shape = (uint8_t)p->shape;
    tool->filter = (uint8_t)p->filter;
    tool->flags = TOOL_FLAG_ISO;
    tool->radius_m = p->params[PARAM_RADIUS_MM] * 1e-3f;
    tool->length_m = p->params[PARAM_LENGTH_MM] * 1e-3f;
    tool->axis[0] = p->axis.x;
    tool->axis[1] = p->axis.y;
    tool->axis[2] = p->axis.z;
    tool->alpha = p->params[PARAM_ALPHA];
    tool->contact_stiffness_n_per_m = p->params[PARAM_STIFFNESS_N_PER_MM] * 1e3f;
    tool->max_force_n = p->params[PARAM_MAX_FORCE_N];
    tool->iso = p->params[PARAM_ISO];
    tool->yield_force_n = p->params[PARAM_YIELD_FORCE_N];
    tool->friction = p->params[PARAM_FRICTION];
    tool->probe_gain = p->params[PARAM_PROBE_GAIN];
    tool->rope_stiffness_n_per_m = p->params[PARAM_ROPE_STIFFNESS_N_PER_MM] * 1e3f;
    tool->model_scale = 1.0f;
    tool->model_offset_m[0] = s->model_offset_m.x;
    tool->model_offset_m[1] = s->model_offset_m.y;
    tool->model_offset_m[2] = s->model_offset_m.z;
}

/* Meshes the whole field and returns its volume; fills the mesh for the caller. With rgb (the
 * painted colour over the grid's bounds) the vertices take it as `argil mesh` colours them. */
static argil_err_t mesh_field(const grid_t *g, const uint8_t *rgb, mesh_t *m, double *volume_m3)
{
    mesh_free(m);
    mesh_init(m);
    const argil_err_t e =
        rgb != NULL ? grid_mesh_region(g, rgb, g->iso, m) : grid_mesh_extract(g, g->iso, m);
    if (e == ARGIL_OK)
        *volume_m3 = mesh_volume_m3(m);
    return e;
}

/* The paint settings model.argil keeps: a paint action's colour (and soft paint's rate), or a
 * colour picked (in the window) while another action is on; a script's other actions leave
 * them be. */
static void track_paint(session_t *s, const host_tool_t *t)
{
    const bool picked =
        t->rgb[0] != HOST_PAINT_R || t->rgb[1] != HOST_PAINT_G || t->rgb[2] != HOST_PAINT_B;
    if (!host_action_paints(t->action) && !picked)
        return;
    s->paint_chosen = true;
    memcpy(s->paint_rgb, t->rgb, 3);
    if (t->action == HOST_ACT_SOFT_PAINT)
        s->soft_paint_per_s = t->strength;
}

static int make_dir(const char *path)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST)
        return 0;
    return -1;
}

/* Copies a file atomically (temp file + rename). */
static argil_err_t copy_file(const char *from, const char *to, char *err, size_t err_len)
{
    char tmp[4096];
    snprintf(tmp, sizeof(tmp), "%s.tmp", to);
    FILE *in = fopen(from, "rb");
    if (!in) {
        snprintf(err, err_len, "%s: cannot open: %s", from, strerror(errno));
        return ARGIL_ERR_IO;
    }
    FILE *out = fopen(tmp, "wb");
    if (!out) {
        snprintf(err, err_len, "%s: cannot create: %s", tmp, strerror(errno));
        fclose(in);
        return ARGIL_ERR_IO;
    }
    char buf[65536];
    size_t n;
    int bad = 0;
    while ((n = fread(buf, 1, sizeof(buf), in)) > 0)
        if (fwrite(buf, 1, n, out) != n)
            bad = 1;
    bad |= ferror(in);
    fclose(in);
    if (fflush(out) != 0 || fsync(fileno(out)) != 0)
        bad = 1;
    if (fclose(out) != 0)
        bad = 1;
    if (bad || rename(tmp, to) != 0) {
        snprintf(err, err_len, "%s: cannot write: %s", to, strerror(errno));
        unlink(tmp);
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}

static void progress(const session_opts_t *o, double t_s, double total_s)
{
    if (!o->progress)
        return;
    const double frac = total_s > 0 ? t_s / total_s : 1.0;
    const int bar = (int)(frac * 30.0);
    fprintf(stderr, "\r  [%-30.*s] %5.1f %%  %.1f / %.1f s simulated", bar,
            "##############################", frac * 100.0, t_s, total_s);
    fflush(stderr);
}

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Undo and redo requests (the script's, the live window's keys), after the peer's tick: done
 * right after a solve step, so the journal's record of that step holds the change. A script's
 * request releases its player once done or refused; a refusal is told through on_note. */
static void undo_requests(session_t *s, const session_opts_t *opts)
{
    script_player_t *pl = &s->player;
    if (pl->history_op && !s->undo_script_queued)
        s->undo_script_queued = session_undo_request(
            &s->undo, pl->history_op == SCRIPT_UNDO ? SESSION_UNDO_OP_UNDO : SESSION_UNDO_OP_REDO,
            pl->history_line);
    const bool solved = s->peer.stats.solves != s->undo_solves;
    s->undo_solves = s->peer.stats.solves;
    for (;;) {
        int line = 0;
        char msg[160];
        const session_undo_result_t r = session_undo_process(&s->undo, &s->peer,
                                                             (pl->buttons & 1) != 0, solved,
                                                             &line, msg, sizeof(msg));
        if (r == SESSION_UNDO_NONE || r == SESSION_UNDO_WAIT)
            break;
        if (line > 0 && line == pl->history_line) {
            pl->history_op = 0;
            s->undo_script_queued = false;
        }
        if (r == SESSION_UNDO_REFUSED && opts->on_note) {
            char full[4352];
            if (line > 0)
                snprintf(full, sizeof(full), "%s: line %d: %s",
                         opts->script_path ? opts->script_path : "script", line, msg);
            else
                snprintf(full, sizeof(full), "%s", msg);
            opts->on_note(opts->note_ctx, full);
        }
    }
    if (pl->history_op && !s->undo_script_queued) {
        /* The queue is full (keys pressed many times): refuse the script's line, go on. */
        if (opts->on_note) {
            char full[4352];
            snprintf(full, sizeof(full), "%s: line %d: %s refused: too many requests waiting",
                     opts->script_path ? opts->script_path : "script", pl->history_line,
                     pl->history_op == SCRIPT_UNDO ? "undo" : "redo");
            opts->on_note(opts->note_ctx, full);
        }
        s->undo.stats.refused++;
        pl->history_op = 0;
    }
}

/* Loads the script, refusing (with its line) a verb the chosen model cannot play. */
static argil_err_t load_script(session_t *s, const session_opts_t *opts, char *err,
                               size_t err_len)
{
    if (!opts->script_path)
        return ARGIL_OK;
    const argil_err_t rc =
        script_err_argil(script_load(&s->script, opts->script_path, err, err_len));
    if (rc != ARGIL_OK)
        return rc;
    /* Script lines only the B-spline model can carry out, with why the springs cannot. */
    static const struct {
        int (*first_line)(const script_t *s);
        const char *what;
        const char *why;
    } needs_bspline[] = {
        {script_first_paint_line, "'paint' needs", "the springs' material is uniform"},
        {script_first_history_line, "'undo' and 'redo' need", "the springs keep no history"},
        {script_first_host_tool_line, "host tool settings need", "the springs only carve"},
    };
    for (size_t i = 0; i < sizeof(needs_bspline) / sizeof(needs_bspline[0]); i++) {
        const int line = needs_bspline[i].first_line(&s->script);
        if (line > 0 && opts->global_solve != PEER_SOLVE_BSPLINE) {
            snprintf(err, err_len, "%s: line %d: %s the B-spline model "
                     "(--global-solve bspline); %s",
                     opts->script_path, line, needs_bspline[i].what, needs_bspline[i].why);
            return ARGIL_ERR_ARG;
        }
    }
    /* Each refine halves R: R = 2 allows one, R = 4 two; with springs there are no knots. */
    const int allowed = opts->global_solve != PEER_SOLVE_BSPLINE ? 0
                        : opts->knot_ratio == 4                  ? 2
                        : opts->knot_ratio == 2                  ? 1
                                                                 : 0;
    const int refine_line = script_refine_line(&s->script, allowed + 1);
    if (refine_line > 0) {
        if (opts->global_solve != PEER_SOLVE_BSPLINE)
            snprintf(err, err_len, "%s: line %d: 'refine' needs the B-spline model "
                     "(--global-solve bspline); the springs have no knots",
                     opts->script_path, refine_line);
        else
            snprintf(err, err_len, "%s: line %d: 'refine': already at one coefficient per "
                     "sample (--knot-ratio %d allows %d refine%s)", opts->script_path,
                     refine_line, opts->knot_ratio, allowed, allowed == 1 ? "" : "s");
        return ARGIL_ERR_ARG;
    }
    return ARGIL_OK;
}

/* The simulated device and the board; tick_us receives the board's period. */
static argil_err_t open_rig(session_t *s, const session_opts_t *opts, uint32_t *tick_us,
                            char *err, size_t err_len)
{
    sim_rig_cfg_t rcfg;
    sim_rig_cfg_default(&rcfg);
    if (opts->tick_us)
        rcfg.board.tick_us = opts->tick_us;
    if (!opts->deadline_faults)
        rcfg.board.safety.overrun_streak = 0;
    if (sim_rig_init(&s->rig, &rcfg) != ARGIL_OK) {
        snprintf(err, err_len, "board configuration refused");
        return ARGIL_ERR_ARG;
    }
    *tick_us = rcfg.board.tick_us;
    return ARGIL_OK;
}

/* The host's clay (a sphere at the model origin), its global solve, its first surface and the
 * undo history; then the hand, at the workspace centre in front of the clay. */
static argil_err_t make_clay(session_t *s, const session_opts_t *opts, session_summary_t *sum,
                             char *err, size_t err_len)
{
    const int32_t dims[3] = {SESSION_GRID_EDGE, SESSION_GRID_EDGE, SESSION_GRID_EDGE};
    const float half = 0.5f * (float)(SESSION_GRID_EDGE - 1) * SESSION_SPACING_M;
    argil_err_t rc = grid_init(&s->grid, dims, SESSION_SPACING_M, vec3(-half, -half, -half));
    if (rc != ARGIL_OK) {
        snprintf(err, err_len, "cannot allocate the density grid");
        return rc;
    }
    grid_fill_sphere(&s->grid, vec3(0, 0, 0), SESSION_CLAY_RADIUS_M);
    sum->grid_bytes_start = grid_bytes(&s->grid);

    peer_cfg_t pcfg;
    peer_cfg_default(&pcfg);
    pcfg.window_edge = opts->window_edge;
    pcfg.global_solve = opts->global_solve;
    pcfg.knot_ratio = opts->knot_ratio;
    if (opts->window_edge < 4 || opts->window_edge > ARGIL_WINDOW_MAX) {
        snprintf(err, err_len, "window edge %d refused (4 … %d)", opts->window_edge,
                 ARGIL_WINDOW_MAX);
        return ARGIL_ERR_ARG;
    }
    if (opts->knot_ratio != 1 && opts->knot_ratio != 2 && opts->knot_ratio != 4) {
        snprintf(err, err_len, "knot ratio %d refused (1, 2 or 4 samples per knot span)",
                 opts->knot_ratio);
        return ARGIL_ERR_ARG;
    }
    /* With the B-spline solve the grid becomes the model's view here (seeded from it). */
    rc = peer_init(&s->peer, &pcfg, &s->grid, link_send, on_telemetry, s);
    if (rc != ARGIL_OK) {
        snprintf(err, err_len, "cannot set up the global solve: %s",
                 rc == ARGIL_ERR_NOMEM ? "out of memory" : "the model refused the grid");
        return rc;
    }
    rc = mesh_field(&s->grid, NULL, &s->mesh, &sum->volume_before_m3);
    if (rc != ARGIL_OK) {
        snprintf(err, err_len, "meshing the initial clay failed");
        return rc;
    }
    /* Undo: off with the springs (their grid keeps no history) or --undo-mb 0, said in the
     * summary; out of memory leaves it off too, and the session goes on. */
    (void)session_undo_init(&s->undo, s->peer.gs ? &s->peer.gs->field : NULL,
                            (size_t)opts->undo_mb << 20);

    const vec3_t centre = sim_rig_tip_m(&s->rig);
    s->model_offset_m = vec3_sub(vec3(0, 0, SESSION_START_Z_M), centre);
    script_player_init(&s->player, &s->script, vec3(0, 0, SESSION_START_Z_M));
    return ARGIL_OK;
}

/* With an output directory: creates it, starts telemetry.csv (as a temporary file) and, when
 * journaling, the autosave journal. */
static argil_err_t open_outputs(session_t *s, const session_opts_t *opts, char *err,
                                size_t err_len)
{
    if (!opts->out_dir)
        return ARGIL_OK;
    if (make_dir(opts->out_dir) != 0) {
        snprintf(err, err_len, "%s: cannot create directory: %s", opts->out_dir,
                 strerror(errno));
        return ARGIL_ERR_IO;
    }
    snprintf(s->csv_path, sizeof(s->csv_path), "%s/telemetry.csv", opts->out_dir);
    snprintf(s->csv_tmp, sizeof(s->csv_tmp), "%s/telemetry.csv.tmp", opts->out_dir);
    s->csv = fopen(s->csv_tmp, "wb");
    if (!s->csv) {
        snprintf(err, err_len, "%s: cannot create: %s", s->csv_tmp, strerror(errno));
        return ARGIL_ERR_IO;
    }
    fprintf(s->csv, "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state,tool,buttons,"
                    "contact,sculpting\n");

    if (opts->journal) {
        const argil_err_t rc = peer_journal_open(&s->journal, opts->out_dir, &s->grid,
                                                 opts->autosave_s, opts->checkpoint_s, err,
                                                 err_len);
        if (rc != ARGIL_OK)
            return rc;
        s->journaling = true;
        s->journal_steps.dump_record = opts->debug_dump_record;
        s->journal_steps.dump_path = opts->debug_dump_path;
    }
    return ARGIL_OK;
}

/* Everything before the first tick: the script, the rig, the clay, the output files and the
 * loop's clock (tick_us from the board). */
static argil_err_t session_setup(session_t *s, const session_opts_t *opts,
                                 session_summary_t *sum, lockstep_t *lp, char *err,
                                 size_t err_len)
{
    uint32_t tick_us = 0;
    argil_err_t rc = load_script(s, opts, err, err_len);
    if (rc == ARGIL_OK)
        rc = open_rig(s, opts, &tick_us, err, err_len);
    if (rc == ARGIL_OK)
        rc = make_clay(s, opts, sum, err, err_len);
    if (rc == ARGIL_OK)
        rc = open_outputs(s, opts, err, err_len);
    if (rc != ARGIL_OK)
        return rc;

    memset(lp, 0, sizeof(*lp));
    lp->dt_us = tick_us;
    lp->dt_s = (float)lp->dt_us * 1e-6f;
    const double script_s = script_duration_s(&s->script);
    lp->total_s = opts->settle_s + script_s + SESSION_TAIL_S;
    lp->hold_open = opts->hook && opts->hook->hold_open;
    lp->max_ticks = lp->hold_open ? UINT64_MAX : (uint64_t)(lp->total_s / lp->dt_s) + 1u;
    return ARGIL_OK;
}

/* Starts the script once the board is ACTIVE and plays it on; ARGIL_ERR_STATE when the board
 * has not become ACTIVE within the settle time. */
static argil_err_t advance_script(session_t *s, const session_opts_t *opts, lockstep_t *lp,
                                  double t_s, char *err, size_t err_len)
{
    if (!lp->started && s->peer.have_tm && s->peer.last_tm.state == SAFETY_ACTIVE)
        lp->started = true;
    if (!lp->started && t_s > opts->settle_s) {
        snprintf(err, err_len, "the board did not become ACTIVE within %.1f s (state %s)",
                 (double)opts->settle_s,
                 s->peer.have_tm ? safety_state_name((safety_state_t)s->peer.last_tm.state)
                                 : "no telemetry");
        return ARGIL_ERR_STATE;
    }
    if (lp->started && !lp->finished && script_player_step(&s->player, lp->dt_s)) {
        lp->finished = true;
        lp->finished_at_s = t_s;
    }
    return ARGIL_OK;
}

/* The script's material paints of this tick, each a stroke of its own, at the stylus tip. */
static argil_err_t play_paints(session_t *s, char *err, size_t err_len)
{
    for (int k = 0; k < s->player.paints_pending; k++) {
        const script_paint_t *pt = &s->player.paints[k];
        session_undo_peer_edit_start(&s->undo, &s->peer); /* a paint is a stroke of its own */
        /* At the stylus tip the board reports (the hand's target before any telemetry). */
        const vec3_t at = s->peer.have_tm ? vec3(s->peer.last_tm.pos_m[0],
                                                 s->peer.last_tm.pos_m[1],
                                                 s->peer.last_tm.pos_m[2])
                                          : pt->pos_m;
        const argil_err_t pe = peer_paint_material(
            &s->peer, pt->channel == SCRIPT_PAINT_MASS ? PEER_MAT_MASS : PEER_MAT_STIFFNESS,
            at, pt->radius_m, pt->scale);
        if (pe != ARGIL_OK) {
            snprintf(err, err_len, "painting %s at %.1f %.1f %.1f mm failed (error %d)",
                     pt->channel == SCRIPT_PAINT_MASS ? "mass" : "stiffness",
                     (double)at.x * 1e3, (double)at.y * 1e3, (double)at.z * 1e3, (int)pe);
            return pe;
        }
    }
    return ARGIL_OK;
}

/* The script's knot refinements of this tick. */
static argil_err_t play_refines(session_t *s, char *err, size_t err_len)
{
    for (int k = 0; k < s->player.refines_pending; k++) {
        float dd = 0.0f;
        const int32_t r0 = peer_knot_ratio(&s->peer);
        /* The open stroke becomes a step first: undo then says the history is cut. */
        session_undo_peer_edit_start(&s->undo, &s->peer);
        const argil_err_t re = peer_refine(&s->peer, &dd);
        if (re != ARGIL_OK) {
            snprintf(err, err_len, "refine at R = %d failed: %s", (int)r0,
                     re == ARGIL_ERR_STATE ? "already at one coefficient per sample"
                     : re == ARGIL_ERR_NOMEM ? "out of memory"
                                             : "the model refused it");
            return re;
        }
    }
    return ARGIL_OK;
}

/* The script's new tool and clay settings, sent to the board and the host's field. */
static void apply_params(session_t *s)
{
    if (!s->player.params_changed)
        return;
    msg_tool_t tool;
    tool_from_player(s, &tool);
    peer_set_tool(&s->peer, &tool);
    /* Refused only with the springs solve (the live window keeps its own in step). */
    (void)peer_set_host_tool(&s->peer, &s->player.host_tool);
    track_paint(s, &s->player.host_tool);
    s->grid.material.stiffness = s->player.params[PARAM_CLAY_STIFFNESS];
    s->grid.material.damping = s->player.params[PARAM_CLAY_DAMPING];
    s->grid.material.plastic_rate_hz = s->player.params[PARAM_PLASTIC_RATE_HZ];
    s->player.params_changed = 0;
}

/* The hand, the arm and its drives, the board's tick, then the host's: the peer, undo and
 * the grid's compaction. */
static void step_rig_and_host(session_t *s, const session_opts_t *opts, uint32_t dt_us)
{
    const vec3_t target_dev = vec3_sub(s->player.pos_m, s->model_offset_m);
    sim_rig_set_hand(&s->rig, target_dev, s->player.vel_m_s, (s->player.buttons & 1) != 0,
                     (s->player.buttons & 2) != 0);

    const uint32_t compute_us = sim_rig_step_ns(&s->rig, dt_us) / 1000u;
    if (!s->rig.io.prev_compute_preempted) /* an untimed tick's figure is not its own */
        s->compute_hist_us[compute_us < COMPUTE_HIST_BINS ? compute_us : COMPUTE_HIST_BINS - 1u]++;
    const size_t n = sim_rig_host_receive(&s->rig, s->rx, sizeof(s->rx));
    peer_receive(&s->peer, s->rx, n);
    session_undo_observe(&s->undo, &s->peer, dt_us); /* a new stroke; its diff a slice a tick */
    peer_tick(&s->peer, dt_us);
    undo_requests(s, opts);
    if (s->peer.stats.solves != s->compact_solves &&
        s->peer.stats.solves % SESSION_COMPACT_SOLVES == 0) {
        /* Blocks that came to rest uniform (carved empty, filled solid) give memory back. */
        s->compact_solves = s->peer.stats.solves;
        grid_compact(&s->grid);
    }
}

/* One lockstep tick: the script, then the rig and the host, then the journal and the hook.
 * *end is set when the session ends here without an error (the tail after the script has
 * passed, a stop was asked for, the journal's dump record was written). */
static argil_err_t lockstep_tick(session_t *s, const session_opts_t *opts, lockstep_t *lp,
                                 session_summary_t *sum, bool *end, char *err, size_t err_len)
{
    const double t_s = (double)lp->tick * lp->dt_s;
    argil_err_t rc = advance_script(s, opts, lp, t_s, err, err_len);
    if (rc != ARGIL_OK)
        return rc;
    rc = play_paints(s, err, err_len);
    s->player.paints_pending = 0;
    if (rc == ARGIL_OK)
        rc = play_refines(s, err, err_len);
    s->player.refines_pending = 0;
    if (rc != ARGIL_OK)
        return rc;
    if (lp->finished && t_s - lp->finished_at_s >= SESSION_TAIL_S && !lp->hold_open) {
        *end = true;
        return ARGIL_OK;
    }
    if (opts->stop && *opts->stop) {
        sum->interrupted = true;
        *end = true;
        return ARGIL_OK;
    }
    if (lp->started && s->peer.have_tm &&
        (s->peer.last_tm.state == SAFETY_FAULT || s->peer.last_tm.state == SAFETY_ESTOP)) {
        snprintf(err, err_len, "the board stopped in %s at %.3f s: %s",
                 safety_state_name((safety_state_t)s->peer.last_tm.state), t_s,
                 safety_fault_name((fault_code_t)s->peer.stats.last_fault_code));
        return ARGIL_ERR_STATE;
    }
    apply_params(s);
    step_rig_and_host(s, opts, lp->dt_us);
    if (s->journaling) {
        rc = peer_journal_step(&s->journal, &s->journal_steps, &s->peer,
                               (double)(lp->tick + 1u) * lp->dt_s, end, err, err_len);
        if (rc != ARGIL_OK || *end)
            return rc;
    }
    if (opts->hook) {
        session_frame_t f = {(double)(lp->tick + 1u) * lp->dt_s, lp->started, lp->finished,
                             &s->peer, &s->player, s->model_offset_m, &s->undo};
        opts->hook->on_tick(opts->hook->ctx, &f);
    }
    if (lp->tick % 1000u == 0)
        progress(opts, t_s, lp->total_s);
    return ARGIL_OK;
}

/* Arms the board, says HELLO and runs ticks until the session ends; lp->tick then counts the
 * ticks run, and sum the loop's wall time. */
static argil_err_t lockstep_run(session_t *s, const session_opts_t *opts, lockstep_t *lp,
                                session_summary_t *sum, char *err, size_t err_len)
{
    argil_err_t rc = ARGIL_OK;
    peer_request_arm(&s->peer);
    (void)peer_send_hello(&s->peer, "argil sculpt"); /* the board serves a host that says HELLO */
    const double loop_real0_s = clock_s(CLOCK_MONOTONIC);
    for (lp->tick = 0; lp->tick < lp->max_ticks; lp->tick++) {
        bool end = false;
        rc = lockstep_tick(s, opts, lp, sum, &end, err, err_len);
        if (rc != ARGIL_OK || end)
            break;
    }
    sum->real_seconds = clock_s(CLOCK_MONOTONIC) - loop_real0_s;
    const double sim_s = (double)lp->tick * lp->dt_s;
    progress(opts, sim_s, sim_s);
    if (opts->progress)
        fputc('\n', stderr);
    return rc;
}

/* The board's, the link's, the solve's and undo's figures for the summary. */
static void summarise_run(const session_t *s, const lockstep_t *lp, session_summary_t *sum)
{
    sim_rig_board_stats_t board;
    sim_rig_board_stats(&s->rig, &board);
    sum->sim_seconds = (double)lp->tick * lp->dt_s;
    sum->board_ticks = board.ticks;
    sum->tick_hz = 1000000u / lp->dt_us;
    sum->worst_compute_ns = board.worst_compute_ns;
    sum->deadline_misses = board.deadline_misses;
    sum->preempted_ticks = board.preempted_ticks;
    sum->preempted_over_period = board.preempted_over_period;
    for (uint32_t i = 0; i < SESSION_PREEMPTED_KEPT && i < BOARD_PREEMPTED_KEPT; i++) {
        sum->preempted_over_tick[i] = board.preempted_over_tick[i];
        sum->deadline_miss_tick[i] = board.deadline_miss_tick[i];
    }
    sum->rt_stats_frames = s->peer.stats.rt_stats_frames;
    sum->rt = s->peer.last_rt;
    sum->median_compute_ns = hist_quantile_bin(s->compute_hist_us, COMPUTE_HIST_BINS, 0.5) * 1000u;
    sum->p99_compute_ns = hist_quantile_bin(s->compute_hist_us, COMPUTE_HIST_BINS, 0.99) * 1000u;
    sum->peak_force_n = board.peak_force_n;
    sum->peak_delivered_force_n = board.peak_delivered_force_n;
    sum->force_limit_n = board.max_force_n;
    sum->final_state = board.state;
    sum->fault_code = board.fault;
    sum->windows_sent = s->peer.stats.windows_sent;
    sum->impulse_frames = s->peer.stats.impulse_frames;
    sum->link_errors = s->peer.stats.decode_errors + board.link_errors;
    sum->telemetry_rows = s->csv_rows;
    sum->solves = s->peer.stats.solves;
    sum->solve_errors = s->peer.stats.solve_errors;
    sum->refines = s->peer.stats.refines;
    sum->undo_on = s->undo.on;
    sum->undo_steps = s->undo.stats.steps;
    sum->undos = s->undo.stats.undos;
    sum->redos = s->undo.stats.redos;
    sum->undo_refused = s->undo.stats.refused;
    sum->undo_bytes = session_undo_bytes(&s->undo);
    sum->undo_max_step_bytes = s->undo.stats.max_step_bytes;
    sum->undo_shadow_bytes = session_undo_shadow_bytes(&s->undo);
    sum->undo_max_work_ms = s->undo.stats.max_work_ms;
    snprintf(sum->undo_note, sizeof(sum->undo_note), "%s",
             s->undo.on ? s->undo.note : s->undo.off_reason);
    sum->refine_max_dd = s->peer.stats.refine_max_dd;
    sum->knot_ratio_end = peer_knot_ratio(&s->peer);
    peer_solve_times_ms(&s->peer, &sum->solve_median_ms, &sum->solve_p99_ms, &sum->solve_max_ms);
}

/* Compacts the final grid and meshes it, with its painted colour (over the grid's bounds, as
 * the GRID box; none when nothing shows paint), kept for model.argil's COLR. Returns rc, or
 * when rc is ARGIL_OK the meshing's error. */
static argil_err_t mesh_final(session_t *s, session_summary_t *sum, argil_err_t rc, char *err,
                              size_t err_len)
{
    grid_compact(&s->grid);
    sum->grid_bytes_end = grid_bytes(&s->grid);
    grid_bounds(&s->grid, sum->grid_lo, sum->grid_hi);
    sum->grid_dense_bytes_end = grid_count(&s->grid) * GRID_CH_N * sizeof(float);
    int32_t rlo[3], rn[3];
    const bool painted = grid_rgb_painted(&s->grid);
    s->final_rgb = painted ? grid_dense_copy_rgb(&s->grid, rlo, rn) : NULL;
    const argil_err_t me = painted && s->final_rgb == NULL
                               ? ARGIL_ERR_NOMEM
                               : mesh_field(&s->grid, s->final_rgb, &s->mesh,
                                            &sum->volume_after_m3);
    if (me != ARGIL_OK && rc == ARGIL_OK) {
        snprintf(err, err_len, "meshing the final clay failed");
        rc = me;
    }
    size_t boundary = 0, nonmanifold = 0;
    sum->watertight = me == ARGIL_OK && mesh_watertight(&s->mesh, &boundary, &nonmanifold);
    sum->triangles = s->mesh.n_tri;
    sum->vertices = s->mesh.n_vert;
    return rc;
}

/* Writes telemetry.csv, session.scn, final.ply and model.argil into out_dir, whatever happened
 * (each file appears whole, by rename). Returns rc, or when rc is ARGIL_OK the first write's
 * error. */
static argil_err_t write_outputs(session_t *s, const session_opts_t *opts, argil_err_t rc,
                                 char *err, size_t err_len)
{
    if (!opts->out_dir)
        return rc;
    char ferr[512], path[4096];
    int bad = 0;
    if (s->csv) {
        bad |= fflush(s->csv) != 0 || fsync(fileno(s->csv)) != 0;
        bad |= fclose(s->csv) != 0;
        s->csv = NULL;
        if (bad || rename(s->csv_tmp, s->csv_path) != 0) {
            if (rc == ARGIL_OK)
                snprintf(err, err_len, "%s: cannot write: %s", s->csv_path, strerror(errno));
            rc = rc == ARGIL_OK ? ARGIL_ERR_IO : rc;
        }
    }
    snprintf(path, sizeof(path), "%s/session.scn", opts->out_dir);
    if (opts->script_path &&
        copy_file(opts->script_path, path, ferr, sizeof(ferr)) != ARGIL_OK && rc == ARGIL_OK) {
        snprintf(err, err_len, "%s", ferr);
        rc = ARGIL_ERR_IO;
    }
    /* The model: densities, material and the painted channels (docs/files.md). */
    argil_doc_t doc;
    argil_doc_init(&doc);
    doc.grid = s->grid; /* borrowed: the document is not freed */
    doc.rgb = s->final_rgb; /* borrowed, as the final mesh's colours */
    if (s->paint_chosen) { /* the paint settings; an unpainted session's file as before */
        doc.tool.paint_chosen = true;
        memcpy(doc.tool.paint_rgb, s->paint_rgb, 3);
        doc.tool.soft_paint_per_s = s->soft_paint_per_s;
    }
    doc.state.device_offset_m = s->model_offset_m;
    doc.state.edits = s->journaling ? s->journal.seq : 0u;
    char model_path[4096];
    snprintf(path, sizeof(path), "%s/final.ply", opts->out_dir);
    snprintf(model_path, sizeof(model_path), "%s/model.argil", opts->out_dir);
    if (doc.rgb == NULL && grid_rgb_painted(&s->grid)) {
        if (rc == ARGIL_OK) {
            snprintf(err, err_len, "%s: out of memory for the painted colour", model_path);
            rc = ARGIL_ERR_NOMEM;
        }
    } else if (session_files_write(path, &s->mesh, model_path, &doc, ferr, sizeof(ferr)) !=
                   ARGIL_OK &&
               rc == ARGIL_OK) {
        snprintf(err, err_len, "%s", ferr);
        rc = ARGIL_ERR_IO;
    }
    return rc;
}

/* The journal's figures for the summary; after a clean end (the outputs are whole) or a board
 * stop the journal is no longer needed and is removed. Returns rc, or when rc is ARGIL_OK the
 * removal's error. */
static argil_err_t finish_journal(session_t *s, session_summary_t *sum, argil_err_t rc,
                                  char *err, size_t err_len)
{
    if (!s->journaling)
        return rc;
    sum->journal_records = s->journal.stats.records;
    sum->journal_syncs = s->journal.stats.syncs;
    sum->journal_checkpoints = s->journal.stats.checkpoints;
    sum->journal_bytes = s->journal.stats.bytes;
    sum->journal_stray_records = s->journal_steps.stray_records;
    sum->journal_real_s = s->journal_steps.real_s;
    sum->journal_cpu_s = s->journal_steps.cpu_s;
    sum->journal_peak_bytes = s->journal_steps.peak_bytes;
    if (rc == ARGIL_OK || rc == ARGIL_ERR_STATE) {
        char jerr[512];
        if (journal_finish(&s->journal, jerr, sizeof(jerr)) != ARGIL_OK && rc == ARGIL_OK) {
            snprintf(err, err_len, "%s", jerr);
            rc = ARGIL_ERR_IO;
        }
    }
    return rc;
}

/* Closes what is still open (an unfinished telemetry file is deleted) and frees the session. */
static void session_free(session_t *s)
{
    if (s->journaling)
        journal_close(&s->journal);
    if (s->csv) {
        fclose(s->csv);
        unlink(s->csv_tmp);
    }
    mesh_free(&s->mesh);
    free(s->final_rgb);
    session_undo_free(&s->undo);
    peer_free(&s->peer);
    grid_free(&s->grid);
    script_free(&s->script);
    free(s);
}

argil_err_t session_run(const session_opts_t *opts, session_summary_t *sum, char *err,
                        size_t err_len)
{
    memset(sum, 0, sizeof(*sum));
    session_t *s = calloc(1, sizeof(*s));
    if (!s) {
        snprintf(err, err_len, "out of memory for the session");
        return ARGIL_ERR_NOMEM;
    }
    /* Touch every page now, as the board daemon does with mlockall: no page faults inside
     * ticks (explicit_bzero, because a plain memset after calloc may be optimised away). */
    explicit_bzero(s, sizeof(*s));
    s->soft_paint_per_s = host_action_default_strength(HOST_ACT_SOFT_PAINT);
    mesh_init(&s->mesh);
    script_init(&s->script);

    lockstep_t lp;
    argil_err_t rc = session_setup(s, opts, sum, &lp, err, err_len);
    if (rc != ARGIL_OK) {
        session_free(s);
        return rc;
    }
    rc = lockstep_run(s, opts, &lp, sum, err, err_len);
    summarise_run(s, &lp, sum);
    if (rc == ARGIL_OK && s->peer.stats.solve_errors > 0) {
        snprintf(err, err_len, "the global solve failed %u times (last error %d); the model "
                 "kept its last good state", s->peer.stats.solve_errors,
                 (int)s->peer.stats.last_solve_error);
        rc = ARGIL_ERR_STATE;
    }
    rc = mesh_final(s, sum, rc, err, err_len);
    rc = write_outputs(s, opts, rc, err, err_len);
    rc = finish_journal(s, sum, rc, err, err_len);
    session_free(s);
    return rc;
}
