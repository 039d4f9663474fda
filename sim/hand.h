/* The virtual hand: a person holding the stylus with a compliant grip, modelled as a spring
 * and damper between where the hand wants the tip to be (the target) and where the tip is.
 * A stiff grip (k large) drags the tip along; the device's forces deflect the grip by F / k,
 * which is what a real wrist and fingers do. */
#ifndef ARGIL_HAND_H
#define ARGIL_HAND_H

#include "shared/vec3.h"

typedef struct {
    float stiffness_n_per_m;     /* grip stiffness, default 800 N/m */
    float damping_n_s_per_m;     /* grip damping, default 8 N s/m */
} hand_params_t;

/* The default grip: 800 N/m and 8 N s/m (damping ratio 0.5 with a 0.08 kg stylus). */
void hand_params_default(hand_params_t *p);

/* The force the hand applies to the stylus tip: k (target − tip) + c (target_vel − tip_vel). */
vec3_t hand_force_n(const hand_params_t *p, vec3_t target_m, vec3_t target_vel_m_s,
                    vec3_t tip_m, vec3_t tip_vel_m_s);

#endif
