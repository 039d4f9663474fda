/* The fixed tick sequence (see tick_script.h). Integer-scripted inputs, so the host and the
 * MCU feed the core identical bytes; only the core's float maths can differ between them. */
#include "tick_script.h"

#include <string.h>

#include "shared/gpio_lines.h"

#define WIN_EDGE 16
#define WIN_SPACING_M 0.0025f
#define CLAY_RADIUS_M 0.010f

static void put_msg(tick_script_t *s, size_t *len, const proto_msg_t *m)
{
    size_t n = 0;
    if (proto_encode(m, s->seq, s->link + *len, sizeof(s->link) - *len, &n) == PROTO_OK) {
        *len += n;
        s->seq++;
    }
}

argil_err_t tick_script_init(tick_script_t *s)
{
    memset(s, 0, sizeof(*s));
    board_cfg_t cfg;
    board_cfg_default(&cfg);
    cfg.safety.overrun_streak = 0; /* compute time is not scripted */
    const argil_err_t rc = board_init(&s->board, &cfg);
    if (rc != ARGIL_OK)
        return rc;
    /* A clay ball below the home tip (0, 0, 0.174 m): density 1 inside, 0 outside, a linear
     * ramp one spacing wide across the surface (iso 0.5). */
    const float cx = 0.0f, cy = 0.0f, cz = 0.174f - 0.015f;
    const float ox = -7.5f * WIN_SPACING_M, oy = -7.5f * WIN_SPACING_M,
                oz = 0.174f - 7.5f * WIN_SPACING_M;
    for (int z = 0; z < WIN_EDGE; z++)
        for (int y = 0; y < WIN_EDGE; y++)
            for (int x = 0; x < WIN_EDGE; x++) {
                const float dx = ox + (float)x * WIN_SPACING_M - cx;
                const float dy = oy + (float)y * WIN_SPACING_M - cy;
                const float dz = oz + (float)z * WIN_SPACING_M - cz;
                const float r2 = dx * dx + dy * dy + dz * dz;
                /* Piecewise in r² so no libm call is needed (identical on every target). */
                const float in2 = (CLAY_RADIUS_M - WIN_SPACING_M) * (CLAY_RADIUS_M - WIN_SPACING_M);
                const float out2 = (CLAY_RADIUS_M + WIN_SPACING_M) * (CLAY_RADIUS_M + WIN_SPACING_M);
                float d = (out2 - r2) / (out2 - in2);
                d = d < 0.0f ? 0.0f : (d > 1.0f ? 1.0f : d);
                s->window[x + WIN_EDGE * (y + WIN_EDGE * z)] = d;
            }
    for (int j = 0; j < ARGIL_DRIVES; j++)
        s->drive[j].power = CIA402_SWITCH_ON_DISABLED;
    return ARGIL_OK;
}

/* Elbow counts along the script: rest, fold 700 counts (tip ~15 mm toward the clay), hold,
 * back. Integer arithmetic only. */
static int32_t elbow_counts(uint32_t t)
{
    if (t < 150u) return 0;
    if (t < 450u) return (int32_t)((t - 150u) * 700u / 300u);
    if (t < 550u) return 700;
    if (t < 850u) return (int32_t)((850u - t) * 700u / 300u);
    return 0;
}

static void drive_apply(tick_script_t *s, int j, uint16_t cw, int16_t torque)
{
    uint8_t *p = &s->drive[j].power;
    s->drive[j].torque = torque;
    if ((cw & 0x0002u) == 0u) { /* disable voltage */
        *p = CIA402_SWITCH_ON_DISABLED;
        return;
    }
    switch (*p) {
    case CIA402_SWITCH_ON_DISABLED:
        if ((cw & 0x0087u) == 0x0006u) *p = CIA402_READY_TO_SWITCH_ON;
        break;
    case CIA402_READY_TO_SWITCH_ON:
        if ((cw & 0x008Fu) == 0x0007u) *p = CIA402_SWITCHED_ON;
        else if ((cw & 0x008Fu) == 0x000Fu) *p = CIA402_OPERATION_ENABLED;
        break;
    case CIA402_SWITCHED_ON:
        if ((cw & 0x008Fu) == 0x000Fu) *p = CIA402_OPERATION_ENABLED;
        else if ((cw & 0x0087u) == 0x0006u) *p = CIA402_READY_TO_SWITCH_ON;
        break;
    case CIA402_OPERATION_ENABLED:
        if ((cw & 0x0004u) == 0u) *p = CIA402_SWITCH_ON_DISABLED; /* quick stop, done at once */
        else if ((cw & 0x008Fu) == 0x0007u) *p = CIA402_SWITCHED_ON;
        else if ((cw & 0x0087u) == 0x0006u) *p = CIA402_READY_TO_SWITCH_ON;
        break;
    default:
        break;
    }
}

void tick_script_step(tick_script_t *s, tick_result_t *r)
{
    const uint32_t t = ++s->tick;
    can_frame_t f;
    /* Drives: answer last tick's frames, then heartbeat (boot-up at tick 1, every 100). */
    bool sync = false;
    s->to_board.n = 0;
    for (uint8_t i = 0; i < s->out.can_tx.n; i++) {
        const can_frame_t *in = &s->out.can_tx.f[i];
        nmt_cmd_t cmd;
        uint8_t node;
        uint16_t cw;
        int16_t tq;
        if (canopen_nmt_decode(in, &cmd, &node)) {
            for (int j = 0; j < ARGIL_DRIVES; j++)
                if (node == 0 || node == j + 1)
                    s->drive[j].operational = cmd == NMT_CMD_START;
        } else if (canopen_rpdo_decode(in, &node, &cw, &tq) && node >= 1 && node <= ARGIL_DRIVES) {
            if (s->drive[node - 1].operational)
                drive_apply(s, node - 1, cw, tq);
        } else if (canopen_is_sync(in)) {
            sync = true;
        }
    }
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        if (sync && s->drive[j].operational) {
            const int32_t pos = j == 2 ? elbow_counts(t) : (j == 0 ? (int32_t)(t % 7u) : 0);
            canopen_tpdo_encode(&f, (uint8_t)(j + 1),
                                cia402_statusword((cia402_state_t)s->drive[j].power), pos,
                                s->drive[j].power == CIA402_OPERATION_ENABLED ? s->drive[j].torque : 0);
            (void)can_batch_push(&s->to_board, &f);
        }
        if (t == 1u || t % 100u == 0u) {
            canopen_heartbeat_encode(&f, (uint8_t)(j + 1),
                                     t == 1u ? NMT_STATE_BOOTUP
                                             : (s->drive[j].operational ? NMT_STATE_OPERATIONAL
                                                                        : NMT_STATE_PREOP));
            (void)can_batch_push(&s->to_board, &f);
        }
    }

    /* Host frames: HELLO, TOOL, the window in chunks, heartbeats every 5 ms (silent 760-860),
     * ARM at 40, after the e-stop (700) and after the silence (900). */
    size_t len = 0;
    static proto_msg_t m; /* ~1 KiB: keep it off the MCU stack */
    memset(&m, 0, sizeof(m));
    if (t == 1u) {
        m.type = MSG_HELLO;
        m.u.hello.role = PROTO_ROLE_HOST;
        put_msg(s, &len, &m);
    } else if (t == 2u) {
        m.type = MSG_TOOL;
        m.u.tool.kind = TOOL_TOUCH;
        m.u.tool.radius_m = 0.004f;
        m.u.tool.axis[2] = 1.0f;
        m.u.tool.alpha = 12000.0f;
        m.u.tool.contact_stiffness_n_per_m = 800.0f;
        m.u.tool.max_force_n = 3.3f;
        m.u.tool.model_scale = 1.0f;
        put_msg(s, &len, &m);
    }
    const uint8_t dims[3] = {WIN_EDGE, WIN_EDGE, WIN_EDGE};
    const uint16_t chunks = window_chunk_count(dims, 1);
    for (uint32_t k = 0; k < 4u; k++) {
        const uint32_t idx = (t >= 3u ? (t - 3u) * 4u : 9999u) + k;
        if (idx >= chunks)
            break;
        msg_window_t head;
        memset(&head, 0, sizeof(head));
        head.version = 1;
        head.chunk_count = chunks;
        memcpy(head.dims, dims, 3);
        head.channels = 1;
        head.origin_m[0] = -7.5f * WIN_SPACING_M;
        head.origin_m[1] = -7.5f * WIN_SPACING_M;
        head.origin_m[2] = 0.174f - 7.5f * WIN_SPACING_M;
        head.spacing_m = WIN_SPACING_M;
        head.iso = 0.5f;
        head.node_mass = 1.0f;
        head.stiffness = 50.0f;
        head.damping = 2.0f;
        m.type = MSG_WINDOW;
        if (window_chunk_fill(&head, s->window, (uint16_t)idx, &m.u.window) == PROTO_OK)
            put_msg(s, &len, &m);
    }
    const bool silent = t >= 760u && t < 860u;
    if (t % 5u == 0u && !silent) {
        memset(&m, 0, sizeof(m));
        m.type = MSG_HEARTBEAT;
        m.u.heartbeat.time_us = (uint64_t)t * 1000u;
        m.u.heartbeat.window_version = 1;
        m.u.heartbeat.command = (t == 40u || t == 700u || t == 900u) ? PROTO_CMD_ARM : PROTO_CMD_NONE;
        put_msg(s, &len, &m);
    }

    board_in_t in;
    memset(&in, 0, sizeof(in));
    in.can_rx = &s->to_board;
    const bool estop = t >= 600u && t < 650u;
    in.gpio_in = (estop ? 0u : GPIO_IN_ESTOP_N) | GPIO_IN_DRIVE_FAULT_N;
    in.link_rx = s->link;
    in.link_rx_len = len;
    in.prev_compute_ns = 0;
    board_tick(&s->board, &in, &s->out);

    r->tick = t;
    r->state = (uint8_t)s->board.safety.state;
    r->fault = (uint8_t)s->board.safety.fault;
    r->can_tx = s->out.can_tx.n;
    r->gpio_out = s->out.gpio_out;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        r->torque_permille[j] = 0;
        for (uint8_t i = 0; i < s->out.can_tx.n; i++) {
            uint8_t node;
            uint16_t cw;
            int16_t tq;
            if (canopen_rpdo_decode(&s->out.can_tx.f[i], &node, &cw, &tq) && node == j + 1)
                r->torque_permille[j] = tq;
        }
    }
    r->force_n[0] = s->board.force_n.x;
    r->force_n[1] = s->board.force_n.y;
    r->force_n[2] = s->board.force_n.z;
    r->link_tx_bytes = (uint32_t)s->out.link_tx_len;
}
