/* firmware/argil.dbc against shared/canopen.c: every frame the encoder makes, decoded signal by
 * signal through the DBC's start bit, length, sign and factor, gives back the values encoded,
 * so the file a CAN tool reads and the code on the bus cannot drift apart. Also the DBC reader's
 * error rules, and a candump line decoded through the DBC. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/canopen.h"
#include "tests/unit/dbc_parser.h"

#define DBC_PATH "firmware/argil.dbc"
#define NODES 3u

static dbc_t g_dbc;

/* |a - b| <= eps in double precision (cmocka 1.1.5 compares floats only). */
static void assert_near_impl(double a, double b, double eps, const char *file, int line)
{
    if (!(fabs(a - b) <= eps)) {
        fprintf(stderr, "%.17g != %.17g (eps %g)\n", a, b, eps);
        _fail(file, line);
    }
}
#define assert_near(a, b, eps) assert_near_impl((a), (b), (eps), __FILE__, __LINE__)

static int load_dbc(void **state)
{
    (void)state;
    FILE *fp = fopen(DBC_PATH, "rb");
    if (fp == NULL) {
        fprintf(stderr, "test_dbc: cannot open %s (run from the repository root)\n", DBC_PATH);
        return -1;
    }
    static char text[64 * 1024];
    const size_t n = fread(text, 1, sizeof(text), fp);
    fclose(fp);
    if (n == sizeof(text))
        return -1;
    uint32_t line = 0;
    const dbc_err_t e = dbc_parse(&g_dbc, text, n, &line);
    if (e != DBC_OK) {
        fprintf(stderr, "test_dbc: %s line %u: error %d\n", DBC_PATH, line, (int)e);
        return -1;
    }
    return 0;
}

/* A small deterministic generator (xorshift32) for the value sweeps. */
static uint32_t rng_next(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

/* The DBC message for a frame; fails the test unless it exists with the frame's length. */
static const dbc_message_t *message_for(const can_frame_t *f)
{
    const dbc_message_t *m = dbc_find(&g_dbc, f->id);
    if (m == NULL)
        fail_msg("frame id 0x%03X is not in %s", (unsigned)f->id, DBC_PATH);
    assert_int_equal(m->dlc, f->len);
    return m;
}

/* Raw value of the signal called name in the frame's message (must exist). */
static int64_t raw_of(const can_frame_t *f, const char *name)
{
    const dbc_message_t *m = message_for(f);
    const dbc_signal_t *s = dbc_signal(m, name);
    if (s == NULL)
        fail_msg("%s has no signal %s", m->name, name);
    return dbc_raw(s, f->data);
}

static double phys_of(const can_frame_t *f, const char *name)
{
    const dbc_message_t *m = message_for(f);
    const dbc_signal_t *s = dbc_signal(m, name);
    if (s == NULL)
        fail_msg("%s has no signal %s", m->name, name);
    return dbc_physical(s, f->data);
}

/* Every message is one argil sends, and every bit of its frame belongs to exactly one signal
 * (the parser already refuses overlaps), so no byte of a frame goes undescribed. */
static void test_dbc_lists_exactly_argils_frames(void **state)
{
    (void)state;
    assert_int_equal(g_dbc.n_messages, 2u + 4u * NODES);
    const struct {
        uint32_t base;
        uint8_t dlc;
        uint8_t n_signals;
    } per_node[] = {
        {CANOPEN_COB_EMCY, 8, 3},
        {CANOPEN_COB_TPDO1, 8, 3},
        {CANOPEN_COB_RPDO1, 4, 2},
        {CANOPEN_COB_HEARTBEAT, 1, 2},
    };
    const dbc_message_t *nmt = dbc_find(&g_dbc, CANOPEN_COB_NMT);
    assert_non_null(nmt);
    assert_int_equal(nmt->dlc, 2);
    assert_int_equal(nmt->n_signals, 2);
    const dbc_message_t *sync = dbc_find(&g_dbc, CANOPEN_COB_SYNC);
    assert_non_null(sync);
    assert_int_equal(sync->dlc, 0);
    assert_int_equal(sync->n_signals, 0);
    for (uint32_t node = 1; node <= NODES; node++) {
        for (size_t k = 0; k < sizeof(per_node) / sizeof(per_node[0]); k++) {
            const dbc_message_t *m = dbc_find(&g_dbc, per_node[k].base + node);
            assert_non_null(m);
            assert_int_equal(m->dlc, per_node[k].dlc);
            assert_int_equal(m->n_signals, per_node[k].n_signals);
        }
    }
    for (uint32_t i = 0; i < g_dbc.n_messages; i++) {
        const dbc_message_t *m = &g_dbc.msg[i];
        unsigned bits = 0;
        for (uint8_t j = 0; j < m->n_signals; j++) {
            bits += m->sig[j].length;
            assert_true(m->sig[j].factor != 0.0);
        }
        assert_int_equal(bits, m->dlc * 8u);
    }
}

static void check_rpdo(uint8_t node, uint16_t cw, int16_t torque)
{
    char n_cw[32], n_tq[32];
    snprintf(n_cw, sizeof(n_cw), "RPDO1_%u_Controlword", node);
    snprintf(n_tq, sizeof(n_tq), "RPDO1_%u_TargetTorque", node);
    can_frame_t f;
    canopen_rpdo_encode(&f, node, cw, torque);
    assert_int_equal(raw_of(&f, n_cw), cw);
    assert_int_equal(raw_of(&f, n_tq), torque);
    /* the DBC shows per mille as percent: factor 0.1 */
    assert_near(phys_of(&f, n_tq), torque * 0.1, 1e-9);
    assert_near(phys_of(&f, n_cw), cw, 0.0);
}

static void test_rpdo_decodes_through_dbc(void **state)
{
    (void)state;
    const uint16_t cws[] = {CIA402_CW_SHUTDOWN, CIA402_CW_SWITCH_ON, CIA402_CW_ENABLE_OP,
                            CIA402_CW_DISABLE_VOLTAGE, CIA402_CW_QUICK_STOP,
                            CIA402_CW_FAULT_RESET, 0xFFFFu, 0x8000u};
    const int16_t tqs[] = {0, 1, -1, 1000, -1000, INT16_MAX, INT16_MIN, 0x00FF, -256};
    for (uint8_t node = 1; node <= NODES; node++)
        for (size_t i = 0; i < sizeof(cws) / sizeof(cws[0]); i++)
            for (size_t j = 0; j < sizeof(tqs) / sizeof(tqs[0]); j++)
                check_rpdo(node, cws[i], tqs[j]);
    uint32_t seed = 0x2468ACE1u;
    for (int i = 0; i < 3000; i++) {
        const uint32_t r = rng_next(&seed);
        check_rpdo((uint8_t)(1u + r % NODES), (uint16_t)(r >> 8), (int16_t)(uint16_t)(r >> 16));
    }
}

static void check_tpdo(uint8_t node, uint16_t sw, int32_t pos, int16_t torque)
{
    char n_sw[32], n_pos[40], n_tq[32];
    snprintf(n_sw, sizeof(n_sw), "TPDO1_%u_Statusword", node);
    snprintf(n_pos, sizeof(n_pos), "TPDO1_%u_PositionActual", node);
    snprintf(n_tq, sizeof(n_tq), "TPDO1_%u_TorqueActual", node);
    can_frame_t f;
    canopen_tpdo_encode(&f, node, sw, pos, torque);
    assert_int_equal(raw_of(&f, n_sw), sw);
    assert_true(raw_of(&f, n_pos) == (int64_t)pos);
    assert_int_equal(raw_of(&f, n_tq), torque);
    assert_near(phys_of(&f, n_pos), (double)pos, 0.0);
    assert_near(phys_of(&f, n_tq), torque * 0.1, 1e-9);
    /* and the board's own decoder reads the same frame the same way */
    uint8_t dn = 0;
    uint16_t dsw = 0;
    int32_t dpos = 0;
    int16_t dtq = 0;
    assert_true(canopen_tpdo_decode(&f, &dn, &dsw, &dpos, &dtq));
    assert_int_equal(dn, node);
    assert_true(dpos == pos && dtq == torque && dsw == sw);
}

static void test_tpdo_decodes_through_dbc(void **state)
{
    (void)state;
    const int32_t pos[] = {0, 1, -1, 1000, -1000, INT32_MAX, INT32_MIN, 0x00FFFF00, -65536};
    const uint16_t sws[] = {0x0040u, 0x0031u, 0x0033u, 0x0037u, 0x0017u, 0x0008u, 0xFFFFu};
    for (uint8_t node = 1; node <= NODES; node++)
        for (size_t i = 0; i < sizeof(sws) / sizeof(sws[0]); i++)
            for (size_t j = 0; j < sizeof(pos) / sizeof(pos[0]); j++)
                check_tpdo(node, sws[i], pos[j], (int16_t)(pos[j] >> 8));
    uint32_t seed = 0x13579BDFu;
    for (int i = 0; i < 3000; i++) {
        const uint32_t a = rng_next(&seed), b = rng_next(&seed);
        check_tpdo((uint8_t)(1u + a % NODES), (uint16_t)(a >> 8), (int32_t)b,
                   (int16_t)(uint16_t)(a >> 16));
    }
}

static void test_heartbeat_decodes_through_dbc(void **state)
{
    (void)state;
    const nmt_state_t states[] = {NMT_STATE_BOOTUP, NMT_STATE_STOPPED, NMT_STATE_OPERATIONAL,
                                  NMT_STATE_PREOP};
    for (uint8_t node = 1; node <= NODES; node++) {
        for (size_t i = 0; i < sizeof(states) / sizeof(states[0]); i++) {
            char n_st[32], n_tg[32];
            snprintf(n_st, sizeof(n_st), "HB%u_State", node);
            snprintf(n_tg, sizeof(n_tg), "HB%u_Toggle", node);
            can_frame_t f;
            canopen_heartbeat_encode(&f, node, states[i]);
            assert_int_equal(raw_of(&f, n_st), states[i]);
            assert_int_equal(raw_of(&f, n_tg), 0);
        }
    }
}

static void test_emcy_decodes_through_dbc(void **state)
{
    (void)state;
    uint32_t seed = 0xCAFEF00Du;
    for (int i = 0; i < 1000; i++) {
        const uint32_t r = rng_next(&seed);
        const uint8_t node = (uint8_t)(1u + r % NODES);
        uint16_t code = (uint16_t)(r >> 8);
        uint8_t reg = (uint8_t)(r >> 24);
        if (i == 0) {
            code = CANOPEN_EMCY_OVERCURRENT;
            reg = CANOPEN_ERRREG_GENERIC | CANOPEN_ERRREG_CURRENT;
        } else if (i == 1) {
            code = CANOPEN_EMCY_NO_ERROR;
            reg = 0;
        }
        char n_c[32], n_r[32], n_m[40];
        snprintf(n_c, sizeof(n_c), "EMCY%u_ErrorCode", node);
        snprintf(n_r, sizeof(n_r), "EMCY%u_ErrorRegister", node);
        snprintf(n_m, sizeof(n_m), "EMCY%u_ManufacturerData", node);
        can_frame_t f;
        canopen_emcy_encode(&f, node, code, reg);
        assert_int_equal(raw_of(&f, n_c), code);
        assert_int_equal(raw_of(&f, n_r), reg);
        assert_int_equal(raw_of(&f, n_m), 0);
    }
}

static void test_nmt_and_sync_decode_through_dbc(void **state)
{
    (void)state;
    const nmt_cmd_t cmds[] = {NMT_CMD_START, NMT_CMD_STOP, NMT_CMD_PREOP, NMT_CMD_RESET_NODE,
                              NMT_CMD_RESET_COMM};
    for (size_t i = 0; i < sizeof(cmds) / sizeof(cmds[0]); i++) {
        for (uint8_t node = 0; node <= 127; node++) {
            can_frame_t f;
            canopen_nmt_encode(&f, cmds[i], node);
            assert_int_equal(raw_of(&f, "NMT_Command"), cmds[i]);
            assert_int_equal(raw_of(&f, "NMT_Node"), node);
        }
    }
    can_frame_t f;
    canopen_sync_encode(&f);
    const dbc_message_t *m = message_for(&f);
    assert_string_equal(m->name, "SYNC");
}

static void test_candump_line_decodes_via_dbc(void **state)
{
    (void)state;
    const char *line = "(0.001000) vcan0 181#2700E8030000F401";
    can_frame_t f;
    assert_int_equal(dbc_candump_line(line, strlen(line), &f), DBC_OK);
    assert_int_equal(f.id, 0x181);
    assert_int_equal(f.len, 8);
    const dbc_message_t *m = message_for(&f);
    assert_string_equal(m->name, "TPDO1_Drive1");
    assert_int_equal(raw_of(&f, "TPDO1_1_Statusword"), 0x0027);
    assert_near(phys_of(&f, "TPDO1_1_PositionActual"), 1000.0, 0.0);
    assert_near(phys_of(&f, "TPDO1_1_TorqueActual"), 50.0, 1e-9);
    assert_int_equal(cia402_state_from_statusword(0x0027), CIA402_OPERATION_ENABLED);

    const char *rpdo = "(1700000000.250000) can0 203#0F00CEFF\n";
    assert_int_equal(dbc_candump_line(rpdo, strlen(rpdo), &f), DBC_OK);
    assert_int_equal(raw_of(&f, "RPDO1_3_Controlword"), CIA402_CW_ENABLE_OP);
    assert_near(phys_of(&f, "RPDO1_3_TargetTorque"), -5.0, 1e-9);

    const char *sync = "(0.002000) vcan0 080#";
    assert_int_equal(dbc_candump_line(sync, strlen(sync), &f), DBC_OK);
    assert_true(canopen_is_sync(&f));
    assert_string_equal(message_for(&f)->name, "SYNC");

    /* what the encoder writes, printed as candump prints it, reads back through the DBC */
    canopen_tpdo_encode(&f, 2, 0x0037u, -123456, -321);
    char text[64];
    int k = snprintf(text, sizeof(text), "(12.000001) vcan0 %03X#", (unsigned)f.id);
    for (uint8_t i = 0; i < f.len; i++)
        k += snprintf(text + k, sizeof(text) - (size_t)k, "%02X", f.data[i]);
    can_frame_t g;
    assert_int_equal(dbc_candump_line(text, strlen(text), &g), DBC_OK);
    assert_near(phys_of(&g, "TPDO1_2_PositionActual"), -123456.0, 0.0);
    assert_near(phys_of(&g, "TPDO1_2_TorqueActual"), -32.1, 1e-9);
}

static void test_candump_errors(void **state)
{
    (void)state;
    const struct {
        const char *line;
        dbc_err_t want;
    } cases[] = {
        {"0.1 vcan0 181#00", DBC_ERR_SYNTAX},           /* no parenthesis */
        {"(x) vcan0 181#00", DBC_ERR_SYNTAX},           /* no timestamp */
        {"(0.1 vcan0 181#00", DBC_ERR_SYNTAX},          /* unclosed */
        {"(0.1) 181#00", DBC_ERR_SYNTAX},               /* interface missing: id read as name */
        {"(0.1) vcan0 #00", DBC_ERR_SYNTAX},            /* no id */
        {"(0.1) vcan0 18G#00", DBC_ERR_SYNTAX},         /* not hex */
        {"(0.1) vcan0 12345678#00", DBC_ERR_RANGE},     /* extended id */
        {"(0.1) vcan0 181#0", DBC_ERR_SYNTAX},          /* half a byte */
        {"(0.1) vcan0 181#001122334455667788", DBC_ERR_RANGE}, /* 9 bytes */
        {"(0.1) vcan0 181#00 junk", DBC_ERR_SYNTAX},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        can_frame_t f;
        const dbc_err_t e = dbc_candump_line(cases[i].line, strlen(cases[i].line), &f);
        if (e != cases[i].want)
            fail_msg("'%s': got %d, want %d", cases[i].line, (int)e, (int)cases[i].want);
    }
}

/* Every rule of the reader, each reached by the smallest input that breaks it. */
static void test_dbc_reader_errors(void **state)
{
    (void)state;
    const struct {
        const char *text;
        dbc_err_t want;
        uint32_t line;
    } cases[] = {
        {"BO_ 385 T: 8 D\n SG_ a : 0|16@1+ (1,0) [0|1] \"\" B\n", DBC_OK, 0},
        {"VERSION \"\"\n\nSG_ a : 0|8@1+ (1,0) [0|1] \"\" B\n", DBC_ERR_ORPHAN, 3},
        {"BO_ x T: 8 D\n", DBC_ERR_SYNTAX, 1},
        {"BO_ 2048 T: 8 D\n", DBC_ERR_RANGE, 1},
        {"BO_ 99999999999 T: 8 D\n", DBC_ERR_RANGE, 1},
        {"BO_ 1 T: 9 D\n", DBC_ERR_RANGE, 1},
        {"BO_ 1 T 8 D\n", DBC_ERR_SYNTAX, 1},
        {"BO_ 1 T: 8\n", DBC_ERR_SYNTAX, 1},
        {"BO_ 1 T: 8 D extra\n", DBC_ERR_SYNTAX, 1},
        {"BO_ 1 T: 8 D\nBO_ 1 U: 8 D\n", DBC_ERR_DUPLICATE, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|0@1+ (1,0) [0|1] \"\" B\n", DBC_ERR_RANGE, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|65@1+ (1,0) [0|1] \"\" B\n", DBC_ERR_RANGE, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@0+ (1,0) [0|1] \"\" B\n", DBC_ERR_UNSUPPORTED, 2},
        {"BO_ 1 T: 8 D\n SG_ a M : 0|8@1+ (1,0) [0|1] \"\" B\n", DBC_ERR_UNSUPPORTED, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@2+ (1,0) [0|1] \"\" B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1* (1,0) [0|1] \"\" B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (x,0) [0|1] \"\" B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1-,0) [0|1] \"\" B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1e999,0) [0|1] \"\" B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"unclosed B\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"\"\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"\" B,\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"\" B C\n", DBC_ERR_SYNTAX, 2},
        {"BO_ 1 T: 2 D\n SG_ a : 8|9@1+ (1,0) [0|1] \"\" B\n", DBC_ERR_LAYOUT, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"\" B\n SG_ b : 7|2@1+ (1,0) [0|1] \"\" B\n",
         DBC_ERR_LAYOUT, 3},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"\" B\n SG_ a : 8|8@1+ (1,0) [0|1] \"\" B\n",
         DBC_ERR_DUPLICATE, 3},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1] \"a unit far too long\" B\n",
         DBC_ERR_TOO_LONG, 2},
        {"BO_ 1 T: 8 D\n SG_ a : 0|8@1+ (1,0) [0|1000000000000000000000000000000000000000] \"\" B\n",
         DBC_ERR_TOO_LONG, 2},
        {"BO_ 1 T_a_name_that_is_longer_than_forty_eight_characters_in_all: 8 D\n",
         DBC_ERR_TOO_LONG, 1},
    };
    static dbc_t d;
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        uint32_t line = 99;
        const dbc_err_t e = dbc_parse(&d, cases[i].text, strlen(cases[i].text), &line);
        if (e != cases[i].want || line != cases[i].line)
            fail_msg("case %zu: got %d at line %u, want %d at line %u", i, (int)e, line,
                     (int)cases[i].want, cases[i].line);
    }
    /* the bounds: one message too many, one signal too many */
    static char big[(DBC_MESSAGES_MAX + 1u) * 24u];
    size_t n = 0;
    for (uint32_t i = 0; i <= DBC_MESSAGES_MAX; i++)
        n += (size_t)snprintf(big + n, sizeof(big) - n, "BO_ %u M%u: 8 D\n", i, i);
    uint32_t line = 0;
    assert_int_equal(dbc_parse(&d, big, n, &line), DBC_ERR_FULL);
    assert_int_equal(line, DBC_MESSAGES_MAX + 1u);
    n = (size_t)snprintf(big, sizeof(big), "BO_ 1 M: 8 D\n");
    for (uint32_t i = 0; i <= DBC_SIGNALS_MAX; i++)
        n += (size_t)snprintf(big + n, sizeof(big) - n, " SG_ s%u : %u|1@1+ (1,0) [0|1] \"\" B\n",
                              i, i);
    assert_int_equal(dbc_parse(&d, big, n, &line), DBC_ERR_FULL);
    assert_int_equal(line, DBC_SIGNALS_MAX + 2u);
}

/* Sign extension and factor/offset of the generic decoder, on hand-made layouts. */
static void test_dbc_decoder_bits(void **state)
{
    (void)state;
    static dbc_t d;
    const char *text = "BO_ 16 X: 8 D\n"
                       " SG_ lo : 3|5@1- (2,-1) [0|1] \"\" B\n"
                       " SG_ mid : 8|12@1+ (0.5,10) [0|1] \"\" B\n"
                       " SG_ top : 20|44@1- (1,0) [0|1] \"\" B\n";
    uint32_t line = 0;
    assert_int_equal(dbc_parse(&d, text, strlen(text), &line), DBC_OK);
    const dbc_message_t *m = dbc_find(&d, 16);
    assert_non_null(m);
    uint8_t data[8] = {0xF8, 0x34, 0xF2, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
    /* lo = bits 3..7 of byte 0 = 0b11111 = -1 → 2*(-1) - 1 */
    assert_int_equal(dbc_raw(&m->sig[0], data), -1);
    assert_near(dbc_physical(&m->sig[0], data), -3.0, 0.0);
    /* mid = byte 1 + low nibble of byte 2 << 8 = 0x234 */
    assert_int_equal(dbc_raw(&m->sig[1], data), 0x234);
    assert_near(dbc_physical(&m->sig[1], data), 0x234 * 0.5 + 10.0, 0.0);
    /* top = every remaining bit set = -1 */
    assert_int_equal(dbc_raw(&m->sig[2], data), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dbc_lists_exactly_argils_frames),
        cmocka_unit_test(test_rpdo_decodes_through_dbc),
        cmocka_unit_test(test_tpdo_decodes_through_dbc),
        cmocka_unit_test(test_heartbeat_decodes_through_dbc),
        cmocka_unit_test(test_emcy_decodes_through_dbc),
        cmocka_unit_test(test_nmt_and_sync_decode_through_dbc),
        cmocka_unit_test(test_candump_line_decodes_via_dbc),
        cmocka_unit_test(test_candump_errors),
        cmocka_unit_test(test_dbc_reader_errors),
        cmocka_unit_test(test_dbc_decoder_bits),
    };
    return cmocka_run_group_tests(tests, load_dbc, NULL);
}
