/* The grid as the field's view: the field's densities copied into the grid, clamped to [0, 1],
 * only where they moved by more than GSOLVE_VIEW_EPS. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>

#include "host/solve/gsolve_internal.h"

/* Copies the field's densities in sample box [lo, hi) (clipped to the grid) into the grid,
 * clamped to [0, 1], where they differ by more than GSOLVE_VIEW_EPS (so the round-off of a
 * field at rest neither re-sends windows nor fills the journal); returns the largest change
 * written, or -1 when out of memory. */
float gsolve_dense_to_grid(grid_t *g, const float *d, const int32_t lo[3], const int32_t n[3])
{
    int32_t hi[3], a0[3], a1[3];
    for (int a = 0; a < 3; a++)
        hi[a] = lo[a] + n[a];
    if (!grid_clip(g, lo, hi, a0, a1))
        return 0.0f;
    /* The grid's box, changed where the field moved it, stored back when anything changed. */
    int32_t an[3];
    for (int a = 0; a < 3; a++)
        an[a] = a1[a] - a0[a];
    float *cur = malloc((size_t)an[0] * (size_t)an[1] * (size_t)an[2] * sizeof(float));
    if (cur == NULL)
        return -1.0f;
    grid_read_box(g, GRID_DENSITY, a0, an, cur);
    float change = 0.0f;
    size_t k = 0;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const float *src = d + (size_t)n[0] * ((size_t)(y - lo[1]) +
                                                   (size_t)n[1] * (size_t)(z - lo[2])) -
                               lo[0];
            for (int32_t x = a0[0]; x < a1[0]; x++, k++) {
                const float v = gsolve_clamp01(src[x]);
                const float c = fabsf(v - cur[k]);
                if (c > GSOLVE_VIEW_EPS) {
                    if (c > change)
                        change = c;
                    cur[k] = v;
                }
            }
        }
    if (change > 0.0f && grid_write_box(g, GRID_DENSITY, a0, an, cur) != ARGIL_OK)
        change = -1.0f;
    free(cur);
    return change;
}

/* The field's densities in sample box [lo, hi) into the grid, as gsolve_dense_to_grid. */
float gsolve_view_to_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    int32_t a0[3], a1[3], n[3];
    if (!grid_clip(g, lo, hi, a0, a1))
        return 0.0f;
    for (int a = 0; a < 3; a++)
        n[a] = a1[a] - a0[a];
    float *d = gsolve_scratch(gs, (size_t)n[0] * n[1] * n[2]);
    if (!d)
        return -1.0f;
    sparse_read_box(&gs->field.samp, FS_D, a0, n, d);
    return gsolve_dense_to_grid(g, d, a0, n);
}
