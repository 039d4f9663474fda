/* When the global solve steps and how far it reaches around the board's window (DESIGN.md
 * "The data that flows" step 8): the solve period's clock, the adaptive margin of real-time
 * hosts, and the statistics of the steps' CPU times. Time is passed in; nothing is read here. */
#ifndef ARGIL_SOLVE_SCHED_H
#define ARGIL_SOLVE_SCHED_H

#include <stdbool.h>
#include <stdint.h>

#define SOLVE_PERIOD_MIN_US 2000u
#define SOLVE_PERIOD_MAX_US 50000u
#define SOLVE_MARGIN_MAX 4            /* samples of margin around the board's window */
#define SOLVE_MARGIN_GROW_STEPS 50u   /* fast steps in a row before the margin grows again */
#define SOLVE_HIST_BINS 5001u         /* step thread CPU time, 10 µs bins (last: ≥ 50 ms) */

typedef struct {
    uint32_t since_us;                /* since the last solve step */
    bool adaptive;                    /* a step over 80 % of its period lowers the margin */
    int32_t margin;                   /* samples of the solve's margin (SOLVE_MARGIN_MAX unless
                                       * adaptive lowered it) */
    uint32_t fast_steps;              /* steps in a row under 40 % of the period */
    uint32_t shrinks;                 /* times the margin was lowered */
    int32_t margin_min;               /* the smallest margin used (samples) */
    uint32_t hist_10us[SOLVE_HIST_BINS]; /* thread CPU time of each solve step */
    double max_ms;
} solve_sched_t;

/* A schedule with the full margin and no steps yet; adaptive as the host asks (real-time
 * hosts: true; lockstep sessions, which must stay reproducible: false). */
void solve_sched_init(solve_sched_t *s, bool adaptive);

/* Advances the clock by dt_us (also while no board is there: the first step comes at once). */
void solve_sched_advance(solve_sched_t *s, uint32_t dt_us);

/* True when a step of period_us is due now; the clock then restarts. */
bool solve_sched_take(solve_sched_t *s, uint32_t period_us);

/* True when solve_sched_take would be true after advancing by dt_us. */
bool solve_sched_due(const solve_sched_t *s, uint32_t period_us, uint32_t dt_us);

/* us clamped to SOLVE_PERIOD_MIN_US..SOLVE_PERIOD_MAX_US. */
uint32_t solve_period_clamp_us(uint32_t us);

/* Records a step that took step_ms of thread CPU time (histogram, max) and, when adaptive,
 * applies solve_sched_adapt. */
void solve_sched_record(solve_sched_t *s, uint32_t period_us, double step_ms);

/* The adaptive rule after a step of step_ms: over 80 % of the period lowers the margin by one
 * sample (not below 0); SOLVE_MARGIN_GROW_STEPS steps in a row under 40 % raise it by one (not
 * above SOLVE_MARGIN_MAX). */
void solve_sched_adapt(solve_sched_t *s, uint32_t period_us, double step_ms);

/* Median, 99th percentile (10 µs resolution) and max of the recorded steps, ms. */
void solve_sched_times_ms(const solve_sched_t *s, double *median, double *p99, double *max);

#endif
