/* Seeding the field from the grid's densities (a new session, a loaded model):
 * quasi-interpolation, then at R > 1 a least-squares fit (CGLS); the result is the rest shape
 * and the grid shows it. */
#include "host/solve/gsolve.h"

#include <stdlib.h>
#include <string.h>

#include "host/model/cgls.h"
#include "host/solve/gsolve_internal.h"

/* A and Aᵀ of seed_fit's least squares: the field's samples in [a0, a1) of coefficients in the
 * box at clo of nc. */
typedef struct {
    const field_t *f;
    const int32_t *a0, *a1, *clo, *nc;
    float *tmp;
} seed_fit_op_t;

/* A p: the field's samples of the coefficients p. */
static void seed_fit_a(void *ctx, const float *p, float *out)
{
    const seed_fit_op_t *o = ctx;
    field_samples_from(o->f, p, o->clo, o->nc, o->a0, o->a1, out, o->tmp);
}

/* Aᵀ r: what the sample residuals r give each coefficient. */
static void seed_fit_at(void *ctx, const float *r, float *out)
{
    const seed_fit_op_t *o = ctx;
    field_coefs_from(o->f, r, o->a0, o->a1, o->clo, o->nc, out, o->tmp);
}

/* Least squares for R > 1: GSOLVE_SEED_FIT_ITERS of CGLS on A p = d over the grid's samples in
 * [lo, hi), from the quasi-interpolant already in the field (the coefficients those samples
 * depend on are free). */
static argil_err_t seed_fit(field_t *f, const grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    int32_t a0[3], a1[3], clo[3], chi[3], nc[3], ns[3];
    if (!grid_clip(g, lo, hi, a0, a1))
        return ARGIL_OK;
    field_coefs_of_samples(f, a0, a1, clo, chi);
    size_t ncoef = 1, nsamp = 1;
    for (int a = 0; a < 3; a++) {
        nc[a] = chi[a] - clo[a];
        ns[a] = a1[a] - a0[a];
        ncoef *= (size_t)nc[a];
        nsamp *= (size_t)ns[a];
    }
    /* What field_samples_from and field_coefs_from need as scratch (field.h). */
    const size_t tmp_a = (size_t)ns[0] * nc[1] * nc[2] + (size_t)ns[0] * ns[1] * nc[2];
    const size_t tmp_at = (size_t)nc[0] * ns[1] * ns[2] + (size_t)nc[0] * nc[1] * ns[2];
    float *buf = malloc((3 * ncoef + 2 * nsamp + (tmp_a > tmp_at ? tmp_a : tmp_at)) *
                        sizeof(float));
    if (!buf)
        return ARGIL_ERR_NOMEM;
    float *P = buf, *S = P + ncoef, *Q = S + ncoef, *Rs = Q + ncoef, *T = Rs + nsamp,
          *tmp = T + nsamp;
    sparse_read_box(&f->coef, FC_P, clo, nc, P);
    field_samples_from(f, P, clo, nc, a0, a1, Rs, tmp);
    for (int32_t z = 0, k = 0; z < ns[2]; z++)
        for (int32_t y = 0; y < ns[1]; y++)
            for (int32_t x = 0; x < ns[0]; x++, k++)
                Rs[k] = grid_get(g, GRID_DENSITY, a0[0] + x, a0[1] + y, a0[2] + z) - Rs[k];
    seed_fit_op_t o = {f, a0, a1, clo, nc, tmp};
    const cgls_op_t op = {seed_fit_a, seed_fit_at, &o, ncoef, nsamp};
    (void)cgls_solve(&op, GSOLVE_SEED_FIT_ITERS, P, Rs, S, Q, T);
    const argil_err_t e = sparse_write_box(&f->coef, FC_P, clo, nc, P);
    free(buf);
    return e;
}

/* The field fitted to the grid in [lo, hi) and made the rest shape; the grid shows it. */
argil_err_t gsolve_seed_from_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    field_t *f = &gs->field;
    int32_t clo[3], chi[3], nc[3], slo[3], shi[3], ns[3];
    for (int a = 0; a < 3; a++)
        if (hi[a] <= lo[a])
            return ARGIL_ERR_ARG;
    gsolve_close_window(gs);
    field_coefs_of_samples(f, lo, hi, clo, chi);
    size_t ncoef = 1, nsamp = 1;
    field_samples_of_coefs(f, clo, chi, slo, shi);
    for (int a = 0; a < 3; a++) {
        nc[a] = chi[a] - clo[a];
        ns[a] = shi[a] - slo[a];
        ncoef *= (size_t)nc[a];
        nsamp *= (size_t)ns[a];
    }
    float *p = gsolve_scratch(gs, ncoef > nsamp ? ncoef : nsamp);
    if (!p)
        return ARGIL_ERR_NOMEM;
    /* Quasi-interpolation: coefficient c takes the density at its own sample R c. */
    size_t k = 0;
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t y = 0; y < nc[1]; y++)
            for (int32_t x = 0; x < nc[0]; x++, k++) {
                const int32_t s[3] = {(clo[0] + x) * f->ratio, (clo[1] + y) * f->ratio,
                                      (clo[2] + z) * f->ratio};
                p[k] = grid_get(g, GRID_DENSITY, s[0], s[1], s[2]);
            }
    argil_err_t e = sparse_write_box(&f->coef, FC_P, clo, nc, p);
    if (e == ARGIL_OK) {
        memset(p, 0, ncoef * sizeof(float));
        e = sparse_write_box(&f->coef, FC_V, clo, nc, p);
    }
    if (e == ARGIL_OK && f->ratio > 1)
        e = seed_fit(f, g, lo, hi);
    if (e == ARGIL_OK)
        e = field_refresh(f, slo, shi);
    if (e != ARGIL_OK)
        return e;
    p = gsolve_scratch(gs, nsamp); /* field_refresh may not move it, but re-take it anyway */
    if (!p)
        return ARGIL_ERR_NOMEM;
    sparse_read_box(&f->samp, FS_D, slo, ns, p);
    e = sparse_write_box(&f->samp, FS_REST, slo, ns, p);
    if (e != ARGIL_OK)
        return e;
    if (gsolve_view_to_grid(gs, g, slo, shi) < 0.0f)
        return ARGIL_ERR_NOMEM;
    int32_t a0[3], a1[3];
    if (grid_clip(g, slo, shi, a0, a1))
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++)
                for (int32_t x = a0[0]; x < a1[0]; x++) {
                    if (grid_set(g, GRID_REST, x, y, z, grid_get(g, GRID_DENSITY, x, y, z)) !=
                            ARGIL_OK ||
                        grid_set(g, GRID_VELOCITY, x, y, z, 0.0f) != ARGIL_OK)
                        return ARGIL_ERR_NOMEM;
                }
    return ARGIL_OK;
}
