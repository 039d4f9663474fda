/* What the board knows about the arm: geometry, transmission and encoders of the 3-DOF
 * PHANToM-like serial arm, its forward kinematics and Jacobian. The simulator (sim/) adds the
 * dynamics. Device frame: origin at the shoulder (where the yaw and pitch axes meet),
 * x to the user's right, y up, z toward the user; metres and radians. */
#ifndef ARGIL_ARM_KIN_H
#define ARGIL_ARM_KIN_H

#include <stdbool.h>
#include <stdint.h>

#include "argil_limits.h"
#include "vec3.h"

typedef struct {
    float link1_m;                          /* shoulder → elbow */
    float link2_m;                          /* elbow → stylus tip */
    float gear_ratio[ARGIL_DRIVES];         /* motor turns per joint turn */
    int32_t encoder_counts_per_rev[ARGIL_DRIVES]; /* motor side, after quadrature */
    float rated_torque_nm[ARGIL_DRIVES];    /* motor rated torque: 1000 ‰ in CiA 402 */
    float q_min_rad[ARGIL_DRIVES];          /* joint limits */
    float q_max_rad[ARGIL_DRIVES];
    float q_home_rad[ARGIL_DRIVES];         /* pose at power-up: encoders read 0 here */
} arm_desc_t;

/* The default arm, documented in docs/arm.md. */
void arm_desc_default(arm_desc_t *d);

/* Joints: q0 yaw about y; q1 shoulder pitch from the horizontal; q2 elbow pitch relative to
 * the upper arm. Returns the stylus tip in the device frame. */
vec3_t arm_fk(const arm_desc_t *d, const float q_rad[ARGIL_DRIVES]);

/* j[r][c] = d tip_r / d q_c (metres per radian). */
void arm_jacobian(const arm_desc_t *d, const float q_rad[ARGIL_DRIVES],
                  float j[3][ARGIL_DRIVES]);

/* Joint torques tau = Jᵀ F for a force F (N) at the tip. */
void arm_jt_force(const float j[3][ARGIL_DRIVES], vec3_t force_n,
                  float tau_nm[ARGIL_DRIVES]);

/* Elbow-down inverse kinematics; false when tip is out of reach or outside the joint limits. */
bool arm_ik(const arm_desc_t *d, vec3_t tip_m, float q_rad[ARGIL_DRIVES]);

/* The device-frame workspace centre: the stylus tip at q_home_rad (fk(q_home)). */
vec3_t arm_workspace_centre(const arm_desc_t *d);

/* The default drives' peak torque (current limit) in per-mille of the rated torque: 4x rated.
 * Target torques beyond it are clipped by the drive (docs/arm.md). */
#define ARM_PEAK_TORQUE_PERMILLE 4000

/* Joint angle from a motor encoder reading (counts since power-up at q_home_rad). */
float arm_counts_to_rad(const arm_desc_t *d, int joint, int32_t counts);
/* The encoder reading for a joint angle (rounded toward zero count quantisation). */
int32_t arm_rad_to_counts(const arm_desc_t *d, int joint, float q_rad);

#endif
