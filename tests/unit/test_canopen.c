/* Unit tests for shared/canopen: byte layouts on the wire, round trips, rejection rules. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "shared/canopen.h"

/* A frame pre-filled with junk, so encoders are seen to set every byte. */
static can_frame_t junk_frame(void)
{
    can_frame_t f;
    memset(&f, 0xAA, sizeof f);
    return f;
}

static void assert_bytes(const can_frame_t *f, uint32_t id, uint8_t len, const uint8_t *data)
{
    assert_int_equal(f->id, id);
    assert_int_equal(f->len, len);
    assert_memory_equal(f->data, data, 8); /* unused bytes are zero */
}

static void test_batch_push_until_full(void **state)
{
    (void)state;
    can_batch_t b;
    b.n = 0;
    can_frame_t f;
    canopen_sync_encode(&f);
    for (unsigned i = 0; i < CAN_BATCH_MAX; i++) {
        f.id = 0x100u + i;
        assert_int_equal(can_batch_push(&b, &f), ARGIL_OK);
    }
    assert_int_equal(b.n, CAN_BATCH_MAX);
    assert_int_equal(can_batch_push(&b, &f), ARGIL_ERR_FULL);
    assert_int_equal(b.n, CAN_BATCH_MAX);
    assert_int_equal(b.f[0].id, 0x100u);
    assert_int_equal(b.f[CAN_BATCH_MAX - 1].id, 0x100u + CAN_BATCH_MAX - 1);
    assert_int_equal(can_batch_push(NULL, &f), ARGIL_ERR_ARG);
    assert_int_equal(can_batch_push(&b, NULL), ARGIL_ERR_ARG);
}

static void test_nmt(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_nmt_encode(&f, NMT_CMD_START, 3);
    const uint8_t want[8] = {0x01, 0x03};
    assert_bytes(&f, 0x000, 2, want);
    const nmt_cmd_t cmds[] = {NMT_CMD_START, NMT_CMD_STOP, NMT_CMD_PREOP, NMT_CMD_RESET_NODE,
                              NMT_CMD_RESET_COMM};
    for (unsigned i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        nmt_cmd_t c;
        uint8_t node = 99;
        canopen_nmt_encode(&f, cmds[i], 0);
        assert_true(canopen_nmt_decode(&f, &c, &node));
        assert_int_equal(c, cmds[i]);
        assert_int_equal(node, 0);
    }
    nmt_cmd_t c;
    uint8_t node;
    canopen_nmt_encode(&f, NMT_CMD_RESET_NODE, 127);
    assert_int_equal(f.data[0], 0x81);
    assert_true(canopen_nmt_decode(&f, &c, &node));
    assert_int_equal(node, 127);
    f.len = 3;
    assert_false(canopen_nmt_decode(&f, &c, &node));   /* wrong length */
    f.len = 2;
    f.id = 0x001;
    assert_false(canopen_nmt_decode(&f, &c, &node));   /* wrong id */
    f.id = 0x000;
    f.data[0] = 0x05;
    assert_false(canopen_nmt_decode(&f, &c, &node));   /* no such command */
    f.data[0] = 0x01;
    f.data[1] = 200;
    assert_false(canopen_nmt_decode(&f, &c, &node));   /* no such node */
}

static void test_sync(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_sync_encode(&f);
    const uint8_t want[8] = {0};
    assert_bytes(&f, 0x080, 0, want);
    assert_true(canopen_is_sync(&f));
    f.len = 1;
    assert_false(canopen_is_sync(&f));
    f.len = 0;
    f.id = 0x081;
    assert_false(canopen_is_sync(&f));
}

static void test_rpdo(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_rpdo_encode(&f, 2, 0x000F, -1234);
    const uint8_t want[8] = {0x0F, 0x00, 0x2E, 0xFB};
    assert_bytes(&f, 0x202, 4, want);
    const int16_t torques[] = {0, 1, -1, 1000, -4000, INT16_MAX, INT16_MIN};
    for (unsigned i = 0; i < sizeof torques / sizeof torques[0]; i++) {
        uint8_t node;
        uint16_t cw;
        int16_t tq;
        canopen_rpdo_encode(&f, 127, 0x8086, torques[i]);
        assert_true(canopen_rpdo_decode(&f, &node, &cw, &tq));
        assert_int_equal(node, 127);
        assert_int_equal(cw, 0x8086);
        assert_int_equal(tq, torques[i]);
    }
    uint8_t node;
    uint16_t cw;
    int16_t tq;
    canopen_rpdo_encode(&f, 1, 0x0006, 0);
    assert_int_equal(f.id, 0x201);
    f.len = 8;
    assert_false(canopen_rpdo_decode(&f, &node, &cw, &tq));   /* wrong length */
    f.len = 4;
    f.id = 0x200;
    assert_false(canopen_rpdo_decode(&f, &node, &cw, &tq));   /* node 0 */
    f.id = 0x280;
    assert_false(canopen_rpdo_decode(&f, &node, &cw, &tq));   /* RPDO2 range */
    f.id = 0x181;
    assert_false(canopen_rpdo_decode(&f, &node, &cw, &tq));   /* a TPDO */
}

static void test_tpdo(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_tpdo_encode(&f, 1, 0x0637, -123456, 500);
    const uint8_t want[8] = {0x37, 0x06, 0xC0, 0x1D, 0xFE, 0xFF, 0xF4, 0x01};
    assert_bytes(&f, 0x181, 8, want);
    const int32_t pos[] = {0, 1, -1, 40000, -40000, INT32_MAX, INT32_MIN};
    for (unsigned i = 0; i < sizeof pos / sizeof pos[0]; i++) {
        uint8_t node;
        uint16_t sw;
        int32_t p;
        int16_t tq;
        canopen_tpdo_encode(&f, 3, 0x0027, pos[i], (int16_t)(-(int)i * 1000));
        assert_true(canopen_tpdo_decode(&f, &node, &sw, &p, &tq));
        assert_int_equal(node, 3);
        assert_int_equal(sw, 0x0027);
        assert_int_equal(p, pos[i]);
        assert_int_equal(tq, -(int)i * 1000);
    }
    uint8_t node;
    uint16_t sw;
    int32_t p;
    int16_t tq;
    f.len = 4;
    assert_false(canopen_tpdo_decode(&f, &node, &sw, &p, &tq));
    f.len = 8;
    f.id = 0x180;
    assert_false(canopen_tpdo_decode(&f, &node, &sw, &p, &tq));
    f.id = 0x200;
    assert_false(canopen_tpdo_decode(&f, &node, &sw, &p, &tq));
    f.id = 0x1FF;
    assert_true(canopen_tpdo_decode(&f, &node, &sw, &p, &tq));
    assert_int_equal(node, 127);
}

static void test_heartbeat(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_heartbeat_encode(&f, 3, NMT_STATE_PREOP);
    const uint8_t want[8] = {0x7F};
    assert_bytes(&f, 0x703, 1, want);
    const nmt_state_t states[] = {NMT_STATE_BOOTUP, NMT_STATE_STOPPED, NMT_STATE_OPERATIONAL,
                                  NMT_STATE_PREOP};
    const uint8_t bytes[] = {0x00, 0x04, 0x05, 0x7F};
    for (unsigned i = 0; i < 4; i++) {
        uint8_t node;
        nmt_state_t s;
        canopen_heartbeat_encode(&f, 1, states[i]);
        assert_int_equal(f.data[0], bytes[i]);
        assert_true(canopen_heartbeat_decode(&f, &node, &s));
        assert_int_equal(node, 1);
        assert_int_equal(s, states[i]);
    }
    uint8_t node;
    nmt_state_t s;
    f.len = 2;
    assert_false(canopen_heartbeat_decode(&f, &node, &s));
    f.len = 1;
    f.id = 0x700;
    assert_false(canopen_heartbeat_decode(&f, &node, &s));
    f.id = 0x701;
    f.data[0] = 0x06;
    assert_false(canopen_heartbeat_decode(&f, &node, &s));   /* no such state */
}

static void test_emcy(void **state)
{
    (void)state;
    can_frame_t f = junk_frame();
    canopen_emcy_encode(&f, 2, CANOPEN_EMCY_OVERCURRENT, 0x03);
    const uint8_t want[8] = {0x10, 0x23, 0x03, 0, 0, 0, 0, 0};
    assert_bytes(&f, 0x082, 8, want);
    uint8_t node, reg;
    uint16_t code;
    assert_true(canopen_emcy_decode(&f, &node, &code, &reg));
    assert_int_equal(node, 2);
    assert_int_equal(code, 0x2310);
    assert_int_equal(reg, 0x03);
    canopen_emcy_encode(&f, 127, 0xFF01, 0x80);
    assert_true(canopen_emcy_decode(&f, &node, &code, &reg));
    assert_int_equal(f.id, 0x0FF);
    assert_int_equal(code, 0xFF01);
    assert_int_equal(reg, 0x80);
    f.len = 4;
    assert_false(canopen_emcy_decode(&f, &node, &code, &reg));
    can_frame_t s;
    canopen_sync_encode(&s);
    assert_false(canopen_emcy_decode(&s, &node, &code, &reg)); /* SYNC is 0x080: not an EMCY */
    s.len = 8;
    assert_false(canopen_emcy_decode(&s, &node, &code, &reg));
    f.len = 8;
    f.id = 0x100;
    assert_false(canopen_emcy_decode(&f, &node, &code, &reg));
}

static void test_frames_are_not_mistaken_for_each_other(void **state)
{
    (void)state;
    can_frame_t fr[6];
    canopen_nmt_encode(&fr[0], NMT_CMD_START, 1);
    canopen_sync_encode(&fr[1]);
    canopen_rpdo_encode(&fr[2], 1, 0x0F, 10);
    canopen_tpdo_encode(&fr[3], 1, 0x27, 10, 10);
    canopen_heartbeat_encode(&fr[4], 1, NMT_STATE_OPERATIONAL);
    canopen_emcy_encode(&fr[5], 1, 0x2310, 1);
    for (int i = 0; i < 6; i++) {
        nmt_cmd_t c;
        nmt_state_t s;
        uint8_t node, reg;
        uint16_t w;
        int16_t t;
        int32_t p;
        const int kinds = (int)canopen_nmt_decode(&fr[i], &c, &node) + (int)canopen_is_sync(&fr[i]) +
                          (int)canopen_rpdo_decode(&fr[i], &node, &w, &t) +
                          (int)canopen_tpdo_decode(&fr[i], &node, &w, &p, &t) +
                          (int)canopen_heartbeat_decode(&fr[i], &node, &s) +
                          (int)canopen_emcy_decode(&fr[i], &node, &w, &reg);
        assert_int_equal(kinds, 1);
    }
}

static void test_statusword_states(void **state)
{
    (void)state;
    for (int s = CIA402_NOT_READY; s <= CIA402_FAULT; s++)
        assert_int_equal(cia402_state_from_statusword(cia402_statusword((cia402_state_t)s)), s);
    /* canonical words */
    assert_int_equal(cia402_statusword(CIA402_SWITCH_ON_DISABLED), 0x0040);
    assert_int_equal(cia402_statusword(CIA402_READY_TO_SWITCH_ON), 0x0031);
    assert_int_equal(cia402_statusword(CIA402_SWITCHED_ON), 0x0033);
    assert_int_equal(cia402_statusword(CIA402_OPERATION_ENABLED), 0x0037);
    assert_int_equal(cia402_statusword(CIA402_QUICK_STOP_ACTIVE), 0x0017);
    assert_int_equal(cia402_statusword(CIA402_FAULT_REACTION_ACTIVE), 0x001F);
    assert_int_equal(cia402_statusword(CIA402_FAULT), 0x0008);
    /* words as real drives send them, with remote (bit 9), warning (bit 7), target reached
     * (bit 10) and manufacturer bits set */
    const struct {
        uint16_t sw;
        cia402_state_t s;
    } real[] = {
        {0x0200, CIA402_NOT_READY},          {0x0250, CIA402_SWITCH_ON_DISABLED},
        {0x0660, CIA402_SWITCH_ON_DISABLED}, {0x0231, CIA402_READY_TO_SWITCH_ON},
        {0x8221, CIA402_READY_TO_SWITCH_ON}, {0x0233, CIA402_SWITCHED_ON},
        {0x0237, CIA402_OPERATION_ENABLED},  {0x06B7, CIA402_OPERATION_ENABLED},
        {0x0217, CIA402_QUICK_STOP_ACTIVE},  {0x0007, CIA402_QUICK_STOP_ACTIVE},
        {0x021F, CIA402_FAULT_REACTION_ACTIVE}, {0x023F, CIA402_FAULT_REACTION_ACTIVE},
        {0x0218, CIA402_FAULT},              {0x0238, CIA402_FAULT},
    };
    for (unsigned i = 0; i < sizeof real / sizeof real[0]; i++)
        assert_int_equal(cia402_state_from_statusword(real[i].sw), real[i].s);
    /* a word with no defined pattern is never taken as enabled */
    assert_int_equal(cia402_state_from_statusword(0x0001), CIA402_NOT_READY);
    assert_int_equal(cia402_state_from_statusword(0x0067), CIA402_NOT_READY);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_batch_push_until_full),
        cmocka_unit_test(test_nmt),
        cmocka_unit_test(test_sync),
        cmocka_unit_test(test_rpdo),
        cmocka_unit_test(test_tpdo),
        cmocka_unit_test(test_heartbeat),
        cmocka_unit_test(test_emcy),
        cmocka_unit_test(test_frames_are_not_mistaken_for_each_other),
        cmocka_unit_test(test_statusword_states),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
