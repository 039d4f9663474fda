/* Option values more than one argil command takes (argil sculpt, argil connect): each parser
 * returns false for a value outside its set, and the command prints its one-line error ending in
 * the matching CLI_*_EXPECTS text. */
#ifndef ARGIL_CLI_OPTS_H
#define ARGIL_CLI_OPTS_H

#include <stdbool.h>
#include <stdint.h>

#include "host/app/peer.h"

#define CLI_GLOBAL_SOLVE_EXPECTS "'bspline' or 'springs'"
#define CLI_KNOT_RATIO_EXPECTS "1, 2 or 4 (grid samples per knot span)"
#define CLI_AUTOSAVE_EXPECTS "seconds in 0.001..3600"

/* --global-solve: "bspline" or "springs". */
bool cli_global_solve(const char *v, peer_global_solve_t *out);

/* --knot-ratio: "1", "2" or "4". */
bool cli_knot_ratio(const char *v, int *out);

#define CLI_RATE_HZ_EXPECTS "1000, 2000 or 4000 (the board's loop rate, Hz)"
/* --rate-hz: "1000", "2000" or "4000"; *out the loop period in microseconds. */
bool cli_rate_hz(const char *v, uint32_t *tick_us);

/* --autosave-s, --checkpoint-s: a number of seconds in 0.001 … 3600. */
bool cli_autosave_s(const char *v, float *out);

/* The summary's words for a global solve ("B-spline model (implicit)", ...). */
const char *cli_global_solve_text(peer_global_solve_t gs);

#endif
