/* The telemetry chart (see plot.h). */
#include "host/render/plot.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const rgb8_t BG = {255, 255, 255}, INK = {30, 30, 35}, GRID = {225, 228, 232},
                    FORCE = {200, 40, 40}, HEIGHT = {30, 90, 190}, HIGH_PASS = {150, 60, 20},
                    GOAL = {0, 160, 70}, STEP = {235, 120, 0};
static const rgb8_t STATE_COLORS[TELEMETRY_STATES_MAX] = {
    {150, 150, 150}, {240, 190, 60}, {70, 170, 90}, {200, 60, 60},
    {120, 90, 200}, {60, 170, 200}, {220, 120, 180}, {110, 110, 60}};

typedef struct {
    int x0, y0, x1, y1;      /* the plot area in pixels, y0 on top */
    double t0, t1, v0, v1;   /* the data range it shows */
} panel_t;

double plot_nice_step(double span, int count)
{
    const double raw = span / (count > 0 ? count : 1);
    const double mag = pow(10.0, floor(log10(raw)));
    const double f = raw / mag;
    return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

static int px_x(const panel_t *p, double t)
{
    return p->x0 + (int)lround((t - p->t0) / (p->t1 - p->t0) * (p->x1 - p->x0));
}

static int px_y(const panel_t *p, double v)
{
    return p->y1 - (int)lround((v - p->v0) / (p->v1 - p->v0) * (p->y1 - p->y0));
}

static void format_tick(char *buf, size_t len, double v, double step)
{
    int dec = (int)ceil(-log10(step) - 1e-9);
    dec = dec < 0 ? 0 : (dec > 6 ? 6 : dec);
    if (fabs(v) < step * 1e-6)
        v = 0.0;
    snprintf(buf, len, "%.*f", dec, v);
}

/* Frame, horizontal grid with y tick labels, and the rotated axis name. */
static void draw_y_axis(canvas_t *c, const panel_t *p, const char *name, int s)
{
    /* About 4 labelled ticks, fewer when the panel is too short to keep them apart. */
    const int fit = (p->y1 - p->y0) / (3 * FONT_H * s);
    const double step = plot_nice_step(p->v1 - p->v0, fit < 1 ? 1 : (fit > 4 ? 4 : fit));
    char buf[32];
    for (double v = ceil(p->v0 / step - 1e-9) * step; v <= p->v1 + step * 1e-9; v += step) {
        const int y = px_y(p, v);
        canvas_line(c, p->x0, y, p->x1, y, 1, GRID);
        canvas_line(c, p->x0 - 4 * s, y, p->x0, y, 1, INK);
        format_tick(buf, sizeof(buf), v, step);
        canvas_text(c, p->x0 - 6 * s - canvas_text_width(buf, s), y - (FONT_H * s) / 2, buf, s,
                    INK);
    }
    const int mid = (p->y0 + p->y1) / 2 + canvas_text_width(name, s) / 2;
    canvas_text_up(c, 6 * s, mid, name, s, INK);
}

static void draw_x_axis(canvas_t *c, const panel_t *p, bool labels, int s)
{
    const double step = plot_nice_step(p->t1 - p->t0, 8);
    char buf[32];
    for (double t = ceil(p->t0 / step - 1e-9) * step; t <= p->t1 + step * 1e-9; t += step) {
        const int x = px_x(p, t);
        canvas_line(c, x, p->y0, x, p->y1, 1, GRID);
        canvas_line(c, x, p->y1, x, p->y1 + 4 * s, 1, INK);
        if (labels) {
            format_tick(buf, sizeof(buf), t, step);
            canvas_text(c, x - canvas_text_width(buf, s) / 2, p->y1 + 6 * s, buf, s, INK);
        }
    }
}

static void draw_frame(canvas_t *c, const panel_t *p)
{
    canvas_line(c, p->x0, p->y0, p->x1, p->y0, 1, INK);
    canvas_line(c, p->x0, p->y1, p->x1, p->y1, 1, INK);
    canvas_line(c, p->x0, p->y0, p->x0, p->y1, 1, INK);
    canvas_line(c, p->x1, p->y0, p->x1, p->y1, 1, INK);
}

/* The series as a min/max envelope per pixel column, joined column to column. */
static void draw_series(canvas_t *c, const panel_t *p, const telemetry_log_t *log,
                        const float *v, size_t stride, rgb8_t col, int thick)
{
    int prev_x = -1, prev_lo = 0, prev_hi = 0;
    size_t i = 0;
    while (i < log->n) {
        const int x = px_x(p, log->time_s[i]);
        float lo = v[i * stride], hi = lo;
        size_t j = i + 1;
        while (j < log->n && px_x(p, log->time_s[j]) == x) {
            lo = fminf(lo, v[j * stride]);
            hi = fmaxf(hi, v[j * stride]);
            j++;
        }
        const int ylo = px_y(p, lo), yhi = px_y(p, hi);
        if (prev_x >= 0) {
            /* Join to the previous column's nearest end so steps stay vertical. */
            const int from = (ylo > prev_hi) ? prev_hi : (yhi < prev_lo ? prev_lo : ylo);
            canvas_line(c, prev_x, from, x, from == prev_hi || from == prev_lo ? ylo : from,
                        thick, col);
        }
        canvas_line(c, x, ylo, x, yhi, thick, col);
        prev_x = x;
        prev_lo = ylo;
        prev_hi = yhi;
        i = j;
    }
}

/* The chatter panel: the high-passed force clipped to the panel's top, the goal as a line,
 * each counted step as a mark on the top edge, and the figure as the heading inside. */
static void draw_chatter(canvas_t *c, const panel_t *p, const telemetry_log_t *log,
                         const chatter_t *ch, const chatter_trace_t *tr, int s)
{
    draw_x_axis(c, p, false, s);
    draw_y_axis(c, p, "> 50 HZ (N)", s);
    float *clipped = malloc(log->n * sizeof(*clipped));
    if (clipped != NULL) {
        for (size_t i = 0; i < log->n; i++)
            clipped[i] = fminf(tr->high_pass_n[i], (float)p->v1);
        draw_series(c, p, log, clipped, 1, HIGH_PASS, 1);
        free(clipped);
    }
    const int yg = px_y(p, CHATTER_GOAL_RMS_N);
    canvas_line(c, p->x0, yg, p->x1, yg, s, GOAL);
    if (tr->step != NULL)
        for (size_t i = 0; i < log->n; i++)
            if (tr->step[i])
                canvas_fill_rect(c, px_x(p, log->time_s[i]) - s, p->y0,
                                 px_x(p, log->time_s[i]) + s, p->y0 + 5 * s, STEP);
    draw_frame(c, p);
    char head[256];
    chatter_format(ch, head, sizeof(head));
    if (canvas_text_width(head, s) > p->x1 - p->x0 - 8 * s)
        snprintf(head, sizeof(head), "%.3f N RMS, %zu STEPS (GOAL %.2f N, 0)", ch->rms_n,
                 ch->steps, CHATTER_GOAL_RMS_N);
    /* The heading in the gap above the panel; the goal's name over its line at the right. */
    canvas_text(c, p->x0, p->y0 - (FONT_H + 2) * s, head, s, chatter_goal_met(ch) ? GOAL : INK);
    const char *goal = "GOAL";
    canvas_text(c, p->x1 - canvas_text_width(goal, s) - 4 * s, yg - (FONT_H + 2) * s, goal, s,
                GOAL);
}

static void value_range(const telemetry_log_t *log, const float *v, size_t stride, double *lo,
                        double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < log->n; i++) {
        *lo = fmin(*lo, v[i * stride]);
        *hi = fmax(*hi, v[i * stride]);
    }
    const double pad = (*hi - *lo) > 1e-9 ? 0.06 * (*hi - *lo) : 1.0;
    *lo -= pad;
    *hi += pad;
}

argil_err_t plot_telemetry(const telemetry_log_t *log, canvas_t *c, const char *title,
                           const chatter_t *ch, const chatter_trace_t *tr)
{
    if (log->n == 0 || c->width < 320 || c->height < 240)
        return ARGIL_ERR_ARG;
    const int s = c->width >= 1400 ? 2 : 1;  /* font scale */
    canvas_fill_rect(c, 0, 0, c->width - 1, c->height - 1, BG);
    const int left = 70 * s, right = c->width - 20 * s;
    const int top = 30 * s, bottom = c->height - 50 * s;
    const int gap = 14 * s;
    const int h_state = 26 * s;
    const bool with_chatter = ch != NULL && tr != NULL && tr->high_pass_n != NULL;
    const int h_panels = bottom - top - h_state - (with_chatter ? 3 : 2) * gap;
    /* With the chatter panel: force and z 3/8 each, the chatter panel 1/4. */
    const int h_main = with_chatter ? h_panels * 3 / 8 : h_panels / 2;
    const int h_chatter = with_chatter ? h_panels - 2 * h_main : -gap;
    double t0 = log->time_s[0], t1 = log->time_s[log->n - 1];
    if (t1 - t0 < 1e-9)
        t1 = t0 + 1.0;

    panel_t pf = {left, top, right, top + h_main, t0, t1, 0, 0};
    double lo, hi;
    value_range(log, log->force_mag_n, 1, &lo, &hi);
    pf.v0 = fmin(0.0, lo);
    pf.v1 = hi;
    /* 0 to a little over the trace's peak, at least 3 goals and at most 10 (spikes clip). */
    panel_t ph = {left, pf.y1 + gap, right, pf.y1 + gap + h_chatter, t0, t1, 0,
                  3 * CHATTER_GOAL_RMS_N};
    for (size_t i = 0; with_chatter && i < log->n; i++)
        ph.v1 = fmax(ph.v1, fmin(1.06 * tr->high_pass_n[i], 10 * CHATTER_GOAL_RMS_N));
    panel_t pz = {left, ph.y1 + gap, right, ph.y1 + gap + h_main, t0, t1, 0, 0};
    value_range(log, log->pos_mm + 2, 3, &pz.v0, &pz.v1);
    panel_t ps = {left, pz.y1 + gap, right, pz.y1 + gap + h_state, t0, t1, 0, 1};

    if (title != NULL)
        canvas_text(c, left, 10 * s, title, s, INK);
    draw_x_axis(c, &pf, false, s);
    draw_y_axis(c, &pf, "FORCE (N)", s);
    draw_series(c, &pf, log, log->force_mag_n, 1, FORCE, s);
    draw_frame(c, &pf);
    if (with_chatter)
        draw_chatter(c, &ph, log, ch, tr, s);
    draw_x_axis(c, &pz, false, s);
    draw_y_axis(c, &pz, "TOOL Z (MM)", s);
    draw_series(c, &pz, log, log->pos_mm + 2, 3, HEIGHT, s);
    draw_frame(c, &pz);

    /* State: a coloured band, one colour per state, with a legend under the axis. */
    for (size_t i = 0; i < log->n;) {
        size_t j = i + 1;
        while (j < log->n && log->state[j] == log->state[i])
            j++;
        const int xa = px_x(&ps, log->time_s[i]);
        const int xb = j < log->n ? px_x(&ps, log->time_s[j]) : ps.x1;
        canvas_fill_rect(c, xa, ps.y0, xb, ps.y1, STATE_COLORS[log->state[i]]);
        i = j;
    }
    draw_x_axis(c, &ps, true, s);
    draw_frame(c, &ps);
    canvas_text_up(c, 6 * s, ps.y1, "STATE", s, INK);
    const char *xname = "TIME (S)";
    canvas_text(c, (left + right - canvas_text_width(xname, s)) / 2, ps.y1 + 18 * s, xname, s,
                INK);
    int lx = left;
    const int ly = ps.y1 + 30 * s;
    for (int k = 0; k < log->n_states; k++) {
        canvas_fill_rect(c, lx, ly, lx + 8 * s, ly + FONT_H * s - 1, STATE_COLORS[k]);
        lx += 11 * s;
        lx += canvas_text(c, lx, ly, log->state_name[k], s, INK) + 12 * s;
    }
    return ARGIL_OK;
}
