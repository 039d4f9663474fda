/* The virtual hand's grip force (see hand.h). */
#include "hand.h"

void hand_params_default(hand_params_t *p)
{
    p->stiffness_n_per_m = 800.0f;
    p->damping_n_s_per_m = 8.0f;
}

vec3_t hand_force_n(const hand_params_t *p, vec3_t target_m, vec3_t target_vel_m_s,
                    vec3_t tip_m, vec3_t tip_vel_m_s)
{
    const vec3_t spring = vec3_scale(vec3_sub(target_m, tip_m), p->stiffness_n_per_m);
    const vec3_t damper = vec3_scale(vec3_sub(target_vel_m_s, tip_vel_m_s), p->damping_n_s_per_m);
    return vec3_add(spring, damper);
}
