/* argil sculpt: a scripted (or, in the live window, mouse-driven) session on the simulated arm,
 * in lockstep; writes the result into the output directory and prints a summary. */
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/app/sculpt_window.h"
#include "host/app/session.h"
#include "host/render/colour_map.h"
#include "shared/safety_codes.h"

/* What the command line asked of a sculpting session. */
typedef struct {
    session_opts_t o;
    sculpt_window_opts_t wo;
    bool quiet;                   /* no progress line and no summary */
    bool discard_journal;
    bool headless;                /* no window even with a display */
    const char *screenshot;       /* FILE.png to render the result into afterwards, or NULL */
    char frames_dir[4096];        /* DIR/frames, for --screenshot-every */
} sculpt_args_t;

static volatile sig_atomic_t g_stop;

/* Ctrl-C ends the session early; what was sculpted so far is still written. */
static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

/* The text of `argil sculpt --help`. */
static void usage_sculpt(FILE *f)
{
    fprintf(f,
            "usage: argil sculpt [--device sim] [--script FILE] [--out DIR] [--window N]\n"
            "                    [--quiet] [--no-deadline-fault] [--screenshot FILE.png]\n"
            "\n"
            "Runs a sculpting session. With --device sim (the default) the arm, its drives and\n"
            "the hand holding the stylus are simulated in lockstep on a virtual clock, so the\n"
            "same script always gives the same files.\n"
            "\n"
            "options:\n"
            "  --device sim    the simulated arm, in lockstep (the only device here; a real\n"
            "                  board over USB or UDP: 'argil connect --device usb|udp:H:P')\n"
            "  --script FILE   the session script (default scripts/default.scn; format in\n"
            "                  docs/script.md)\n"
            "  --out DIR       where to write final.ply, model.argil (with any painted\n"
            "                  material), telemetry.csv and session.scn (default out;\n"
            "                  created if missing)\n"
            "  --window N      edge of the board's local density window in samples, 4..32\n"
            "                  (default 16)\n"
            "  --global-solve bspline|springs\n"
            "                  the host's global solve: the implicit B-spline model or the\n"
            "                  explicit density springs on the grid (default bspline;\n"
            "                  docs/model.md)\n"
            "  --rate-hz 1000|2000|4000\n"
            "                  the simulated board's loop rate (default 1000, as argil-board's\n"
            "                  [loop] rate_hz); telemetry.csv gets a row per tick\n"
            "  --knot-ratio 1|2|4\n"
            "                  B-spline: grid samples per knot span at the start (default 1,\n"
            "                  one coefficient per sample); 2 or 4 solve fewer coefficients and\n"
            "                  a script's 'refine' (or the K key) inserts knots: R halves\n"
            "  --undo-mb N     memory for undo and redo, MiB (default 256; 0: no undo): one\n"
            "                  step per stroke, the oldest dropped first (script verbs undo,\n"
            "                  redo; Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y in the window)\n"
            "  --quiet         no progress line and no summary\n"
            "  --screenshot FILE.png\n"
            "                  afterwards, render the final clay with the tool where it ended\n"
            "                  (as 'argil view DIR/final.ply --telemetry DIR/telemetry.csv')\n"
            "  --autosave-s S  journal every edit into DIR/journal.log and make it durable within\n"
            "                  S seconds (default 1; docs/files.md); a clean end removes it,\n"
            "                  after a crash 'argil recover DIR' restores the model\n"
            "  --checkpoint-s S  rotate the journal onto a new snapshot every S simulated s (60)\n"
            "  --no-journal    no autosave journal\n"
            "  --discard-journal\n"
            "                  start even though DIR holds an unfinished session's journal,\n"
            "                  deleting it\n"
            "  --no-deadline-fault\n"
            "                  count deadline misses but do not fault on a streak of them\n"
            "                  (for profiling under valgrind, where every tick overruns)\n"
            "  live window (when DISPLAY is set; docs/render.md):\n"
            "  --headless      no window even with a display (the files are the same either way)\n"
            "  --fast          run the session as fast as it can instead of in real time\n"
            "  --mouse         no script: sculpt with the mouse until the window is closed\n"
            "  --screenshot-every MS\n"
            "                  write DIR/frames/frame_<simulated ms>.png every MS simulated ms\n"
            "  --input FILE    scripted keys and mouse for the window (tests, demos)\n"
            "  --linger S      keep the window S seconds after the session ends (default 2)\n"
            "  --width W, --height H  window size in pixels (default 1024 x 768)\n"
            "  --iso2 L        show the density field's level L (0.05..0.95; the clay is 0.5)\n"
            "                  as a wireframe over the clay (keys I, [ and ] in the window)\n"
            "  --colour stiffness|mass|none\n"
            "                  colour the clay by its painted material (key M)\n"
            "  -h, --help      this text\n");
}

/* A refused undo / redo of the script, as it happens (the session goes on). */
static void print_note(void *ctx, const char *msg)
{
    (void)ctx;
    fprintf(stderr, "argil sculpt: %s\n", msg);
}
/* The options that shape the session and its files. *i moves past any value taken. */
static cli_opt_t parse_session_option(sculpt_args_t *sa, int argc, char **argv, int *i)
{
    const cli_session_t shared = {&sa->o.global_solve, NULL, &sa->o.knot_ratio, &sa->o.tick_us,
                                  &sa->o.autosave_s, &sa->o.checkpoint_s, &sa->o.undo_mb};
    const cli_opt_t r = cli_session_option("sculpt", &shared, argc, argv, i);
    if (r != CLI_OPT_OTHER || strcmp(argv[*i], "--debug-journal-dump") != 0)
        return r;
    /* Tests: --debug-journal-dump N FILE.argil writes the model as of journal record N and ends
     * the session there (tests/sys/test_crash_recovery.sh). */
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    char *end = NULL;
    const unsigned long rec = v ? strtoul(v, &end, 10) : 0;
    if (!v || *end != '\0' || rec < 1 || rec > 0xffffffffUL || *i + 2 >= argc) {
        fprintf(stderr, "argil sculpt: --debug-journal-dump needs a record number >= 1 "
                        "and a file\n");
        return CLI_OPT_BAD;
    }
    sa->o.debug_dump_record = (uint32_t)rec;
    sa->o.debug_dump_path = argv[*i + 2];
    *i += 2;
    return CLI_OPT_TAKEN;
}

/* --device (only sim) and the board's window edge --window. *i moves past the value. */
static cli_opt_t parse_valued_option(sculpt_args_t *sa, int argc, char **argv, int *i)
{
    const char *a = argv[*i];
    if (strcmp(a, "--device") != 0 && strcmp(a, "--window") != 0)
        return CLI_OPT_OTHER;
    const char *v = cli_value("sculpt", "a value", argc, argv, i);
    if (!v)
        return CLI_OPT_BAD;
    if (strcmp(a, "--device") == 0) {
        if (strcmp(v, "sim") != 0) {
            fprintf(stderr,
                    "argil sculpt: device '%s': a scripted session runs on 'sim' (the "
                    "simulated arm); for a board use 'argil connect --device %s'\n",
                    v, v);
            return CLI_OPT_BAD;
        }
    } else {
        char *end;
        const long n = strtol(v, &end, 10);
        if (*end != '\0' || n < 4 || n > 32) {
            fprintf(stderr, "argil sculpt: --window must be a whole number 4..32, got '%s'\n",
                    v);
            return CLI_OPT_BAD;
        }
        sa->o.window_edge = (int)n;
    }
    return CLI_OPT_TAKEN;
}

/* The live window's options (docs/render.md). *i moves past any value taken. */
static cli_opt_t parse_window_option(sculpt_args_t *sa, int argc, char **argv, int *i)
{
    const char *a = argv[*i];
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    sculpt_window_opts_t *wo = &sa->wo;
    if (strcmp(a, "--screenshot-every") == 0 || strcmp(a, "--linger") == 0) {
        char *end = NULL;
        const double x = v ? strtod(v, &end) : 0.0;
        const double hi = a[2] == 's' ? 3.6e6 : 3600.0;
        if (!v || *end != '\0' || !(x >= 0.0 && x <= hi)) {
            fprintf(stderr, "argil sculpt: %s needs a number 0..%g (see --help)\n", a, hi);
            return CLI_OPT_BAD;
        }
        (*i)++;
        if (a[2] == 's')
            wo->screenshot_every_s = x * 1e-3;
        else
            wo->linger_s = x;
    } else if (strcmp(a, "--width") == 0 || strcmp(a, "--height") == 0) {
        char *end = NULL;
        const long px = v ? strtol(v, &end, 10) : 0;
        if (!v || *end != '\0' || px < 64 || px > 8192) {
            fprintf(stderr, "argil sculpt: %s needs pixels 64..8192 (see --help)\n", a);
            return CLI_OPT_BAD;
        }
        (*i)++;
        *(a[2] == 'w' ? &wo->width : &wo->height) = (int)px;
    } else if (strcmp(a, "--iso2") == 0) {
        char *end = NULL;
        const double x = v ? strtod(v, &end) : 0.0;
        if (!v || *end != '\0' || !(x >= 0.05 && x <= 0.95)) {
            fprintf(stderr, "argil sculpt: --iso2 needs a density level 0.05..0.95 (the "
                            "clay's is 0.5)\n");
            return CLI_OPT_BAD;
        }
        (*i)++;
        wo->iso2 = (float)x;
    } else if (strcmp(a, "--colour") == 0) {
        colour_map_t cm;
        if (!v || !colour_map_parse(v, &cm)) {
            fprintf(stderr, "argil sculpt: --colour needs stiffness, mass or none\n");
            return CLI_OPT_BAD;
        }
        (*i)++;
        wo->colour = (int)cm;
    } else if (strcmp(a, "--input") == 0) {
        if (!v) {
            fprintf(stderr, "argil sculpt: --input needs a file (see --help)\n");
            return CLI_OPT_BAD;
        }
        wo->input_path = argv[++*i];
    } else {
        return CLI_OPT_OTHER;
    }
    return CLI_OPT_TAKEN;
}

/* The options of argil sculpt that are not flags: the session's, the valued and the window's. */
static cli_opt_t parse_sculpt_option(void *opts, int argc, char **argv, int *i)
{
    sculpt_args_t *sa = opts;
    cli_opt_t r = parse_session_option(sa, argc, argv, i);
    if (r == CLI_OPT_OTHER)
        r = parse_valued_option(sa, argc, argv, i);
    if (r == CLI_OPT_OTHER)
        r = parse_window_option(sa, argc, argv, i);
    return r;
}

/* argil sculpt's command line (cli_parse). */
static const cli_flag_t SCULPT_FLAGS[] = {
    {"--quiet", offsetof(sculpt_args_t, quiet), true},
    {"--no-deadline-fault", offsetof(sculpt_args_t, o.deadline_faults), false},
    {"--no-journal", offsetof(sculpt_args_t, o.journal), false},
    {"--discard-journal", offsetof(sculpt_args_t, discard_journal), true},
    {"--headless", offsetof(sculpt_args_t, headless), true},
    {"--fast", offsetof(sculpt_args_t, wo.fast), true},
    {"--mouse", offsetof(sculpt_args_t, wo.mouse), true},
};
static const cli_word_t SCULPT_WORDS[] = {
    {"--script", offsetof(sculpt_args_t, o.script_path)},
    {"--out", offsetof(sculpt_args_t, o.out_dir)},
    {"--screenshot", offsetof(sculpt_args_t, screenshot)},
};
static const cli_cmd_t SCULPT_CLI = {
    .name = "sculpt", .usage = usage_sculpt, .option = parse_sculpt_option,
    .flags = SCULPT_FLAGS, .n_flags = sizeof(SCULPT_FLAGS) / sizeof(SCULPT_FLAGS[0]),
    .words = SCULPT_WORDS, .n_words = sizeof(SCULPT_WORDS) / sizeof(SCULPT_WORDS[0]),
};

/* The window's options need a window: a display (DISPLAY) and no --headless. Returns false,
 * having said which option on stderr, when one is given without. */
static bool window_options_fit(const sculpt_args_t *sa, bool live)
{
    const sculpt_window_opts_t *wo = &sa->wo;
    if (live || !(wo->mouse || wo->input_path || wo->screenshot_every_s > 0.0 ||
                  wo->iso2 > 0.0f || wo->colour != 0))
        return true;
    fprintf(stderr, "argil sculpt: %s needs the window: a display (DISPLAY) and no "
                    "--headless\n",
            wo->mouse ? "--mouse" : wo->input_path ? "--input" : wo->iso2 > 0.0f ? "--iso2"
                    : wo->colour != 0 ? "--colour" : "--screenshot-every");
    return false;
}

/* Runs the session in the live window when there is one, and headless otherwise or when the
 * window cannot open (told on stderr; *window_failed set), unless it was to be sculpted with
 * the mouse: then the window's failure is the result. */
static argil_err_t run_sculpt_session(sculpt_args_t *sa, bool live, session_summary_t *s,
                                      bool *window_failed, char *err, size_t err_len)
{
    snprintf(sa->frames_dir, sizeof(sa->frames_dir), "%s/frames",
             sa->o.out_dir ? sa->o.out_dir : ".");
    sa->wo.frames_dir = sa->wo.screenshot_every_s > 0.0 ? sa->frames_dir : NULL;
    sa->wo.screenshot_path = sa->screenshot;
    sa->wo.report = !sa->quiet;
    *window_failed = false;
    argil_err_t rc = ARGIL_ERR_STATE;
    if (live) {
        /* The simulated board shares this machine's cores with the renderer (llvmpipe draws on
         * every core), which no real board does: its deadline misses are counted and shown, but
         * a streak of them must not fault the sculpture a person is watching. */
        sa->o.deadline_faults = false;
        rc = sculpt_window_run(&sa->o, &sa->wo, s, window_failed, err, err_len);
        if (*window_failed) {
            if (sa->wo.mouse)
                return rc;
            fprintf(stderr, "argil sculpt: %s; running without a window\n", err);
        } else {
            sa->screenshot = NULL; /* the window wrote it */
        }
    }
    if (!live || *window_failed)
        rc = session_run(&sa->o, s, err, err_len);
    return rc;
}

/* " 12 345 …\n": the tick numbers the summary kept of count ticks (the first ones). */
static void print_ticks(const uint32_t *kept, uint32_t count)
{
    for (uint32_t i = 0; i < count && i < SESSION_PREEMPTED_KEPT; i++)
        printf(" %u", kept[i]);
    printf("%s\n", count > SESSION_PREEMPTED_KEPT ? " …" : "");
}

/* The summary's lines on time: ticks, their compute time, the board's RT reports, the solve. */
static void print_timing(const sculpt_args_t *sa, const session_summary_t *s)
{
    const session_opts_t *o = &sa->o;
    const sculpt_window_opts_t *wo = &sa->wo;
    printf("argil: session %s on the simulated arm%s\n",
           wo->mouse ? "sculpted with the mouse" : o->script_path,
           s->interrupted ? " (interrupted: files hold the clay as it was then)" : "");
    printf("  simulated time      %.3f s (%u board ticks at %u Hz)\n", s->sim_seconds,
           s->board_ticks, s->tick_hz);
    printf("  worst tick compute  %.1f us of a %u us period, deadline misses %u\n",
           s->worst_compute_ns / 1000.0, 1000000u / s->tick_hz, s->deadline_misses);
    if (s->deadline_misses > 0) {
        /* The session is deterministic: real work past the period misses at the same tick
         * again when the same script runs again; a machine that held the vCPU does not
         * (docs/board.md, "Timing a simulated tick"). */
        printf("  deadline missed     at ticks");
        print_ticks(s->deadline_miss_tick, s->deadline_misses);
    }
    printf("  tick compute        median %u us, 99th percentile %u us (thread CPU time); "
           "%u ticks preempted by the machine, not timed\n",
           s->median_compute_ns / 1000u, s->p99_compute_ns / 1000u, s->preempted_ticks);
    if (s->preempted_over_period > 0) {
        /* Not misses, but not hidden: a real overrun is past the period again at the same
         * tick when the same script runs again (docs/board.md, "Timing a simulated tick"). */
        printf("  preempted, charged  %u past the period, at ticks", s->preempted_over_period);
        print_ticks(s->preempted_over_tick, s->preempted_over_period);
    }
    if (s->rt_stats_frames > 0)
        printf("  board RT stats      %u reports, last over %u ticks: wake-up latency "
               "min/mean/max %.1f/%.1f/%.1f us, compute %.1f/%.1f/%.1f us, %u overruns "
               "(worst streak %u)\n",
               s->rt_stats_frames, s->rt.ticks, s->rt.wake_min_ns / 1000.0,
               s->rt.wake_mean_ns / 1000.0, s->rt.wake_max_ns / 1000.0,
               s->rt.compute_min_ns / 1000.0, s->rt.compute_mean_ns / 1000.0,
               s->rt.compute_max_ns / 1000.0, s->rt.overruns, s->rt.worst_streak);
    printf("  global solve        %s, %u steps, CPU time per step median %.2f ms, 99th "
           "percentile %.2f ms, max %.2f ms; session wall time %.2f s\n",
           cli_global_solve_text(o->global_solve),
           s->solves, s->solve_median_ms, s->solve_p99_ms, s->solve_max_ms, s->real_seconds);
}

/* The summary's lines on the result: knots, undo, force, clay, mesh, link, board, files, memory
 * and the journal. */
static void print_result(const sculpt_args_t *sa, const session_summary_t *s)
{
    const session_opts_t *o = &sa->o;
    const sculpt_window_opts_t *wo = &sa->wo;
    const double vb = s->volume_before_m3 * 1e6, va = s->volume_after_m3 * 1e6;
    if (o->global_solve == PEER_SOLVE_BSPLINE)
        printf("  knots               %d sample%s per knot span at the start, %d at the end; "
               "%u refinement%s (largest density change %.2g)\n",
               o->knot_ratio, o->knot_ratio == 1 ? "" : "s", s->knot_ratio_end, s->refines,
               s->refines == 1 ? "" : "s", (double)s->refine_max_dd);
    if (s->undo_on)
        printf("  undo                %u stroke%s recorded (%u undone, %u redone, %u refused), "
               "%.1f KiB held of %u MiB (largest %.1f KiB), shadow %.1f MiB, slowest "
               "boundary %.1f ms\n",
               s->undo_steps, s->undo_steps == 1 ? "" : "s", s->undos, s->redos, s->undo_refused,
               (double)s->undo_bytes / 1024.0, o->undo_mb,
               (double)s->undo_max_step_bytes / 1024.0,
               (double)s->undo_shadow_bytes / (1024.0 * 1024.0), s->undo_max_work_ms);
    else
        printf("  undo                %s\n", s->undo_note);
    printf("  peak force          %.3f N (limit %.2f N)\n", (double)s->peak_force_n,
           (double)s->force_limit_n);
    printf("  delivered force     %.3f N at most (the simulated arm's motor torques through "
           "its Jacobian)\n", (double)s->peak_delivered_force_n);
    printf("  clay volume         %.3f cm3 -> %.3f cm3 (%+.2f %%)\n", vb, va,
           vb > 0 ? (va - vb) / vb * 100.0 : 0.0);
    printf("  mesh                %zu triangles, %zu vertices, %s\n", s->triangles, s->vertices,
           s->watertight ? "watertight" : "NOT watertight");
    printf("  link                %u windows sent, %u impulse frames, %u refused frames\n",
           s->windows_sent, s->impulse_frames, s->link_errors);
    printf("  board state         %s%s%s\n", safety_state_name((safety_state_t)s->final_state),
           s->fault_code ? ", last fault: " : "",
           s->fault_code ? safety_fault_name((fault_code_t)s->fault_code) : "");
    if (o->out_dir)
        printf("  files               %s/final.ply, %s/telemetry.csv (%u rows)%s%s%s\n",
               o->out_dir, o->out_dir, s->telemetry_rows, wo->mouse ? "" : ", ",
               wo->mouse ? "" : o->out_dir, wo->mouse ? "" : "/session.scn");
    printf("  grid memory         %.1f KiB sparse at the start, %.1f KiB at the end (a dense "
           "grid of its %dx%dx%d bounds: %.1f KiB)\n", (double)s->grid_bytes_start / 1024.0,
           (double)s->grid_bytes_end / 1024.0, s->grid_hi[0] - s->grid_lo[0],
           s->grid_hi[1] - s->grid_lo[1], s->grid_hi[2] - s->grid_lo[2],
           (double)s->grid_dense_bytes_end / 1024.0);
    if (s->journal_records > 0)
        printf("  autosave journal    %u edits journaled, %.1f KiB, %u fsyncs, %u checkpoints, "
               "%.1f ms of work (%.1f ms CPU), %.1f KiB of memory at most; removed at this "
               "clean end\n",
               s->journal_records, (double)s->journal_bytes / 1024.0, s->journal_syncs,
               s->journal_checkpoints, s->journal_real_s * 1e3, s->journal_cpu_s * 1e3,
               (double)s->journal_peak_bytes / 1024.0);
    if (s->journal_stray_records > 0)
        printf("  journal WARNING     %u edits found outside the solver's dirty box (a bug in "
               "an edit path; journaled anyway)\n",
               s->journal_stray_records);
}

/* With --screenshot, renders the final clay with the tool where it ended (as `argil view`
 * would); the render's error (said on stderr). */
static argil_err_t render_screenshot(const sculpt_args_t *sa, const session_summary_t *s)
{
    if (sa->screenshot == NULL || sa->o.out_dir == NULL || s->triangles == 0)
        return ARGIL_OK;
    char ply[4096], csv[4096];
    snprintf(ply, sizeof(ply), "%s/final.ply", sa->o.out_dir);
    snprintf(csv, sizeof(csv), "%s/telemetry.csv", sa->o.out_dir);
    char *view_argv[] = {ply, "--screenshot", (char *)sa->screenshot, "--telemetry", csv};
    int view_status;
    return cmd_view(5, view_argv, &view_status);
}

/* argil sculpt: a session on the simulated arm, its files written into --out. */
argil_err_t cmd_sculpt(int argc, char **argv, int *exit_status)
{
    sculpt_args_t sa;
    memset(&sa, 0, sizeof(sa));
    session_opts_default(&sa.o);
    sculpt_window_opts_default(&sa.wo);
    bool done, go_on = true;
    const argil_err_t pe = cli_parse(&SCULPT_CLI, &sa, argc, argv, &done, exit_status);
    if (done)
        return pe;
    if (sa.o.journal) {
        const argil_err_t oe = recover_offer(sa.o.out_dir, sa.discard_journal,
                                             isatty(STDIN_FILENO) != 0, &go_on, exit_status);
        if (!go_on)
            return oe;
    }
    sa.o.progress = !sa.quiet && isatty(STDERR_FILENO);
    sa.o.stop = &g_stop;
    sa.o.on_note = print_note;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    /* The live window when there is a display (headless otherwise: the same files). */
    const char *display = getenv("DISPLAY");
    const bool live = !sa.headless && display != NULL && display[0] != '\0';
    if (!window_options_fit(&sa, live))
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    session_summary_t s;
    char err[1024] = "";
    bool window_failed = false;
    const argil_err_t rc = run_sculpt_session(&sa, live, &s, &window_failed, err, sizeof(err));
    if (window_failed && sa.wo.mouse) {
        fprintf(stderr, "argil sculpt: %s\n", err);
        return cmd_end(exit_status, 1, rc);
    }
    if (!sa.quiet && s.board_ticks > 0) {
        print_timing(&sa, &s);
        print_result(&sa, &s);
    }
    if (rc != ARGIL_OK) {
        fprintf(stderr, "argil sculpt: %s\n", err);
        return cmd_end(exit_status, 1, rc);
    }
    const argil_err_t shot = render_screenshot(&sa, &s);
    if (shot != ARGIL_OK)
        return cmd_end(exit_status, 1, shot);
    return cmd_end(exit_status, s.interrupted ? 130 : 0, ARGIL_OK);
}
