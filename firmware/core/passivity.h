/* Passivity observer and controller (Hannaford & Ryu 2002) on the force the board renders:
 * the observer adds up the energy the virtual environment hands to the device beyond what its
 * own springs stored; when that goes positive the controller adds just enough damping to take
 * it back out. */
#ifndef ARGIL_PASSIVITY_H
#define ARGIL_PASSIVITY_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/vec3.h"

#define PASSIVITY_DELAY_MAX 4u

typedef struct {
    float energy_j;          /* generated energy so far; ≤ 0 is passive */
    float max_energy_j;      /* the largest energy_j seen */
    vec3_t prev_pos_m;       /* device-space position at the previous tick */
    vec3_t force_hist_n[PASSIVITY_DELAY_MAX + 1]; /* forces applied, newest first */
    uint32_t delay_ticks;    /* ticks from computing a force to the interval it acts over */
    float prev_potential_j;
    uint32_t env;            /* identifies the environment prev_potential_j belongs to */
    bool valid;
    uint32_t active_ticks;   /* ticks the controller damped */
} passivity_t;

/* delay_ticks: how many ticks after it was computed a force acts over the interval whose
 * displacement the observer sees (1 for an ideal loop; 2 on a CiA 402 bus, where a position
 * arrives one cycle late and a torque acts one cycle after it is sent); clamped to 1 … 4. */
void passivity_init(passivity_t *p, uint32_t delay_ticks);

/* Forgets the history (after the force path was interrupted, e.g. a fault). */
void passivity_reset(passivity_t *p);

/* Observes one tick: the device moved to pos_m under last tick's force; the environment env
 * now stores potential_j. Returns the controller's damping force for this tick: zero while
 * the generated energy is within deadband_j or control is off, otherwise the damping (at most
 * max_damping_n_s_per_m) that dissipates the excess at the device's filtered velocity vel —
 * filtered, so encoder steps do not turn into force spikes. */
vec3_t passivity_process(passivity_t *p, vec3_t pos_m, vec3_t vel_m_s, float potential_j,
                         uint32_t env, float dt_s, bool control, float deadband_j,
                         float max_damping_n_s_per_m);

/* Tells the observer which force was finally applied this tick (after limits). */
void passivity_applied(passivity_t *p, vec3_t force_n);

#endif
