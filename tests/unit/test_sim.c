/* Unit tests for sim/: the emulated CiA 402 drives, the arm's dynamics, the virtual hand and
 * the lockstep device, asserting what the board and a person holding the stylus would see. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "shared/arm_kin.h"
#include "shared/canopen.h"
#include "shared/gpio_lines.h"
#include "sim/arm_sim.h"
#include "sim/drive.h"
#include "sim/hand.h"
#include "sim/sim_device.h"

#define TICK_US 1000u
#define ENABLE GPIO_OUT_DRIVE_ENABLE

/* ---------- small CANopen master for the tests ---------- */

static void batch_clear(can_batch_t *b)
{
    b->n = 0;
}

static void push_nmt(can_batch_t *b, nmt_cmd_t cmd, uint8_t node)
{
    can_frame_t f;
    canopen_nmt_encode(&f, cmd, node);
    assert_int_equal(can_batch_push(b, &f), ARGIL_OK);
}

static void push_sync(can_batch_t *b)
{
    can_frame_t f;
    canopen_sync_encode(&f);
    assert_int_equal(can_batch_push(b, &f), ARGIL_OK);
}

static void push_rpdo_all(can_batch_t *b, uint16_t cw, const int16_t tq[3])
{
    for (int j = 0; j < 3; j++) {
        can_frame_t f;
        canopen_rpdo_encode(&f, (uint8_t)(j + 1), cw, tq ? tq[j] : 0);
        assert_int_equal(can_batch_push(b, &f), ARGIL_OK);
    }
}

/* Number of frames in b with this id. */
static int count_id(const can_batch_t *b, uint32_t id)
{
    int n = 0;
    for (int i = 0; i < b->n; i++)
        n += b->f[i].id == id;
    return n;
}

/* The power state node reports in a TPDO of b; -1 when it sent none. */
static int tpdo_state(const can_batch_t *b, uint8_t node, int32_t *pos, int16_t *tq)
{
    for (int i = 0; i < b->n; i++) {
        uint8_t n;
        uint16_t sw;
        int32_t p;
        int16_t t;
        if (canopen_tpdo_decode(&b->f[i], &n, &sw, &p, &t) && n == node) {
            if (pos)
                *pos = p;
            if (tq)
                *tq = t;
            return (int)cia402_state_from_statusword(sw);
        }
    }
    return -1;
}

/* One 1 ms device step with the given frames. */
static void dev_step(sim_device_t *d, const can_batch_t *in, uint32_t gpio, can_batch_t *out)
{
    sim_device_step(d, in, gpio, out, TICK_US);
}

/* Steps the device with cw + torque and a SYNC; returns the reply. */
static void dev_cmd(sim_device_t *d, uint16_t cw, const int16_t tq[3], uint32_t gpio,
                    can_batch_t *out)
{
    can_batch_t in;
    batch_clear(&in);
    push_rpdo_all(&in, cw, tq);
    push_sync(&in);
    dev_step(d, &in, gpio, out);
}

/* Boots the device, starts the drives and walks them to OPERATION_ENABLED. */
static void dev_enable(sim_device_t *d, const sim_params_t *p)
{
    can_batch_t in, out;
    sim_device_init(d, p);
    dev_step(d, NULL, ENABLE, &out);                 /* boot-ups */
    batch_clear(&in);
    push_nmt(&in, NMT_CMD_START, 0);
    dev_step(d, &in, ENABLE, &out);
    dev_cmd(d, CIA402_CW_SHUTDOWN, NULL, ENABLE, &out);
    dev_cmd(d, CIA402_CW_SWITCH_ON, NULL, ENABLE, &out);
    dev_cmd(d, CIA402_CW_ENABLE_OP, NULL, ENABLE, &out);
    for (uint8_t n = 1; n <= 3; n++)
        assert_int_equal(tpdo_state(&out, n, NULL, NULL), CIA402_OPERATION_ENABLED);
}

/* ---------- drive ---------- */

static void test_drive_boot_and_nmt(void **state)
{
    (void)state;
    drive_cfg_t cfg;
    drive_cfg_default(&cfg);
    drive_t d;
    drive_init(&d, 2, &cfg);
    can_batch_t tx;
    batch_clear(&tx);
    drive_tick(&d, 0, true, TICK_US, &tx);
    assert_int_equal(tx.n, 1);                       /* boot-up */
    assert_int_equal(tx.f[0].id, 0x702);
    assert_int_equal(tx.f[0].len, 1);
    assert_int_equal(tx.f[0].data[0], 0x00);
    assert_int_equal(d.nmt, NMT_STATE_PREOP);
    assert_int_equal(d.power, CIA402_SWITCH_ON_DISABLED);

    /* pre-operational: PDOs and SYNC are ignored */
    can_frame_t f;
    canopen_rpdo_encode(&f, 2, CIA402_CW_SHUTDOWN, 0);
    drive_receive(&d, &f);
    assert_int_equal(d.power, CIA402_SWITCH_ON_DISABLED);
    canopen_sync_encode(&f);
    drive_receive(&d, &f);
    batch_clear(&tx);
    drive_tick(&d, 0, true, TICK_US, &tx);
    assert_int_equal(tx.n, 0);

    /* a start for another node does nothing; one for this node (or all) starts it */
    canopen_nmt_encode(&f, NMT_CMD_START, 3);
    drive_receive(&d, &f);
    assert_int_equal(d.nmt, NMT_STATE_PREOP);
    canopen_nmt_encode(&f, NMT_CMD_START, 2);
    drive_receive(&d, &f);
    assert_int_equal(d.nmt, NMT_STATE_OPERATIONAL);

    /* the next heartbeat says operational */
    batch_clear(&tx);
    for (int t = 0; t < 100; t++)
        drive_tick(&d, 0, true, TICK_US, &tx);
    assert_int_equal(count_id(&tx, 0x702), 1);
    nmt_state_t st;
    uint8_t node;
    assert_true(canopen_heartbeat_decode(&tx.f[0], &node, &st));
    assert_int_equal(st, NMT_STATE_OPERATIONAL);

    /* stop: heartbeat 0x04, no TPDO on SYNC */
    canopen_nmt_encode(&f, NMT_CMD_STOP, 0);
    drive_receive(&d, &f);
    assert_int_equal(d.nmt, NMT_STATE_STOPPED);
    canopen_sync_encode(&f);
    drive_receive(&d, &f);
    batch_clear(&tx);
    for (int t = 0; t < 100; t++)
        drive_tick(&d, 0, true, TICK_US, &tx);
    assert_int_equal(tx.n, 1);
    assert_int_equal(tx.f[0].data[0], 0x04);

    /* reset node: boot-up again, then pre-operational */
    canopen_nmt_encode(&f, NMT_CMD_RESET_NODE, 2);
    drive_receive(&d, &f);
    batch_clear(&tx);
    drive_tick(&d, 0, true, TICK_US, &tx);
    assert_int_equal(tx.n, 1);
    assert_int_equal(tx.f[0].id, 0x702);
    assert_int_equal(tx.f[0].data[0], 0x00);
    assert_int_equal(d.nmt, NMT_STATE_PREOP);
}

static void test_drive_power_state_machine_and_torque(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    sim_device_init(&d, &p);
    can_batch_t in, out;
    const int16_t tq[3] = {500, -500, 10000};
    float m[3];

    dev_step(&d, NULL, ENABLE, &out);
    assert_int_equal(out.n, 3);                                  /* three boot-ups */
    batch_clear(&in);
    push_nmt(&in, NMT_CMD_START, 0);
    dev_step(&d, &in, ENABLE, &out);

    dev_cmd(&d, CIA402_CW_DISABLE_VOLTAGE, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_SWITCH_ON_DISABLED);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f && m[1] == 0.0f && m[2] == 0.0f);

    /* enable op straight from SWITCH_ON_DISABLED is not a transition */
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_SWITCH_ON_DISABLED);

    dev_cmd(&d, CIA402_CW_SHUTDOWN, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_READY_TO_SWITCH_ON);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f);

    dev_cmd(&d, CIA402_CW_SWITCH_ON, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_SWITCHED_ON);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f && m[1] == 0.0f && m[2] == 0.0f);

    int16_t tq_act;
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 3, NULL, &tq_act), CIA402_OPERATION_ENABLED);
    sim_device_motor_torque_nm(&d, m);
    assert_float_equal(m[0], 0.015f, 1e-6f);                     /* 500 ‰ of 0.030 N m */
    assert_float_equal(m[1], -0.015f, 1e-6f);
    assert_float_equal(m[2], 0.120f, 1e-6f);                     /* clipped to 4x rated */
    assert_int_equal(tq_act, 4000);
    assert_int_equal(tpdo_state(&out, 1, NULL, &tq_act), CIA402_OPERATION_ENABLED);
    assert_int_equal(tq_act, 500);

    /* DRIVE_ENABLE low: state kept, no torque */
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, 0, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, &tq_act), CIA402_OPERATION_ENABLED);
    assert_int_equal(tq_act, 0);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f && m[1] == 0.0f && m[2] == 0.0f);
    /* e-stop pressed: no torque even with DRIVE_ENABLE high */
    sim_device_set_estop(&d, true);
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f && m[1] == 0.0f && m[2] == 0.0f);
    assert_int_equal(sim_device_gpio_in(&d) & GPIO_IN_ESTOP_N, 0);
    sim_device_set_estop(&d, false);
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    sim_device_motor_torque_nm(&d, m);
    assert_float_equal(m[0], 0.015f, 1e-6f);

    /* disable operation, then disable voltage */
    dev_cmd(&d, CIA402_CW_SWITCH_ON, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_SWITCHED_ON);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f);
    dev_cmd(&d, CIA402_CW_DISABLE_VOLTAGE, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_SWITCH_ON_DISABLED);
}

static void test_drive_quick_stop_zeroes_torque(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    dev_enable(&d, &p);
    can_batch_t out;
    const int16_t tq[3] = {300, 300, 300};
    float m[3];
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    sim_device_motor_torque_nm(&d, m);
    assert_float_equal(m[1], 0.009f, 1e-6f);
    dev_cmd(&d, CIA402_CW_QUICK_STOP, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_QUICK_STOP_ACTIVE);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[0] == 0.0f && m[1] == 0.0f && m[2] == 0.0f);
    /* enable op does not leave quick stop; 10 ticks (10 ms, counting the tick of the quick
     * stop itself) later the drive is SWITCH_ON_DISABLED */
    for (int t = 0; t < 8; t++) {
        dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
        assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_QUICK_STOP_ACTIVE);
        sim_device_motor_torque_nm(&d, m);
        assert_true(m[2] == 0.0f);
    }
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_SWITCH_ON_DISABLED);
}

static void test_drive_fault_emcy_and_reset(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    dev_enable(&d, &p);
    can_batch_t out;
    const int16_t tq[3] = {200, 200, 200};
    float m[3];
    assert_true(sim_device_gpio_in(&d) & GPIO_IN_DRIVE_FAULT_N);

    sim_device_inject_drive_fault(&d, 1);
    assert_int_equal(sim_device_gpio_in(&d) & GPIO_IN_DRIVE_FAULT_N, 0);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[1] == 0.0f);                                  /* torque off at once */
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    assert_int_equal(count_id(&out, 0x082), 1);                 /* EMCY from node 2 */
    int found = 0;
    for (int i = 0; i < out.n; i++) {
        uint8_t node, reg;
        uint16_t code;
        if (canopen_emcy_decode(&out.f[i], &node, &code, &reg)) {
            assert_int_equal(node, 2);
            assert_int_equal(code, 0x2310);
            assert_int_equal(reg, 0x03);
            found++;
        }
    }
    assert_int_equal(found, 1);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_FAULT);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_OPERATION_ENABLED);
    sim_device_motor_torque_nm(&d, m);
    assert_true(m[1] == 0.0f);
    assert_float_equal(m[0], 0.006f, 1e-6f);                     /* the others carry on */
    assert_int_equal(sim_device_gpio_in(&d) & GPIO_IN_DRIVE_FAULT_N, 0);

    /* no second EMCY while the fault stands; enable op is ignored in FAULT */
    for (int t = 0; t < 5; t++) {
        dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
        assert_int_equal(count_id(&out, 0x082), 0);
        assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_FAULT);
    }

    /* fault reset (rising edge of bit 7): SWITCH_ON_DISABLED, EMCY "no error", line high */
    dev_cmd(&d, CIA402_CW_FAULT_RESET, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_SWITCH_ON_DISABLED);
    assert_true(sim_device_gpio_in(&d) & GPIO_IN_DRIVE_FAULT_N);
    uint8_t node, reg;
    uint16_t code;
    assert_int_equal(count_id(&out, 0x082), 1);
    for (int i = 0; i < out.n; i++)
        if (canopen_emcy_decode(&out.f[i], &node, &code, &reg)) {
            assert_int_equal(code, CANOPEN_EMCY_NO_ERROR);
            assert_int_equal(reg, 0);
        }
    /* and the drive walks back to work */
    dev_cmd(&d, CIA402_CW_SHUTDOWN, tq, ENABLE, &out);
    dev_cmd(&d, CIA402_CW_SWITCH_ON, tq, ENABLE, &out);
    dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 2, NULL, NULL), CIA402_OPERATION_ENABLED);
    sim_device_motor_torque_nm(&d, m);
    assert_float_equal(m[1], 0.006f, 1e-6f);
}

static void test_heartbeat_every_100_ms(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    sim_device_init(&d, &p);
    can_batch_t out;
    int times[20], n = 0;
    for (int t = 0; t < 1000; t++) {
        dev_step(&d, NULL, ENABLE, &out);
        for (int i = 0; i < out.n; i++)
            if (out.f[i].id == 0x701 && n < 20)
                times[n++] = t;
    }
    assert_int_equal(n, 10);                   /* boot-up at 0 ms, then 100 … 900 ms */
    assert_int_equal(times[0], 0);
    for (int k = 1; k < n; k++) {
        const int gap = times[k] - times[k - 1];
        assert_true(gap >= 99 && gap <= 101);
    }
}

static void test_tpdo_only_on_sync(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    dev_enable(&d, &p);
    can_batch_t in, out;
    /* RPDOs without SYNC: no TPDO */
    for (int t = 0; t < 50; t++) {
        batch_clear(&in);
        push_rpdo_all(&in, CIA402_CW_ENABLE_OP, NULL);
        dev_step(&d, &in, ENABLE, &out);
        for (uint8_t j = 1; j <= 3; j++)
            assert_int_equal(count_id(&out, 0x180u + j), 0);
    }
    /* the hand moves the arm; a SYNC gets one TPDO per drive with the position at that
     * instant (before the step's motion), quantised like the encoder */
    sim_device_set_hand(&d, vec3(0.02f, 0.01f, 0.16f), vec3(0, 0, 0), false, false);
    for (int t = 0; t < 30; t++) {
        float q[3];
        sim_device_q_rad(&d, q);
        batch_clear(&in);
        push_sync(&in);
        push_rpdo_all(&in, CIA402_CW_ENABLE_OP, NULL); /* after the SYNC in the batch */
        dev_step(&d, &in, ENABLE, &out);
        for (uint8_t j = 1; j <= 3; j++) {
            int32_t pos;
            assert_int_equal(count_id(&out, 0x180u + j), 1);
            assert_int_equal(tpdo_state(&out, j, &pos, NULL), CIA402_OPERATION_ENABLED);
            assert_int_equal(pos, arm_rad_to_counts(&p.arm.desc, j - 1, q[j - 1]));
        }
    }
    int32_t pos;
    (void)tpdo_state(&out, 1, &pos, NULL);
    assert_true(pos > 100);                     /* the yaw did turn right */
    /* an RPDO after the SYNC in the same batch is latched before the SYNC is answered */
    batch_clear(&in);
    push_sync(&in);
    push_rpdo_all(&in, CIA402_CW_SWITCH_ON, NULL);
    dev_step(&d, &in, ENABLE, &out);
    assert_int_equal(tpdo_state(&out, 1, NULL, NULL), CIA402_SWITCHED_ON);
}

/* ---------- arm + hand ---------- */

static void test_hand_holding_still_keeps_tip(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    dev_enable(&d, &p);                             /* drives on, zero torque */
    const vec3_t home = arm_workspace_centre(&p.arm.desc);
    sim_device_set_hand(&d, home, vec3(0, 0, 0), false, false);
    can_batch_t out;
    const int16_t zero[3] = {0, 0, 0};
    float worst_m = 0.0f;
    for (int t = 0; t < 2000; t++) {
        dev_cmd(&d, CIA402_CW_ENABLE_OP, zero, ENABLE, &out);
        worst_m = fmaxf(worst_m, vec3_norm(vec3_sub(sim_device_tip_m(&d), home)));
    }
    assert_true(worst_m < 0.1e-3f);
    assert_true(vec3_norm(sim_device_hand_force_n(&d)) < 0.01f);
}

static void test_hand_drags_tip_along(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    sim_device_init(&d, &p);
    const vec3_t start = sim_device_tip_m(&d);
    const vec3_t dir = vec3(0.6f, 0.48f, -0.64f);   /* unit length */
    const vec3_t vel = vec3_scale(dir, 0.040f);     /* 20 mm in 0.5 s */
    can_batch_t out;
    float peak_force_n = 0.0f;
    for (int t = 0; t < 500; t++) {
        const vec3_t target = vec3_add(start, vec3_scale(vel, (float)t * 1e-3f));
        sim_device_set_hand(&d, target, vel, false, false);
        dev_step(&d, NULL, 0, &out);
        peak_force_n = fmaxf(peak_force_n, vec3_norm(sim_device_hand_force_n(&d)));
    }
    const vec3_t end = vec3_add(start, vec3_scale(dir, 0.020f));
    const float err_m = vec3_norm(vec3_sub(sim_device_tip_m(&d), end));
    assert_true(err_m < 2e-3f);
    /* moving 75 g at 40 mm/s through light friction takes little force */
    assert_true(peak_force_n < 0.5f);
    assert_true(peak_force_n > 0.01f);
}

static void test_free_arm_energy_decays(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_default(&p);
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    s.qd_rad_s[0] = 1.0;
    s.qd_rad_s[1] = -0.8;
    s.qd_rad_s[2] = 1.5;
    const float zero[3] = {0, 0, 0};
    const double e0 = arm_sim_kinetic_energy_j(&s, &p);
    assert_true(e0 > 1e-4);
    double prev = e0;
    for (int t = 0; t < 1000; t++) {
        arm_sim_step(&s, &p, zero, vec3(0, 0, 0), TICK_US);
        const double e = arm_sim_kinetic_energy_j(&s, &p);
        assert_true(e <= prev);                      /* never grows */
        prev = e;
    }
    assert_true(prev < 1e-6 * e0);                   /* friction has stopped it */
    for (int k = 0; k < 3; k++)
        assert_true(fabs(s.qd_rad_s[k]) < 1e-3);
}

/* The sub-step's bound: 1 .. arm_sim_substep_max_us, and at that bound the explicit friction
 * is still monotone. Without the tip mass the joints decouple (M = R, no velocity-product
 * terms) and the bound is tight: slowing in the tanh smoothing's linear range (|q̇| << ε), one
 * sub-step of the bound never takes a joint's velocity past zero or lets the energy grow, and
 * one sub-step of 1.2 times it does overshoot (the tip mass only adds inertia: M >= R). */
static void test_arm_substep_bound_keeps_friction_monotone(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_default(&p);
    assert_int_equal(arm_sim_substep_us(&p), ARM_SIM_SUBSTEP_US);
    const uint32_t hi = arm_sim_substep_max_us(&p);
    assert_true(hi > ARM_SIM_SUBSTEP_US && hi < 1000u);
    p.substep_us = 0;
    assert_int_equal(arm_sim_substep_us(&p), 1u);
    p.substep_us = 100000u;
    assert_int_equal(arm_sim_substep_us(&p), hi);
    p.tip_mass_kg = 0.0f;
    assert_int_equal(arm_sim_substep_max_us(&p), hi); /* the bound does not count on it */
    const double v0[3] = {2e-4, -1.5e-4, 3e-4};      /* rad/s, ε = 0.01 */
    const float zero[3] = {0, 0, 0};
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    for (int k = 0; k < 3; k++)
        s.qd_rad_s[k] = v0[k];
    double e_prev = arm_sim_kinetic_energy_j(&s, &p);
    for (int t = 0; t < 200; t++) {
        double before[3];
        for (int k = 0; k < 3; k++)
            before[k] = s.qd_rad_s[k];
        arm_sim_step(&s, &p, zero, vec3(0, 0, 0), hi); /* exactly one sub-step */
        for (int k = 0; k < 3; k++) {
            assert_true(s.qd_rad_s[k] * v0[k] >= 0.0);           /* no overshoot past zero */
            assert_true(fabs(s.qd_rad_s[k]) <= fabs(before[k]));
        }
        const double e = arm_sim_kinetic_energy_j(&s, &p);
        assert_true(e <= e_prev);
        e_prev = e;
    }
    for (int k = 0; k < 3; k++)
        assert_true(fabs(s.qd_rad_s[k]) < 1e-3 * fabs(v0[k]));  /* and it did slow down */
    /* past the bound (arm_sim_substep_from takes any h): the first sub-step overshoots */
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    for (int k = 0; k < 3; k++)
        s.qd_rad_s[k] = v0[k];
    arm_kin_now_t kin;
    arm_sim_kin_now(&s, &p, &kin);
    arm_sim_substep_from(&s, &p, &kin, zero, vec3(0, 0, 0), hi + hi / 5u);
    for (int k = 0; k < 3; k++)
        assert_true(s.qd_rad_s[k] * v0[k] < 0.0);
}

/* What a coarse sub-step costs in fidelity, where the HIL rig uses one (argil-sim
 * --arm-substep-us): the hand dragging the tip 20 mm in 0.5 s ends within 10 um of where the
 * default sub-step puts it, and the grip force differs by under 2 % of its peak all the way.
 * Measured at the bound (219 us): 0.02 um and 0.2 %; one 1 ms sub-step (the friction widened so
 * that it is allowed) gives 52 um and 16 %. */
static void test_arm_coarse_substep_follows_default(void **state)
{
    (void)state;
    vec3_t end[2];
    float peak[2], worst_df = 0.0f;
    sim_params_t p[2];
    static sim_device_t d[2];
    for (int r = 0; r < 2; r++) {
        sim_params_default(&p[r]);
        if (r == 1)
            p[r].arm.substep_us = arm_sim_substep_max_us(&p[r].arm);
        sim_device_init(&d[r], &p[r]);
        peak[r] = 0.0f;
    }
    const vec3_t start = sim_device_tip_m(&d[0]);
    const vec3_t vel = vec3_scale(vec3(0.6f, 0.48f, -0.64f), 0.040f);
    can_batch_t out;
    for (int t = 0; t < 500; t++) {
        const vec3_t target = vec3_add(start, vec3_scale(vel, (float)t * 1e-3f));
        for (int r = 0; r < 2; r++) {
            sim_device_set_hand(&d[r], target, vel, false, false);
            dev_step(&d[r], NULL, 0, &out);
            peak[r] = fmaxf(peak[r], vec3_norm(sim_device_hand_force_n(&d[r])));
        }
        worst_df = fmaxf(worst_df, vec3_norm(vec3_sub(sim_device_hand_force_n(&d[0]),
                                                      sim_device_hand_force_n(&d[1]))));
    }
    for (int r = 0; r < 2; r++)
        end[r] = sim_device_tip_m(&d[r]);
    assert_true(peak[0] > 0.01f);
    assert_true(vec3_norm(vec3_sub(end[0], end[1])) < 10e-6f);
    assert_true(worst_df < 0.02f * peak[0]);
}

static void test_constant_torque_gives_inverse_mass_acceleration(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_default(&p);
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const float motor_nm[3] = {0.05f, -0.03f, 0.04f};
    /* expected: M(q) from arm_kin's Jacobian, q̈ = M⁻¹ (gear τ) by Cramer's rule */
    float j[3][3];
    arm_jacobian(&p.desc, p.desc.q_home_rad, j);
    double m[3][3], tau[3];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[r][c] = p.tip_mass_kg * (j[0][r] * j[0][c] + j[1][r] * j[1][c] + j[2][r] * j[2][c]);
        m[r][r] += p.rotor_inertia_kg_m2[r] * p.desc.gear_ratio[r] * p.desc.gear_ratio[r];
        tau[r] = motor_nm[r] * p.desc.gear_ratio[r];
    }
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double want[3];
    for (int c = 0; c < 3; c++) {
        double mc[3][3];
        memcpy(mc, m, sizeof mc);
        for (int r = 0; r < 3; r++)
            mc[r][c] = tau[r];
        want[c] = (mc[0][0] * (mc[1][1] * mc[2][2] - mc[1][2] * mc[2][1]) -
                   mc[0][1] * (mc[1][0] * mc[2][2] - mc[1][2] * mc[2][0]) +
                   mc[0][2] * (mc[1][0] * mc[2][1] - mc[1][1] * mc[2][0])) / det;
    }
    arm_sim_step(&s, &p, motor_nm, vec3(0, 0, 0), TICK_US);
    for (int k = 0; k < 3; k++) {
        const double got = s.qd_rad_s[k] / 1e-3;   /* mean acceleration over the first tick */
        assert_true(fabs(got - want[k]) <= 0.05 * fabs(want[k]));
    }
    /* the solver itself on the same system */
    double x[3];
    assert_true(arm_sim_solve3((const double(*)[3])m, tau, x));
    for (int k = 0; k < 3; k++)
        assert_true(fabs(x[k] - want[k]) <= 1e-9 * fabs(want[k]));
    /* motor torque beyond the drive's peak is clipped */
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const float huge[3] = {5.0f, 0.0f, 0.0f}, peak[3] = {0.12f, 0.0f, 0.0f};
    arm_sim_t s2;
    arm_sim_init(&s2, &p, p.desc.q_home_rad);
    arm_sim_step(&s, &p, huge, vec3(0, 0, 0), TICK_US);
    arm_sim_step(&s2, &p, peak, vec3(0, 0, 0), TICK_US);
    assert_true(s.qd_rad_s[0] == s2.qd_rad_s[0]);
}

static void test_hard_stop_at_joint_limit(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_default(&p);
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const float push[3] = {0.1f, 0.0f, 0.0f};           /* yaw to the right, 1 N m at the joint */
    for (int t = 0; t < 1000; t++)
        arm_sim_step(&s, &p, push, vec3(0, 0, 0), TICK_US);
    assert_true(s.q_rad[0] == (double)p.desc.q_max_rad[0]);
    assert_true(s.qd_rad_s[0] == 0.0);                  /* restitution 0: no bounce */
}

/* ---------- the Premium profile: cable mode, current loop, torque DAC ---------- */

/* The premium profile with no friction and an undamped cable: what a formula can predict. */
static void premium_lossless(arm_params_t *p)
{
    arm_params_premium(p);
    for (int j = 0; j < 3; j++) {
        p->coulomb_nm[j] = 0.0f;
        p->viscous_nm_s_per_rad[j] = 0.0f;
        p->cable_damping_nm_s_per_rad[j] = 0.0f;
    }
}

/* The yaw's cable mode rings at √(k (1/I_motor + 1/I_link)) / 2π, with I_motor = I_rotor gear²
 * and I_link = m r² + the yaw's link inertia (the yaw column of J is orthogonal to the other
 * two, so the yaw decouples): a torque step on the yaw motor makes the motor-side angle, which
 * the encoder reads, swing about the link's. Measured from the twist rate's zero crossings over
 * 100 ms (about 44 periods) at the longest sub-step the bound allows. */
static void test_premium_cable_mode_frequency(void **state)
{
    (void)state;
    arm_params_t p;
    premium_lossless(&p);
    p.substep_us = 100000u;                        /* the bound's own sub-step */
    const uint32_t h_us = arm_sim_substep_us(&p);
    assert_true(h_us > 20u && h_us <= arm_sim_substep_max_us(&p));
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const vec3_t tip = arm_sim_tip_m(&s, &p);
    const double r = hypot(tip.x, tip.z), g = p.desc.gear_ratio[0];
    const double i_motor = p.rotor_inertia_kg_m2[0] * g * g;
    const double i_link = p.tip_mass_kg * r * r + p.link_inertia_kg_m2[0];
    const double k = 1.0 / p.cable_compliance_rad_per_nm[0];
    const double want_hz = sqrt(k * (1.0 / i_motor + 1.0 / i_link)) / (2.0 * M_PI);
    assert_true(want_hz > 300.0 && want_hz < 600.0);  /* docs/arm.md: 441 Hz at home */
    const float step_nm[3] = {0.01f, 0.0f, 0.0f};
    double first_s = -1.0, last_s = -1.0, prev = 0.0, max_twist = 0.0;
    int crossings = 0;
    for (uint32_t n = 1; n * h_us <= 100000u; n++) {
        arm_sim_step(&s, &p, step_nm, vec3(0, 0, 0), h_us);
        const double rate = s.qmd_rad_s[0] - s.qd_rad_s[0];
        const double t_s = (double)(n * h_us) * 1e-6;
        if (n > 1 && rate * prev < 0.0) {
            const double at = t_s - (double)h_us * 1e-6 * rate / (rate - prev);
            if (first_s < 0.0)
                first_s = at;
            last_s = at;
            crossings++;
        }
        prev = rate;
        max_twist = fmax(max_twist, fabs(arm_sim_encoder_rad(&s, &p, 0) - s.q_rad[0]));
    }
    assert_true(crossings > 60);
    const double got_hz = (double)(crossings - 1) / (2.0 * (last_s - first_s));
    assert_true(fabs(got_hz - want_hz) <= 0.01 * want_hz);
    /* the encoder sees the swing: up to twice the static twist g τ i_link / ((i_m + i_l) k) */
    const double static_twist = g * step_nm[0] / k * i_link / (i_motor + i_link);
    assert_true(max_twist > 1.8 * static_twist && max_twist < 2.2 * static_twist);
}

/* On a PHANToM the encoders sit on the motors: with the elbow motor pushing steadily against
 * the hand's grip, the counts the board reads are the motor side's, ahead of the link by the
 * cable's twist gear τ / k (7 counts at 3000 ‰). */
static void test_premium_encoder_reads_motor_side(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    arm_params_premium(&p.arm);
    static sim_device_t d;
    dev_enable(&d, &p);
    const int16_t tq[3] = {0, 0, 3000};
    can_batch_t out;
    for (int t = 0; t < 300; t++)
        dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
    int32_t counts;
    assert_int_equal(tpdo_state(&out, 3, &counts, NULL), CIA402_OPERATION_ENABLED);
    float applied[3];
    arm_sim_applied_torque_nm(&d.arm, applied);
    const double twist_rad = p.arm.desc.gear_ratio[2] * applied[2] * p.arm.cable_compliance_rad_per_nm[2];
    const double rad_per_count = 2.0 * M_PI / (p.arm.desc.gear_ratio[2] *
                                               p.arm.desc.encoder_counts_per_rev[2]);
    assert_true(twist_rad / rad_per_count > 5.0);
    const int32_t link_counts = arm_rad_to_counts(&p.arm.desc, 2, (float)d.arm.q_rad[2]);
    /* the TPDO went out before the latest step's motion: compare with the twist, ±1 count */
    assert_true(fabs(((double)counts - (double)link_counts) - twist_rad / rad_per_count) <= 1.5);
}

/* The current loop: a torque step reaches 1 − 1/e = 63 % of the command at T_c = 1 / (2π f_c)
 * and 99 % by 5 T_c, and the joint gets the matching impulse: a free rigid yaw's speed at T_c is
 * gear τ T_c / (e I), where with no lag it would be gear τ T_c / I. */
static void test_premium_current_loop_step(void **state)
{
    (void)state;
    arm_params_t p;
    premium_lossless(&p);
    for (int j = 0; j < 3; j++)
        p.cable_compliance_rad_per_nm[j] = 0.0f;      /* rigid: the yaw's inertia is M00 */
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const double tc_s = 1.0 / (2.0 * M_PI * p.current_loop_hz[0]);
    const uint32_t tc_us = (uint32_t)lrint(tc_s * 1e6);
    assert_int_equal(tc_us, 159u);                    /* 1 kHz */
    const float cmd[3] = {0.05f, 0.0f, 0.0f};
    float applied[3];
    arm_sim_step(&s, &p, cmd, vec3(0, 0, 0), tc_us);
    arm_sim_applied_torque_nm(&s, applied);
    const double t_s = (double)tc_us * 1e-6;
    assert_true(fabs(applied[0] / cmd[0] - (1.0 - exp(-t_s / tc_s))) < 1e-4);
    assert_true(fabs(applied[0] / cmd[0] - 0.632) < 0.005);
    double m[3][3];
    arm_sim_mass_matrix(&p, s.q_rad, m);
    const double gear_tau = p.desc.gear_ratio[0] * cmd[0];
    const double want = gear_tau / m[0][0] * (t_s - tc_s * (1.0 - exp(-t_s / tc_s)));
    assert_true(fabs(s.qd_rad_s[0] - want) <= 0.01 * want);
    assert_true(s.qd_rad_s[0] < 0.4 * gear_tau / m[0][0] * t_s);  /* far from the unlagged */
    arm_sim_step(&s, &p, cmd, vec3(0, 0, 0), 4u * tc_us);
    arm_sim_applied_torque_nm(&s, applied);
    assert_true(applied[0] > 0.99f * cmd[0] && applied[0] <= cmd[0]);
}

/* The torque DAC: every torque a drive applies is a whole number of steps of 2 peak / 2^12
 * (58.6 µN m, coarser than the 30 µN m of one ‰), the nearest one to the command, and stepping
 * the command ‰ by ‰ moves the torque by 0 or one step. */
static void test_premium_torque_dac_steps(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    arm_params_premium(&p.arm);
    static sim_device_t d;
    dev_enable(&d, &p);
    const double step_nm = 2.0 * p.arm.peak_torque_nm[0] / 4096.0;
    assert_true(fabs(step_nm - 58.59375e-6) < 1e-9);
    can_batch_t out;
    double prev = 0.0;
    int levels = 0;
    for (int pm = -4000; pm <= 4000; pm += 1) {
        const int16_t tq[3] = {(int16_t)pm, 0, 0};
        dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, &out);
        float m[3];
        sim_device_motor_torque_nm(&d, m);
        const double codes = m[0] / step_nm;
        assert_true(fabs(codes - rint(codes)) < 1e-3);
        const double want_nm = pm * 0.030 / 1000.0;
        assert_true(fabs(m[0] - want_nm) <= 0.5 * step_nm + 1e-9 ||
                    (pm == 4000 && fabs(m[0] - (want_nm - step_nm)) < 1e-9)); /* +peak: a code short */
        if (pm > -4000) {
            const double moved = rint((m[0] - prev) / step_nm);
            assert_true(moved == 0.0 || moved == 1.0);
            levels += moved == 1.0;
        }
        prev = m[0];
        dev_step(&d, NULL, 0, &out);  /* power off between commands: keep the arm home */
    }
    assert_int_equal(levels, 4095);
}

/* The free compliant arm with friction and cable damping off keeps its energy, kinetic (links
 * and rotors) plus the cables', through 0.5 s of ringing: no drift (0.1 % between the first and
 * the last 50 ms), and excursions within the bound's ±ω h / 2 = ±12.5 % of the most energy the
 * cables held (measured: 0.8 % of the total where that allows 1.3 %). */
static void test_premium_free_arm_conserves_energy(void **state)
{
    (void)state;
    arm_params_t p;
    premium_lossless(&p);
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    s.qd_rad_s[0] = 0.2;                   /* links moving, rotors still: the cables ring */
    s.qd_rad_s[1] = -0.16;
    s.qd_rad_s[2] = 0.3;
    const float zero[3] = {0, 0, 0};
    const double e0 = arm_sim_kinetic_energy_j(&s, &p) + arm_sim_cable_energy_j(&s, &p);
    double worst = 0.0, early = 0.0, late = 0.0, cable_max = 0.0;
    for (int t = 0; t < 500; t++) {
        arm_sim_step(&s, &p, zero, vec3(0, 0, 0), TICK_US);
        const double cable = arm_sim_cable_energy_j(&s, &p);
        const double e = arm_sim_kinetic_energy_j(&s, &p) + cable;
        worst = fmax(worst, fabs(e - e0));
        cable_max = fmax(cable_max, cable);
        if (t < 50)
            early += e / 50.0;
        if (t >= 450)
            late += e / 50.0;
    }
    assert_true(cable_max > 0.01 * e0);               /* the modes were excited */
    for (int j = 0; j < 3; j++)                       /* no joint reached a stop */
        assert_true(s.q_rad[j] > p.desc.q_min_rad[j] && s.q_rad[j] < p.desc.q_max_rad[j]);
    assert_true(worst < 0.5 * ARM_SIM_OMEGA_H_MAX * cable_max);
    assert_true(fabs(late - early) < 0.002 * e0);
}

/* The sub-step bound with a cable mode: the fastest mode any pose can have, ω_max =
 * √(k (1/I_motor + 1/min link-side floor)), gets ω_max h <= ARM_SIM_OMEGA_H_MAX at the bound and
 * not one microsecond longer; the premium arm still runs at the default 50 µs, and the default
 * arm's bound is the 219 µs docs/arm.md gives (no cable: friction alone sets it). */
static void test_premium_substep_bound(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_premium(&p);
    const uint32_t hi = arm_sim_substep_max_us(&p);
    const double g = p.desc.gear_ratio[0];
    double floor_kg_m2 = INFINITY;
    for (int j = 0; j < 3; j++)
        floor_kg_m2 = fmin(floor_kg_m2, p.link_inertia_kg_m2[j]);
    const double w_max = sqrt(1.0 / p.cable_compliance_rad_per_nm[0] *
                              (1.0 / (p.rotor_inertia_kg_m2[0] * g * g) + 1.0 / floor_kg_m2));
    assert_true(w_max * (double)hi * 1e-6 <= ARM_SIM_OMEGA_H_MAX);
    assert_true(w_max * (double)(hi + 1u) * 1e-6 > ARM_SIM_OMEGA_H_MAX);
    assert_int_equal(arm_sim_substep_us(&p), ARM_SIM_SUBSTEP_US);
    p.substep_us = 1000u;
    assert_int_equal(arm_sim_substep_us(&p), hi);
    arm_params_t def;
    arm_params_default(&def);
    assert_int_equal(arm_sim_substep_max_us(&def), 219u);
    /* a cable with no link-side inertia behind it has no bound: refuse with 1 µs */
    p.link_inertia_kg_m2[1] = 0.0f;
    assert_int_equal(arm_sim_substep_max_us(&p), 1u);
}

/* The default arm has none of it: the torque is the command from the first microsecond, the
 * encoder reads the joint, the cables store nothing, and one ‰ gives its 30 µN m exactly. */
static void test_default_arm_is_rigid_and_unlagged(void **state)
{
    (void)state;
    arm_params_t p;
    arm_params_default(&p);
    arm_sim_t s;
    arm_sim_init(&s, &p, p.desc.q_home_rad);
    const float cmd[3] = {0.01f, -0.02f, 0.03f};
    float applied[3];
    arm_sim_step(&s, &p, cmd, vec3(0.3f, 0, 0), 1u);
    arm_sim_applied_torque_nm(&s, applied);
    for (int j = 0; j < 3; j++)
        assert_true(applied[j] == cmd[j]);
    arm_sim_step(&s, &p, cmd, vec3(0.3f, 0, 0), TICK_US);
    for (int j = 0; j < 3; j++) {
        assert_true(s.q_rad[j] != (double)p.desc.q_home_rad[j]);  /* it moved */
        assert_true(arm_sim_encoder_rad(&s, &p, j) == s.q_rad[j]);
    }
    assert_true(arm_sim_cable_energy_j(&s, &p) == 0.0);
    sim_params_t sp;
    sim_params_default(&sp);
    static sim_device_t d;
    dev_enable(&d, &sp);
    const int16_t one[3] = {1, -1, 1};
    can_batch_t out;
    dev_cmd(&d, CIA402_CW_ENABLE_OP, one, ENABLE, &out);
    float m[3];
    sim_device_motor_torque_nm(&d, m);
    assert_float_equal(m[0], 30e-6f, 1e-10f);
    assert_float_equal(m[1], -30e-6f, 1e-10f);
}

static void test_hand_force_formula(void **state)
{
    (void)state;
    hand_params_t h;
    hand_params_default(&h);
    assert_float_equal(h.stiffness_n_per_m, 800.0f, 0.0f);
    assert_float_equal(h.damping_n_s_per_m, 8.0f, 0.0f);
    const vec3_t f = hand_force_n(&h, vec3(0.01f, 0, 0), vec3(0, 0.1f, 0), vec3(0, 0, 0),
                                  vec3(0, 0, 0.05f));
    assert_float_equal(f.x, 8.0f, 1e-5f);      /* 10 mm × 800 N/m */
    assert_float_equal(f.y, 0.8f, 1e-5f);      /* 0.1 m/s × 8 N s/m */
    assert_float_equal(f.z, -0.4f, 1e-5f);
}

/* The delivered force is the tip force the arm's applied torques make: at a pose off home,
 * torques worked out from a known force by Jᵀ F give that force back; an opposite external
 * force at the tip holds the arm still; a drive command beyond the peak delivers what the peak
 * delivers. */
static void test_delivered_force_from_drive_torques(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    sim_device_init(&d, &p);
    const float q[3] = {0.3f, -0.6f, 1.2f};
    arm_sim_init(&d.arm, &d.p.arm, q);
    const vec3_t want = vec3(0.4f, -1.1f, 2.0f);
    float j[3][3], tau[3];
    arm_jacobian(&p.arm.desc, q, j);
    arm_jt_force(j, want, tau);
    for (int k = 0; k < 3; k++)
        d.arm.torque_nm[k] = tau[k] / p.arm.desc.gear_ratio[k];
    const vec3_t got = sim_device_delivered_force_n(&d);
    assert_float_equal(got.x, want.x, 1e-4f);
    assert_float_equal(got.y, want.y, 1e-4f);
    assert_float_equal(got.z, want.z, 1e-4f);

    /* the applied torques against −F at the tip: no joint accelerates */
    float motor[3];
    arm_sim_applied_torque_nm(&d.arm, motor);
    arm_sim_step(&d.arm, &d.p.arm, motor, vec3_scale(got, -1.0f), TICK_US);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(d.arm.qd_rad_s[k]) < 1e-6);

    /* a command beyond the peak torque: the arm applies the peak, and that is delivered */
    const float over_cmd[3] = {5.0f, 0.0f, 0.0f}, peak_cmd[3] = {p.arm.peak_torque_nm[0], 0, 0};
    arm_sim_init(&d.arm, &d.p.arm, q);
    arm_sim_step(&d.arm, &d.p.arm, over_cmd, vec3(0, 0, 0), TICK_US);
    const vec3_t over = sim_device_delivered_force_n(&d);
    arm_sim_init(&d.arm, &d.p.arm, q);
    arm_sim_step(&d.arm, &d.p.arm, peak_cmd, vec3(0, 0, 0), TICK_US);
    const vec3_t at_peak = sim_device_delivered_force_n(&d);
    assert_true(vec3_norm(vec3_sub(over, at_peak)) == 0.0f);
    assert_true(vec3_norm(at_peak) > 0.1f);
}

static void test_buttons_and_gpio(void **state)
{
    (void)state;
    sim_params_t p;
    sim_params_default(&p);
    sim_device_t d;
    sim_device_init(&d, &p);
    assert_int_equal(sim_device_gpio_in(&d), GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N);
    sim_device_set_hand(&d, sim_device_tip_m(&d), vec3(0, 0, 0), true, false);
    assert_int_equal(sim_device_gpio_in(&d),
                     GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N | GPIO_IN_STYLUS_BTN1);
    sim_device_set_hand(&d, sim_device_tip_m(&d), vec3(0, 0, 0), false, true);
    sim_device_set_estop(&d, true);
    assert_int_equal(sim_device_gpio_in(&d), GPIO_IN_DRIVE_FAULT_N | GPIO_IN_STYLUS_BTN2);
}

/* A scripted session: enable, push with torque, hand motion; returns the tip trace. */
static void scripted_run(vec3_t trace[300], can_batch_t *last_out)
{
    sim_params_t p;
    sim_params_default(&p);
    static sim_device_t d;
    dev_enable(&d, &p);
    const vec3_t home = sim_device_tip_m(&d);
    for (int t = 0; t < 300; t++) {
        const int16_t tq[3] = {(int16_t)(t % 50 * 10), -200, (int16_t)(t % 7 * 30)};
        const vec3_t target = vec3_add(home, vec3(0.01f * sinf((float)t * 0.02f), 0.0f, 0.0f));
        sim_device_set_hand(&d, target, vec3(0.0002f * cosf((float)t * 0.02f) * 1000.0f, 0, 0),
                            t > 100, false);
        if (t == 150)
            sim_device_inject_drive_fault(&d, 0);
        dev_cmd(&d, CIA402_CW_ENABLE_OP, tq, ENABLE, last_out);
        trace[t] = sim_device_tip_m(&d);
    }
}

static void test_determinism(void **state)
{
    (void)state;
    static vec3_t a[300], b[300];
    can_batch_t oa, ob;
    memset(&oa, 0, sizeof oa);
    memset(&ob, 0, sizeof ob);
    scripted_run(a, &oa);
    scripted_run(b, &ob);
    assert_memory_equal(a, b, sizeof a);
    assert_int_equal(oa.n, ob.n);
    assert_memory_equal(oa.f, ob.f, sizeof oa.f[0] * oa.n);
    /* and the run did move the arm */
    assert_true(vec3_norm(vec3_sub(a[299], a[0])) > 1e-3f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drive_boot_and_nmt),
        cmocka_unit_test(test_drive_power_state_machine_and_torque),
        cmocka_unit_test(test_drive_quick_stop_zeroes_torque),
        cmocka_unit_test(test_drive_fault_emcy_and_reset),
        cmocka_unit_test(test_heartbeat_every_100_ms),
        cmocka_unit_test(test_tpdo_only_on_sync),
        cmocka_unit_test(test_hand_holding_still_keeps_tip),
        cmocka_unit_test(test_hand_drags_tip_along),
        cmocka_unit_test(test_free_arm_energy_decays),
        cmocka_unit_test(test_arm_substep_bound_keeps_friction_monotone),
        cmocka_unit_test(test_arm_coarse_substep_follows_default),
        cmocka_unit_test(test_constant_torque_gives_inverse_mass_acceleration),
        cmocka_unit_test(test_hard_stop_at_joint_limit),
        cmocka_unit_test(test_premium_cable_mode_frequency),
        cmocka_unit_test(test_premium_encoder_reads_motor_side),
        cmocka_unit_test(test_premium_current_loop_step),
        cmocka_unit_test(test_premium_torque_dac_steps),
        cmocka_unit_test(test_premium_free_arm_conserves_energy),
        cmocka_unit_test(test_premium_substep_bound),
        cmocka_unit_test(test_default_arm_is_rigid_and_unlagged),
        cmocka_unit_test(test_hand_force_formula),
        cmocka_unit_test(test_delivered_force_from_drive_torques),
        cmocka_unit_test(test_buttons_and_gpio),
        cmocka_unit_test(test_determinism),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
