/* Non-uniform cubic tensor-product B-splines: Cox-de Boor basis, evaluation with the analytic
 * gradient, and Boehm's knot insertion (Hua & Qin §3.2: knots inserted during a session). */
#include "host/model/bspline.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static size_t bspline_count(const int32_t n[3])
{
    return (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
}

argil_err_t bspline_init(bspline_t *b, const int32_t n[3], const double *const knots[3])
{
    memset(b, 0, sizeof(*b));
    int64_t total = 1;
    for (int a = 0; a < 3; a++) {
        if (n[a] < BSPLINE_ORDER || knots[a] == NULL)
            return ARGIL_ERR_ARG;
        total *= n[a];
        if (total > BSPLINE_COEFS_MAX)
            return ARGIL_ERR_ARG;
        for (int32_t i = 0; i < n[a] + BSPLINE_ORDER; i++) {
            if (!isfinite(knots[a][i]) || (i > 0 && knots[a][i] < knots[a][i - 1]))
                return ARGIL_ERR_ARG;
        }
        if (!(knots[a][n[a]] > knots[a][3]))
            return ARGIL_ERR_ARG;
    }
    for (int a = 0; a < 3; a++) {
        b->knots[a] = malloc(sizeof(double) * (size_t)(n[a] + BSPLINE_ORDER));
        if (b->knots[a] == NULL) {
            bspline_free(b);
            return ARGIL_ERR_NOMEM;
        }
        memcpy(b->knots[a], knots[a], sizeof(double) * (size_t)(n[a] + BSPLINE_ORDER));
        b->n[a] = n[a];
    }
    b->coef = calloc(bspline_count(n), sizeof(float));
    if (b->coef == NULL) {
        bspline_free(b);
        return ARGIL_ERR_NOMEM;
    }
    return ARGIL_OK;
}

argil_err_t bspline_init_uniform(bspline_t *b, const int32_t n[3], const double lo[3],
                                 const double hi[3])
{
    double *k[3] = {NULL, NULL, NULL};
    argil_err_t err = ARGIL_OK;
    for (int a = 0; a < 3 && err == ARGIL_OK; a++) {
        if (n[a] < BSPLINE_ORDER || n[a] > BSPLINE_COEFS_MAX || !isfinite(lo[a]) ||
            !isfinite(hi[a]) || !(hi[a] > lo[a])) {
            err = ARGIL_ERR_ARG;
            break;
        }
        k[a] = malloc(sizeof(double) * (size_t)(n[a] + BSPLINE_ORDER));
        if (k[a] == NULL) {
            err = ARGIL_ERR_NOMEM;
            break;
        }
        const double h = (hi[a] - lo[a]) / (double)(n[a] - 3);
        for (int32_t i = 0; i < n[a] + BSPLINE_ORDER; i++)
            k[a][i] = lo[a] + h * (double)(i - 3);
    }
    if (err == ARGIL_OK) {
        const double *const kc[3] = {k[0], k[1], k[2]};
        err = bspline_init(b, n, kc);
    } else {
        memset(b, 0, sizeof(*b));
    }
    for (int a = 0; a < 3; a++)
        free(k[a]);
    return err;
}

void bspline_free(bspline_t *b)
{
    for (int a = 0; a < 3; a++) {
        free(b->knots[a]);
        b->knots[a] = NULL;
        b->n[a] = 0;
    }
    free(b->coef);
    b->coef = NULL;
}

int32_t bspline_span(const double *knots, int32_t n, double t)
{
    if (!isfinite(t) || t < knots[3] || t > knots[n])
        return -1;
    if (t >= knots[n]) {
        int32_t s = n - 1;
        while (s > 3 && !(knots[s] < knots[s + 1]))
            s--;
        return s;
    }
    int32_t lo = 3, hi = n;
    while (hi - lo > 1) {
        const int32_t mid = (lo + hi) / 2;
        if (t < knots[mid])
            hi = mid;
        else
            lo = mid;
    }
    return lo;
}

void bspline_basis(const double *knots, int32_t span, double t, double N[4], double dN[4])
{
    double left[4], right[4], n2[3] = {0.0, 0.0, 0.0};
    N[0] = 1.0;
    for (int j = 1; j <= 3; j++) {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        double saved = 0.0;
        for (int r = 0; r < j; r++) {
            const double den = right[r + 1] + left[j - r];
            const double tmp = den != 0.0 ? N[r] / den : 0.0;
            N[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        N[j] = saved;
        if (j == 2)
            memcpy(n2, N, sizeof(n2));
    }
    if (dN == NULL)
        return;
    /* N'_{i,3} = 3 (N_{i,2} / (u_{i+3} - u_i) - N_{i+1,2} / (u_{i+4} - u_{i+1})) */
    for (int r = 0; r < 4; r++) {
        const int32_t i = span - 3 + r;
        double d = 0.0;
        if (r >= 1) {
            const double den = knots[i + 3] - knots[i];
            if (den > 0.0)
                d += n2[r - 1] / den;
        }
        if (r <= 2) {
            const double den = knots[i + 4] - knots[i + 1];
            if (den > 0.0)
                d -= n2[r] / den;
        }
        dN[r] = 3.0 * d;
    }
}

double bspline_eval(const bspline_t *b, const double uvw[3], double grad[3])
{
    int32_t span[3];
    double N[3][4], dN[3][4];
    if (grad != NULL)
        grad[0] = grad[1] = grad[2] = 0.0;
    for (int a = 0; a < 3; a++) {
        span[a] = bspline_span(b->knots[a], b->n[a], uvw[a]);
        if (span[a] < 0)
            return 0.0;
        bspline_basis(b->knots[a], span[a], uvw[a], N[a], dN[a]);
    }
    const int32_t nx = b->n[0], ny = b->n[1];
    double v = 0.0, gx = 0.0, gy = 0.0, gz = 0.0; /* Hua & Qin eq. 1 */
    for (int k = 0; k < 4; k++) {
        const int32_t z = span[2] - 3 + k;
        for (int j = 0; j < 4; j++) {
            const int32_t y = span[1] - 3 + j;
            const float *row = b->coef + (size_t)nx * ((size_t)y + (size_t)ny * (size_t)z);
            double s = 0.0, sx = 0.0;
            for (int i = 0; i < 4; i++) {
                const double c = (double)row[span[0] - 3 + i];
                s += c * N[0][i];
                sx += c * dN[0][i];
            }
            v += s * N[1][j] * N[2][k];
            gx += sx * N[1][j] * N[2][k];
            gy += s * dN[1][j] * N[2][k];
            gz += s * N[1][j] * dN[2][k];
        }
    }
    if (grad != NULL) {
        grad[0] = gx;
        grad[1] = gy;
        grad[2] = gz;
    }
    return v;
}

argil_err_t bspline_insert_knot(bspline_t *b, int axis, double t)
{
    if (axis < 0 || axis > 2)
        return ARGIL_ERR_ARG;
    const int32_t n = b->n[axis];
    const double *U = b->knots[axis];
    if (!isfinite(t) || !(t > U[3]) || !(t < U[n]))
        return ARGIL_ERR_ARG;
    int32_t nn[3] = {b->n[0], b->n[1], b->n[2]};
    nn[axis] = n + 1;
    if ((int64_t)nn[0] * nn[1] * nn[2] > BSPLINE_COEFS_MAX)
        return ARGIL_ERR_ARG;
    const int32_t k = bspline_span(U, n, t);
    double *nk = malloc(sizeof(double) * (size_t)(n + 1 + BSPLINE_ORDER));
    float *nc = malloc(sizeof(float) * bspline_count(nn));
    if (nk == NULL || nc == NULL) {
        free(nk);
        free(nc);
        return ARGIL_ERR_NOMEM;
    }
    /* Boehm: Q_i = a_i P_i + (1 - a_i) P_{i-1}, a_i = (t - u_i) / (u_{i+3} - u_i), k-2 <= i <= k */
    double alpha[3];
    for (int32_t i = k - 2; i <= k; i++) {
        const double den = U[i + 3] - U[i];
        alpha[i - (k - 2)] = den > 0.0 ? (t - U[i]) / den : 0.0;
    }
    const size_t stride_old[3] = {1, (size_t)b->n[0], (size_t)b->n[0] * (size_t)b->n[1]};
    const size_t stride_new[3] = {1, (size_t)nn[0], (size_t)nn[0] * (size_t)nn[1]};
    const int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
    for (int32_t q = 0; q < b->n[o2]; q++) {
        for (int32_t r = 0; r < b->n[o1]; r++) {
            const float *src = b->coef + (size_t)r * stride_old[o1] + (size_t)q * stride_old[o2];
            float *dst = nc + (size_t)r * stride_new[o1] + (size_t)q * stride_new[o2];
            const size_t so = stride_old[axis], sn = stride_new[axis];
            for (int32_t i = 0; i <= n; i++) {
                double v;
                if (i <= k - 3)
                    v = (double)src[(size_t)i * so];
                else if (i <= k) {
                    const double a = alpha[i - (k - 2)];
                    v = a * (double)src[(size_t)i * so] + (1.0 - a) * (double)src[(size_t)(i - 1) * so];
                } else
                    v = (double)src[(size_t)(i - 1) * so];
                dst[(size_t)i * sn] = (float)v;
            }
        }
    }
    for (int32_t i = 0; i <= k; i++)
        nk[i] = U[i];
    nk[k + 1] = t;
    for (int32_t i = k + 1; i < n + BSPLINE_ORDER; i++)
        nk[i + 1] = U[i];
    free(b->knots[axis]);
    free(b->coef);
    b->knots[axis] = nk;
    b->coef = nc;
    b->n[axis] = n + 1;
    return ARGIL_OK;
}
