/* Constraints on the physical window (Hua & Qin §6.3): point and curve constraint springs
 * (soft: a stiff spring between (x, d) and (x, d')) and hard linear constraints eliminated from
 * the unknowns (eq. 14-16). Rows are the B-spline basis at the point over the window's
 * coefficients; coefficients outside the window move into the target. */
#ifndef ARGIL_CONSTRAINTS_H
#define ARGIL_CONSTRAINTS_H

#include <stddef.h>

#include "host/model/field.h"
#include "host/model/physwin.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

/* The row "density at x = density" over the window. ARGIL_ERR_ARG when x's support has no
 * coefficient inside the window; ARGIL_ERR_NONFINITE. */
argil_err_t constraint_row(const physwin_t *w, const field_t *f, vec3_t x_m, float density,
                           solver_row_t *row);

/* Soft point constraint spring of stiffness k_n (N per unit density). */
argil_err_t constraint_point(physwin_t *w, const field_t *f, vec3_t x_m, float density, float k_n);

/* Soft curve constraint: the polyline pts[0..n) discretised at ≤ step_m, one spring per point.
 * ARGIL_ERR_ARG for n < 2 or a step that is not finite and > 0. */
argil_err_t constraint_curve(physwin_t *w, const field_t *f, const vec3_t *pts_m, size_t n,
                             float density, float k_n, float step_m);

/* Hard point constraint, eliminated (eq. 14-16): the solver keeps density at x exactly. */
argil_err_t constraint_hard_point(physwin_t *w, const field_t *f, vec3_t x_m, float density);

#endif
