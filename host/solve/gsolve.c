/* The global solve's object (gsolve.h): its init from the grid, the scratch its parts share,
 * closing its windows, its free. Each of its jobs has its own file: gsolve_step.c (one period),
 * gsolve_window.c, gsolve_settle.c, gsolve_view.c, gsolve_seed.c, gsolve_refine.c,
 * gsolve_material.c, gsolve_host_tool.c, gsolve_colour.c, gsolve_restore.c. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/f32_buf.h"
#include "host/solve/gsolve_internal.h"

/* gs->buf grown to at least n floats; NULL when out of memory. */
float *gsolve_scratch(gsolve_t *gs, size_t n)
{
    return f32_buf_reserve(&gs->buf, &gs->buf_n, n) ? gs->buf : NULL;
}

/* gsolve_init_ratio at GSOLVE_RATIO_DEFAULT samples per knot span. */
argil_err_t gsolve_init(gsolve_t *gs, grid_t *g)
{
    return gsolve_init_ratio(gs, g, GSOLVE_RATIO_DEFAULT);
}

/* A field at ratio samples per knot span, seeded from the whole grid. */
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

/* Frees the windows, the field and the scratch. */
void gsolve_free(gsolve_t *gs)
{
    gsolve_close_window(gs);
    field_free(&gs->field);
    free(gs->buf);
    gs->buf = NULL;
    gs->buf_n = 0;
}

/* Closes the physical window and the settling region's; the field keeps their last step. */
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

/* R, the field's samples per knot span. */
int32_t gsolve_ratio(const gsolve_t *gs)
{
    return gs->field.ratio;
}
