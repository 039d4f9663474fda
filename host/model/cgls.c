/* CGLS in single precision with double-precision dot products. */
#include "host/model/cgls.h"

#include <string.h>

static double cgls_dot(const float *a, const float *b, size_t n)
{
    double v = 0.0;
    for (size_t i = 0; i < n; i++)
        v += (double)a[i] * b[i];
    return v;
}

int cgls_solve(const cgls_op_t *op, int iters, float *p, float *r, float *s, float *q, float *t)
{
    const size_t nc = op->unknowns, nr = op->rows;
    op->at(op->ctx, r, s);
    memcpy(q, s, nc * sizeof(float));
    double gamma = cgls_dot(s, s, nc);
    int it = 0;
    for (; it < iters && gamma > 0.0; it++) {
        op->a(op->ctx, q, t);
        const double tt = cgls_dot(t, t, nr);
        if (!(tt > 0.0))
            break;
        const float alpha = (float)(gamma / tt);
        for (size_t i = 0; i < nc; i++)
            p[i] += alpha * q[i];
        for (size_t i = 0; i < nr; i++)
            r[i] -= alpha * t[i];
        op->at(op->ctx, r, s);
        const double gamma1 = cgls_dot(s, s, nc);
        const float beta = (float)(gamma1 / gamma);
        gamma = gamma1;
        for (size_t i = 0; i < nc; i++)
            q[i] = s[i] + beta * q[i];
    }
    return it;
}
