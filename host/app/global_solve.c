/* The session's global solve on the B-spline model: field + physical window + grid view. */
#include "host/app/global_solve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/material.h"
#include "host/model/tools.h"

static int32_t floordiv(int32_t a, int32_t b)
{
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}

static float clamp01(float v)
{
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

static float *scratch(gsolve_t *gs, size_t n)
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

/* Intersection of [lo, hi) with the grid; false when empty. */
static bool clip_to_grid(const grid_t *g, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
                         int32_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = lo[a] < 0 ? 0 : lo[a];
        chi[a] = hi[a] > g->dims[a] ? g->dims[a] : hi[a];
        if (chi[a] <= clo[a])
            return false;
    }
    return true;
}

/* Copies the field's densities in sample box [lo, hi) (clipped to the grid) into the grid,
 * clamped to [0, 1], where they differ by more than GSOLVE_VIEW_EPS (so the round-off of a
 * field at rest neither re-sends windows nor fills the journal); returns the largest change
 * written, or -1 when out of memory. */
static float dense_to_grid(grid_t *g, const float *d, const int32_t lo[3], const int32_t n[3])
{
    int32_t hi[3], a0[3], a1[3];
    for (int a = 0; a < 3; a++)
        hi[a] = lo[a] + n[a];
    if (!clip_to_grid(g, lo, hi, a0, a1))
        return 0.0f;
    float change = 0.0f;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const size_t row = (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
            const float *src = d + (size_t)n[0] * ((size_t)(y - lo[1]) +
                                                   (size_t)n[1] * (size_t)(z - lo[2])) -
                               lo[0];
            for (int32_t x = a0[0]; x < a1[0]; x++) {
                const float v = clamp01(src[x]);
                const float c = fabsf(v - g->density[row + (size_t)x]);
                if (c > GSOLVE_VIEW_EPS) {
                    if (c > change)
                        change = c;
                    g->density[row + (size_t)x] = v;
                }
            }
        }
    return change;
}

static float view_to_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    int32_t a0[3], a1[3], n[3];
    if (!clip_to_grid(g, lo, hi, a0, a1))
        return 0.0f;
    for (int a = 0; a < 3; a++)
        n[a] = a1[a] - a0[a];
    float *d = scratch(gs, (size_t)n[0] * n[1] * n[2]);
    if (!d)
        return -1.0f;
    sparse_read_box(&gs->field.samp, FS_D, a0, n, d);
    return dense_to_grid(g, d, a0, n);
}

void gsolve_set_material(gsolve_t *gs, const spring_material_t *m)
{
    gs->mat = *m;
    gs->field.material.mass_kg = m->node_mass;
    gs->field.material.damping_n_s = m->damping;
    gs->field.material.stiffness_n = m->stiffness;
    gs->field.material.coupling_n = m->coupling;
    if (gs->win_open)
        physwin_sync_inputs(&gs->win, &gs->field);
    gs->resting = false;
}

argil_err_t gsolve_init(gsolve_t *gs, grid_t *g)
{
    memset(gs, 0, sizeof(*gs));
    argil_err_t e = field_init(&gs->field, g->spacing_m * (float)GSOLVE_RATIO, GSOLVE_RATIO,
                               g->origin_m);
    if (e != ARGIL_OK)
        return e;
    gs->field.iso = g->iso;
    gs->field.band_m = g->band_m; /* the grid's density ramp, so tools cut the same profile */
    solver_cfg_default(&gs->cfg);
    gs->cfg.acc_threshold = INFINITY; /* implicit: unconditionally stable, no step halving */
    gs->cfg.cg_tol = GSOLVE_CG_TOL;
    gsolve_set_material(gs, &g->material);
    const int32_t lo[3] = {0, 0, 0};
    e = gsolve_seed_from_grid(gs, g, lo, g->dims);
    if (e != ARGIL_OK)
        gsolve_free(gs);
    return e;
}

void gsolve_free(gsolve_t *gs)
{
    if (gs->win_open)
        physwin_close(&gs->win);
    gs->win_open = false;
    field_free(&gs->field);
    free(gs->buf);
    gs->buf = NULL;
    gs->buf_n = 0;
}

static void close_window(gsolve_t *gs)
{
    if (gs->win_open)
        physwin_close(&gs->win);
    gs->win_open = false;
    gs->stale = false;
    gs->resting = false;
}

/* Reads the window's coefficients, their velocity, the rest shape and the fixed part of d
 * (coefficients outside the window) again, as physwin_open does: after a tool edit, or (moved)
 * after the window was shifted by whole knot spans, when the fixed flags and the material are
 * read too. The taps repeat every knot span, so they stay, and no array is reallocated (a
 * fresh physwin_open of a 32³ window faults in ~7 MB of new pages). */
static argil_err_t reload_window(gsolve_t *gs, float dt_s, bool moved)
{
    physwin_t *w = &gs->win;
    solver_t *s = &w->solver;
    const field_t *f = &gs->field;
    int32_t nc[3], ns[3];
    for (int a = 0; a < 3; a++) {
        nc[a] = w->chi[a] - w->clo[a];
        ns[a] = w->shi[a] - w->slo[a];
    }
    float *d = scratch(gs, s->nsamp + (s->nsamp > s->ncoef ? s->nsamp : s->ncoef));
    if (!d)
        return ARGIL_ERR_NOMEM;
    float *tmp = d + s->nsamp;
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
        if (!plain || !gs->win_plain || s->k_rest_n != f->material.stiffness_n ||
            s->coupling_n != f->material.coupling_n) {
            s->k_rest_n = f->material.stiffness_n;
            s->coupling_n = f->material.coupling_n;
            solver_material_changed(s);
        }
        gs->win_plain = plain;
    } else {
        sparse_read_box(&f->samp, FS_REST, w->slo, ns, s->rest);
        sparse_read_box(&f->samp, FS_RESTLEN, w->slo, ns, tmp);
        for (size_t i = 0; i < s->nsamp; i++)
            s->rest[i] += tmp[i];
    }
    gs->stale = false;
    gs->resting = false;
    return ARGIL_OK;
}

void gsolve_close_window(gsolve_t *gs)
{
    close_window(gs);
}

argil_err_t gsolve_seed_from_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    field_t *f = &gs->field;
    int32_t clo[3], chi[3], nc[3], slo[3], shi[3], ns[3];
    for (int a = 0; a < 3; a++)
        if (hi[a] <= lo[a])
            return ARGIL_ERR_ARG;
    close_window(gs);
    field_coefs_of_samples(f, lo, hi, clo, chi);
    size_t ncoef = 1, nsamp = 1;
    field_samples_of_coefs(f, clo, chi, slo, shi);
    for (int a = 0; a < 3; a++) {
        nc[a] = chi[a] - clo[a];
        ns[a] = shi[a] - slo[a];
        ncoef *= (size_t)nc[a];
        nsamp *= (size_t)ns[a];
    }
    float *p = scratch(gs, ncoef > nsamp ? ncoef : nsamp);
    if (!p)
        return ARGIL_ERR_NOMEM;
    /* Quasi-interpolation: coefficient c takes the density at its own sample R c. */
    size_t k = 0;
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t y = 0; y < nc[1]; y++)
            for (int32_t x = 0; x < nc[0]; x++, k++) {
                const int32_t s[3] = {(clo[0] + x) * f->ratio, (clo[1] + y) * f->ratio,
                                      (clo[2] + z) * f->ratio};
                bool in = true;
                for (int a = 0; a < 3; a++)
                    in = in && s[a] >= 0 && s[a] < g->dims[a];
                p[k] = in ? g->density[(size_t)s[0] + (size_t)g->dims[0] *
                                       ((size_t)s[1] + (size_t)g->dims[1] * (size_t)s[2])]
                          : 0.0f;
            }
    argil_err_t e = sparse_write_box(&f->coef, FC_P, clo, nc, p);
    if (e == ARGIL_OK) {
        memset(p, 0, ncoef * sizeof(float));
        e = sparse_write_box(&f->coef, FC_V, clo, nc, p);
    }
    if (e == ARGIL_OK)
        e = field_refresh(f, slo, shi);
    if (e != ARGIL_OK)
        return e;
    p = scratch(gs, nsamp); /* field_refresh may not move it, but re-take it anyway */
    if (!p)
        return ARGIL_ERR_NOMEM;
    sparse_read_box(&f->samp, FS_D, slo, ns, p);
    e = sparse_write_box(&f->samp, FS_REST, slo, ns, p);
    if (e != ARGIL_OK)
        return e;
    if (view_to_grid(gs, g, slo, shi) < 0.0f)
        return ARGIL_ERR_NOMEM;
    int32_t a0[3], a1[3];
    if (clip_to_grid(g, slo, shi, a0, a1))
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++)
                for (int32_t x = a0[0]; x < a1[0]; x++) {
                    const size_t i = (size_t)x + (size_t)g->dims[0] *
                                     ((size_t)y + (size_t)g->dims[1] * (size_t)z);
                    g->rest[i] = g->density[i];
                    g->velocity[i] = 0.0f;
                }
    return ARGIL_OK;
}

argil_err_t gsolve_step(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                        float dt_s, int32_t dlo[3], int32_t dhi[3], float *max_change)
{
    for (int a = 0; a < 3; a++)
        dlo[a] = dhi[a] = 0;
    *max_change = 0.0f;
    if (!(dt_s > 0.0f) || !isfinite(dt_s))
        return ARGIL_ERR_ARG;
    field_t *f = &gs->field;
    if (gs->win_open && (memcmp(lo, gs->box_lo, sizeof(gs->box_lo)) != 0 ||
                         memcmp(hi, gs->box_hi, sizeof(gs->box_hi)) != 0)) {
        /* Same size, shifted by whole knot spans: move the open window instead of reopening. */
        bool same = true;
        int32_t shift[3];
        for (int a = 0; a < 3; a++) {
            shift[a] = lo[a] - gs->box_lo[a];
            same = same && hi[a] - lo[a] == gs->box_hi[a] - gs->box_lo[a] &&
                   shift[a] % f->ratio == 0;
        }
        if (same) {
            physwin_t *w = &gs->win;
            for (int a = 0; a < 3; a++) {
                w->clo[a] += shift[a] / f->ratio;
                w->chi[a] += shift[a] / f->ratio;
                w->slo[a] += shift[a];
                w->shi[a] += shift[a];
            }
            memcpy(gs->box_lo, lo, sizeof(gs->box_lo));
            memcpy(gs->box_hi, hi, sizeof(gs->box_hi));
            const argil_err_t e = reload_window(gs, dt_s, true);
            if (e != ARGIL_OK) {
                close_window(gs);
                return e;
            }
            gs->stats.windows_moved++;
        } else {
            close_window(gs);
        }
    }
    if (gs->win_open && gs->stale) {
        const argil_err_t e = reload_window(gs, dt_s, false);
        if (e != ARGIL_OK)
            return e;
    }
    if (!gs->win_open) {
        int32_t clo[3], chi[3];
        for (int a = 0; a < 3; a++) {
            clo[a] = floordiv(lo[a], f->ratio);
            chi[a] = floordiv(hi[a] - 1, f->ratio) + 1;
            if (chi[a] - clo[a] < 4)
                chi[a] = clo[a] + 4;
        }
        gs->cfg.dt_s = dt_s;
        const argil_err_t e = physwin_open(&gs->win, f, clo, chi, &gs->cfg);
        if (e != ARGIL_OK)
            return e;
        gs->win_open = true;
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
    if (clip_to_grid(g, w->slo, w->shi, a0, a1)) {
        const int32_t nx = w->shi[0] - w->slo[0], ny = w->shi[1] - w->slo[1];
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++)
                for (int32_t x = a0[0]; x < a1[0]; x++) {
                    const size_t gi = (size_t)x + (size_t)g->dims[0] *
                                      ((size_t)y + (size_t)g->dims[1] * (size_t)z);
                    const size_t si = (size_t)(x - w->slo[0]) +
                                      (size_t)nx * ((size_t)(y - w->slo[1]) +
                                                    (size_t)ny * (size_t)(z - w->slo[2]));
                    s->force_n[si] = g->force[gi];
                    forced = forced || g->force[gi] != 0.0f;
                    g->force[gi] = 0.0f;
                }
    }
    /* At rest and left alone: nothing to step (and no round-off to integrate). */
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
        close_window(gs);
        return e;
    }
    gs->stats.steps++;
    gs->stats.last_cg_iters = s->stats.cg_iters;
    gs->stats.cg_iters_total += (uint64_t)s->stats.cg_iters;
    gs->stats.last_residual = s->stats.residual;
    if (s->stats.residual > gs->stats.max_residual)
        gs->stats.max_residual = s->stats.residual;
    /* d = A p + d_fixed once; plastic flow (the rest shape follows the current one at the
     * material's rate); then p, the coefficient velocity, d and the rest go back to the field
     * (what physwin_store does, without computing d twice) and d into the grid. */
    int32_t nc[3], ns[3];
    for (int a = 0; a < 3; a++) {
        nc[a] = w->chi[a] - w->clo[a];
        ns[a] = w->shi[a] - w->slo[a];
    }
    float *d = scratch(gs, s->nsamp + (s->nsamp > s->ncoef ? s->nsamp : s->ncoef));
    if (!d)
        return ARGIL_ERR_NOMEM;
    float *tmp = d + s->nsamp;
    solver_densities(s, d);
    const float plastic = gs->mat.plastic_rate_hz * dt_s > 1.0f ? 1.0f
                                                                : gs->mat.plastic_rate_hz * dt_s;
    if (plastic > 0.0f) {
        sparse_read_box(&f->samp, FS_REST, w->slo, ns, tmp);
        for (size_t i = 0; i < s->nsamp; i++) {
            const float delta = plastic * (d[i] - s->rest[i]);
            s->rest[i] += delta;
            tmp[i] += delta;
        }
        e = sparse_write_box(&f->samp, FS_REST, w->slo, ns, tmp);
    }
    const float change = dense_to_grid(g, d, w->slo, ns);
    /* Rest: no force acted and no sample of the view moved by GSOLVE_REST_DD. The velocity is
     * zeroed (CG's 8 iterations leave the B-spline's high-frequency modes, which barely show
     * in the samples, almost undamped: their round-off would otherwise drift on), and the
     * window is not stepped again until a force, a tool, the material or a new window moves
     * it. */
    gs->resting = !forced && change < GSOLVE_REST_DD;
    if (gs->resting)
        memcpy(s->p_prev, s->p, s->ncoef * sizeof(float));
    if (e == ARGIL_OK)
        e = sparse_write_box(&f->coef, FC_P, w->clo, nc, s->p);
    if (e == ARGIL_OK) {
        for (size_t i = 0; i < s->ncoef; i++)
            tmp[i] = (s->p[i] - s->p_prev[i]) / s->dt_prev_s;
        e = sparse_write_box(&f->coef, FC_V, w->clo, nc, tmp);
    }
    if (e == ARGIL_OK)
        e = sparse_write_box(&f->samp, FS_D, w->slo, ns, d);
    if (e != ARGIL_OK) {
        close_window(gs);
        return e;
    }
    *max_change = change;
    if (change > 0.0f && clip_to_grid(g, w->slo, w->shi, dlo, dhi))
        return ARGIL_OK;
    for (int a = 0; a < 3; a++)
        dlo[a] = dhi[a] = 0;
    return ARGIL_OK;
}

argil_err_t gsolve_carve_sphere(gsolve_t *gs, grid_t *g, vec3_t centre_m, float radius_m,
                                int32_t lo[3], int32_t hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = 0;
    if (!vec3_isfinite(centre_m) || !isfinite(radius_m) || !(radius_m >= 0.0f))
        return ARGIL_ERR_ARG;
    field_t *f = &gs->field;
    /* The tool changes coefficients the open window holds: reload it on the next step. */
    gs->stale = gs->win_open;
    gs->resting = false;
    tool_shape_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_SPHERE;
    t.radius_m = radius_m;
    tool_pose_t pose;
    tool_pose_at(&pose, centre_m);
    tool_params_t prm;
    tool_params_default(&prm, TOOL_CARVE);
    tool_stats_t st;
    memset(&st, 0, sizeof(st));
    const argil_err_t e = tool_apply(f, &t, &pose, &prm, NULL, &st);
    if (e != ARGIL_OK)
        return e;
    gs->stats.carves++;
    if (st.coefs_changed == 0)
        return ARGIL_OK;
    /* Samples a changed coefficient can reach: the sphere, the ramp and two knot spans. */
    const float reach_m = radius_m + f->band_m + 3.0f * f->coef_spacing_m;
    const float c[3] = {centre_m.x - f->origin_m.x, centre_m.y - f->origin_m.y,
                        centre_m.z - f->origin_m.z};
    int32_t slo[3], shi[3];
    for (int a = 0; a < 3; a++) {
        slo[a] = (int32_t)floorf((c[a] - reach_m) / f->sample_spacing_m);
        shi[a] = (int32_t)ceilf((c[a] + reach_m) / f->sample_spacing_m) + 1;
    }
    const float change = view_to_grid(gs, g, slo, shi);
    if (change < 0.0f)
        return ARGIL_ERR_NOMEM;
    if (change > 0.0f && !clip_to_grid(g, slo, shi, lo, hi))
        for (int a = 0; a < 3; a++)
            lo[a] = hi[a] = 0;
    return ARGIL_OK;
}

argil_err_t gsolve_paint(gsolve_t *gs, gsolve_material_t ch, vec3_t centre_m, float radius_m,
                         float scale)
{
    if (!isfinite(scale) || !(scale > 0.0f))
        return ARGIL_ERR_ARG;
    const argil_err_t e = material_paint(&gs->field, ch == GSOLVE_MAT_MASS ? FS_MASS : FS_STIFF,
                                         centre_m, radius_m, scale, MATERIAL_SCALE, NULL);
    if (e == ARGIL_OK && gs->win_open)
        physwin_sync_inputs(&gs->win, &gs->field);
    gs->resting = false;
    return e;
}

float gsolve_material_at(const gsolve_t *gs, gsolve_material_t ch, vec3_t x_m)
{
    const field_t *f = &gs->field;
    int32_t s[3];
    const float c[3] = {x_m.x - f->origin_m.x, x_m.y - f->origin_m.y, x_m.z - f->origin_m.z};
    for (int a = 0; a < 3; a++) {
        const float u = c[a] / f->sample_spacing_m;
        if (!isfinite(u) || fabsf(u) > (float)(SPARSE_INDEX_MAX / 2))
            return 1.0f;
        s[a] = (int32_t)lrintf(u);
    }
    return sparse_get(&f->samp, ch == GSOLVE_MAT_MASS ? FS_MASS : FS_STIFF, s[0], s[1], s[2]);
}
