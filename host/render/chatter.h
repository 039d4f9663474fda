/* The chatter figure of a session's telemetry (docs/haptics.md, "Contact without buzz"): how
 * much of the force the hand feels lies above ~50 Hz while in contact, and how often the force
 * steps from one tick to the next. Read by `argil plot` for its panel and for --chatter. */
#ifndef ARGIL_CHATTER_H
#define ARGIL_CHATTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/render/telemetry_log.h"
#include "shared/argil_err.h"

#define CHATTER_WINDOW_S 0.020     /* the moving average's span, at any loop rate */
#define CHATTER_CONTACT_N 0.05     /* a tick is in contact when |F| reaches this */
#define CHATTER_STEP_N 0.2         /* a tick-to-tick change of F above this is a step */
#define CHATTER_GOAL_RMS_N 0.05    /* the goal: RMS at most this, and no step */
#define CHATTER_STRETCH_S 0.25     /* the span of the worst stretch reported */

typedef struct {
    size_t rows_per_window;        /* CHATTER_WINDOW_S in rows, from the log's mean tick */
    size_t contact_ticks;          /* rows with |F| >= CHATTER_CONTACT_N */
    double rms_n;                  /* of F minus its moving average, over the contact ticks */
    size_t steps;                  /* |F(t) - F(t-1)| > CHATTER_STEP_N, not on first contact */
    size_t first_contact_steps;    /* the same at a row where the contact flag rises */
    double worst_step_n;           /* the largest counted step (0 without one) */
    double worst_step_time_s;
    double stretch_rms_n;          /* the worst CHATTER_STRETCH_S: RMS over its contact ticks */
    double stretch_t0_s;           /* where that stretch starts */
} chatter_t;

/* Optional per-row outputs, each NULL or log->n long. */
typedef struct {
    float *high_pass_n;            /* |F - moving average| on contact ticks, 0 elsewhere */
    uint8_t *step;                 /* 1 where a counted step lands */
} chatter_trace_t;

/* Measures log into out (and trace, which may be NULL). The moving average is over the rows
 * of the last CHATTER_WINDOW_S, this row included (fewer at the log's start); the window's
 * row count comes from the mean row interval, since time_s is printed to the millisecond.
 * First contact is the log's contact column going 0 -> 1; without the column every step
 * counts. ARGIL_ERR_ARG for an empty log. */
argil_err_t chatter_measure(const telemetry_log_t *log, chatter_t *out,
                            const chatter_trace_t *trace);

/* True when the RMS is at most CHATTER_GOAL_RMS_N and no step was counted. */
bool chatter_goal_met(const chatter_t *c);

/* The figure as one line, e.g. "force above 50 Hz: 0.093 N RMS over 3895 ticks in contact, 13
 * steps > 0.2 N (+0 on first contact; goal 0.05 N, 0)"; returns what snprintf returns. */
int chatter_format(const chatter_t *c, char *buf, size_t len);

/* Where to look, as one line: the worst stretch and the worst counted step with their times. */
int chatter_format_worst(const chatter_t *c, char *buf, size_t len);

#endif
