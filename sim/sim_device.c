/* The simulated device in lockstep: drives on a virtual CAN bus, the arm, GPIO and the hand. */
#include "sim_device.h"

#include <stddef.h>

void sim_params_default(sim_params_t *p)
{
    arm_params_default(&p->arm);
    hand_params_default(&p->hand);
    p->heartbeat_period_ms = 100u;
    p->quick_stop_ms = 10u;
}

void sim_device_init(sim_device_t *d, const sim_params_t *p)
{
    d->p = *p;
    arm_sim_init(&d->arm, &d->p.arm, d->p.arm.desc.q_home_rad);
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        drive_cfg_t cfg;
        drive_cfg_default(&cfg);
        cfg.heartbeat_period_us = p->heartbeat_period_ms * 1000u;
        cfg.quick_stop_us = p->quick_stop_ms * 1000u;
        cfg.rated_torque_nm = p->arm.desc.rated_torque_nm[j];
        cfg.peak_torque_nm = p->arm.peak_torque_nm[j];
        cfg.dac_bits = p->arm.torque_dac_bits[j];
        drive_init(&d->drive[j], (uint8_t)(j + 1), &cfg);
    }
    d->hand_holding = true;
    d->hand_target_m = arm_sim_tip_m(&d->arm, &d->p.arm);
    d->hand_target_vel_m_s = vec3(0.0f, 0.0f, 0.0f);
    d->btn1 = false;
    d->btn2 = false;
    d->estop_pressed = false;
    d->hand_force_n = vec3(0.0f, 0.0f, 0.0f);
    d->time_us = 0;
}

void sim_device_set_hand(sim_device_t *d, vec3_t target_device_m, vec3_t target_vel_m_s,
                         bool btn1, bool btn2)
{
    d->hand_holding = true;
    d->hand_target_m = target_device_m;
    d->hand_target_vel_m_s = target_vel_m_s;
    d->btn1 = btn1;
    d->btn2 = btn2;
}

void sim_device_release_hand(sim_device_t *d)
{
    d->hand_holding = false;
    d->hand_target_vel_m_s = vec3(0.0f, 0.0f, 0.0f);
}

void sim_device_set_estop(sim_device_t *d, bool pressed)
{
    d->estop_pressed = pressed;
}

void sim_device_inject_drive_fault(sim_device_t *d, int joint)
{
    if (joint >= 0 && joint < ARGIL_DRIVES)
        drive_inject_fault(&d->drive[joint], CANOPEN_EMCY_OVERCURRENT,
                           CANOPEN_ERRREG_GENERIC | CANOPEN_ERRREG_CURRENT);
}

void sim_device_step(sim_device_t *d, const can_batch_t *from_board, uint32_t gpio_out,
                     can_batch_t *to_board, uint32_t dt_us)
{
    if (to_board != NULL)
        to_board->n = 0;
    /* 1. the board's frames, in bus order; SYNC is only noted here */
    if (from_board != NULL) {
        const uint8_t n = from_board->n <= CAN_BATCH_MAX ? from_board->n : CAN_BATCH_MAX;
        for (uint8_t i = 0; i < n; i++)
            for (int j = 0; j < ARGIL_DRIVES; j++)
                drive_receive(&d->drive[j], &from_board->f[i]);
    }
    /* 2. drives: heartbeats, EMCY, torque stage, TPDOs with the encoders at this instant */
    const bool power = (gpio_out & GPIO_OUT_DRIVE_ENABLE) != 0 && !d->estop_pressed;
    float motor_nm[ARGIL_DRIVES];
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        const float enc_rad = (float)arm_sim_encoder_rad(&d->arm, &d->p.arm, j);
        const int32_t counts = arm_rad_to_counts(&d->p.arm.desc, j, enc_rad);
        drive_tick(&d->drive[j], counts, power, dt_us, to_board);
        motor_nm[j] = drive_motor_torque_nm(&d->drive[j]);
    }
    /* 3. the arm, in sub-steps with the hand's grip force re-evaluated each sub-step */
    vec3_t impulse_ns = vec3(0.0f, 0.0f, 0.0f);
    uint32_t done_us = 0;
    const uint32_t sub_us = arm_sim_substep_us(&d->p.arm);
    while (done_us < dt_us) {
        const uint32_t left = dt_us - done_us;
        const uint32_t h_us = left < sub_us ? left : sub_us;
        arm_kin_now_t k; /* once per sub-step: for the hand and for the dynamics */
        arm_sim_kin_now(&d->arm, &d->p.arm, &k);
        vec3_t f = vec3(0.0f, 0.0f, 0.0f);
        if (d->hand_holding) {
            const float t_s = (float)done_us * 1e-6f;
            const vec3_t target =
                vec3_add(d->hand_target_m, vec3_scale(d->hand_target_vel_m_s, t_s));
            f = hand_force_n(&d->p.hand, target, d->hand_target_vel_m_s, vec3_from_d(k.tip_m),
                             vec3_from_d(k.tip_vel_m_s));
        }
        arm_sim_substep_from(&d->arm, &d->p.arm, &k, motor_nm, f, h_us);
        impulse_ns = vec3_add(impulse_ns, vec3_scale(f, (float)h_us * 1e-6f));
        done_us += h_us;
    }
    d->hand_force_n = dt_us > 0 ? vec3_scale(impulse_ns, 1e6f / (float)dt_us) : vec3(0, 0, 0);
    if (d->hand_holding)
        d->hand_target_m = vec3_add(d->hand_target_m,
                                    vec3_scale(d->hand_target_vel_m_s, (float)dt_us * 1e-6f));
    d->time_us += dt_us;
}

uint32_t sim_device_gpio_in(const sim_device_t *d)
{
    uint32_t in = 0;
    bool fault = false;
    for (int j = 0; j < ARGIL_DRIVES; j++)
        fault = fault || drive_fault_active(&d->drive[j]);
    if (!d->estop_pressed)
        in |= GPIO_IN_ESTOP_N;
    if (!fault)
        in |= GPIO_IN_DRIVE_FAULT_N;
    if (d->btn1)
        in |= GPIO_IN_STYLUS_BTN1;
    if (d->btn2)
        in |= GPIO_IN_STYLUS_BTN2;
    return in;
}

vec3_t sim_device_tip_m(const sim_device_t *d)
{
    return arm_sim_tip_m(&d->arm, &d->p.arm);
}

vec3_t sim_device_tip_vel_m_s(const sim_device_t *d)
{
    return arm_sim_tip_vel_m_s(&d->arm, &d->p.arm);
}

vec3_t sim_device_hand_force_n(const sim_device_t *d)
{
    return d->hand_force_n;
}

void sim_device_motor_torque_nm(const sim_device_t *d, float out[3])
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        out[j] = drive_motor_torque_nm(&d->drive[j]);
}

void sim_device_q_rad(const sim_device_t *d, float out[3])
{
    arm_sim_q_rad(&d->arm, out);
}

vec3_t sim_device_delivered_force_n(const sim_device_t *d)
{
    arm_kin_now_t k;
    arm_sim_kin_now(&d->arm, &d->p.arm, &k);
    float applied[ARGIL_DRIVES];
    arm_sim_applied_torque_nm(&d->arm, applied);
    double jt[3][3], tau[3], f[3];
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        tau[j] = d->p.arm.desc.gear_ratio[j] * (double)applied[j];
        for (int a = 0; a < 3; a++)
            jt[j][a] = k.jac[a][j];
    }
    if (!arm_sim_solve3(jt, tau, f))
        return vec3(0.0f, 0.0f, 0.0f);
    return vec3((float)f[0], (float)f[1], (float)f[2]);
}
