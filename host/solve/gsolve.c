/* The session's global solve on the B-spline model: field + physical window + grid view. */
#include "host/solve/gsolve.h"
#include "host/solve/gsolve_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


float *gsolve_scratch(gsolve_t *gs, size_t n)
{
    if (n > gs->buf_n) {
        float *b = realloc(gs->buf, n * sizeof(float));
        if (!b)
            return NULL;
        gs->buf = b;
        gs->buf_n = n;
    }
    return gs->buf;
}

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

argil_err_t gsolve_init(gsolve_t *gs, grid_t *g)
{
    return gsolve_init_ratio(gs, g, GSOLVE_RATIO_DEFAULT);
}

argil_err_t gsolve_init_ratio(gsolve_t *gs, grid_t *g, int32_t ratio)
{
    memset(gs, 0, sizeof(*gs));
    if (ratio != 1 && ratio != 2 && ratio != GSOLVE_RATIO_MAX)
        return ARGIL_ERR_ARG;
    argil_err_t e = field_init(&gs->field, g->spacing_m * (float)ratio, ratio, g->origin_m);
    if (e != ARGIL_OK)
        return e;
    /* On: clay the board's window left while still moving keeps settling (docs/model.md
     * "Settling"). It was off while tests/sil/test_knot_refine.c's two dents ended 0.85 mm apart
     * with it on; the cause was the board's bisected contact crossing, which turned one ulp of
     * state into a 0.01 mm step of penetration (firmware/core/haptics.c bracket_crossing). */
    gs->settle_enabled = true;
    gs->settle_clip = true;
    gs->field.iso = g->iso;
    gs->field.band_m = g->band_m; /* the grid's density ramp, so tools cut the same profile */
    solver_cfg_default(&gs->cfg);
    gs->cfg.acc_threshold = INFINITY; /* implicit: unconditionally stable, no step halving */
    gs->cfg.cg_tol = GSOLVE_CG_TOL;
    gsolve_set_material(gs, &g->material);
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    e = gsolve_seed_from_grid(gs, g, lo, hi);
    if (e != ARGIL_OK)
        gsolve_free(gs);
    return e;
}

void gsolve_free(gsolve_t *gs)
{
    gsolve_close_window(gs);
    field_free(&gs->field);
    free(gs->buf);
    gs->buf = NULL;
    gs->buf_n = 0;
}

void gsolve_close_window(gsolve_t *gs)
{
    if (gs->win_open)
        physwin_close(&gs->win);
    gs->win_open = false;
    gs->stale = false;
    gs->resting = false;
    if (gs->settle.open)
        physwin_close(&gs->settle.win);
    free(gs->settle.next);
    gs->settle.next = NULL;
    gs->settle.open = false;
    gs->settle.active = false;
}

int32_t gsolve_ratio(const gsolve_t *gs)
{
    return gs->field.ratio;
}
