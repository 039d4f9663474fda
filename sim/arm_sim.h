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

/* The integration sub-step arm_params_default sets: arm_sim_step splits dt_us into pieces of
 * at most arm_params_t.substep_us (docs/arm.md, "Integration"). */
#define ARM_SIM_SUBSTEP_US 50u

typedef struct {
    arm_desc_t desc;                                  /* geometry, gears, encoders, limits */
    float tip_mass_kg;                                /* effective moving mass at the tip */
    float rotor_inertia_kg_m2[ARGIL_DRIVES];          /* per motor, motor side */
    float viscous_nm_s_per_rad[ARGIL_DRIVES];         /* joint side */
    float coulomb_nm[ARGIL_DRIVES];                   /* joint side, smoothed near zero speed */
    float coulomb_smooth_rad_s;                       /* width of the tanh smoothing */
    float peak_torque_nm[ARGIL_DRIVES];               /* drive current limit, motor side */
    uint32_t substep_us;                              /* numerical: the integration sub-step,
                                                         used within 1 .. arm_sim_substep_max_us */
} arm_params_t;

typedef struct {
    double q_rad[ARGIL_DRIVES];                       /* joint angles */
    double qd_rad_s[ARGIL_DRIVES];                    /* joint velocities */
    double qdd_rad_s2[ARGIL_DRIVES];                  /* acceleration of the latest sub-step */
} arm_sim_t;

/* The default arm of docs/arm.md (arm_desc_default plus PHANToM Premium 1.0-class dynamics). */
void arm_params_default(arm_params_t *p);

/* The longest sub-step whose explicit friction stays monotone: h (c/ε + b) / I_min <= 1, with
 * c/ε the tanh smoothing's slope, b the viscous friction and I_min the smallest rotor inertia
 * through its gear (the mass matrix's smallest eigenvalue is at least that). Longer sub-steps
 * make the velocity overshoot zero each sub-step (and diverge past twice this). At least 1. */
uint32_t arm_sim_substep_max_us(const arm_params_t *p);

/* Puts the arm at rest at q0_rad (clamped into the joint limits). */
void arm_sim_init(arm_sim_t *sim, const arm_params_t *p, const float q0_rad[ARGIL_DRIVES]);

/* Advances the arm by dt_us (fixed sub-steps of at most p->substep_us, semi-implicit
 * Euler) under the motor torques (clamped to the peak limit; non-finite counts as 0) and an
 * external force at the tip, held constant over the step. */
void arm_sim_step(arm_sim_t *sim, const arm_params_t *p,
                  const float motor_torque_nm[ARGIL_DRIVES], vec3_t tip_force_n,
                  uint32_t dt_us);

/* The arm's kinematics at its present state (q, q̇): all one sub-step needs, and where the tip
 * is and how fast it moves for a hand that holds it. One evaluation serves both: sin and cos of
 * the joint angles are most of a sub-step's cost, and under the HIL rig's emulation argil-sim
 * fell behind the board's SYNCs computing them three times over. */
typedef struct {
    double jac[3][ARGIL_DRIVES];                      /* J(q), m/rad */
    double tip_m[3];                                  /* the stylus tip, device frame */
    double tip_vel_m_s[3];                            /* J q̇ */
    double acc_bias_m_s2[3];                          /* J̇ q̇: the tip acceleration at q̈ = 0 */
} arm_kin_now_t;

void arm_sim_kin_now(const arm_sim_t *sim, const arm_params_t *p, arm_kin_now_t *k);

/* arm_sim_step for one sub-step of h_us (at most arm_sim_substep_us(p)) from k, which
 * arm_sim_kin_now gave for the arm's present state: bit-identical to arm_sim_step(…, h_us). */
void arm_sim_substep_from(arm_sim_t *sim, const arm_params_t *p, const arm_kin_now_t *k,
                          const float motor_torque_nm[ARGIL_DRIVES], vec3_t tip_force_n,
                          uint32_t h_us);

/* p->substep_us within 1 .. arm_sim_substep_max_us(p). */
uint32_t arm_sim_substep_us(const arm_params_t *p);

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
