/* One solve period (gsolve_step): the main physical window follows the box it is asked to
 * cover, takes the grid's external forces and takes one implicit step; then the settling
 * region, while one moves. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve_internal.h"

/* gsolve_win_reload of the main window, which is then current and not at rest. */
static argil_err_t reload_window(gsolve_t *gs, float dt_s, bool moved)
{
    const argil_err_t e = gsolve_win_reload(gs, &gs->win, dt_s, moved, &gs->win_plain);
    if (e == ARGIL_OK) {
        gs->stale = false;
        gs->resting = false;
    }
    return e;
}

/* One step of the main window; *stepped false when it rested untouched. */
static argil_err_t step_main(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                             float dt_s, int32_t dlo[3], int32_t dhi[3], float *max_change)
{
    field_t *f = &gs->field;
    /* The coefficients whose samples cover the box (at least 4 per axis). */
    int32_t clo[3], chi[3];
    gsolve_coef_box(f, lo, hi, clo, chi);
    if (gs->win_open && (memcmp(clo, gs->win.clo, sizeof(clo)) != 0 ||
                         memcmp(chi, gs->win.chi, sizeof(chi)) != 0)) {
        /* The clay the window leaves behind may still be moving: keep stepping it. */
        if (!gs->resting && gs->settle_enabled)
            gsolve_settle_take(gs, gs->box_lo, gs->box_hi);
        /* Same size, shifted by whole knot spans (R samples each; a box that moved less stays
         * on the same coefficients): move the open window instead of reopening. */
        if (gsolve_win_move(&gs->win, f->ratio, clo, chi)) {
            const argil_err_t e = reload_window(gs, dt_s, true);
            if (e != ARGIL_OK) {
                gsolve_close_window(gs);
                return e;
            }
            gs->stats.windows_moved++;
        } else {
            physwin_close(&gs->win);
            gs->win_open = false;
        }
    }
    if (gs->win_open) {
        memcpy(gs->box_lo, lo, sizeof(gs->box_lo));
        memcpy(gs->box_hi, hi, sizeof(gs->box_hi));
    }
    if (gs->win_open && gs->stale) {
        const argil_err_t e = reload_window(gs, dt_s, false);
        if (e != ARGIL_OK)
            return e;
    }
    if (!gs->win_open) {
        gs->cfg.dt_s = dt_s;
        const argil_err_t e = physwin_open(&gs->win, f, clo, chi, &gs->cfg);
        if (e != ARGIL_OK)
            return e;
        gs->win_open = true;
        gs->stale = false;
        gs->resting = false;
        gs->win_plain = false; /* unknown: the next move rebuilds the derived arrays */
        memcpy(gs->box_lo, lo, sizeof(gs->box_lo));
        memcpy(gs->box_hi, hi, sizeof(gs->box_hi));
        gs->stats.windows_opened++;
    }
    physwin_t *w = &gs->win;
    solver_t *s = &w->solver;
    /* The grid's external forces (impulses / dt) on the window's samples act over this step. */
    memset(s->force_n, 0, s->nsamp * sizeof(float));
    bool forced = false;
    int32_t a0[3], a1[3];
    if (grid_clip(g, w->slo, w->shi, a0, a1)) {
        /* The grid holds every index the window can have: its box is the window's. */
        const int32_t ns[3] = {w->shi[0] - w->slo[0], w->shi[1] - w->slo[1],
                               w->shi[2] - w->slo[2]};
        grid_read_box(g, GRID_FORCE, w->slo, ns, s->force_n);
        for (size_t i = 0; i < s->nsamp && !forced; i++)
            forced = s->force_n[i] != 0.0f;
        if (forced) {
            float *zero = calloc(s->nsamp, sizeof(float));
            if (zero == NULL || grid_write_box(g, GRID_FORCE, w->slo, ns, zero) != ARGIL_OK) {
                free(zero);
                return ARGIL_ERR_NOMEM;
            }
            free(zero);
        }
    }
    /* At rest and left alone: nothing to step (and no round-off to integrate); the window is
     * not stepped again until a force, a tool, the material or a new window moves it. */
    if (gs->resting && !forced) {
        gs->stats.rest_skips++;
        return ARGIL_OK;
    }
    s->cfg.dt_s = dt_s;
    if (s->cfg.dt_min_s > dt_s)
        s->cfg.dt_min_s = dt_s;
    argil_err_t e = solver_step_implicit(s);
    if (e != ARGIL_OK) {
        /* A non-finite step is not stored: the field keeps its last good state. */
        gsolve_close_window(gs);
        return e;
    }
    gs->stats.steps++;
    gs->stats.last_cg_iters = s->stats.cg_iters;
    gs->stats.cg_iters_total += (uint64_t)s->stats.cg_iters;
    gs->stats.last_residual = s->stats.residual;
    if (s->stats.residual > gs->stats.max_residual)
        gs->stats.max_residual = s->stats.residual;
    float change = 0.0f;
    e = gsolve_win_store(gs, g, w, NULL, dt_s, forced, GSOLVE_REST_DD, &change, &gs->resting);
    if (e != ARGIL_OK) {
        gsolve_close_window(gs);
        return e;
    }
    if (change > 0.0f) {
        gsolve_grow_changed(g, w, dlo, dhi);
        *max_change = change;
    }
    return ARGIL_OK;
}

/* The main window's step, then the settling region's while it moves. */
argil_err_t gsolve_step(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                        float dt_s, int32_t dlo[3], int32_t dhi[3], float *max_change)
{
    for (int a = 0; a < 3; a++)
        dlo[a] = dhi[a] = 0;
    *max_change = 0.0f;
    if (!(dt_s > 0.0f) || !isfinite(dt_s))
        return ARGIL_ERR_ARG;
    argil_err_t e = step_main(gs, g, lo, hi, dt_s, dlo, dhi, max_change);
    if (e == ARGIL_OK && gs->settle.active)
        e = gsolve_settle_step(gs, g, dt_s, dlo, dhi, max_change);
    return e;
}
