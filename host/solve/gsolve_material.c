/* The model's material: the base taken from the grid's, painted stiffness and mass scales,
 * and the painted channels mirrored to and from the grid's (.argil MTLS, journal). */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/material.h"

/* The grid's material becomes the field's base; an open window reads it at once. */
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

/* Paints a stiffness or mass scale; the open window reads it at once. */
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

/* The painted scale at the sample nearest x_m; 1 beyond the lattice's index range. */
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

/* The painted scale over a box into out; true when any is not 1. */
bool gsolve_material_box(const gsolve_t *gs, gsolve_material_t ch, const int32_t lo[3],
                         const int32_t dims[3], float *out)
{
    const int32_t n = dims[0] * dims[1] * dims[2];
    for (int32_t i = 0; i < n; i++)
        out[i] = 1.0f; /* what a refused box reads */
    sparse_read_box(&gs->field.samp, ch == GSOLVE_MAT_MASS ? FS_MASS : FS_STIFF, lo, dims, out);
    bool painted = false;
    for (int32_t i = 0; i < n; i++)
        painted |= out[i] != 1.0f;
    return painted;
}

/* The field channel each of the grid's material channels mirrors. */
static const int GSOLVE_GRID_MAT_FS[GRID_MAT_N] = {FS_STIFF, FS_MASS, FS_DAMP, FS_RESTLEN};

/* The model's painted channels in [lo, hi) mirrored into the grid's, bit for bit. */
argil_err_t gsolve_material_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                    const int32_t hi[3])
{
    int32_t a0[3], a1[3], n[3];
    if (!grid_clip(g, lo, hi, a0, a1))
        return ARGIL_OK;
    for (int a = 0; a < 3; a++)
        n[a] = a1[a] - a0[a];
    const size_t vol = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    float *v = malloc(2 * vol * sizeof(float));
    if (v == NULL)
        return ARGIL_ERR_NOMEM;
    float *old = v + vol;
    bool changed = false;
    argil_err_t e = ARGIL_OK;
    for (int ch = 0; ch < GRID_MAT_N && e == ARGIL_OK; ch++) {
        sparse_read_box(&gs->field.samp, GSOLVE_GRID_MAT_FS[ch], a0, n, v);
        grid_mat_read_box(g, (grid_mat_t)ch, a0, n, old);
        if (memcmp(old, v, vol * sizeof(float)) == 0)
            continue;
        e = grid_mat_write_box(g, (grid_mat_t)ch, a0, n, v);
        changed = changed || e == ARGIL_OK;
    }
    free(v);
    if (changed)
        g->mat_writes++;
    return e;
}

/* The grid's painted channels become the model's. */
argil_err_t gsolve_material_from_grid(gsolve_t *gs, const grid_t *g)
{
    int32_t lo[3], n[3];
    bool any = false;
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        if (!grid_mat_painted(g, (grid_mat_t)ch))
            continue;
        float *m = grid_dense_copy_mat(g, (grid_mat_t)ch, lo, n);
        if (m == NULL)
            return ARGIL_ERR_NOMEM;
        const argil_err_t e = sparse_write_box(&gs->field.samp, GSOLVE_GRID_MAT_FS[ch], lo, n, m);
        free(m);
        if (e != ARGIL_OK)
            return e;
        any = true;
    }
    if (any && gs->win_open)
        physwin_sync_inputs(&gs->win, &gs->field);
    gs->resting = false;
    return ARGIL_OK;
}
