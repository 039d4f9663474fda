/* First-order adaptive windowing of the stylus velocity (velocity.h). */
#include "velocity.h"

#include <math.h>

void velocity_window_reset(velocity_window_t *w)
{
    w->head = 0;
    w->n = 0;
}

static float axis(vec3_t v, int a)
{
    return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}

/* The i-th newest slot (0 = the newest). */
static uint32_t slot(const velocity_window_t *w, uint32_t i)
{
    return (w->head + VELOCITY_WINDOW_MAX - 1u - i) % VELOCITY_WINDOW_MAX;
}

/* One axis: the slope of the longest window n (1 ≤ n < w->n) whose positions in between lie
 * within tolerance_m of the line from the newest to the n-th newest. */
static float axis_slope(const velocity_window_t *w, int a, float tick_s, float tolerance_m)
{
    const uint32_t s0 = slot(w, 0);
    const float x0 = axis(w->pos_m[s0], a);
    float best = 0.0f;
    for (uint32_t n = 1; n < w->n; n++) {
        const uint32_t sn = slot(w, n);
        const float span_s = (float)(w->tick[s0] - w->tick[sn]) * tick_s;
        if (!(span_s > 0.0f))
            break;
        const float slope = (x0 - axis(w->pos_m[sn], a)) / span_s;
        for (uint32_t j = 1; j < n; j++) {
            const uint32_t sj = slot(w, j);
            const float line = x0 - slope * (float)(w->tick[s0] - w->tick[sj]) * tick_s;
            if (fabsf(axis(w->pos_m[sj], a) - line) > tolerance_m)
                return best;
        }
        best = slope;
    }
    return best;
}

vec3_t velocity_window_add(velocity_window_t *w, vec3_t pos_m, uint32_t tick, float tick_s,
                           float tolerance_m)
{
    w->pos_m[w->head] = pos_m;
    w->tick[w->head] = tick;
    w->head = (w->head + 1u) % VELOCITY_WINDOW_MAX;
    if (w->n < VELOCITY_WINDOW_MAX)
        w->n++;
    return vec3(axis_slope(w, 0, tick_s, tolerance_m), axis_slope(w, 1, tick_s, tolerance_m),
                axis_slope(w, 2, tick_s, tolerance_m));
}
