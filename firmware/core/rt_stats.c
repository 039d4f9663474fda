/* Wake-up latency and compute-time statistics for the fast loop. */
#include "rt_stats.h"

#include <string.h>

static const uint32_t edges_us[RT_HIST_BINS] = RT_HIST_EDGES_US;

_Static_assert(RT_HIST_BINS == PROTO_RT_HIST_BINS, "RT_STATS carries the whole histogram");

static void series_init(rt_series_t *s)
{
    memset(s, 0, sizeof(*s));
    s->min_ns = 0xFFFFFFFFu;
}

void rt_stats_init(rt_stats_t *s)
{
    series_init(&s->wake);
    series_init(&s->compute);
    s->overruns = 0;
    s->streak = 0;
    s->worst_streak = 0;
}

static void series_add(rt_series_t *s, uint32_t ns)
{
    s->count++;
    s->sum_ns += ns;
    if (ns < s->min_ns)
        s->min_ns = ns;
    if (ns > s->max_ns)
        s->max_ns = ns;
    uint32_t bin = RT_HIST_BINS - 1u;
    for (uint32_t i = 0; i + 1u < RT_HIST_BINS; i++) {
        if (ns < edges_us[i] * 1000u) {
            bin = i;
            break;
        }
    }
    s->hist[bin]++;
}

uint32_t rt_stats_add(rt_stats_t *s, uint32_t wake_ns, uint32_t compute_ns, uint32_t period_ns)
{
    series_add(&s->wake, wake_ns);
    series_add(&s->compute, compute_ns);
    const uint64_t used = (uint64_t)wake_ns + compute_ns;
    if (used > period_ns) {
        s->overruns++;
        s->streak++;
        if (s->streak > s->worst_streak)
            s->worst_streak = s->streak;
    } else {
        s->streak = 0;
    }
    return s->streak;
}

uint32_t rt_series_mean_ns(const rt_series_t *s)
{
    return s->count ? (uint32_t)(s->sum_ns / s->count) : 0u;
}

uint32_t rt_hist_edge_us(uint32_t i)
{
    return i < RT_HIST_BINS ? edges_us[i] : 0u;
}

/* Min, mean and max of a series; all 0 when it is empty. */
static void series_summary(const rt_series_t *s, uint32_t *min_ns, uint32_t *mean_ns,
                           uint32_t *max_ns)
{
    *min_ns = s->count ? s->min_ns : 0u;
    *mean_ns = rt_series_mean_ns(s);
    *max_ns = s->count ? s->max_ns : 0u;
}

void rt_stats_to_msg(const rt_stats_t *s, uint32_t period_ns, uint64_t time_us,
                     msg_rt_stats_t *m)
{
    m->time_us = time_us;
    m->ticks = s->wake.count;
    m->period_ns = period_ns;
    series_summary(&s->wake, &m->wake_min_ns, &m->wake_mean_ns, &m->wake_max_ns);
    series_summary(&s->compute, &m->compute_min_ns, &m->compute_mean_ns, &m->compute_max_ns);
    m->overruns = s->overruns;
    m->worst_streak = s->worst_streak;
    memcpy(m->wake_hist, s->wake.hist, sizeof m->wake_hist);
    memcpy(m->compute_hist, s->compute.hist, sizeof m->compute_hist);
}
