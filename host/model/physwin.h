/* The physical window (Hua & Qin §6.3 local sculpting, McDonnell et al. §7.3): only the
 * coefficients inside a chosen box are simulated; d_1 = A_1 p_1 + A_2 p_2 with the fixed part
 * A_2 p_2 computed once when the window opens. Copies between the sparse field and a solver. */
#ifndef ARGIL_PHYSWIN_H
#define ARGIL_PHYSWIN_H

#include <stdint.h>

#include "host/model/field.h"
#include "host/model/solver.h"

typedef struct {
    solver_t solver;
    int32_t clo[3], chi[3];      /* free coefficients */
    int32_t slo[3], shi[3];      /* samples they move, plus one fixed ring for the springs */
} physwin_t;

/* Opens a window on coefficients [clo, chi) (at least 4 per axis): loads p, the coefficient
 * velocity, fixed points, and every sample's density, rest shape and material. ARGIL_ERR_ARG,
 * ARGIL_ERR_NOMEM. */
argil_err_t physwin_open(physwin_t *w, const field_t *f, const int32_t clo[3], const int32_t chi[3],
                         const solver_cfg_t *cfg);

/* Reloads material, rest shape and external forces from the field (after painting). */
void physwin_sync_inputs(physwin_t *w, const field_t *f);

/* Writes p, the coefficient velocity and d = A p + d_fixed back; changed blocks become dirty. */
argil_err_t physwin_store(physwin_t *w, field_t *f);

void physwin_close(physwin_t *w);

#endif
