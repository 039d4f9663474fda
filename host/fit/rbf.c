/* RBF implicit after Zhang et al. §5: φ(r) = r³ with a linear polynomial; for each surface sample
 * one constraint f = 0 at the sample, f = +δ at an interior point and f = -δ at an exterior point
 * along the normal, giving the (3n+4)² system [A P; Pᵀ 0][w; p] = [f; 0], solved by LU with
 * partial pivoting in double precision. */
#include "host/fit/rbf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rbf_opts_default(rbf_opts_t *o)
{
    memset(o, 0, sizeof(*o));
    o->max_surface_samples = 300;
    o->offset_m = 0.0f; /* 0 = 1 % of the bounding-box diagonal */
}

argil_err_t rbf_alloc(rbf_model_t *r, uint32_t n)
{
    memset(r, 0, sizeof(*r));
    if (n > RBF_CENTRES_MAX)
        return ARGIL_ERR_ARG;
    r->centre_m = calloc((size_t)n * 3 + 1, sizeof(float));
    r->weight = calloc((size_t)n + 1, sizeof(float));
    if (r->centre_m == NULL || r->weight == NULL) {
        rbf_free(r);
        return ARGIL_ERR_NOMEM;
    }
    r->n = n;
    return ARGIL_OK;
}

void rbf_free(rbf_model_t *r)
{
    free(r->centre_m);
    free(r->weight);
    memset(r, 0, sizeof(*r));
}

float rbf_eval(const rbf_model_t *r, vec3_t p)
{
    double f = r->poly[0] + r->poly[1] * p.x + r->poly[2] * p.y + r->poly[3] * p.z;
    for (uint32_t i = 0; i < r->n; i++) {
        const double dx = p.x - r->centre_m[3 * i], dy = p.y - r->centre_m[3 * i + 1],
                     dz = p.z - r->centre_m[3 * i + 2];
        const double d = sqrt(dx * dx + dy * dy + dz * dz);
        f += r->weight[i] * d * d * d;
    }
    return (float)f;
}

/* f and its gradient at p. */
static double rbf_eval_grad(const rbf_model_t *r, vec3_t p, double g[3])
{
    double f = r->poly[0] + r->poly[1] * p.x + r->poly[2] * p.y + r->poly[3] * p.z;
    g[0] = r->poly[1];
    g[1] = r->poly[2];
    g[2] = r->poly[3];
    for (uint32_t i = 0; i < r->n; i++) {
        const double dx = p.x - r->centre_m[3 * i], dy = p.y - r->centre_m[3 * i + 1],
                     dz = p.z - r->centre_m[3 * i + 2];
        const double d = sqrt(dx * dx + dy * dy + dz * dz);
        f += r->weight[i] * d * d * d;
        const double k = 3.0 * r->weight[i] * d;
        g[0] += k * dx;
        g[1] += k * dy;
        g[2] += k * dz;
    }
    return f;
}

/* Solves the n×n system a x = b in place (b becomes x); false when singular or stopped. */
static bool rbf_lu_solve(double *a, double *b, size_t n, const rbf_opts_t *o)
{
    for (size_t k = 0; k < n; k++) {
        if (o->stop != NULL && *o->stop)
            return false;
        if (o->progress != NULL && (k & 63) == 0) {
            const double done = 1.0 - pow((double)(n - k) / (double)n, 3.0);
            o->progress(o->progress_ctx, 0.9 * done);
        }
        size_t piv = k;
        double best = fabs(a[k * n + k]);
        for (size_t i = k + 1; i < n; i++)
            if (fabs(a[i * n + k]) > best) {
                best = fabs(a[i * n + k]);
                piv = i;
            }
        if (!(best > 1e-300))
            return false;
        if (piv != k) {
            for (size_t j = 0; j < n; j++) {
                const double t = a[k * n + j];
                a[k * n + j] = a[piv * n + j];
                a[piv * n + j] = t;
            }
            const double t = b[k];
            b[k] = b[piv];
            b[piv] = t;
        }
        const double inv = 1.0 / a[k * n + k];
        for (size_t i = k + 1; i < n; i++) {
            const double m = a[i * n + k] * inv;
            if (m == 0.0)
                continue;
            double *ri = a + i * n, *rk = a + k * n;
            for (size_t j = k + 1; j < n; j++)
                ri[j] -= m * rk[j];
            b[i] -= m * b[k];
        }
    }
    for (size_t k = n; k-- > 0;) {
        double s = b[k];
        for (size_t j = k + 1; j < n; j++)
            s -= a[k * n + j] * b[j];
        b[k] = s / a[k * n + k];
    }
    return true;
}

argil_err_t rbf_fit(const mesh_t *pts, const rbf_opts_t *o, rbf_model_t *out)
{
    memset(out, 0, sizeof(*out));
    if (pts == NULL || o == NULL || pts->n_vert < 4 || pts->normal == NULL)
        return ARGIL_ERR_ARG;
    const size_t np = pts->n_vert;
    vec3_t lo = vec3(INFINITY, INFINITY, INFINITY), hi = vec3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t i = 0; i < np; i++) {
        const float *p = pts->pos + 3 * i, *n = pts->normal + 3 * i;
        for (int k = 0; k < 3; k++)
            if (!isfinite(p[k]) || !isfinite(n[k]))
                return ARGIL_ERR_ARG;
        lo = vec3(fminf(lo.x, p[0]), fminf(lo.y, p[1]), fminf(lo.z, p[2]));
        hi = vec3(fmaxf(hi.x, p[0]), fmaxf(hi.y, p[1]), fmaxf(hi.z, p[2]));
    }
    const float diag = vec3_norm(vec3_sub(hi, lo));
    const float delta = o->offset_m > 0.0f ? o->offset_m : 0.01f * diag;
    size_t m = o->max_surface_samples < 2 ? 2 : o->max_surface_samples;
    if (m > np)
        m = np;
    if (3 * m > RBF_CENTRES_MAX)
        m = RBF_CENTRES_MAX / 3;
    const size_t nc = 3 * m, n = nc + 4;
    argil_err_t e = rbf_alloc(out, (uint32_t)nc);
    if (e != ARGIL_OK)
        return e;
    double *a = malloc(n * n * sizeof(double));
    double *b = malloc(n * sizeof(double));
    if (a == NULL || b == NULL) {
        free(a);
        free(b);
        rbf_free(out);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t s = 0; s < m; s++) {
        const size_t i = s * np / m; /* spread evenly over the cloud */
        const float *p = pts->pos + 3 * i, *nn = pts->normal + 3 * i;
        const float off[3] = {0.0f, -delta, delta}; /* on, interior (+), exterior (-) */
        for (int k = 0; k < 3; k++) {
            float *c = out->centre_m + 3 * (3 * s + (size_t)k);
            for (int q = 0; q < 3; q++)
                c[q] = p[q] + off[k] * nn[q];
            b[3 * s + (size_t)k] = k == 0 ? 0.0 : (k == 1 ? delta : -delta);
        }
    }
    for (size_t i = 0; i < nc; i++) {
        const float *ci = out->centre_m + 3 * i;
        for (size_t j = 0; j < nc; j++) {
            const float *cj = out->centre_m + 3 * j;
            const double dx = ci[0] - cj[0], dy = ci[1] - cj[1], dz = ci[2] - cj[2];
            const double d = sqrt(dx * dx + dy * dy + dz * dz);
            a[i * n + j] = d * d * d;
        }
        a[i * n + nc] = 1.0;
        for (int q = 0; q < 3; q++)
            a[i * n + nc + 1 + (size_t)q] = ci[q];
        a[nc * n + i] = 1.0;
        for (int q = 0; q < 3; q++)
            a[(nc + 1 + (size_t)q) * n + i] = ci[q];
    }
    for (size_t i = nc; i < n; i++) {
        for (size_t j = nc; j < n; j++)
            a[i * n + j] = 0.0;
        b[i] = 0.0;
    }
    const bool ok = rbf_lu_solve(a, b, n, o);
    free(a);
    if (!ok) {
        free(b);
        rbf_free(out);
        return ARGIL_ERR_STATE;
    }
    for (size_t i = 0; i < nc; i++)
        out->weight[i] = (float)b[i];
    for (int q = 0; q < 4; q++)
        out->poly[q] = (float)b[nc + (size_t)q];
    free(b);
    double sum2 = 0, mx = 0;
    for (size_t i = 0; i < np; i++) {
        if ((i & 1023) == 0 && o->progress != NULL)
            o->progress(o->progress_ctx, 0.9 + 0.1 * (double)i / (double)np);
        double g[3];
        const float *p = pts->pos + 3 * i;
        const double f = rbf_eval_grad(out, vec3(p[0], p[1], p[2]), g);
        const double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        const double d = gl > 1e-30 ? fabs(f) / gl : fabs(f);
        sum2 += d * d;
        if (d > mx)
            mx = d;
    }
    out->rms_err_m = (float)sqrt(sum2 / (double)np);
    out->max_err_m = (float)mx;
    return ARGIL_OK;
}
