/* CiA 402 master: NMT start, the power state machine walk, quick stop, fault reset on re-arm,
 * heartbeat consumer, EMCY decoding, SocketCAN error frames (error-passive, bus-off, restart)
 * and the bounded recovery time, and the shutdown frames. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "firmware/core/drives.h"

static drives_cfg_t cfg;
static const int16_t torque[ARGIL_DRIVES] = {500, -300, 1200};

static void rx_frame(drives_t *dr, const can_frame_t *f)
{
    can_batch_t b = {0};
    (void)can_batch_push(&b, f);
    drives_receive(dr, &b);
}

static void heartbeat_all(drives_t *dr, nmt_state_t st)
{
    can_frame_t f;
    for (uint8_t n = 1; n <= ARGIL_DRIVES; n++) {
        canopen_heartbeat_encode(&f, n, st);
        rx_frame(dr, &f);
    }
}

static void status_all(drives_t *dr, cia402_state_t s)
{
    can_frame_t f;
    for (uint8_t n = 1; n <= ARGIL_DRIVES; n++) {
        canopen_tpdo_encode(&f, n, cia402_statusword(s), 100 * n, 0);
        rx_frame(dr, &f);
    }
}

/* The controlword and torque the master sent to node in tx. */
static bool rpdo_of(const can_batch_t *tx, uint8_t node, uint16_t *cw, int16_t *tq)
{
    for (uint8_t i = 0; i < tx->n; i++) {
        uint8_t nd;
        if (canopen_rpdo_decode(&tx->f[i], &nd, cw, tq) && nd == node)
            return true;
    }
    return false;
}

static void test_nmt_start_then_power_walk(void **st)
{
    (void)st;
    drives_t dr;
    drives_cfg_default(&cfg);
    drives_init(&dr);
    can_batch_t tx = {0};
    drives_process(&dr, &cfg, true, torque, 1000, &tx);
    assert_int_equal(tx.n, 1); /* only SYNC: no drive has announced itself */
    heartbeat_all(&dr, NMT_STATE_PREOP);
    tx.n = 0;
    drives_process(&dr, &cfg, true, torque, 1000, &tx);
    int starts = 0;
    for (uint8_t i = 0; i < tx.n; i++) {
        nmt_cmd_t c;
        uint8_t node;
        if (canopen_nmt_decode(&tx.f[i], &c, &node) && c == NMT_CMD_START)
            starts++;
    }
    assert_int_equal(starts, 3);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    const struct { cia402_state_t s; uint16_t cw; } walk[] = {
        {CIA402_SWITCH_ON_DISABLED, CIA402_CW_SHUTDOWN},
        {CIA402_READY_TO_SWITCH_ON, CIA402_CW_SWITCH_ON},
        {CIA402_SWITCHED_ON, CIA402_CW_ENABLE_OP},
        {CIA402_OPERATION_ENABLED, CIA402_CW_ENABLE_OP},
    };
    for (size_t k = 0; k < 4; k++) {
        status_all(&dr, walk[k].s);
        tx.n = 0;
        drives_process(&dr, &cfg, true, torque, 1000, &tx);
        uint16_t cw;
        int16_t tq;
        assert_true(rpdo_of(&tx, 3, &cw, &tq));
        assert_int_equal(cw, walk[k].cw);
        /* Torque only once the drive reports OPERATION_ENABLED. */
        assert_int_equal(tq, walk[k].s == CIA402_OPERATION_ENABLED ? 1200 : 0);
        assert_true(canopen_is_sync(&tx.f[tx.n - 1])); /* SYNC closes every tick */
    }
    assert_true(drives_all_enabled(&dr));
}

static void test_quick_stop_and_fault_reset(void **st)
{
    (void)st;
    drives_t dr;
    drives_cfg_default(&cfg);
    drives_init(&dr);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    status_all(&dr, CIA402_OPERATION_ENABLED);
    can_batch_t tx = {0};
    drives_process(&dr, &cfg, false, torque, 1000, &tx);
    uint16_t cw;
    int16_t tq;
    assert_true(rpdo_of(&tx, 1, &cw, &tq));
    assert_int_equal(cw, CIA402_CW_QUICK_STOP); /* e-stop / disarm: quick stop, zero torque */
    assert_int_equal(tq, 0);
    /* A faulted drive gets a rising edge of bit 7 when re-armed, alternating with 0. */
    status_all(&dr, CIA402_FAULT);
    uint16_t seen[4];
    for (int k = 0; k < 4; k++) {
        tx.n = 0;
        drives_process(&dr, &cfg, true, torque, 1000, &tx);
        assert_true(rpdo_of(&tx, 2, &seen[k], &tq));
        assert_int_equal(tq, 0);
    }
    assert_int_equal(seen[0], CIA402_CW_FAULT_RESET);
    assert_int_equal(seen[1], CIA402_CW_DISABLE_VOLTAGE);
    assert_int_equal(seen[2], CIA402_CW_FAULT_RESET);
}

/* 1 ms ticks of the CiA 402 master; returns the tick (1-based) at which a heartbeat was first
 * reported lost, 0 if none. Drive 2 beats every 100 ms except at the beats in skip[]; the others
 * beat every 100 ms. */
static int ticks_until_lost(int ticks, const int *skip, int n_skip)
{
    drives_t dr;
    drives_init(&dr);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    can_batch_t tx = {0};
    for (int ms = 1; ms <= ticks; ms++) {
        if (ms % 100 == 0) {
            bool skipped = false;
            for (int k = 0; k < n_skip; k++)
                skipped |= skip[k] == ms / 100;
            can_frame_t f;
            for (uint8_t n = 1; n <= ARGIL_DRIVES; n++) {
                canopen_heartbeat_encode(&f, n, NMT_STATE_OPERATIONAL);
                if (n != 2 || !skipped)
                    rx_frame(&dr, &f);
            }
        }
        if (drives_heartbeat_lost(&dr, &cfg))
            return ms;
        tx.n = 0;
        drives_process(&dr, &cfg, false, torque, 1000, &tx);
    }
    return 0;
}

/* CiA 301 practice: a consumer time of two producer periods plus margin (250 ms for 100 ms
 * beats), so one lost heartbeat never faults and two in a row do before the third is due. */
static void test_heartbeat_consumer_rides_one_lost_beat(void **st)
{
    (void)st;
    drives_cfg_default(&cfg);
    assert_int_equal(cfg.heartbeat_timeout_us, 250000u);
    assert_int_equal(ticks_until_lost(2000, NULL, 0), 0);
    /* one lost beat, and one lost beat every other beat: never a fault */
    static const int one[] = {3}, every_other[] = {2, 4, 6, 8, 10, 12, 14, 16, 18};
    assert_int_equal(ticks_until_lost(2000, one, 1), 0);
    assert_int_equal(ticks_until_lost(2000, every_other, 9), 0);
    /* beats 3 and 4 lost: the last one received was at 200 ms; lost at 200 + 250 ms + one
     * tick (the age must exceed the consumer time), before beat 5 at 500 ms */
    static const int two[] = {3, 4};
    assert_int_equal(ticks_until_lost(2000, two, 2), 451);
}

static void test_emcy_latched_and_classified(void **st)
{
    (void)st;
    drives_t dr;
    drives_init(&dr);
    can_frame_t f;
    canopen_emcy_encode(&f, 2, CANOPEN_EMCY_NO_ERROR, 0);
    rx_frame(&dr, &f);
    assert_false(drives_any_emcy(&dr)); /* "error reset" is not a fault */
    canopen_emcy_encode(&f, 2, CANOPEN_EMCY_OVERCURRENT, 0x03);
    rx_frame(&dr, &f);
    assert_true(drives_any_emcy(&dr));
    assert_int_equal(dr.d[1].emcy_code, 0x2310);
    assert_int_equal(dr.d[1].emcy_register, 0x03);
    assert_string_equal(drives_emcy_class(dr.d[1].emcy_code), "current");
    assert_string_equal(drives_emcy_class(0x4210), "temperature");
    assert_string_equal(drives_emcy_class(0x8130), "communication");
    drives_clear_emcy(&dr);
    assert_false(drives_any_emcy(&dr));
}

static can_frame_t error_frame(uint32_t cls, uint8_t ctrl)
{
    can_frame_t f;
    memset(&f, 0, sizeof(f));
    f.id = ARGIL_CAN_ERR_FLAG | cls;
    f.len = 8;
    f.data[1] = ctrl;
    return f;
}

static void test_bus_passive_off_and_recovery(void **st)
{
    (void)st;
    drives_t dr;
    drives_cfg_default(&cfg);
    drives_init(&dr);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    can_batch_t tx = {0};
    can_frame_t f = error_frame(ARGIL_CAN_ERR_CRTL, ARGIL_CAN_CRTL_TX_PASSIVE);
    rx_frame(&dr, &f);
    assert_int_equal(dr.bus, CAN_BUS_PASSIVE);
    for (int ms = 0; ms < 99; ms++)
        drives_process(&dr, &cfg, false, torque, 1000, (tx.n = 0, &tx));
    assert_false(drives_bus_error(&dr, &cfg)); /* 99 ms error-passive: tolerated */
    drives_process(&dr, &cfg, false, torque, 1000, (tx.n = 0, &tx));
    assert_true(drives_bus_error(&dr, &cfg));  /* 100 ms: a fault */
    f = error_frame(ARGIL_CAN_ERR_CRTL, ARGIL_CAN_CRTL_ACTIVE);
    rx_frame(&dr, &f);
    assert_false(drives_bus_error(&dr, &cfg));

    f = error_frame(ARGIL_CAN_ERR_BUSOFF, 0);
    rx_frame(&dr, &f);
    assert_true(drives_bus_error(&dr, &cfg)); /* bus-off: a fault in the same tick */
    tx.n = 0;
    drives_process(&dr, &cfg, true, torque, 1000, &tx);
    assert_int_equal(tx.n, 0);                /* nothing queued while off the bus */
    for (int ms = 1; ms < 500; ms++)
        drives_process(&dr, &cfg, true, torque, 1000, (tx.n = 0, &tx));
    assert_true(drives_bus_unrecoverable(&dr, &cfg)); /* 500 ms without a restart */
    f = error_frame(ARGIL_CAN_ERR_RESTARTED, 0);
    rx_frame(&dr, &f);
    assert_int_equal(dr.bus, CAN_BUS_ACTIVE);
    assert_false(drives_bus_unrecoverable(&dr, &cfg));
    assert_int_equal(dr.bus_off_events, 1);
    assert_int_equal(dr.bus_restarts, 1);
    /* After the restart the master starts the drives again. */
    heartbeat_all(&dr, NMT_STATE_PREOP);
    tx.n = 0;
    drives_process(&dr, &cfg, true, torque, 1000, &tx);
    nmt_cmd_t c;
    uint8_t node;
    assert_true(canopen_nmt_decode(&tx.f[0], &c, &node) && c == NMT_CMD_START);
}

static void test_shutdown_frames(void **st)
{
    (void)st;
    drives_t dr;
    drives_init(&dr);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    can_batch_t tx = {0};
    drives_shutdown(&dr, &tx);
    assert_int_equal(tx.n, 6);
    uint16_t cw;
    int16_t tq;
    assert_true(rpdo_of(&tx, 1, &cw, &tq));
    assert_int_equal(cw, CIA402_CW_DISABLE_VOLTAGE);
    assert_int_equal(tq, 0);
    nmt_cmd_t c;
    uint8_t node;
    assert_true(canopen_nmt_decode(&tx.f[5], &c, &node));
    assert_int_equal(c, NMT_CMD_STOP);
    assert_int_equal(node, 3);
}

/* A drive that tripped while the power is off (FAULT, DRIVE_FAULT_N low) gets fault resets for
 * exactly the requested window and nothing that could enable it; afterwards it is left alone. */
static void test_fault_reset_while_off_is_bounded(void **st)
{
    (void)st;
    drives_t dr;
    drives_cfg_default(&cfg);
    drives_init(&dr);
    heartbeat_all(&dr, NMT_STATE_OPERATIONAL);
    status_all(&dr, CIA402_FAULT);
    can_batch_t tx = {0};
    uint16_t cw;
    int16_t tq;
    drives_process(&dr, &cfg, false, torque, 1000, &tx);
    assert_true(rpdo_of(&tx, 1, &cw, &tq));
    assert_int_equal(cw, CIA402_CW_DISABLE_VOLTAGE); /* no reset unless asked */
    drives_request_fault_reset(&dr, 5000);          /* 5 ticks of 1 ms */
    int resets = 0, others = 0;
    for (int k = 0; k < 12; k++) {
        tx.n = 0;
        drives_process(&dr, &cfg, false, torque, 1000, &tx);
        assert_true(rpdo_of(&tx, 3, &cw, &tq));
        assert_int_equal(tq, 0);
        if (cw == CIA402_CW_FAULT_RESET)
            resets++;
        else if (cw != CIA402_CW_DISABLE_VOLTAGE)
            others++; /* shutdown / switch on / enable would be a defect */
        if (k >= 5)
            assert_int_equal(cw, CIA402_CW_DISABLE_VOLTAGE);
    }
    assert_int_equal(others, 0);
    assert_true(resets >= 2); /* rising edges of bit 7 alternate with 0 */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nmt_start_then_power_walk),
        cmocka_unit_test(test_quick_stop_and_fault_reset),
        cmocka_unit_test(test_fault_reset_while_off_is_bounded),
        cmocka_unit_test(test_heartbeat_consumer_rides_one_lost_beat),
        cmocka_unit_test(test_emcy_latched_and_classified),
        cmocka_unit_test(test_bus_passive_off_and_recovery),
        cmocka_unit_test(test_shutdown_frames),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
