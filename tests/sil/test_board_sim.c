/* SIL: the board core against the simulated arm and drives, with the host's protocol peer and
 * a clay sphere, on a virtual clock. Assertions are what a person at the arm would notice. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/board_hal.h"
#include "firmware/hal/hal_sim.h"
#include "host/app/peer.h"
#include "host/model/grid.h"
#include "shared/gpio_lines.h"
#include "sim/sim_device.h"

typedef struct {
    hal_t hal;
    board_t board;
    board_io_t io;
    sim_device_t dev;
    sim_params_t sp;
    grid_t grid;
    peer_t peer;
    vec3_t offset_m;          /* model = device + offset */
    vec3_t hand_model_m;
    bool btn1;
    bool host_alive;          /* the host ticks and answers */
    can_batch_t last_from_board;
    uint8_t rx[HAL_SIM_LINK_BYTES];
    uint32_t ms;
} rig_t;

static bool rig_send(void *ctx, const uint8_t *f, size_t len)
{
    rig_t *r = ctx;
    return hal_sim_host_send(&r->hal, f, len) == ARGIL_OK;
}

static rig_t *rig_new(float stiffness_n_per_mm)
{
    rig_t *r = calloc(1, sizeof(*r));
    assert_non_null(r);
    sim_params_default(&r->sp);
    sim_device_init(&r->dev, &r->sp);
    hal_sim_init(&r->hal);
    board_cfg_t bc;
    board_cfg_default(&bc);
    bc.arm = r->sp.arm.desc;
    assert_int_equal(board_init(&r->board, &bc), ARGIL_OK);
    board_io_init(&r->io);
    const int32_t dims[3] = {72, 72, 72};
    const float half = 0.5f * 71 * 0.00125f;
    assert_int_equal(grid_init(&r->grid, dims, 0.00125f, vec3(-half, -half, -half)), ARGIL_OK);
    grid_fill_sphere(&r->grid, vec3(0, 0, 0), 0.030f);
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    assert_int_equal(peer_init(&r->peer, &pc, &r->grid, rig_send, NULL, r), ARGIL_OK);
    r->offset_m = vec3_sub(vec3(0, 0, 0.060f), sim_device_tip_m(&r->dev));
    r->hand_model_m = vec3(0, 0, 0.060f);
    r->host_alive = true;
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_TOUCH;
    t.radius_m = 0.004f;
    t.alpha = 12000.0f;
    t.contact_stiffness_n_per_m = stiffness_n_per_mm * 1000.0f;
    t.max_force_n = 3.3f;
    t.model_scale = 1.0f;
    t.model_offset_m[0] = r->offset_m.x;
    t.model_offset_m[1] = r->offset_m.y;
    t.model_offset_m[2] = r->offset_m.z;
    peer_set_tool(&r->peer, &t);
    peer_request_arm(&r->peer);
    return r;
}

static void rig_free(rig_t *r)
{
    peer_free(&r->peer);
    grid_free(&r->grid);
    free(r);
}

/* One millisecond of the whole system. */
static void rig_tick(rig_t *r)
{
    sim_device_set_hand(&r->dev, vec3_sub(r->hand_model_m, r->offset_m), vec3(0, 0, 0), r->btn1,
                        false);
    can_batch_t to_board = {0};
    hal_sim_take_from_board(&r->hal, &r->last_from_board);
    sim_device_step(&r->dev, &r->last_from_board, hal_sim_gpio_out(&r->hal), &to_board, 1000);
    hal_sim_put_to_board(&r->hal, &to_board);
    hal_sim_set_gpio_in(&r->hal, sim_device_gpio_in(&r->dev));
    (void)board_run_tick(&r->board, &r->io, &r->hal);
    const size_t n = hal_sim_host_receive(&r->hal, r->rx, sizeof(r->rx));
    if (r->host_alive) {
        peer_receive(&r->peer, r->rx, n);
        peer_tick(&r->peer, 1000);
    }
    r->ms++;
}

/* Runs until the board is ACTIVE; returns the milliseconds it took (or -1). */
static int rig_until_active(rig_t *r, int max_ms)
{
    for (int i = 0; i < max_ms; i++) {
        rig_tick(r);
        if (r->board.safety.state == SAFETY_ACTIVE)
            return i + 1;
    }
    return -1;
}

/* Moves the hand in a straight line over ms milliseconds. */
static void rig_move(rig_t *r, vec3_t to_m, int ms)
{
    const vec3_t from = r->hand_model_m;
    for (int i = 1; i <= ms; i++) {
        r->hand_model_m = vec3_add(from, vec3_scale(vec3_sub(to_m, from), (float)i / (float)ms));
        rig_tick(r);
    }
}

static void test_arms_and_becomes_active(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    const int ms = rig_until_active(r, 1000);
    assert_in_range(ms, 1, 300);
    assert_true(drives_all_enabled(&r->board.drives));
    assert_true(hal_sim_gpio_out(&r->hal) & GPIO_OUT_DRIVE_ENABLE);
    /* The board's view of the tool matches the simulated tip to within 0.1 mm. */
    for (int i = 0; i < 20; i++)
        rig_tick(r);
    const vec3_t tip_model = vec3_add(sim_device_tip_m(&r->dev), r->offset_m);
    assert_true(vec3_norm(vec3_sub(tip_model, r->board.pos_m)) < 1e-4f);
    rig_free(r);
}

static void test_touching_the_clay_pushes_back(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    assert_true(rig_until_active(r, 1000) > 0);
    rig_move(r, vec3(0, 0, 0.031f), 600); /* hand 1 mm outside the surface + 4 mm tool radius */
    rig_move(r, vec3(0, 0, 0.028f), 300);
    for (int i = 0; i < 200; i++)
        rig_tick(r);
    const vec3_t f = r->board.force_n;
    assert_true(f.z > 0.5f);                     /* pushes the stylus out along +z */
    assert_true(fabsf(f.x) < 0.1f && fabsf(f.y) < 0.1f);
    const vec3_t tip = vec3_add(sim_device_tip_m(&r->dev), r->offset_m);
    assert_true(tip.z > 0.028f + 0.0005f);       /* the tip is held off the hand's target */
    assert_true(r->board.stats.peak_force_n <= r->board.cfg.max_force_n + 1e-6f);
    rig_free(r);
}

static void test_force_never_exceeds_limit(void **st)
{
    (void)st;
    rig_t *r = rig_new(5.0f); /* stiff contact, hand driven 12 mm deep */
    assert_true(rig_until_active(r, 1000) > 0);
    rig_move(r, vec3(0, 0, 0.034f), 500);
    rig_move(r, vec3(0, 0, 0.022f), 500);
    float peak = 0.0f;
    for (int i = 0; i < 500; i++) {
        rig_tick(r);
        const float n = vec3_norm(r->board.force_n);
        if (n > peak)
            peak = n;
    }
    assert_true(peak > 3.0f);                    /* it did push hard */
    assert_true(peak <= 3.3f + 1e-5f);           /* and never past the 3.3 N limit */
    rig_free(r);
}

/* The torque the board commands in its RPDO frames of the last tick, per mille. */
static int max_commanded_torque(const rig_t *r, bool *quick_stop)
{
    int m = 0;
    *quick_stop = false;
    for (uint8_t i = 0; i < r->io.out.can_tx.n; i++) {
        uint8_t node;
        uint16_t cw;
        int16_t tq;
        if (canopen_rpdo_decode(&r->io.out.can_tx.f[i], &node, &cw, &tq)) {
            if (abs(tq) > m)
                m = abs(tq);
            if (cw == CIA402_CW_QUICK_STOP)
                *quick_stop = true;
        }
    }
    return m;
}

static void test_estop_cuts_torque_in_the_same_tick(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    assert_true(rig_until_active(r, 1000) > 0);
    rig_move(r, vec3(0, 0, 0.031f), 500);
    rig_move(r, vec3(0, 0, 0.028f), 300);
    bool qs;
    assert_true(max_commanded_torque(r, &qs) > 0); /* pressing on the clay */
    sim_device_set_estop(&r->dev, true);
    rig_tick(r);
    assert_int_equal(r->board.safety.state, SAFETY_ESTOP);
    assert_int_equal(max_commanded_torque(r, &qs), 0);
    assert_true(qs);                                /* drives told to quick-stop */
    assert_float_equal(vec3_norm(r->board.force_n), 0.0f, 0.0f);
    for (int i = 0; i < 5; i++)
        rig_tick(r);
    float tq[3];
    sim_device_motor_torque_nm(&r->dev, tq);
    assert_float_equal(fabsf(tq[0]) + fabsf(tq[1]) + fabsf(tq[2]), 0.0f, 0.0f);
    assert_false(hal_sim_gpio_out(&r->hal) & GPIO_OUT_DRIVE_ENABLE);
    /* Released, but nobody re-armed: still latched, still no torque. */
    sim_device_set_estop(&r->dev, false);
    for (int i = 0; i < 200; i++)
        rig_tick(r);
    assert_int_equal(r->board.safety.state, SAFETY_ESTOP);
    assert_int_equal(max_commanded_torque(r, &qs), 0);
    rig_free(r);
}

static void test_host_lost_fades_force_within_20ms(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    assert_true(rig_until_active(r, 1000) > 0);
    rig_move(r, vec3(0, 0, 0.031f), 500);
    rig_move(r, vec3(0, 0, 0.028f), 300);
    assert_true(vec3_norm(r->board.force_n) > 0.3f);
    r->host_alive = false;
    int fault_ms = -1, zero_ms = -1;
    for (int ms = 1; ms <= 200; ms++) {
        rig_tick(r);
        if (fault_ms < 0 && r->board.safety.state == SAFETY_FAULT)
            fault_ms = ms;
        if (fault_ms > 0 && zero_ms < 0 && vec3_norm(r->board.force_n) == 0.0f)
            zero_ms = ms;
    }
    assert_int_equal(r->board.safety.fault, FAULT_HOST_LOST);
    assert_in_range(fault_ms, 40, 60);      /* 50 ms heartbeat timeout (host beats every 5 ms) */
    assert_in_range(zero_ms - fault_ms, 0, 20);
    rig_free(r);
}

static void test_drive_fault_reaches_fault_state(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    assert_true(rig_until_active(r, 1000) > 0);
    sim_device_inject_drive_fault(&r->dev, 1);
    int ms = 0;
    while (r->board.safety.state != SAFETY_FAULT && ms < 100) {
        rig_tick(r);
        ms++;
    }
    assert_in_range(ms, 1, 3);
    assert_true(r->board.safety.fault == FAULT_DRIVE_LINE || r->board.safety.fault == FAULT_DRIVE_EMCY);
    assert_float_equal(vec3_norm(r->board.force_n), 0.0f, 0.0f);
    rig_free(r);
}

static void test_garbage_on_the_link_is_refused_not_fatal(void **st)
{
    (void)st;
    rig_t *r = rig_new(0.8f);
    assert_true(rig_until_active(r, 1000) > 0);
    uint8_t junk[300];
    uint32_t x = 12345;
    for (size_t i = 0; i < sizeof(junk); i++) {
        x = x * 1103515245u + 12345u;
        junk[i] = (uint8_t)(x >> 16);
    }
    junk[0] = 'A'; junk[1] = 'R'; junk[2] = 'G'; junk[3] = 'L'; /* looks like a frame, is not */
    for (int i = 0; i < 50; i++) {
        assert_int_equal(hal_sim_host_send(&r->hal, junk, sizeof(junk)), ARGIL_OK);
        rig_tick(r);
    }
    assert_int_equal(r->board.safety.state, SAFETY_ACTIVE);
    assert_true(r->board.stats.link_errors >= 50);
    rig_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arms_and_becomes_active),
        cmocka_unit_test(test_touching_the_clay_pushes_back),
        cmocka_unit_test(test_force_never_exceeds_limit),
        cmocka_unit_test(test_estop_cuts_torque_in_the_same_tick),
        cmocka_unit_test(test_host_lost_fades_force_within_20ms),
        cmocka_unit_test(test_drive_fault_reaches_fault_state),
        cmocka_unit_test(test_garbage_on_the_link_is_refused_not_fatal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
