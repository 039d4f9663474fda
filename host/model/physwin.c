/* Window copy-in / copy-out between the sparse field and a dense solver region. */
#include "host/model/physwin.h"

#include <stdlib.h>
#include <string.h>

void physwin_sync_inputs(physwin_t *w, const field_t *f)
{
    solver_t *s = &w->solver;
    int32_t ns[3];
    for (int a = 0; a < 3; a++)
        ns[a] = w->shi[a] - w->slo[a];
    float *tmp = s->w_ns[0];
    sparse_read_box(&f->samp, FS_MASS, w->slo, ns, s->mass_kg);
    sparse_read_box(&f->samp, FS_DAMP, w->slo, ns, s->damp_n_s);
    sparse_read_box(&f->samp, FS_STIFF, w->slo, ns, s->kscale);
    sparse_read_box(&f->samp, FS_REST, w->slo, ns, s->rest);
    sparse_read_box(&f->samp, FS_RESTLEN, w->slo, ns, tmp);
    sparse_read_box(&f->samp, FS_FORCE, w->slo, ns, s->force_n);
    for (size_t i = 0; i < s->nsamp; i++) {
        s->mass_kg[i] *= f->material.mass_kg;
        s->damp_n_s[i] *= f->material.damping_n_s;
        s->rest[i] += tmp[i]; /* rest-length offset: > 0 inflates, < 0 deflates (Hua & Qin §6.3) */
    }
    s->k_rest_n = f->material.stiffness_n;
    s->coupling_n = f->material.coupling_n;
    solver_material_changed(s);
}

argil_err_t physwin_open(physwin_t *w, const field_t *f, const int32_t clo[3], const int32_t chi[3],
                         const solver_cfg_t *cfg)
{
    memset(w, 0, sizeof(*w));
    int32_t nc[3], ns[3];
    for (int a = 0; a < 3; a++) {
        nc[a] = chi[a] - clo[a];
        if (nc[a] < 4 || clo[a] < -SPARSE_INDEX_MAX / 2 || chi[a] > SPARSE_INDEX_MAX / 2)
            return ARGIL_ERR_ARG;
    }
    field_samples_of_coefs(f, clo, chi, w->slo, w->shi);
    for (int a = 0; a < 3; a++) {
        w->slo[a] -= 1;
        w->shi[a] += 1;
        ns[a] = w->shi[a] - w->slo[a];
        w->clo[a] = clo[a];
        w->chi[a] = chi[a];
    }
    solver_t *s = &w->solver;
    argil_err_t e = solver_init(s, nc, ns, cfg);
    if (e != ARGIL_OK)
        return e;
    for (int a = 0; a < 3; a++)
        for (int32_t i = 0; i < ns[a]; i++) {
            float wt[4];
            const int32_t rel = field_sample_taps(f, w->slo[a] + i, wt) - clo[a];
            int32_t cf = rel < 0 ? 0 : rel;
            if (cf > nc[a] - 4)
                cf = nc[a] - 4;
            s->tap_first[a][i] = cf;
            for (int j = 0; j < 4; j++) {
                const int32_t orig = cf + j - rel; /* which of the 4 taps this coefficient is */
                s->tap_w[a][4 * i + j] = (orig >= 0 && orig < 4) ? wt[orig] : 0.0f;
            }
        }
    float *tmp = s->w_nc[0];
    sparse_read_box(&f->coef, FC_P, clo, nc, s->p);
    sparse_read_box(&f->coef, FC_V, clo, nc, tmp);
    for (size_t i = 0; i < s->ncoef; i++)
        s->p_prev[i] = s->p[i] - tmp[i] * cfg->dt_s;
    sparse_read_box(&f->coef, FC_FIXED, clo, nc, tmp);
    for (size_t i = 0; i < s->ncoef; i++)
        s->fixed[i] = tmp[i] != 0.0f;
    /* d_fixed = d - A_1 p_1 (McDonnell et al. §7.3) */
    float *d = s->w_ns[2], *ap = s->w_ns[3];
    sparse_read_box(&f->samp, FS_D, w->slo, ns, d);
    memset(s->d_fixed, 0, sizeof(float) * s->nsamp);
    solver_densities(s, ap);
    for (size_t i = 0; i < s->nsamp; i++)
        s->d_fixed[i] = d[i] - ap[i];
    physwin_sync_inputs(w, f);
    return ARGIL_OK;
}

argil_err_t physwin_store(physwin_t *w, field_t *f)
{
    solver_t *s = &w->solver;
    int32_t nc[3], ns[3];
    for (int a = 0; a < 3; a++) {
        nc[a] = w->chi[a] - w->clo[a];
        ns[a] = w->shi[a] - w->slo[a];
    }
    argil_err_t e = sparse_write_box(&f->coef, FC_P, w->clo, nc, s->p);
    if (e != ARGIL_OK)
        return e;
    float *v = s->w_nc[0];
    for (size_t i = 0; i < s->ncoef; i++)
        v[i] = (s->p[i] - s->p_prev[i]) / s->dt_prev_s;
    e = sparse_write_box(&f->coef, FC_V, w->clo, nc, v);
    if (e != ARGIL_OK)
        return e;
    float *d = s->w_ns[2];
    solver_densities(s, d);
    return sparse_write_box(&f->samp, FS_D, w->slo, ns, d);
}

void physwin_close(physwin_t *w)
{
    solver_free(&w->solver);
}
