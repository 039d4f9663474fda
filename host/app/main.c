/* argil: the desktop program. Today: `argil sculpt` runs a scripted session on the simulated
 * arm and writes the result. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/commands.h"
#include "host/app/session.h"

static volatile sig_atomic_t g_stop;

/* Ctrl-C ends the session early; what was sculpted so far is still written. */
static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

/* Every subcommand: one line here and one declaration in commands.h. */
static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} COMMANDS[] = {
    {"sculpt", cmd_sculpt, "run a sculpting session (see 'argil sculpt --help')"},
    {"fit", cmd_fit, "fit a point cloud, mesh or volume into a model (see 'argil fit --help')"},
    {"mesh", cmd_mesh, "write a model's surface as PLY, STL or OBJ (see 'argil mesh --help')"},
    {"info", cmd_info, "describe a model, mesh, point cloud or volume file"},
    {"plot", cmd_plot, "draw a session's telemetry.csv as a PNG chart (see 'argil plot --help')"},
    {"view", cmd_view, "render a mesh to a PNG or show it in a window (see 'argil view --help')"},
};

static void usage_main(FILE *f)
{
    fprintf(f, "usage: argil COMMAND [OPTIONS]\n\n"
               "argil is a haptic virtual-clay sculpting system.\n\n"
               "commands:\n");
    for (size_t i = 0; i < sizeof(COMMANDS) / sizeof(COMMANDS[0]); i++)
        fprintf(f, "  %-9s %s\n", COMMANDS[i].name, COMMANDS[i].summary);
    fprintf(f, "  %-9s %s\n", "help", "show this text");
}

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
            "  --device sim    the device to sculpt with (sim: the simulated arm; USB and UDP\n"
            "                  boards come with the host-application work)\n"
            "  --script FILE   the session script (default scripts/default.scn; format in\n"
            "                  docs/script.md)\n"
            "  --out DIR       where to write final.ply, telemetry.csv and session.scn\n"
            "                  (default out; created if missing)\n"
            "  --window N      edge of the board's local density window in samples, 4..32\n"
            "                  (default 16)\n"
            "  --quiet         no progress line and no summary\n"
            "  --screenshot FILE.png\n"
            "                  afterwards, render the final clay with the tool where it ended\n"
            "                  (as 'argil view DIR/final.ply --telemetry DIR/telemetry.csv')\n"
            "  --no-deadline-fault\n"
            "                  count deadline misses but do not fault on a streak of them\n"
            "                  (for profiling under valgrind, where every tick overruns)\n"
            "  -h, --help      this text\n");
}

int cmd_sculpt(int argc, char **argv)
{
    session_opts_t o;
    session_opts_default(&o);
    int quiet = 0;
    const char *screenshot = NULL;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage_sculpt(stdout);
            return 0;
        } else if (strcmp(a, "--quiet") == 0) {
            quiet = 1;
        } else if (strcmp(a, "--no-deadline-fault") == 0) {
            o.deadline_faults = false;
        } else if (strcmp(a, "--device") == 0 || strcmp(a, "--script") == 0 ||
                   strcmp(a, "--out") == 0 || strcmp(a, "--window") == 0 ||
                   strcmp(a, "--screenshot") == 0) {
            if (!v) {
                fprintf(stderr, "argil sculpt: %s needs a value (see --help)\n", a);
                return 2;
            }
            i++;
            if (strcmp(a, "--device") == 0) {
                if (strcmp(v, "sim") != 0) {
                    fprintf(stderr,
                            "argil sculpt: device '%s' is not available in this build; only "
                            "'sim' (the simulated arm) is\n",
                            v);
                    return 2;
                }
            } else if (strcmp(a, "--script") == 0) {
                o.script_path = v;
            } else if (strcmp(a, "--out") == 0) {
                o.out_dir = v;
            } else if (strcmp(a, "--screenshot") == 0) {
                screenshot = v;
            } else {
                char *end;
                const long n = strtol(v, &end, 10);
                if (*end != '\0' || n < 4 || n > 32) {
                    fprintf(stderr, "argil sculpt: --window must be a whole number 4..32, got '%s'\n",
                            v);
                    return 2;
                }
                o.window_edge = (int)n;
            }
        } else {
            fprintf(stderr, "argil sculpt: unknown option '%s' (see --help)\n", a);
            return 2;
        }
    }
    o.progress = !quiet && isatty(STDERR_FILENO);
    o.stop = &g_stop;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    session_summary_t s;
    char err[1024] = "";
    const argil_err_t rc = session_run(&o, &s, err, sizeof(err));
    if (!quiet && s.board_ticks > 0) {
        const double vb = s.volume_before_m3 * 1e6, va = s.volume_after_m3 * 1e6;
        printf("argil: session %s on the simulated arm%s\n", o.script_path,
               s.interrupted ? " (interrupted: files hold the clay as it was then)" : "");
        printf("  simulated time      %.3f s (%u board ticks at %u Hz)\n", s.sim_seconds,
               s.board_ticks, s.tick_hz);
        printf("  worst tick compute  %.1f us of a %u us period, deadline misses %u\n",
               s.worst_compute_ns / 1000.0, 1000000u / s.tick_hz, s.deadline_misses);
        printf("  tick compute        median %u us, 99th percentile %u us (thread CPU time)\n",
               s.median_compute_ns / 1000u, s.p99_compute_ns / 1000u);
        printf("  peak force          %.3f N (limit %.2f N)\n", (double)s.peak_force_n,
               (double)s.force_limit_n);
        printf("  clay volume         %.3f cm3 -> %.3f cm3 (%+.2f %%)\n", vb, va,
               vb > 0 ? (va - vb) / vb * 100.0 : 0.0);
        printf("  mesh                %zu triangles, %zu vertices, %s\n", s.triangles, s.vertices,
               s.watertight ? "watertight" : "NOT watertight");
        printf("  link                %u windows sent, %u impulse frames, %u refused frames\n",
               s.windows_sent, s.impulse_frames, s.link_errors);
        printf("  board state         %s%s%s\n", safety_state_name((safety_state_t)s.final_state),
               s.fault_code ? ", last fault: " : "",
               s.fault_code ? safety_fault_name((fault_code_t)s.fault_code) : "");
        if (o.out_dir)
            printf("  files               %s/final.ply, %s/telemetry.csv (%u rows), "
                   "%s/session.scn\n",
                   o.out_dir, o.out_dir, s.telemetry_rows, o.out_dir);
    }
    if (rc != ARGIL_OK) {
        fprintf(stderr, "argil sculpt: %s\n", err);
        return 1;
    }
    if (screenshot != NULL && o.out_dir != NULL && s.triangles > 0) {
        char ply[4096], csv[4096];
        snprintf(ply, sizeof(ply), "%s/final.ply", o.out_dir);
        snprintf(csv, sizeof(csv), "%s/telemetry.csv", o.out_dir);
        char *view_argv[] = {ply, "--screenshot", (char *)screenshot, "--telemetry", csv};
        if (cmd_view(5, view_argv) != 0)
            return 1;
    }
    return s.interrupted ? 130 : 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage_main(stderr);
        return 2;
    }
    for (size_t i = 0; i < sizeof(COMMANDS) / sizeof(COMMANDS[0]); i++)
        if (strcmp(argv[1], COMMANDS[i].name) == 0)
            return COMMANDS[i].run(argc - 2, argv + 2);
    if (strcmp(argv[1], "help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "--help") == 0) {
        usage_main(stdout);
        return 0;
    }
    fprintf(stderr, "argil: unknown command '%s' (see 'argil --help')\n", argv[1]);
    return 2;
}
