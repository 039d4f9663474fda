/* The arm's rigid-body dynamics for the simulated device: a counterbalanced 3-DOF serial arm
 * (no gravity) whose moving mass is lumped at the stylus tip, plus the motors' rotor inertia
 * through the capstan reductions, joint friction and hard stops at the joint limits.
 * Deterministic: same inputs, bit-identical state. */
#ifndef ARGIL_ARM_SIM_H
#define ARGIL_ARM_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/arm_kin.h"
#include "shared/vec3.h"

/* Internal integration sub-step: arm_sim_step splits dt_us into pieces of at most this. */
#define ARM_SIM_SUBSTEP_US 50u

typedef struct {
    arm_desc_t desc;                                  /* geometry, gears, encoders, limits */
    float tip_mass_kg;                                /* effective moving mass at the tip */
    float rotor_inertia_kg_m2[ARGIL_DRIVES];          /* per motor, motor side */
    float viscous_nm_s_per_rad[ARGIL_DRIVES];         /* joint side */
    float coulomb_nm[ARGIL_DRIVES];                   /* joint side, smoothed near zero speed */
    float coulomb_smooth_rad_s;                       /* width of the tanh smoothing */
    float peak_torque_nm[ARGIL_DRIVES];               /* drive current limit, motor side */
} arm_params_t;

typedef struct {
    double q_rad[ARGIL_DRIVES];                       /* joint angles */
    double qd_rad_s[ARGIL_DRIVES];                    /* joint velocities */
    double qdd_rad_s2[ARGIL_DRIVES];                  /* acceleration of the latest sub-step */
} arm_sim_t;

/* The default arm of docs/arm.md (arm_desc_default plus PHANToM Premium 1.0-class dynamics). */
void arm_params_default(arm_params_t *p);

/* Puts the arm at rest at q0_rad (clamped into the joint limits). */
void arm_sim_init(arm_sim_t *sim, const arm_params_t *p, const float q0_rad[ARGIL_DRIVES]);

/* Advances the arm by dt_us (fixed sub-steps of at most ARM_SIM_SUBSTEP_US, semi-implicit
 * Euler) under the motor torques (clamped to the peak limit; non-finite counts as 0) and an
 * external force at the tip, held constant over the step. */
void arm_sim_step(arm_sim_t *sim, const arm_params_t *p,
                  const float motor_torque_nm[ARGIL_DRIVES], vec3_t tip_force_n,
                  uint32_t dt_us);

/* The joint-space mass matrix M(q) = Jᵀ m_tip J + diag(rotor inertia · gear²), kg m². */
void arm_sim_mass_matrix(const arm_params_t *p, const double q_rad[ARGIL_DRIVES],
                         double m[ARGIL_DRIVES][ARGIL_DRIVES]);

/* Kinetic energy ½ q̇ᵀ M(q) q̇ of the arm in joules. */
double arm_sim_kinetic_energy_j(const arm_sim_t *sim, const arm_params_t *p);

/* Solves the 3x3 system a x = b (Gaussian elimination, partial pivoting); false when singular. */
bool arm_sim_solve3(const double a[3][3], const double b[3], double x[3]);

/* The stylus tip in the device frame, metres. */
vec3_t arm_sim_tip_m(const arm_sim_t *sim, const arm_params_t *p);

/* The stylus tip's velocity J(q) q̇ in the device frame, m/s. */
vec3_t arm_sim_tip_vel_m_s(const arm_sim_t *sim, const arm_params_t *p);

/* The joint angles as floats (what the board would compute with arm_kin). */
void arm_sim_q_rad(const arm_sim_t *sim, float q_rad[ARGIL_DRIVES]);

#endif
