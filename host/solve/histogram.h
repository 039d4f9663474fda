/* Quantiles of the fixed-bin timing histograms the host keeps (solve steps, tick compute). */
#ifndef ARGIL_HISTOGRAM_H
#define ARGIL_HISTOGRAM_H

#include <stdint.h>

/* The smallest bin index at or below which the fraction q of the counted samples lie (0 when
 * the histogram is empty). */
uint32_t hist_quantile_bin(const uint32_t *hist, uint32_t bins, double q);

#endif
