/* argil plot: a session's telemetry.csv as a PNG chart (force, its part above 50 Hz, tool z
 * and board state over time), or with --chatter only the chatter figure as a pass/fail line. */
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/render/chatter.h"
#include "host/render/plot.h"
#include "host/render/png_write.h"

/* The text of `argil plot --help`. */
static void usage_plot(FILE *f)
{
    fprintf(f, "usage: argil plot LOG.csv -o FILE.png [--width W] [--height H]\n"
               "       argil plot LOG.csv --chatter\n\n"
               "Draws a session's telemetry (out/telemetry.csv) as a chart: force magnitude,\n"
               "the force above 50 Hz in contact (|F - its 20 ms mean|, with the 0.05 N goal),\n"
               "tool height z and the board's state over time, with ticks and labels; prints\n"
               "the chatter figure (docs/haptics.md) and where it is worst.\n"
               "A malformed log gives one line naming the file, the line and the problem.\n\n"
               "options:\n"
               "  -o FILE.png     the image to write\n"
               "  --width W, --height H  its size in pixels (default 1200 x 700; at least\n"
               "                  320 x 240)\n"
               "  --chatter       no image: print the chatter figure's line and exit 0 when it\n"
               "                  meets the goal (RMS <= 0.05 N, no step > 0.2 N but on first\n"
               "                  contact), 1 when not, 2 for a usage error or unreadable log\n"
               "  -h, --help      this text\n");
}

/* --chatter: the figure's line on stdout; exit status 0 when it meets the goal, 1 when not. */
static argil_err_t print_chatter(telemetry_log_t *log, int *exit_status)
{
    chatter_t ch;
    const argil_err_t rc = chatter_measure(log, &ch, NULL);
    telemetry_log_free(log);
    if (rc != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory measuring the chatter\n");
        return cmd_end(exit_status, 2, rc);
    }
    char line[256];
    chatter_format(&ch, line, sizeof(line));
    printf("%s\n", line);
    return cmd_end(exit_status, chatter_goal_met(&ch) ? 0 : 1, ARGIL_OK);
}

/* The chart of log (read from csv, freed here) into png; prints the chatter figure. */
static argil_err_t draw_plot(telemetry_log_t *log, const char *csv, const char *png, int w, int h)
{
    canvas_t c;
    const rgb8_t white = {255, 255, 255};
    argil_err_t e = canvas_init(&c, w, h, white);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory for a %d x %d image\n", w, h);
        telemetry_log_free(log);
        return e;
    }
    chatter_t ch;
    chatter_trace_t tr = {calloc(log->n, sizeof(float)), calloc(log->n, 1)};
    if (tr.high_pass_n == NULL || tr.step == NULL ||
        chatter_measure(log, &ch, &tr) != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory for %zu rows\n", log->n);
        free(tr.high_pass_n);
        free(tr.step);
        canvas_free(&c);
        telemetry_log_free(log);
        return ARGIL_ERR_NOMEM;
    }
    const char *base = strrchr(csv, '/');
    char title[256];
    snprintf(title, sizeof(title), "%s: %zu rows, %.3f s", base ? base + 1 : csv, log->n,
             log->time_s[log->n - 1] - log->time_s[0]);
    char err[1024], figure[256], worst[256];
    chatter_format(&ch, figure, sizeof(figure));
    chatter_format_worst(&ch, worst, sizeof(worst));
    printf("%s\n%s\n", figure, worst);
    if ((e = plot_telemetry(log, &c, title, &ch, &tr)) != ARGIL_OK)
        fprintf(stderr, "argil plot: cannot draw %s into %d x %d\n", csv, w, h);
    else if ((e = png_write_rgb(png, w, h, c.rgb, err, sizeof(err))) != ARGIL_OK)
        fprintf(stderr, "argil plot: %s\n", err);
    free(tr.high_pass_n);
    free(tr.step);
    canvas_free(&c);
    telemetry_log_free(log);
    return e;
}

/* What argil plot's command line asks for. */
typedef struct {
    const char *csv, *png;
    int w, h;                       /* the image's size, pixels */
    bool chatter_only;
} plot_opts_t;

/* --width W, --height H. */
static cli_opt_t take_size(void *opts, int argc, char **argv, int *i)
{
    plot_opts_t *po = opts;
    const char *a = argv[*i];
    if (strcmp(a, "--width") != 0 && strcmp(a, "--height") != 0)
        return CLI_OPT_OTHER;
    const char *v = cli_value("plot", "a value", argc, argv, i);
    if (v == NULL)
        return CLI_OPT_BAD;
    char *end;
    const long n = strtol(v, &end, 10);
    if (end == v || *end != '\0' || n < (a[2] == 'w' ? 320 : 240) || n > 8192) {
        fprintf(stderr, "argil plot: %s must be a whole number %d..8192, got '%s'\n", a,
                a[2] == 'w' ? 320 : 240, v);
        return CLI_OPT_BAD;
    }
    *(a[2] == 'w' ? &po->w : &po->h) = (int)n;
    return CLI_OPT_TAKEN;
}

/* A second log on the command line. */
static void second_log(const char *first, const char *a)
{
    fprintf(stderr, "argil plot: one log at a time ('%s' and '%s')\n", first, a);
}

/* argil plot's command line (cli_parse). */
static const cli_flag_t PLOT_FLAGS[] = {{"--chatter", offsetof(plot_opts_t, chatter_only), true}};
static const cli_cmd_t PLOT_CLI = {
    .name = "plot", .usage = usage_plot, .option = take_size,
    .flags = PLOT_FLAGS, .n_flags = 1, .second_input = second_log,
    .out_needs = "a value", .out = offsetof(plot_opts_t, png),
    .inputs = true, .input = offsetof(plot_opts_t, csv), .dash_is_input = true,
};

/* argil plot LOG.csv: the chart of a session's telemetry, or with --chatter its figure. */
argil_err_t cmd_plot(int argc, char **argv, int *exit_status)
{
    plot_opts_t po = {NULL, NULL, 1200, 700, false};
    bool done;
    const argil_err_t pe = cli_parse(&PLOT_CLI, &po, argc, argv, &done, exit_status);
    if (done)
        return pe;
    if (po.csv == NULL || (po.png == NULL) == !po.chatter_only) {
        if (po.chatter_only)
            fprintf(stderr, "argil plot: --chatter writes no image (no -o)\n");
        else
            usage_plot(stderr);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    char err[1024];
    telemetry_log_t log;
    const argil_err_t e = telemetry_err_argil(telemetry_log_read(po.csv, &log, err, sizeof(err)));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil plot: %s\n", err);
        return cmd_end(exit_status, po.chatter_only ? 2 : 1, e);
    }
    if (po.chatter_only)
        return print_chatter(&log, exit_status);
    const argil_err_t de = draw_plot(&log, po.csv, po.png, po.w, po.h);
    return cmd_end(exit_status, de == ARGIL_OK ? 0 : 1, de);
}
