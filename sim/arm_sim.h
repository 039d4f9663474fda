/* The arm's dynamics for the simulated device: a counterbalanced 3-DOF serial arm (no gravity)
 * whose moving mass is lumped at the stylus tip, the motors' rotor inertia through the capstan
 * reductions, optionally joined to the links by the capstan cables' compliance (a structural
 * mode; the encoders then read the motor side), the amplifiers' current-loop lag, joint
 * friction and hard stops at the joint limits. Deterministic: same inputs, bit-identical state. */
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

/* The largest ω·h arm_sim_substep_max_us allows for a cable mode of ω rad/s: semi-implicit
 * Euler then gets the mode's frequency within (ω h)² / 24 = 0.26 % and its energy within
 * ±ω h / 2 = ±12.5 % of the mode's own, oscillating, with no drift (docs/arm.md). */
#define ARM_SIM_OMEGA_H_MAX 0.25

typedef struct {
    arm_desc_t desc;                                  /* geometry, gears, encoders, limits */
    float tip_mass_kg;                                /* effective moving mass at the tip */
    float rotor_inertia_kg_m2[ARGIL_DRIVES];          /* per motor, motor side */
    float viscous_nm_s_per_rad[ARGIL_DRIVES];         /* joint side */
    float coulomb_nm[ARGIL_DRIVES];                   /* joint side, smoothed near zero speed */
    float coulomb_smooth_rad_s;                       /* width of the tanh smoothing */
    float peak_torque_nm[ARGIL_DRIVES];               /* drive current limit, motor side */
    float link_inertia_kg_m2[ARGIL_DRIVES];           /* joint side, link side: drum, link and
                                                         what it carries, beyond the tip mass */
    float cable_compliance_rad_per_nm[ARGIL_DRIVES];  /* joint side, 1 / the capstan cable's
                                                         torsional stiffness; 0 = rigid joint
                                                         (motor and link one body) */
    float cable_damping_nm_s_per_rad[ARGIL_DRIVES];   /* joint side, across the cable spring
                                                         (compliant joints only) */
    float current_loop_hz[ARGIL_DRIVES];              /* amplifier current-loop bandwidth: the
                                                         torque lags the command by a first
                                                         order 1 / (2π f); 0 = no lag */
    uint8_t torque_dac_bits[ARGIL_DRIVES];            /* the drive's torque command resolution
                                                         over ±peak (drive_cfg_t.dac_bits);
                                                         0 = continuous */
    uint32_t substep_us;                              /* numerical: the integration sub-step,
                                                         used within 1 .. arm_sim_substep_max_us */
} arm_params_t;

typedef struct {
    double q_rad[ARGIL_DRIVES];                       /* joint angles */
    double qd_rad_s[ARGIL_DRIVES];                    /* joint velocities */
    double qdd_rad_s2[ARGIL_DRIVES];                  /* acceleration of the latest sub-step */
    double qm_rad[ARGIL_DRIVES];                      /* motor angle / gear on a compliant
                                                         joint (the encoder's side) */
    double qmd_rad_s[ARGIL_DRIVES];                   /* its velocity */
    double torque_nm[ARGIL_DRIVES];                   /* motor torque the current loop applies
                                                         now, motor side */
} arm_sim_t;

/* The default arm of docs/arm.md (arm_desc_default plus PHANToM Premium 1.0-class dynamics):
 * rigid joints, no current-loop lag, no torque DAC. */
void arm_params_default(arm_params_t *p);

/* The arm of a PHANToM Premium 1.0/1.5-class device as faithfully as docs/arm.md can source
 * it: the default's geometry, the cable mode, the current loop, a 12-bit torque DAC and friction
 * whose tip equivalents fall in real desktop devices' range (docs/arm.md, "Premium profile"). */
void arm_params_premium(arm_params_t *p);

/* The longest sub-step that keeps the explicit terms in hand, at least 1 µs:
 * - velocity terms stay monotone: h s / I <= 1 for each body, s the slope of what acts on its
 *   velocity (Coulomb smoothing c/ε, viscous b, cable damper d), I its inertia (the rotor
 *   through its gear on the motor side; on the link side the smallest diagonal term M adds to
 *   m JᵀJ, which bounds M's smallest eigenvalue in every pose). Longer sub-steps make a
 *   slowing velocity overshoot zero each sub-step (and diverge past twice this);
 * - each cable mode is resolved: ω h <= ARM_SIM_OMEGA_H_MAX, ω = √(k (1/I_motor + 1/I_link))
 *   with the same lower bound on the link side, so no pose has a faster mode. */
uint32_t arm_sim_substep_max_us(const arm_params_t *p);

/* Whether joint j has a cable mode (its compliance is positive). */
bool arm_sim_joint_compliant(const arm_params_t *p, int j);

/* Puts the arm at rest at q0_rad (clamped into the joint limits). */
void arm_sim_init(arm_sim_t *sim, const arm_params_t *p, const float q0_rad[ARGIL_DRIVES]);

/* Advances the arm by dt_us (fixed sub-steps of at most p->substep_us, semi-implicit
 * Euler) under the commanded motor torques (clamped to the peak limit, non-finite counts as 0;
 * the current loop's output follows them) and an external force at the tip, held constant
 * over the step. */
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

/* The joint-space mass matrix of the link side, kg m²: M(q) = Jᵀ m_tip J + diag(link
 * inertia, plus rotor inertia · gear² on a rigid joint). */
void arm_sim_mass_matrix(const arm_params_t *p, const double q_rad[ARGIL_DRIVES],
                         double m[ARGIL_DRIVES][ARGIL_DRIVES]);

/* Kinetic energy of the arm in joules: ½ q̇ᵀ M(q) q̇ plus, on compliant joints, the rotor's
 * ½ I_rotor gear² q̇m². */
double arm_sim_kinetic_energy_j(const arm_sim_t *sim, const arm_params_t *p);

/* Energy stored in the cable springs, ½ Σ k (qm − q)², joules (0 for rigid joints). */
double arm_sim_cable_energy_j(const arm_sim_t *sim, const arm_params_t *p);

/* The angle joint j's encoder reports, rad at the joint: the motor side (qm) on a compliant
 * joint, as on a PHANToM, whose encoders sit on the motors; the joint angle on a rigid one. */
double arm_sim_encoder_rad(const arm_sim_t *sim, const arm_params_t *p, int j);

/* The motor torques the current loops apply now, N m motor side (the command once no lag). */
void arm_sim_applied_torque_nm(const arm_sim_t *sim, float out[ARGIL_DRIVES]);

/* Solves the 3x3 system a x = b (Gaussian elimination, partial pivoting); false when singular. */
bool arm_sim_solve3(const double a[3][3], const double b[3], double x[3]);

/* The stylus tip in the device frame, metres. */
vec3_t arm_sim_tip_m(const arm_sim_t *sim, const arm_params_t *p);

/* The stylus tip's velocity J(q) q̇ in the device frame, m/s. */
vec3_t arm_sim_tip_vel_m_s(const arm_sim_t *sim, const arm_params_t *p);

/* The joint angles as floats (what the board would compute with arm_kin). */
void arm_sim_q_rad(const arm_sim_t *sim, float q_rad[ARGIL_DRIVES]);

#endif
