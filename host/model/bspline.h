/* Trivariate cubic scalar B-spline patch with non-uniform knot vectors (Hua & Qin §3.1 eq. 1):
 * the geometry the CSG tree combines and the solver's region can be built from. */
#ifndef ARGIL_BSPLINE_H
#define ARGIL_BSPLINE_H

#include <stdint.h>

#include "shared/argil_err.h"

#define BSPLINE_ORDER 4          /* cubic: 4 non-zero basis functions per parameter value */
#define BSPLINE_COEFS_MAX ((int64_t)1 << 28)

/* n[a] coefficients per axis, knots[a] holds n[a] + 4 non-decreasing values; the patch is
 * defined on [knots[a][3], knots[a][n[a]]] and is zero outside it. coef x fastest. */
typedef struct {
    int32_t n[3];
    double *knots[3];
    float *coef;
} bspline_t;

/* Allocates a patch with the given knot vectors (copied) and all coefficients 0. ARGIL_ERR_ARG
 * for n < 4, decreasing or non-finite knots, an empty domain or too many coefficients. */
argil_err_t bspline_init(bspline_t *b, const int32_t n[3], const double *const knots[3]);

/* Uniform knots with the valid domain [lo[a], hi[a]] split into n[a] - 3 equal spans. */
argil_err_t bspline_init_uniform(bspline_t *b, const int32_t n[3], const double lo[3],
                                 const double hi[3]);

void bspline_free(bspline_t *b);

/* Index of the span holding t: knots[span] <= t < knots[span+1], clamped into [3, n-1];
 * -1 when t is outside the valid domain (or not finite). */
int32_t bspline_span(const double *knots, int32_t n, double t);

/* The 4 non-zero cubic basis values N[span-3+i](t) and their derivatives (Cox-de Boor). */
void bspline_basis(const double *knots, int32_t span, double t, double N[4], double dN[4]);

/* Value at parameter uvw; grad (may be NULL) receives the analytic parametric gradient.
 * 0 (and a zero gradient) outside the domain. */
double bspline_eval(const bspline_t *b, const double uvw[3], double grad[3]);

/* Boehm's knot insertion of t on one axis: one more coefficient layer, same function.
 * ARGIL_ERR_ARG for an axis outside 0..2 or t outside the open domain; ARGIL_ERR_NOMEM. */
argil_err_t bspline_insert_knot(bspline_t *b, int axis, double t);

#endif
