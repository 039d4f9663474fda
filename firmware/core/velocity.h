/* The stylus velocity from quantised positions: first-order adaptive windowing (Janabi-Sharifi,
 * Hayward & Chen 2000, the end-fit FOAW). Per axis, the slope through the newest position and
 * the oldest one of the longest window whose every position lies within the tolerance of that
 * line: long windows (a precise, quiet estimate) while the stylus is still or moves evenly, short
 * ones when it changes speed. A backward difference over one tick reads each encoder count as a
 * velocity of count/T; that, times contact damping, was a force kick per count. Fixed size, no
 * heap, bounded loops. */
#ifndef ARGIL_VELOCITY_H
#define ARGIL_VELOCITY_H

#include <stdint.h>

#include "shared/vec3.h"

#define VELOCITY_WINDOW_MAX 16u   /* positions kept; the longest window spans 15 of them */

typedef struct {
    vec3_t pos_m[VELOCITY_WINDOW_MAX];
    uint32_t tick[VELOCITY_WINDOW_MAX]; /* the tick each position was read at */
    uint32_t head;                      /* where the next position goes */
    uint32_t n;                         /* positions held, ≤ VELOCITY_WINDOW_MAX */
} velocity_window_t;

void velocity_window_reset(velocity_window_t *w);

/* Takes the position read at `tick` (ticks must increase) and returns the velocity estimate,
 * m/s: 0 until two positions are held. tolerance_m: the bound on a position's error (about one
 * encoder count at the tip); tick_s: the tick's length. */
vec3_t velocity_window_add(velocity_window_t *w, vec3_t pos_m, uint32_t tick, float tick_s,
                           float tolerance_m);

#endif
