/* Knot insertion during the session (gsolve_refine, field_refine): R halves, the shape stays,
 * and the grid is rewritten only where a density moved by more than GSOLVE_VIEW_EPS. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>

#include "host/solve/gsolve_internal.h"

/* Knot insertion over the whole field; the grid follows only where a density moved. */
argil_err_t gsolve_refine(gsolve_t *gs, grid_t *g, float *max_dd, int32_t lo[3], int32_t hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = 0;
    if (max_dd)
        *max_dd = 0.0f;
    field_t *f = &gs->field;
    if (f->ratio < 2)
        return ARGIL_ERR_STATE;
    /* The field is current after every step (p, velocity, d, rest): only the window goes. A
     * settling region's physical window goes too (its coefficient indices name coarse places),
     * but not the region: its box is in samples, which the refinement keeps, so its next step
     * reopens it on the fine lattice and the clay in it moves on. */
    const bool settling = gs->settle.active;
    gsolve_close_window(gs);
    gs->settle.active = settling;
    int32_t zero[3], top[3], gd[3];
    grid_bounds(g, zero, top);
    for (int a = 0; a < 3; a++)
        gd[a] = top[a] - zero[a];
    const size_t n = grid_count(g);
    float *before = malloc(2 * n * sizeof(float));
    if (!before)
        return ARGIL_ERR_NOMEM;
    float *after = before + n;
    sparse_read_box(&f->samp, FS_D, zero, gd, before);
    const uint32_t gen = f->lattice_gen;
    argil_err_t e = field_refine(f);
    if (e != ARGIL_OK && f->lattice_gen != gen) {
        /* Out of memory after the finer coefficients replaced the coarse ones: some d may still
         * hold the old values (field.h); recompute the grid's part once more. */
        const argil_err_t e2 = field_refresh(f, zero, top);
        if (e2 == ARGIL_OK)
            e = ARGIL_OK;
    }
    if (e != ARGIL_OK) {
        free(before);
        return e;
    }
    sparse_read_box(&f->samp, FS_D, zero, gd, after);
    /* The grid follows only a density the refinement itself moved by > GSOLVE_VIEW_EPS (none
     * measured: ~5e-7): a sample the view left within GSOLVE_VIEW_EPS of the field stays as it
     * is, so the grid, the mesh and the board's window do not change at all. */
    float dd = 0.0f;
    bool changed = false;
    size_t i = 0;
    for (int32_t z = zero[2]; z < top[2]; z++)
        for (int32_t y = zero[1]; y < top[1]; y++)
            for (int32_t x = zero[0]; x < top[0]; x++, i++) {
                const float c = fabsf(after[i] - before[i]);
                if (c > dd)
                    dd = c;
                if (c > GSOLVE_VIEW_EPS) {
                    if (grid_set(g, GRID_DENSITY, x, y, z, gsolve_clamp01(after[i])) != ARGIL_OK) {
                        free(before);
                        return ARGIL_ERR_NOMEM;
                    }
                    changed = true;
                }
            }
    free(before);
    gs->stats.refines++;
    if (max_dd)
        *max_dd = dd;
    if (changed)
        for (int a = 0; a < 3; a++) {
            lo[a] = zero[a];
            hi[a] = top[a];
        }
    return ARGIL_OK;
}
