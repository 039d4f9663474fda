/* The settling region (docs/model.md "Settling"): clay the board's window left while it still
 * moved, stepped after the main window with the main window's coefficients held on their path,
 * until it rests. */
#include "host/solve/gsolve.h"

#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve_internal.h"

/* The board's window moved away from the box [lo, hi) while the clay in it still moved: step
 * that box on as the settling region (replacing an older one, whose velocity stays in the
 * field and resumes when a window covers it again). */
void gsolve_settle_take(gsolve_t *gs, const int32_t lo[3], const int32_t hi[3])
{
    gsolve_settle_t *st = &gs->settle;
    if (st->active)
        gs->stats.settle_dropped++;
    memcpy(st->box_lo, lo, sizeof(st->box_lo));
    memcpy(st->box_hi, hi, sizeof(st->box_hi));
    st->active = true;
    st->quiet_steps = 0;
}

/* Clips the settling region's coefficient box [clo, chi) (the box the window left) to what its
 * step needs beside the window's coefficient box [wlo, whi): the bounding box of the layers the
 * window left, grown by GSOLVE_SETTLE_MARGIN inside the old box (every held coefficient that
 * reaches a free one's equations; those farther act the same through d_fixed, at the place the
 * field holds). Left as it was when the left part is not one box (the window moved along two
 * or more axes, or shrank on both sides of one) or the boxes do not meet. False when the window
 * covers the whole box (nothing left to settle). */
static bool settle_clip_box(int32_t clo[3], int32_t chi[3], const int32_t wlo[3],
                            const int32_t whi[3])
{
    int cut_axis = -1, cuts = 0;
    for (int a = 0; a < 3; a++) {
        if (whi[a] <= clo[a] || wlo[a] >= chi[a])
            return true; /* apart: the window left all of it */
        if (wlo[a] > clo[a] || whi[a] < chi[a]) {
            cut_axis = a;
            cuts++;
        }
    }
    if (cuts == 0)
        return false;
    const int a = cut_axis;
    const bool low = wlo[a] > clo[a], high = whi[a] < chi[a];
    if (cuts > 1 || (low && high))
        return true;
    /* The left layers: [clo, wlo) below the window or [whi, chi) above it. */
    const int32_t llo = low ? clo[a] : whi[a], lhi = low ? wlo[a] : chi[a];
    const int32_t lo = llo - GSOLVE_SETTLE_MARGIN, hi = lhi + GSOLVE_SETTLE_MARGIN;
    clo[a] = lo > clo[a] ? lo : clo[a];
    chi[a] = hi < chi[a] ? hi : chi[a];
    if (chi[a] - clo[a] < 4) /* physwin_open's least; not reached: a layer + the margin is 4 */
        chi[a] = clo[a] + 4;
    return true;
}

/* One step of the settling region, after the main window's: every coefficient the main window
 * holds free is fixed here (block Gauss-Seidel: each coefficient moves once per period), the
 * rest of its box moves freely with no external force. Reloaded every step, since the main
 * window has just moved coefficients it reads. */
argil_err_t gsolve_settle_step(gsolve_t *gs, grid_t *g, float dt_s, int32_t dlo[3],
                               int32_t dhi[3], float *max_change)
{
    gsolve_settle_t *st = &gs->settle;
    field_t *f = &gs->field;
    physwin_t *w = &st->win;
    argil_err_t e;
    int32_t clo[3], chi[3];
    gsolve_coef_box(f, st->box_lo, st->box_hi, clo, chi);
    /* Every step, against where the main window is now (it may have moved on without taking a
     * newer region, when it rested): the region's free coefficients are the same either way. */
    if (gs->settle_clip && gs->win_open && !settle_clip_box(clo, chi, gs->win.clo, gs->win.chi)) {
        /* The main window took it all over. */
        st->active = false;
        return ARGIL_OK;
    }
    if (st->open && !gsolve_win_move(w, f->ratio, clo, chi)) {
        physwin_close(w);
        st->open = false;
    }
    if (!st->open) {
        gs->cfg.dt_s = dt_s;
        e = physwin_open(w, f, clo, chi, &gs->cfg);
        if (e != ARGIL_OK) {
            st->active = false;
            return e;
        }
        free(st->next);
        st->next = malloc(w->solver.ncoef * sizeof(float));
        if (!st->next) {
            physwin_close(w);
            st->active = false;
            return ARGIL_ERR_NOMEM;
        }
        w->solver.fixed_next = st->next;
        st->open = true;
        st->plain = false;
    }
    e = gsolve_win_reload(gs, w, dt_s, true, &st->plain);
    if (e != ARGIL_OK) {
        physwin_close(w);
        st->open = st->active = false;
        return e;
    }
    /* Hold what the main window moves, on the path it took this period: the field has them
     * at p_i+1 already, so this step starts them at p_i = p_i+1 - v dt (p_i-1 = p_i - v dt:
     * their velocity as if constant) and ends them at p_i+1. Held still instead, their mass
     * (the B-spline's mass matrix couples neighbours) would drag the clay beside them. */
    solver_t *s = &w->solver;
    float *next = st->next;
    size_t free_n = 0, k = 0;
    for (int32_t z = w->clo[2]; z < w->chi[2]; z++)
        for (int32_t y = w->clo[1]; y < w->chi[1]; y++)
            for (int32_t x = w->clo[0]; x < w->chi[0]; x++, k++) {
                const int32_t c[3] = {x, y, z};
                bool held = gs->win_open;
                for (int a = 0; a < 3 && held; a++)
                    held = c[a] >= gs->win.clo[a] && c[a] < gs->win.chi[a];
                next[k] = s->p[k];
                if (held) {
                    const float step = s->p[k] - s->p_prev[k];
                    s->fixed[k] = true;
                    s->p[k] -= step;
                    s->p_prev[k] -= step;
                }
                free_n += !s->fixed[k];
            }
    if (free_n == 0) {
        /* The main window took it all over. */
        st->active = false;
        return ARGIL_OK;
    }
    memset(s->force_n, 0, s->nsamp * sizeof(float));
    s->cfg.dt_s = dt_s;
    if (s->cfg.dt_min_s > dt_s)
        s->cfg.dt_min_s = dt_s;
    e = solver_step_implicit(s);
    if (e != ARGIL_OK) {
        physwin_close(w);
        st->open = st->active = false;
        return e;
    }
    gs->stats.settle_steps++;
    gs->stats.settle_coefs += s->ncoef;
    float change = 0.0f;
    bool quiet = false;
    st->quiet_steps++;
    /* Velocity zeroed only on the last of the quiet steps, when the region rests. */
    e = gsolve_win_store(gs, g, w, gs->win_open ? &gs->win : NULL, dt_s, false,
                   st->quiet_steps >= GSOLVE_SETTLE_QUIET_STEPS ? GSOLVE_SETTLE_DD : 0.0f, &change,
                   &quiet);
    if (e != ARGIL_OK) {
        physwin_close(w);
        st->open = st->active = false;
        return e;
    }
    if (change > 0.0f) {
        gsolve_grow_changed(g, w, dlo, dhi);
        if (change > *max_change)
            *max_change = change;
        /* The main window's fixed part (d of the coefficients outside it) changed. */
        gs->stale = gs->win_open;
        gs->stats.settle_reloads += gs->win_open;
    }
    if (change >= GSOLVE_SETTLE_DD)
        st->quiet_steps = 0;
    if (quiet) {
        st->active = false;
        gs->stats.settle_rested++;
    }
    return ARGIL_OK;
}
