/* Density springs (Hua & Qin §5.1): every sample of a density block is a mass point that moves
 * only along the density axis, tied to its rest density and to its six neighbours. The board's
 * local window and the host's global field step with this same code. */
#ifndef ARGIL_DENSITY_SPRINGS_H
#define ARGIL_DENSITY_SPRINGS_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    float node_mass;          /* > 0 */
    float stiffness;          /* spring to the rest density, per unit density */
    float coupling;           /* springs to the six neighbours (4D length; density part acts) */
    float damping;            /* viscous, per unit density rate */
    float plastic_rate_hz;    /* rest densities follow the current ones at this rate; 0 = elastic */
} spring_material_t;

/* A dense block of samples, x fastest. The arrays belong to the caller. */
typedef struct {
    int32_t dims[3];
    float *density;
    float *rest;
    float *velocity;          /* density rate, 1/s */
    float *force;             /* external force per node; springs_step consumes and zeroes it */
    const float *stiffness;   /* per-node stiffness to rest, or NULL for the material's */
} spring_field_t;

/* The default clay: heavily damped, plastic. */
void spring_material_default(spring_material_t *m);

/* True when every material value is finite and in range (mass > 0, others ≥ 0). */
bool spring_material_valid(const spring_material_t *m);

/* Largest explicit time step (s) that stays stable for this material. */
float springs_stable_dt_s(const spring_material_t *m);

/* Advances nodes in the box [lo, hi) by dt_s with semi-implicit Euler; nodes outside the box
 * stay fixed and act as boundary. External forces inside the box are consumed. Returns the
 * largest |acceleration| seen (for adaptive step halving). Densities stay within [0, 1]. */
float springs_step(spring_field_t *f, const spring_material_t *m, const int32_t lo[3],
                   const int32_t hi[3], float dt_s);

#endif
