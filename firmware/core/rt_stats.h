/* Deadline statistics of the fast loop: per tick, the wake-up latency (how late the loop woke
 * after its absolute deadline) and the compute time; min/mean/max, a histogram, overruns and
 * the overrun streak. Numbers are passed in; nothing here reads a clock. */
#ifndef ARGIL_RT_STATS_H
#define ARGIL_RT_STATS_H

#include <stdint.h>

#include "shared/proto.h"

#define RT_HIST_BINS 12u
/* Upper edges of the histogram bins in µs; the last bin holds everything above 10 ms. */
#define RT_HIST_EDGES_US {5u, 10u, 20u, 50u, 100u, 200u, 500u, 1000u, 2000u, 5000u, 10000u, 0u}

typedef struct {
    uint32_t count;
    uint32_t min_ns;
    uint32_t max_ns;
    uint64_t sum_ns;
    uint32_t hist[RT_HIST_BINS];
} rt_series_t;

typedef struct {
    rt_series_t wake;             /* wake-up latency */
    rt_series_t compute;          /* work done in the tick */
    uint32_t overruns;            /* ticks whose latency + compute passed the period */
    uint32_t streak;              /* current run of overruns */
    uint32_t worst_streak;
} rt_stats_t;

void rt_stats_init(rt_stats_t *s);

/* Records one tick; returns the current overrun streak (0 when this tick met its period). */
uint32_t rt_stats_add(rt_stats_t *s, uint32_t wake_ns, uint32_t compute_ns, uint32_t period_ns);

/* Mean of a series in ns, 0 when empty. */
uint32_t rt_series_mean_ns(const rt_series_t *s);

/* Upper edge of histogram bin i in µs; 0 for the open last bin. */
uint32_t rt_hist_edge_us(uint32_t i);

/* The RT_STATS message of s (docs/protocol.md): min, mean and max are 0 while no tick was
 * recorded, so the message is always valid for a period_ns > 0. */
void rt_stats_to_msg(const rt_stats_t *s, uint32_t period_ns, uint64_t time_us,
                     msg_rt_stats_t *m);

#endif
