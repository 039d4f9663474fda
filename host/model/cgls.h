/* CGLS: conjugate gradients on the normal equations Aᵀ A p = Aᵀ d, the least-squares fit of
 * B-spline coefficients p to samples d (Hua & Qin §6.2; the seeding of a refined field). A and
 * Aᵀ are the caller's, as callbacks, so no matrix is ever formed. */
#ifndef ARGIL_CGLS_H
#define ARGIL_CGLS_H

#include <stddef.h>

/* out = the operator applied to in. */
typedef void (*cgls_apply_fn)(void *ctx, const float *in, float *out);

typedef struct {
    cgls_apply_fn a;      /* out (rows) = A in (unknowns) */
    cgls_apply_fn at;     /* out (unknowns) = Aᵀ in (rows), 0 at every unknown held fixed */
    void *ctx;
    size_t unknowns, rows;
} cgls_op_t;

/* Up to iters CGLS iterations from p (the unknowns, updated in place); r holds d - A p on entry
 * and the residual of the returned p on return. s and q (unknowns each) and t (rows) are
 * scratch. Stops early once Aᵀ r or A q is zero. Returns the iterations done. */
int cgls_solve(const cgls_op_t *op, int iters, float *p, float *r, float *s, float *q, float *t);

#endif
