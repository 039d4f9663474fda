/* Constraint rows from the uniform B-spline basis at a point. */
#include "host/model/constraints.h"

#include <math.h>
#include <string.h>

argil_err_t constraint_row(const physwin_t *w, const field_t *f, vec3_t x_m, float density,
                           solver_row_t *row)
{
    if (!vec3_isfinite(x_m) || !isfinite(density))
        return ARGIL_ERR_NONFINITE;
    int32_t lo[3];
    float wt[3][4];
    if (!field_point_taps(f, x_m, lo, wt))
        return ARGIL_ERR_ARG;
    memset(row, 0, sizeof(*row));
    float outside = 0.0f;
    const int32_t *nc = w->solver.nc;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                const int32_t c[3] = {lo[0] + i, lo[1] + j, lo[2] + k};
                const float wgt = wt[0][i] * wt[1][j] * wt[2][k];
                const int32_t r[3] = {c[0] - w->clo[0], c[1] - w->clo[1], c[2] - w->clo[2]};
                if (r[0] < 0 || r[1] < 0 || r[2] < 0 || r[0] >= nc[0] || r[1] >= nc[1] || r[2] >= nc[2]) {
                    /* fixed part of the row moves to the target side */
                    outside += wgt * sparse_get(&f->coef, FC_P, c[0], c[1], c[2]);
                    continue;
                }
                if (wgt == 0.0f)
                    continue;
                row->idx[row->n] = r[0] + nc[0] * (r[1] + nc[1] * r[2]);
                row->w[row->n] = wgt;
                row->n++;
            }
    if (row->n == 0)
        return ARGIL_ERR_ARG;
    row->target = density - outside;
    return ARGIL_OK;
}

argil_err_t constraint_point(physwin_t *w, const field_t *f, vec3_t x_m, float density, float k_n)
{
    if (!isfinite(k_n) || !(k_n > 0.0f))
        return ARGIL_ERR_ARG;
    solver_row_t row;
    argil_err_t e = constraint_row(w, f, x_m, density, &row);
    if (e != ARGIL_OK)
        return e;
    row.k_n = k_n;
    return solver_add_soft(&w->solver, &row);
}

argil_err_t constraint_curve(physwin_t *w, const field_t *f, const vec3_t *pts_m, size_t n,
                             float density, float k_n, float step_m)
{
    if (pts_m == NULL || n < 2 || !isfinite(step_m) || !(step_m > 0.0f))
        return ARGIL_ERR_ARG;
    argil_err_t e = constraint_point(w, f, pts_m[0], density, k_n);
    for (size_t i = 1; i < n && e == ARGIL_OK; i++) {
        const vec3_t d = vec3_sub(pts_m[i], pts_m[i - 1]);
        const float len = vec3_norm(d);
        if (!isfinite(len))
            return ARGIL_ERR_NONFINITE;
        const int32_t k = (int32_t)ceilf(len / step_m);
        if (k > 100000)
            return ARGIL_ERR_ARG;
        for (int32_t j = 1; j <= k && e == ARGIL_OK; j++)
            e = constraint_point(w, f, vec3_add(pts_m[i - 1], vec3_scale(d, (float)j / (float)k)), density, k_n);
    }
    return e;
}

argil_err_t constraint_hard_point(physwin_t *w, const field_t *f, vec3_t x_m, float density)
{
    solver_row_t row;
    argil_err_t e = constraint_row(w, f, x_m, density, &row);
    if (e != ARGIL_OK)
        return e;
    return solver_add_hard(&w->solver, &row);
}
