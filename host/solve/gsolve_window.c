/* The physical window (host/model/physwin.h) the implicit step runs in, kept in step with the
 * field: its coefficient box, re-read after an edit or a shift by whole knot spans, and a step
 * stored back (plastic flow, rest) into the field and the grid. */
#include "host/solve/gsolve.h"

#include <string.h>

#include "host/model/floor_div.h"
#include "host/solve/gsolve_internal.h"

/* Coefficient box of the sample box [lo, hi): every coefficient centred in it, at least 4 per
 * axis. */
void gsolve_coef_box(const field_t *f, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
                     int32_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = floor_div_i32(lo[a], f->ratio);
        chi[a] = floor_div_i32(hi[a] - 1, f->ratio) + 1;
        if (chi[a] - clo[a] < 4)
            chi[a] = clo[a] + 4;
    }
}

/* The window's coefficient and sample extents, and scratch for one sample array (returned)
 * followed by one array of max(samples, coefficients) (*tmp); NULL when out of memory. */
static float *win_scratch(gsolve_t *gs, const physwin_t *w, int32_t nc[3], int32_t ns[3],
                          float **tmp)
{
    const solver_t *s = &w->solver;
    for (int a = 0; a < 3; a++) {
        nc[a] = w->chi[a] - w->clo[a];
        ns[a] = w->shi[a] - w->slo[a];
    }
    float *d = gsolve_scratch(gs, s->nsamp + (s->nsamp > s->ncoef ? s->nsamp : s->ncoef));
    if (d)
        *tmp = d + s->nsamp;
    return d;
}

/* Reads the window's coefficients, their velocity, the rest shape and the fixed part of d
 * (coefficients outside the window) again, as physwin_open does: after a tool edit, or (moved)
 * after the window was shifted by whole knot spans, when the fixed flags and the material are
 * read too. The taps repeat every knot span, so they stay, and no array is reallocated (a
 * fresh physwin_open of a 32³ window faults in ~7 MB of new pages). */
argil_err_t gsolve_win_reload(gsolve_t *gs, physwin_t *w, float dt_s, bool moved,
                              bool *plain_io)
{
    solver_t *s = &w->solver;
    const field_t *f = &gs->field;
    int32_t nc[3], ns[3];
    float *tmp;
    float *d = win_scratch(gs, w, nc, ns, &tmp);
    if (!d)
        return ARGIL_ERR_NOMEM;
    sparse_read_box(&f->coef, FC_P, w->clo, nc, s->p);
    sparse_read_box(&f->coef, FC_V, w->clo, nc, tmp);
    for (size_t i = 0; i < s->ncoef; i++)
        s->p_prev[i] = s->p[i] - tmp[i] * dt_s;
    s->dt_prev_s = dt_s;
    sparse_read_box(&f->samp, FS_D, w->slo, ns, d);
    memset(s->d_fixed, 0, sizeof(float) * s->nsamp);
    solver_densities(s, tmp);
    for (size_t i = 0; i < s->nsamp; i++)
        s->d_fixed[i] = d[i] - tmp[i];
    if (moved) {
        sparse_read_box(&f->coef, FC_FIXED, w->clo, nc, tmp);
        for (size_t i = 0; i < s->ncoef; i++)
            s->fixed[i] = tmp[i] != 0.0f;
        /* What physwin_sync_inputs reads; the derived arrays depend only on the material scales
         * and the layout, so with unpainted material before and after they stay as they are. */
        sparse_read_box(&f->samp, FS_MASS, w->slo, ns, s->mass_kg);
        sparse_read_box(&f->samp, FS_DAMP, w->slo, ns, s->damp_n_s);
        sparse_read_box(&f->samp, FS_STIFF, w->slo, ns, s->kscale);
        bool plain = true;
        for (size_t i = 0; i < s->nsamp; i++) {
            plain = plain && s->mass_kg[i] == 1.0f && s->damp_n_s[i] == 1.0f &&
                    s->kscale[i] == 1.0f;
            s->mass_kg[i] *= f->material.mass_kg;
            s->damp_n_s[i] *= f->material.damping_n_s;
        }
        sparse_read_box(&f->samp, FS_REST, w->slo, ns, s->rest);
        sparse_read_box(&f->samp, FS_RESTLEN, w->slo, ns, tmp);
        for (size_t i = 0; i < s->nsamp; i++)
            s->rest[i] += tmp[i];
        if (!plain || !*plain_io || s->k_rest_n != f->material.stiffness_n ||
            s->coupling_n != f->material.coupling_n) {
            s->k_rest_n = f->material.stiffness_n;
            s->coupling_n = f->material.coupling_n;
            solver_material_changed(s);
        }
        *plain_io = plain;
    } else {
        sparse_read_box(&f->samp, FS_REST, w->slo, ns, s->rest);
        sparse_read_box(&f->samp, FS_RESTLEN, w->slo, ns, tmp);
        for (size_t i = 0; i < s->nsamp; i++)
            s->rest[i] += tmp[i];
    }
    return ARGIL_OK;
}

/* Shifts an open window whose sample box was at old_lo to new_lo (same size, by whole knot
 * spans: the taps repeat every span, so only the boxes move). */
static void win_shift(physwin_t *w, int32_t ratio, const int32_t old_lo[3],
                      const int32_t new_lo[3])
{
    for (int a = 0; a < 3; a++) {
        const int32_t shift = new_lo[a] - old_lo[a];
        w->clo[a] += shift / ratio;
        w->chi[a] += shift / ratio;
        w->slo[a] += shift;
        w->shi[a] += shift;
    }
}

/* Moves open window w onto the coefficient box [clo, chi) and returns true when that box has
 * w's size (a shift by whole knot spans); false, w as it was, when it has not. */
bool gsolve_win_move(physwin_t *w, int32_t ratio, const int32_t clo[3], const int32_t chi[3])
{
    bool same = true;
    for (int a = 0; a < 3; a++)
        same = same && chi[a] - clo[a] == w->chi[a] - w->clo[a];
    if (!same)
        return false;
    int32_t old_lo[3], new_lo[3];
    for (int a = 0; a < 3; a++) {
        old_lo[a] = w->clo[a] * ratio;
        new_lo[a] = clo[a] * ratio;
    }
    win_shift(w, ratio, old_lo, new_lo);
    return true;
}

/* After an implicit step of window w: d = A p + d_fixed once; plastic flow (the rest shape
 * follows the current one at the material's rate); p, the coefficient velocity, d and the rest
 * back to the field (what physwin_store does, without computing d twice) and d into the grid.
 * Rest: no force acted and no sample of the view moved by rest_dd; the velocity is then
 * zeroed (CG's 8 iterations leave the B-spline's high-frequency modes, which barely show in
 * the samples, almost undamped: their round-off would otherwise drift on). */
argil_err_t gsolve_win_store(gsolve_t *gs, grid_t *g, physwin_t *w, const physwin_t *skip,
                             float dt_s, bool forced, float rest_dd, float *change_out,
                             bool *resting_out)
{
    field_t *f = &gs->field;
    solver_t *s = &w->solver;
    int32_t nc[3], ns[3];
    float *tmp;
    float *d = win_scratch(gs, w, nc, ns, &tmp);
    if (!d)
        return ARGIL_ERR_NOMEM;
    solver_densities(s, d);
    argil_err_t e = ARGIL_OK;
    const float plastic = gs->mat.plastic_rate_hz * dt_s > 1.0f ? 1.0f
                                                                : gs->mat.plastic_rate_hz * dt_s;
    if (plastic > 0.0f) {
        sparse_read_box(&f->samp, FS_REST, w->slo, ns, tmp);
        size_t i = 0;
        for (int32_t z = w->slo[2]; z < w->shi[2]; z++)
            for (int32_t y = w->slo[1]; y < w->shi[1]; y++)
                for (int32_t x = w->slo[0]; x < w->shi[0]; x++, i++) {
                    /* Samples of `skip` (the main window) flowed in its own step. */
                    if (skip && x >= skip->slo[0] && x < skip->shi[0] && y >= skip->slo[1] &&
                        y < skip->shi[1] && z >= skip->slo[2] && z < skip->shi[2])
                        continue;
                    const float delta = plastic * (d[i] - s->rest[i]);
                    s->rest[i] += delta;
                    tmp[i] += delta;
                }
        e = sparse_write_box(&f->samp, FS_REST, w->slo, ns, tmp);
    }
    const float change = gsolve_dense_to_grid(g, d, w->slo, ns);
    const bool resting = !forced && change < rest_dd;
    if (resting)
        memcpy(s->p_prev, s->p, s->ncoef * sizeof(float));
    if (e == ARGIL_OK)
        e = sparse_write_box(&f->coef, FC_P, w->clo, nc, s->p);
    if (e == ARGIL_OK) {
        /* Only the free coefficients' velocity: a fixed one's stays what the field holds
         * (0 for a fixed point; the main window's own for those a settling region holds). */
        sparse_read_box(&f->coef, FC_V, w->clo, nc, tmp);
        for (size_t i = 0; i < s->ncoef; i++)
            if (!s->fixed[i])
                tmp[i] = (s->p[i] - s->p_prev[i]) / s->dt_prev_s;
        e = sparse_write_box(&f->coef, FC_V, w->clo, nc, tmp);
    }
    if (e == ARGIL_OK)
        e = sparse_write_box(&f->samp, FS_D, w->slo, ns, d);
    *change_out = change;
    *resting_out = resting;
    return e;
}

/* Grows the changed box [dlo, dhi) (empty when dlo = dhi) by w's samples clipped to the grid. */
void gsolve_grow_changed(const grid_t *g, const physwin_t *w, int32_t dlo[3], int32_t dhi[3])
{
    int32_t a0[3], a1[3];
    if (!grid_clip(g, w->slo, w->shi, a0, a1))
        return;
    const bool empty = dhi[0] <= dlo[0];
    for (int a = 0; a < 3; a++) {
        dlo[a] = empty || a0[a] < dlo[a] ? a0[a] : dlo[a];
        dhi[a] = empty || a1[a] > dhi[a] ? a1[a] : dhi[a];
    }
}
