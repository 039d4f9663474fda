/* What the files of the global solve (host/solve/gsolve*.c) share and no caller needs: the
 * scratch buffer, the grid view, the physical window's reload, shift and store, the settling
 * region's step and the colour mirror that reports what it changed. */
#ifndef ARGIL_GSOLVE_INTERNAL_H
#define ARGIL_GSOLVE_INTERNAL_H

#include "host/solve/gsolve.h"

/* v clamped to [0, 1]: a density or a colour channel as the grid holds it. */
static inline float gsolve_clamp01(float v)
{
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

/* gs->buf grown to at least n floats (gsolve.c); NULL when out of memory. */
float *gsolve_scratch(gsolve_t *gs, size_t n);

/* Densities d of sample box [lo, lo + n) into the grid (gsolve_view.c); the largest change, -1
 * when out of memory. */
float gsolve_dense_to_grid(grid_t *g, const float *d, const int32_t lo[3], const int32_t n[3]);
/* The field's densities in sample box [lo, hi) into the grid, as gsolve_dense_to_grid. */
float gsolve_view_to_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3]);

/* The physical window (gsolve_window.c): re-read from the field, moved onto a coefficient box
 * of its size (false: another size), its coefficient box, a step stored back, the changed box
 * grown by it. */
argil_err_t gsolve_win_reload(gsolve_t *gs, physwin_t *w, float dt_s, bool moved,
                              bool *plain_io);
bool gsolve_win_move(physwin_t *w, int32_t ratio, const int32_t clo[3], const int32_t chi[3]);
void gsolve_coef_box(const field_t *f, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
                     int32_t chi[3]);
argil_err_t gsolve_win_store(gsolve_t *gs, grid_t *g, physwin_t *w, const physwin_t *skip,
                             float dt_s, bool forced, float rest_dd, float *change_out,
                             bool *resting_out);
void gsolve_grow_changed(const grid_t *g, const physwin_t *w, int32_t dlo[3], int32_t dhi[3]);

/* The settling region (gsolve_settle.c): the box the window left becomes it; its step after
 * the main window's. */
void gsolve_settle_take(gsolve_t *gs, const int32_t lo[3], const int32_t hi[3]);
argil_err_t gsolve_settle_step(gsolve_t *gs, grid_t *g, float dt_s, int32_t dlo[3],
                               int32_t dhi[3], float *max_change);

/* The model's colour in sample box [lo, hi) into the grid's rgb (gsolve_colour.c): 1 when
 * something changed, 0 when nothing did, -1 when out of memory. */
float gsolve_colour_box_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                const int32_t hi[3]);

#endif
