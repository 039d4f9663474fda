/* The B-spline density representation behind the seam (host/model/rep.h): the sparse sample grid
 * the board's windows are cut from, stepped either by the implicit B-spline solve
 * (host/solve/gsolve.h, Hua & Qin eq. 8-12) or by the grid's explicit density springs. */
#ifndef ARGIL_REP_BSPLINE_H
#define ARGIL_REP_BSPLINE_H

#include <stdbool.h>
#include <stdint.h>

#include "host/model/grid.h"
#include "host/model/rep.h"
#include "host/solve/gsolve.h"

#define REP_SPRINGS_SETTLING_MAX 4u   /* regions the springs' window left that still settle */
#define REP_SPRINGS_REST_ACCEL 1e-3f  /* |density acceleration| (1/s²) below which one rests */

typedef struct {
    grid_t *grid;                     /* the caller's; the B-spline model's view when gs is set */
    gsolve_t *gs;                     /* the implicit B-spline model, or NULL: density springs */
    spring_material_t gs_mat;         /* grid material the model last took */
    rep_box_t force;                  /* samples holding external force (hi[0] <= lo[0]: none) */
    rep_box_t region;                 /* springs: the region stepped last */
    bool have_region;
    rep_box_t settling[REP_SPRINGS_SETTLING_MAX];
    uint32_t settling_count;
} rep_bspline_t;

/* A representation over grid g (the caller's, kept): with implicit, the B-spline model with
 * knot_ratio samples per span (1, 2 or 4) seeded from the grid's densities, painted material and
 * colour, the grid becoming its view; without, the grid's density springs (only the default
 * host tool, uniform material). ARGIL_ERR_ARG, ARGIL_ERR_NOMEM (nothing is kept then). */
argil_err_t rep_bspline_init(rep_bspline_t *b, grid_t *g, bool implicit, int32_t knot_ratio);

/* The seam's view of b (valid while b is). */
rep_t rep_bspline(rep_bspline_t *b);

#endif
