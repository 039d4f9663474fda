/* Material painting (Hua & Qin §6.3, McDonnell et al. §7.3): mass, damping, stiffness and rest
 * length painted with a linear falloff (rest length up inflates, down deflates), fixed points,
 * and "reset rest shape" (the current shape becomes permanent). */
#ifndef ARGIL_MATERIAL_H
#define ARGIL_MATERIAL_H

#include <stdbool.h>
#include <stdint.h>

#include "host/model/field.h"
#include "host/model/undo.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef enum {
    MATERIAL_ADD = 0,   /* value += amount * w */
    MATERIAL_SCALE      /* value *= 1 + (amount - 1) * w */
} material_mode_t;

/* Paints sample channel ch (FS_MASS, FS_DAMP, FS_STIFF or FS_RESTLEN) within radius of centre,
 * weight w = 1 - distance / radius. Mass stays > 0, damping and stiffness >= 0. u may be NULL.
 * ARGIL_ERR_ARG for another channel or a radius that is not finite and > 0. */
argil_err_t material_paint(field_t *f, int ch, vec3_t centre_m, float radius_m, float amount,
                           material_mode_t mode, undo_t *u);

/* Fixes (or frees) every coefficient within radius of centre; fixed ones lose their velocity. */
argil_err_t material_fix(field_t *f, vec3_t centre_m, float radius_m, bool fixed, undo_t *u);

/* Makes the current shape the rest shape in sample box [slo, shi): rest = d, rest length 0. */
argil_err_t material_reset_rest(field_t *f, const int32_t slo[3], const int32_t shi[3], undo_t *u);

#endif
