/* argil plot: a session's telemetry.csv as a PNG chart (force, tool z and board state over
 * time). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/commands.h"
#include "host/render/plot.h"
#include "host/render/png_write.h"

static void usage_plot(FILE *f)
{
    fprintf(f, "usage: argil plot LOG.csv -o FILE.png [--width W] [--height H]\n\n"
               "Draws a session's telemetry (out/telemetry.csv) as a chart: force magnitude,\n"
               "tool height z and the board's state over time, with ticks and labels.\n"
               "A malformed log gives one line naming the file, the line and the problem.\n\n"
               "options:\n"
               "  -o FILE.png     the image to write\n"
               "  --width W, --height H  its size in pixels (default 1200 x 700; at least\n"
               "                  320 x 240)\n"
               "  -h, --help      this text\n");
}

int cmd_plot(int argc, char **argv)
{
    const char *csv = NULL, *png = NULL;
    int w = 1200, h = 700;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage_plot(stdout);
            return 0;
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
    if (csv == NULL || png == NULL) {
        usage_plot(stderr);
        return 2;
    }
    char err[1024];
    telemetry_log_t log;
    if (telemetry_log_read(csv, &log, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "argil plot: %s\n", err);
        return 1;
    }
    canvas_t c;
    const rgb8_t white = {255, 255, 255};
    if (canvas_init(&c, w, h, white) != ARGIL_OK) {
        fprintf(stderr, "argil plot: out of memory for a %d x %d image\n", w, h);
        telemetry_log_free(&log);
        return 1;
    }
    const char *base = strrchr(csv, '/');
    char title[256];
    snprintf(title, sizeof(title), "%s: %zu rows, %.3f s", base ? base + 1 : csv, log.n,
             log.time_s[log.n - 1] - log.time_s[0]);
    int status = 0;
    if (plot_telemetry(&log, &c, title) != ARGIL_OK) {
        fprintf(stderr, "argil plot: cannot draw %s into %d x %d\n", csv, w, h);
        status = 1;
    } else if (png_write_rgb(png, w, h, c.rgb, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "argil plot: %s\n", err);
        status = 1;
    }
    canvas_free(&c);
    telemetry_log_free(&log);
    return status;
}
