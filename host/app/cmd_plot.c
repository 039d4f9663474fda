/* argil plot: a session's telemetry.csv as a PNG chart (force, its part above 50 Hz, tool z
 * and board state over time), or with --chatter only the chatter figure as a pass/fail line. */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/commands.h"
#include "host/render/chatter.h"
#include "host/render/plot.h"
#include "host/render/png_write.h"

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

/* --chatter: the figure's line on stdout; 0 when it meets the goal, 1 when not. */
static int print_chatter(telemetry_log_t *log)
{
    chatter_t ch;
    const argil_err_t rc = chatter_measure(log, &ch, NULL);
    telemetry_log_free(log);
    if (rc != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory measuring the chatter\n");
        return 2;
    }
    char line[256];
    chatter_format(&ch, line, sizeof(line));
    printf("%s\n", line);
    return chatter_goal_met(&ch) ? 0 : 1;
}

/* The chart of log (read from csv, freed here) into png; prints the chatter figure. */
static int draw_plot(telemetry_log_t *log, const char *csv, const char *png, int w, int h)
{
    canvas_t c;
    const rgb8_t white = {255, 255, 255};
    if (canvas_init(&c, w, h, white) != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory for a %d x %d image\n", w, h);
        telemetry_log_free(log);
        return 1;
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
        return 1;
    }
    const char *base = strrchr(csv, '/');
    char title[256];
    snprintf(title, sizeof(title), "%s: %zu rows, %.3f s", base ? base + 1 : csv, log->n,
             log->time_s[log->n - 1] - log->time_s[0]);
    int status = 0;
    char err[1024], figure[256], worst[256];
    chatter_format(&ch, figure, sizeof(figure));
    chatter_format_worst(&ch, worst, sizeof(worst));
    printf("%s\n%s\n", figure, worst);
    if (plot_telemetry(log, &c, title, &ch, &tr) != ARGIL_OK) {
        fprintf(stderr, "argil plot: cannot draw %s into %d x %d\n", csv, w, h);
        status = 1;
    } else if (png_write_rgb(png, w, h, c.rgb, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "argil plot: %s\n", err);
        status = 1;
    }
    free(tr.high_pass_n);
    free(tr.step);
    canvas_free(&c);
    telemetry_log_free(log);
    return status;
}

int cmd_plot(int argc, char **argv)
{
    const char *csv = NULL, *png = NULL;
    int w = 1200, h = 700;
    bool chatter_only = false;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage_plot(stdout);
            return 0;
        } else if (strcmp(a, "--chatter") == 0) {
            chatter_only = true;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--width") == 0 ||
                   strcmp(a, "--height") == 0) {
            if (i + 1 >= argc) {
                fprintf(stderr, "argil plot: %s needs a value (see --help)\n", a);
                return 2;
            }
            const char *v = argv[++i];
            if (strcmp(a, "-o") == 0) {
                png = v;
                continue;
            }
            char *end;
            const long n = strtol(v, &end, 10);
            if (end == v || *end != '\0' || n < (a[2] == 'w' ? 320 : 240) || n > 8192) {
                fprintf(stderr, "argil plot: %s must be a whole number %d..8192, got '%s'\n", a,
                        a[2] == 'w' ? 320 : 240, v);
                return 2;
            }
            *(a[2] == 'w' ? &w : &h) = (int)n;
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "argil plot: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (csv == NULL) {
            csv = a;
        } else {
            fprintf(stderr, "argil plot: one log at a time ('%s' and '%s')\n", csv, a);
            return 2;
        }
    }
    if (csv == NULL || (png == NULL) == !chatter_only) {
        if (chatter_only)
            fprintf(stderr, "argil plot: --chatter writes no image (no -o)\n");
        else
            usage_plot(stderr);
        return 2;
    }
    char err[1024];
    telemetry_log_t log;
    if (telemetry_log_read(csv, &log, err, sizeof(err)) != TELEMETRY_OK) {
        fprintf(stderr, "argil plot: %s\n", err);
        return chatter_only ? 2 : 1;
    }
    if (chatter_only)
        return print_chatter(&log);
    return draw_plot(&log, csv, png, w, h);
}
