/* Histogram quantiles (see histogram.h). */
#include "host/solve/histogram.h"

uint32_t hist_quantile_bin(const uint32_t *hist, uint32_t bins, double q)
{
    uint64_t total = 0, seen = 0;
    for (uint32_t i = 0; i < bins; i++)
        total += hist[i];
    for (uint32_t i = 0; i < bins; i++) {
        seen += hist[i];
        if (total > 0 && (double)seen >= q * (double)total)
            return i;
    }
    return 0;
}
