/* Draws a session's telemetry as a chart: force magnitude, (given the chatter figure) the force
 * above 50 Hz in contact against its goal, tool height z and the board's state over time, in
 * stacked panels sharing the time axis, with ticks and labels. */
#ifndef ARGIL_PLOT_H
#define ARGIL_PLOT_H

#include "host/render/chatter.h"
#include "host/render/raster.h"
#include "host/render/telemetry_log.h"
#include "shared/argil_err.h"

/* Draws log into c (at least 320 × 240; ARGIL_ERR_ARG otherwise or for an empty log) under
 * title (may be NULL). With ch and tr (chatter_measure's figure and its high-pass trace; both
 * NULL for none) a panel under the force shows the trace, the CHATTER_GOAL_RMS_N line, the
 * counted steps as marks on its top edge, and the figure's line as its heading. */
argil_err_t plot_telemetry(const telemetry_log_t *log, canvas_t *c, const char *title,
                           const chatter_t *ch, const chatter_trace_t *tr);

/* A step of 1, 2 or 5 × 10^k giving about `count` intervals over span (> 0). */
double plot_nice_step(double span, int count);

#endif
