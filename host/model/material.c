/* Painting of per-sample material scales and per-coefficient fixed flags. */
#include "host/model/material.h"

#include <math.h>
#include <stdlib.h>

/* Lattice box (spacing h) covering the ball; false when it is empty or too large. */
static bool material_box(const field_t *f, float h, vec3_t c, float r, int32_t lo[3], int32_t n[3])
{
    const float cc[3] = {c.x, c.y, c.z}, o[3] = {f->origin_m.x, f->origin_m.y, f->origin_m.z};
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        const double l = ceil(((double)cc[a] - r - o[a]) / h), hi = floor(((double)cc[a] + r - o[a]) / h);
        if (!isfinite(l) || !isfinite(hi) || fabs(l) > SPARSE_INDEX_MAX / 4 || fabs(hi) > SPARSE_INDEX_MAX / 4 || hi < l)
            return false;
        lo[a] = (int32_t)l;
        n[a] = (int32_t)(hi - l) + 1;
        vol *= n[a];
        if (vol > ((int64_t)1 << 26))
            return false;
    }
    return true;
}

/* Closes the open undo step (whatever was changed, even partly, is one step); the first error wins. */
static argil_err_t material_done(undo_t *u, const field_t *f, argil_err_t e)
{
    if (u == NULL)
        return e;
    const argil_err_t ec = undo_commit(u, f);
    return e != ARGIL_OK ? e : ec;
}

argil_err_t material_paint(field_t *f, int ch, vec3_t centre_m, float radius_m, float amount,
                           material_mode_t mode, undo_t *u)
{
    if (ch != FS_MASS && ch != FS_DAMP && ch != FS_STIFF && ch != FS_RESTLEN)
        return ARGIL_ERR_ARG;
    if (!isfinite(radius_m) || !(radius_m > 0.0f) || (mode != MATERIAL_ADD && mode != MATERIAL_SCALE))
        return ARGIL_ERR_ARG;
    if (!vec3_isfinite(centre_m) || !isfinite(amount))
        return ARGIL_ERR_NONFINITE;
    int32_t lo[3], n[3];
    if (!material_box(f, f->sample_spacing_m, centre_m, radius_m, lo, n))
        return ARGIL_ERR_ARG;
    const int32_t hi[3] = {lo[0] + n[0], lo[1] + n[1], lo[2] + n[2]};
    argil_err_t e;
    if (u != NULL && (e = undo_begin(u, f, lo, lo, 0, lo, hi, 1u << ch)) != ARGIL_OK)
        return e;
    const size_t vol = (size_t)n[0] * n[1] * n[2];
    float *v = malloc(sizeof(float) * vol);
    if (v == NULL)
        return material_done(u, f, ARGIL_ERR_NOMEM);
    sparse_read_box(&f->samp, ch, lo, n, v);
    size_t i = 0;
    for (int32_t z = 0; z < n[2]; z++)
        for (int32_t y = 0; y < n[1]; y++)
            for (int32_t x = 0; x < n[0]; x++, i++) {
                const int32_t s[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                const float dist = vec3_norm(vec3_sub(field_sample_pos(f, s), centre_m));
                if (dist >= radius_m)
                    continue;
                const float w = 1.0f - dist / radius_m; /* Hua & Qin §6.3: linear falloff */
                v[i] = mode == MATERIAL_ADD ? v[i] + amount * w : v[i] * (1.0f + (amount - 1.0f) * w);
                if (ch == FS_MASS && !(v[i] > 1.0e-6f))
                    v[i] = 1.0e-6f;
                if ((ch == FS_DAMP || ch == FS_STIFF) && v[i] < 0.0f)
                    v[i] = 0.0f;
            }
    e = sparse_write_box(&f->samp, ch, lo, n, v);
    free(v);
    return material_done(u, f, e);
}

argil_err_t material_fix(field_t *f, vec3_t centre_m, float radius_m, bool fixed, undo_t *u)
{
    if (!isfinite(radius_m) || !(radius_m > 0.0f))
        return ARGIL_ERR_ARG;
    if (!vec3_isfinite(centre_m))
        return ARGIL_ERR_NONFINITE;
    int32_t lo[3], n[3];
    if (!material_box(f, f->coef_spacing_m, centre_m, radius_m, lo, n))
        return ARGIL_ERR_ARG;
    const int32_t hi[3] = {lo[0] + n[0], lo[1] + n[1], lo[2] + n[2]};
    argil_err_t e = ARGIL_OK;
    if (u != NULL && (e = undo_begin(u, f, lo, hi, (1u << FC_FIXED) | (1u << FC_V), lo, lo, 0)) != ARGIL_OK)
        return e;
    for (int32_t z = 0; z < n[2] && e == ARGIL_OK; z++)
        for (int32_t y = 0; y < n[1] && e == ARGIL_OK; y++)
            for (int32_t x = 0; x < n[0] && e == ARGIL_OK; x++) {
                const int32_t c[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                if (vec3_norm(vec3_sub(field_coef_pos(f, c), centre_m)) > radius_m)
                    continue;
                e = sparse_set(&f->coef, FC_FIXED, c[0], c[1], c[2], fixed ? 1.0f : 0.0f);
                if (e == ARGIL_OK && fixed)
                    e = sparse_set(&f->coef, FC_V, c[0], c[1], c[2], 0.0f);
            }
    return material_done(u, f, e);
}

argil_err_t material_reset_rest(field_t *f, const int32_t slo[3], const int32_t shi[3], undo_t *u)
{
    int32_t n[3];
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        n[a] = shi[a] - slo[a];
        if (n[a] < 1)
            return ARGIL_ERR_ARG;
        vol *= n[a];
        if (vol > ((int64_t)1 << 26))
            return ARGIL_ERR_ARG;
    }
    argil_err_t e;
    if (u != NULL && (e = undo_begin(u, f, slo, slo, 0, slo, shi, (1u << FS_REST) | (1u << FS_RESTLEN))) != ARGIL_OK)
        return e;
    float *v = malloc(sizeof(float) * (size_t)vol);
    if (v == NULL)
        return material_done(u, f, ARGIL_ERR_NOMEM);
    sparse_read_box(&f->samp, FS_D, slo, n, v);
    e = sparse_write_box(&f->samp, FS_REST, slo, n, v); /* elastic → plastic (McDonnell §7.3) */
    for (int64_t i = 0; i < vol; i++)
        v[i] = 0.0f;
    if (e == ARGIL_OK)
        e = sparse_write_box(&f->samp, FS_RESTLEN, slo, n, v);
    free(v);
    return material_done(u, f, e);
}
