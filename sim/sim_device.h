/* The simulated haptic device as the board sees it: three CiA 402 drives on a CAN bus, the
 * arm they move, the GPIO lines (e-stop, drive fault, stylus buttons, drive enable) and a
 * virtual hand holding the stylus. Lockstep and deterministic: the caller passes the board's
 * frames and GPIO outputs and the time step; same inputs give bit-identical outputs. */
#ifndef ARGIL_SIM_DEVICE_H
#define ARGIL_SIM_DEVICE_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/canopen.h"
#include "shared/gpio_lines.h"
#include "shared/vec3.h"
#include "sim/arm_sim.h"
#include "sim/drive.h"
#include "sim/hand.h"

typedef struct {
    arm_params_t arm;
    hand_params_t hand;
    uint32_t heartbeat_period_ms;   /* drives' heartbeat producer time, default 100 */
    uint32_t quick_stop_ms;         /* drives' quick stop duration before SWITCH_ON_DISABLED */
} sim_params_t;

typedef struct sim_device {
    sim_params_t p;
    arm_sim_t arm;
    drive_t drive[ARGIL_DRIVES];    /* joint j is node j + 1 */
    bool hand_holding;              /* false: nobody holds the stylus (no hand force) */
    vec3_t hand_target_m;           /* device frame; moves on at hand_target_vel_m_s */
    vec3_t hand_target_vel_m_s;
    bool btn1, btn2;
    bool estop_pressed;
    vec3_t hand_force_n;            /* mean hand force over the latest step */
    uint64_t time_us;               /* simulated time since init */
} sim_device_t;

/* Defaults: the arm of docs/arm.md, an 800 N/m / 8 N s/m grip, 100 ms heartbeats, 10 ms quick
 * stop. */
void sim_params_default(sim_params_t *p);

/* Arm at rest at q_home, hand holding still at the workspace centre, buttons up, e-stop
 * released, drives powered up (their boot-up heartbeats go out on the first step). */
void sim_device_init(sim_device_t *d, const sim_params_t *p);

/* The hand grips the stylus and wants the tip at target_device_m, moving at target_vel_m_s
 * (the target keeps moving at that velocity until the next call); button levels. */
void sim_device_set_hand(sim_device_t *d, vec3_t target_device_m, vec3_t target_vel_m_s,
                         bool btn1, bool btn2);

/* The hand lets go of the stylus (no hand force until the next sim_device_set_hand). */
void sim_device_release_hand(sim_device_t *d);

/* Presses or releases the e-stop; pressed also cuts the drives' power stage (like STO). */
void sim_device_set_estop(sim_device_t *d, bool pressed);

/* Trips drive `joint` (0..2) with an over-current fault: EMCY 0x2310 / error register 0x03
 * and FAULT at the next step, DRIVE_FAULT_N low until the board resets the fault. */
void sim_device_inject_drive_fault(sim_device_t *d, int joint);

/* One step: clears to_board; handles the board's frames (NMT, RPDO, SYNC: RPDOs in the batch
 * are latched before the SYNC in the same batch is acted on), answers SYNC with TPDOs that
 * report the position at that instant, then advances the arm by dt_us under the drives'
 * torques and the hand's force. from_board may be NULL (no frames). */
void sim_device_step(sim_device_t *d, const can_batch_t *from_board, uint32_t gpio_out,
                     can_batch_t *to_board, uint32_t dt_us);

/* GPIO_IN_* levels: ESTOP_N high when released, DRIVE_FAULT_N high when every drive is
 * healthy, buttons high when pressed. */
uint32_t sim_device_gpio_in(const sim_device_t *d);

/* The stylus tip in the device frame, metres. */
vec3_t sim_device_tip_m(const sim_device_t *d);
/* The stylus tip's velocity in the device frame, m/s. */
vec3_t sim_device_tip_vel_m_s(const sim_device_t *d);
/* The force the hand applied to the stylus during the latest step (mean), N. */
vec3_t sim_device_hand_force_n(const sim_device_t *d);
/* The motor torques the drives apply now, N m (motor side). */
void sim_device_motor_torque_nm(const sim_device_t *d, float out[3]);
/* The joint angles now, rad (ground truth, not quantised). */
void sim_device_q_rad(const sim_device_t *d, float out[3]);
/* The force the drives deliver at the stylus tip now, device frame, N: the F with
 * Jᵀ(q) F = gear · τ at the true pose, τ the motor torques the arm applied in its latest step
 * (clipped to the peak, after the current loop's lag where the arm has one:
 * arm_sim_applied_torque_nm) — what the hand feels of the motors, not the force the board
 * commanded. Zero where J is singular. */
vec3_t sim_device_delivered_force_n(const sim_device_t *d);

#endif
