/* The global solve's schedule: period clock, adaptive margin, step-time statistics. */
#include "host/solve/solve_sched.h"

#include <string.h>

#include "host/solve/histogram.h"

void solve_sched_init(solve_sched_t *s, bool adaptive)
{
    memset(s, 0, sizeof(*s));
    s->adaptive = adaptive;
    s->margin = SOLVE_MARGIN_MAX;
    s->margin_min = SOLVE_MARGIN_MAX;
}

bool solve_sched_due(const solve_sched_t *s, uint32_t period_us, uint32_t dt_us)
{
    return s->since_us + dt_us >= period_us;
}

void solve_sched_advance(solve_sched_t *s, uint32_t dt_us)
{
    s->since_us += dt_us;
}

bool solve_sched_take(solve_sched_t *s, uint32_t period_us)
{
    if (s->since_us < period_us)
        return false;
    s->since_us = 0;
    return true;
}

uint32_t solve_period_clamp_us(uint32_t us)
{
    if (us < SOLVE_PERIOD_MIN_US) us = SOLVE_PERIOD_MIN_US;
    if (us > SOLVE_PERIOD_MAX_US) us = SOLVE_PERIOD_MAX_US;
    return us;
}

void solve_sched_record(solve_sched_t *s, uint32_t period_us, double step_ms)
{
    const double bin = step_ms * 100.0;
    s->hist_10us[bin < (double)(SOLVE_HIST_BINS - 1u) ? (uint32_t)bin : SOLVE_HIST_BINS - 1u]++;
    if (step_ms > s->max_ms)
        s->max_ms = step_ms;
    if (s->adaptive)
        solve_sched_adapt(s, period_us, step_ms);
}

/* A solver that falls behind lowers its region, never the board's rate: the margin around the
 * board's window shrinks while steps overrun their budget and grows back after a run of fast
 * steps (the board's own window is always solved). */
void solve_sched_adapt(solve_sched_t *s, uint32_t period_us, double step_ms)
{
    const double period_ms = (double)period_us * 1e-3;
    if (step_ms > 0.8 * period_ms) {
        s->fast_steps = 0;
        if (s->margin > 0) {
            s->margin--;
            s->shrinks++;
            if (s->margin < s->margin_min)
                s->margin_min = s->margin;
        }
    } else if (step_ms < 0.4 * period_ms) {
        if (++s->fast_steps >= SOLVE_MARGIN_GROW_STEPS && s->margin < SOLVE_MARGIN_MAX) {
            s->margin++;
            s->fast_steps = 0;
        }
    } else {
        s->fast_steps = 0;
    }
}

void solve_sched_times_ms(const solve_sched_t *s, double *median, double *p99, double *max)
{
    *median = hist_quantile_bin(s->hist_10us, SOLVE_HIST_BINS, 0.5) * 0.01;
    *p99 = hist_quantile_bin(s->hist_10us, SOLVE_HIST_BINS, 0.99) * 0.01;
    *max = s->max_ms;
}
