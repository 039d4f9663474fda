/* The chatter figure (see chatter.h). */
#include "host/render/chatter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* span_s / the mean row interval, 1 to log->n rows. */
static size_t rows_for(const telemetry_log_t *log, double span_s)
{
    const double dur = log->time_s[log->n - 1] - log->time_s[0];
    if (log->n < 2 || !(dur > 0.0))
        return 1;
    const double rows = span_s / (dur / (double)(log->n - 1));
    if (!(rows < (double)log->n))
        return log->n; /* also a duration too short to divide by */
    return rows < 1.5 ? 1 : (size_t)lround(rows);
}

static double norm3(const float *v)
{
    return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
}

/* The worst stretch of `span` rows that is at least half in contact: RMS over its contact
 * ticks, from the per-row squared high-pass e2 (0 off contact) and the contact marks. */
static void worst_stretch(const telemetry_log_t *log, const double *e2, const uint8_t *in,
                          size_t span, chatter_t *out)
{
    double sum = 0.0;
    size_t n_in = 0;
    for (size_t i = 0; i < log->n; i++) {
        sum += e2[i];
        n_in += in[i];
        if (i >= span) {
            sum -= e2[i - span];
            n_in -= in[i - span];
        }
        const size_t rows = i + 1 < span ? i + 1 : span;
        if (i + 1 < span && i + 1 < log->n)
            continue; /* not a whole stretch yet */
        if (2 * n_in < rows || n_in == 0)
            continue;
        const double rms = sqrt(fmax(sum, 0.0) / (double)n_in);
        if (rms > out->stretch_rms_n) {
            out->stretch_rms_n = rms;
            out->stretch_t0_s = log->time_s[i + 1 - rows];
        }
    }
}

argil_err_t chatter_measure(const telemetry_log_t *log, chatter_t *out,
                            const chatter_trace_t *trace)
{
    memset(out, 0, sizeof(*out));
    if (log == NULL || log->n == 0)
        return ARGIL_ERR_ARG;
    const size_t w = rows_for(log, CHATTER_WINDOW_S);
    out->rows_per_window = w;
    double run[3] = {0.0, 0.0, 0.0}, sum_sq = 0.0;
    /* Per-row squared high-pass and contact marks, for the worst stretch. */
    double *e2 = calloc(log->n, sizeof(*e2));
    uint8_t *in = calloc(log->n, 1);
    if (e2 == NULL || in == NULL) {
        free(e2);
        free(in);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < log->n; i++) {
        const float *f = log->force_n + 3 * i;
        for (int k = 0; k < 3; k++) {
            run[k] += f[k];
            if (i >= w)
                run[k] -= log->force_n[3 * (i - w) + (size_t)k];
        }
        const double rows = (double)(i + 1 < w ? i + 1 : w);
        double d2 = 0.0;
        for (int k = 0; k < 3; k++) {
            const double d = f[k] - run[k] / rows;
            d2 += d * d;
        }
        const bool touching = norm3(f) >= CHATTER_CONTACT_N;
        if (touching) {
            out->contact_ticks++;
            sum_sq += d2;
            e2[i] = d2;
            in[i] = 1;
        }
        if (trace != NULL && trace->high_pass_n != NULL)
            trace->high_pass_n[i] = touching ? (float)sqrt(d2) : 0.0f;
        if (trace != NULL && trace->step != NULL)
            trace->step[i] = 0;
        if (i == 0)
            continue;
        const float *p = log->force_n + 3 * (i - 1);
        const float dv[3] = {f[0] - p[0], f[1] - p[1], f[2] - p[2]};
        const double step = norm3(dv);
        if (step <= CHATTER_STEP_N)
            continue;
        if (log->contact != NULL && log->contact[i] == 1 && log->contact[i - 1] == 0) {
            out->first_contact_steps++;
            continue;
        }
        out->steps++;
        if (trace != NULL && trace->step != NULL)
            trace->step[i] = 1;
        if (step > out->worst_step_n) {
            out->worst_step_n = step;
            out->worst_step_time_s = log->time_s[i];
        }
    }
    if (out->contact_ticks > 0)
        out->rms_n = sqrt(sum_sq / (double)out->contact_ticks);
    worst_stretch(log, e2, in, rows_for(log, CHATTER_STRETCH_S), out);
    free(e2);
    free(in);
    return ARGIL_OK;
}

bool chatter_goal_met(const chatter_t *c)
{
    return c->rms_n <= CHATTER_GOAL_RMS_N && c->steps == 0;
}

int chatter_format_worst(const chatter_t *c, char *buf, size_t len)
{
    if (c->steps == 0)
        return snprintf(buf, len, "worst %.2f s in contact: %.3f N RMS from %.3f s; no step",
                        CHATTER_STRETCH_S, c->stretch_rms_n, c->stretch_t0_s);
    return snprintf(buf, len,
                    "worst %.2f s in contact: %.3f N RMS from %.3f s; worst step %.3f N at %.3f s",
                    CHATTER_STRETCH_S, c->stretch_rms_n, c->stretch_t0_s, c->worst_step_n,
                    c->worst_step_time_s);
}

int chatter_format(const chatter_t *c, char *buf, size_t len)
{
    return snprintf(buf, len,
                    "force above 50 Hz: %.3f N RMS over %zu ticks in contact, %zu steps > %.1f N "
                    "(+%zu on first contact; goal %.2f N, 0)",
                    c->rms_n, c->contact_ticks, c->steps, CHATTER_STEP_N,
                    c->first_contact_steps, CHATTER_GOAL_RMS_N);
}
