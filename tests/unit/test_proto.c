/* Wire protocol v3: CRC, golden frames of docs/protocol.md, round trips, every decoder error
 * branch, and the reassembly of a chunked window. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "shared/crc32c.h"
#include "shared/proto.h"

/* Golden frames: the hex dumps of docs/protocol.md, byte for byte (made independently of this
 * code from the field values in golden_msg()). */
static const uint8_t golden_hello[38] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x01, 0x16, 0x00, 0x01, 0x00, 0x00, 0x00,
    0x01, 0x03, 0x20, 0x00, 0xe8, 0x03, 0x61, 0x72, 0x67, 0x69, 0x6c, 0x2d,
    0x62, 0x6f, 0x61, 0x72, 0x64, 0x20, 0x30, 0x2e, 0x31, 0x00, 0xa7, 0x62,
    0x8f, 0x0d,
};
static const uint8_t golden_heartbeat[33] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x02, 0x11, 0x00, 0x02, 0x00, 0x00, 0x00,
    0xcb, 0x04, 0xfb, 0x71, 0x1f, 0x01, 0x00, 0x00, 0x07, 0x00, 0x00, 0x00,
    0x2a, 0x00, 0x00, 0x00, 0x01, 0xa6, 0x03, 0xc6, 0xe4,
};
static const uint8_t golden_telemetry[80] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x03, 0x40, 0x00, 0x03, 0x00, 0x00, 0x00,
    0x40, 0x42, 0x0f, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00,
    0x03, 0x01, 0x01, 0x03, 0x00, 0x00, 0x00, 0x3e, 0x00, 0x00, 0x80, 0xbe,
    0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x80, 0x3d, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0xc0, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xc0, 0x3f,
    0x00, 0x00, 0x10, 0xc0, 0x07, 0x00, 0x00, 0x00, 0x40, 0xe2, 0x01, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x34, 0x3d, 0x24, 0x49,
};
static const uint8_t golden_impulse[42] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x04, 0x1a, 0x00, 0x04, 0x00, 0x00, 0x00,
    0x07, 0x00, 0x00, 0x00, 0x2b, 0x00, 0x00, 0x00, 0x02, 0x00, 0x21, 0x04,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x3b, 0x22, 0x04, 0x00, 0x00, 0x00, 0x00,
    0x00, 0xbf, 0x29, 0x44, 0xb5, 0x80,
};
static const uint8_t golden_window[82] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x05, 0x42, 0x00, 0x05, 0x00, 0x00, 0x00,
    0x08, 0x00, 0x00, 0x00, 0x02, 0x00, 0x03, 0x00, 0x0f, 0x0f, 0x02, 0x01,
    0x00, 0x00, 0x80, 0xbd, 0x00, 0x00, 0x00, 0x3e, 0x00, 0x00, 0x80, 0x3e,
    0x00, 0x00, 0x00, 0x3c, 0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x80, 0x3a,
    0x00, 0x00, 0x48, 0x43, 0x00, 0x00, 0x20, 0x40, 0x00, 0x00, 0x00, 0x3f,
    0x2a, 0x00, 0x00, 0x00, 0xc0, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
    0x80, 0x3e, 0x00, 0x00, 0x40, 0x3f, 0xb1, 0xe5, 0x37, 0xfa,
};
static const uint8_t golden_window2[138] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x05, 0x7a, 0x00, 0x05, 0x00, 0x00, 0x00,
    0x09, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x02, 0x02, 0x02, 0x02,
    0x00, 0x00, 0x80, 0x3e, 0x00, 0x00, 0x00, 0xbe, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x3c, 0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x80, 0x3a,
    0x00, 0x00, 0x48, 0x43, 0x00, 0x00, 0x20, 0x40, 0x00, 0x00, 0x00, 0x00,
    0x2b, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x3e, 0x00, 0x00, 0x80, 0x3e, 0x00, 0x00,
    0xc0, 0x3e, 0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x20, 0x3f, 0x00, 0x00,
    0x40, 0x3f, 0x00, 0x00, 0x60, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x48, 0x42, 0x00, 0x00, 0xc8, 0x42, 0x00, 0x00, 0x16, 0x43, 0x00, 0x00,
    0x48, 0x43, 0x00, 0x00, 0x7a, 0x43, 0x00, 0x00, 0x96, 0x43, 0x00, 0x40,
    0xaf, 0x43, 0x57, 0x42, 0x74, 0xd3,
};
static const uint8_t golden_tool[88] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x06, 0x48, 0x00, 0x06, 0x00, 0x00, 0x00,
    0x01, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x3c, 0x00, 0x00, 0x80, 0x3c,
    0x9a, 0x99, 0x19, 0x3f, 0x00, 0x00, 0x00, 0x00, 0xcd, 0xcc, 0x4c, 0x3f,
    0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x48, 0x44, 0x00, 0x00, 0x40, 0x40,
    0x00, 0x00, 0xc0, 0x3e, 0x00, 0x00, 0xc0, 0x3f, 0x00, 0x00, 0x80, 0x3e,
    0x00, 0x00, 0x00, 0x3e, 0x00, 0x00, 0xc8, 0x43, 0x00, 0x00, 0x00, 0x40,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xbe, 0x00, 0x00, 0x80, 0x3d,
    0x06, 0xf7, 0xc8, 0xad,
};
static const uint8_t golden_fault[31] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x07, 0x0f, 0x00, 0x07, 0x00, 0x00, 0x00,
    0x40, 0x4b, 0x4c, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 0x00, 0x05, 0xef,
    0xbe, 0xad, 0xde, 0xa3, 0x0b, 0x4f, 0x24,
};
static const uint8_t golden_rt_stats[196] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x08, 0xb4, 0x00, 0x08, 0x00, 0x00, 0x00,
    0xc0, 0xc6, 0x2d, 0x00, 0x00, 0x00, 0x00, 0x00, 0xb8, 0x0b, 0x00, 0x00,
    0x40, 0x42, 0x0f, 0x00, 0xb0, 0x04, 0x00, 0x00, 0x34, 0x21, 0x00, 0x00,
    0xa0, 0x56, 0x09, 0x00, 0x04, 0x10, 0x00, 0x00, 0x00, 0x64, 0x00, 0x00,
    0xd0, 0x12, 0x13, 0x00, 0x03, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
    0x34, 0x08, 0x00, 0x00, 0x80, 0x02, 0x00, 0x00, 0x96, 0x00, 0x00, 0x00,
    0x3c, 0x00, 0x00, 0x00, 0x1e, 0x00, 0x00, 0x00, 0x0c, 0x00, 0x00, 0x00,
    0x05, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x0a, 0x00, 0x00, 0x00, 0xc4, 0x09, 0x00, 0x00,
    0x90, 0x01, 0x00, 0x00, 0x3c, 0x00, 0x00, 0x00, 0x14, 0x00, 0x00, 0x00,
    0x06, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x05, 0x00, 0x00, 0x00, 0x03, 0x09, 0x00, 0x00, 0x0c, 0x00, 0x00, 0x00,
    0x2c, 0x01, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
    0x29, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00,
    0xf4, 0x02, 0xbf, 0x04,
};

#define WINDOW_SAMPLES_32 (32u * 32u * 32u)
#define ARRAY_MAX (PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX)

static float g_src[ARRAY_MAX];
static float g_dst[ARRAY_MAX];
static size_t g_frame_len; /* length of the frame received_chunk() last sent */

/* ---- helpers ---- */

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_f32(uint8_t *p, float v)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    put_u32(p, bits);
}

/* Sets the header's payload length to plen and recomputes the CRC, as a sender would. */
static size_t reseal(uint8_t *f, uint16_t plen)
{
    put_u16(f + 6, plen);
    size_t body = PROTO_HEADER_SIZE + plen;
    put_u32(f + body, crc32c(0u, f, body));
    return body + PROTO_CRC_SIZE;
}

/* Decodes frame f of flen bytes; returns the error. */
static proto_err_t decode_err(const uint8_t *f, size_t flen)
{
    proto_msg_t m;
    size_t used = 0;
    return proto_decode(f, flen, &m, &used);
}

/* Copies a golden frame, lets patch change it, reseals it and returns its decoder verdict. */
static proto_err_t decode_patched_u8(const uint8_t *gold, size_t len, size_t at, uint8_t v)
{
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, gold, len);
    f[at] = v;
    reseal(f, (uint16_t)(len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    return decode_err(f, len);
}

static proto_err_t decode_patched_u16(const uint8_t *gold, size_t len, size_t at, uint16_t v)
{
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, gold, len);
    put_u16(f + at, v);
    reseal(f, (uint16_t)(len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    return decode_err(f, len);
}

static proto_err_t decode_patched_u32(const uint8_t *gold, size_t len, size_t at, uint32_t v)
{
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, gold, len);
    put_u32(f + at, v);
    reseal(f, (uint16_t)(len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    return decode_err(f, len);
}

static proto_err_t decode_patched_f32(const uint8_t *gold, size_t len, size_t at, float v)
{
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, gold, len);
    put_f32(f + at, v);
    reseal(f, (uint16_t)(len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    return decode_err(f, len);
}

static void assert_f32s_equal(const float *a, const float *b, size_t n)
{
    assert_memory_equal(a, b, n * sizeof *a); /* bit patterns, so -0 and +0 differ */
}

/* Asserts that two messages carry the same fields (bit-exact floats, used entries only). */
static void assert_msg_equal(const proto_msg_t *a, const proto_msg_t *b)
{
    assert_int_equal(a->type, b->type);
    assert_int_equal(a->seq, b->seq);
    switch (a->type) {
    case MSG_HELLO:
        assert_int_equal(a->u.hello.role, b->u.hello.role);
        assert_int_equal(a->u.hello.drives, b->u.hello.drives);
        assert_int_equal(a->u.hello.window_max, b->u.hello.window_max);
        assert_int_equal(a->u.hello.tick_hz, b->u.hello.tick_hz);
        assert_memory_equal(a->u.hello.name, b->u.hello.name, PROTO_NAME_LEN);
        break;
    case MSG_HEARTBEAT:
        assert_true(a->u.heartbeat.time_us == b->u.heartbeat.time_us);
        assert_int_equal(a->u.heartbeat.window_version, b->u.heartbeat.window_version);
        assert_int_equal(a->u.heartbeat.impulse_seq, b->u.heartbeat.impulse_seq);
        assert_int_equal(a->u.heartbeat.command, b->u.heartbeat.command);
        break;
    case MSG_TELEMETRY: {
        const msg_telemetry_t *x = &a->u.telemetry, *y = &b->u.telemetry;
        assert_true(x->time_us == y->time_us);
        assert_int_equal(x->tick, y->tick);
        assert_int_equal(x->state, y->state);
        assert_int_equal(x->tool_kind, y->tool_kind);
        assert_int_equal(x->buttons, y->buttons);
        assert_int_equal(x->flags, y->flags);
        assert_f32s_equal(x->pos_m, y->pos_m, 3);
        assert_f32s_equal(x->vel_m_s, y->vel_m_s, 3);
        assert_f32s_equal(x->force_n, y->force_n, 3);
        assert_int_equal(x->window_version, y->window_version);
        assert_int_equal(x->compute_ns, y->compute_ns);
        assert_int_equal(x->deadline_misses, y->deadline_misses);
        break;
    }
    case MSG_IMPULSE: {
        const msg_impulse_t *x = &a->u.impulse, *y = &b->u.impulse;
        assert_int_equal(x->window_version, y->window_version);
        assert_int_equal(x->impulse_seq, y->impulse_seq);
        assert_int_equal(x->count, y->count);
        for (uint32_t i = 0; i < x->count && i < PROTO_IMPULSE_MAX; i++) {
            assert_int_equal(x->entries[i].node, y->entries[i].node);
            assert_f32s_equal(&x->entries[i].impulse_ns, &y->entries[i].impulse_ns, 1);
        }
        break;
    }
    case MSG_WINDOW: {
        const msg_window_t *x = &a->u.window, *y = &b->u.window;
        assert_int_equal(x->version, y->version);
        assert_int_equal(x->chunk_index, y->chunk_index);
        assert_int_equal(x->chunk_count, y->chunk_count);
        assert_memory_equal(x->dims, y->dims, 3);
        assert_int_equal(x->channels, y->channels);
        assert_f32s_equal(x->origin_m, y->origin_m, 3);
        assert_f32s_equal(&x->spacing_m, &y->spacing_m, 1);
        assert_f32s_equal(&x->iso, &y->iso, 1);
        assert_f32s_equal(&x->node_mass, &y->node_mass, 1);
        assert_f32s_equal(&x->stiffness, &y->stiffness, 1);
        assert_f32s_equal(&x->damping, &y->damping, 1);
        assert_f32s_equal(&x->plastic_rate_hz, &y->plastic_rate_hz, 1);
        assert_int_equal(x->impulse_seq, y->impulse_seq);
        assert_int_equal(x->first_sample, y->first_sample);
        assert_int_equal(x->sample_count, y->sample_count);
        assert_true(x->sample_count <= PROTO_WINDOW_CHUNK_SAMPLES);
        assert_f32s_equal(x->samples, y->samples, x->sample_count);
        break;
    }
    case MSG_TOOL: {
        const msg_tool_t *x = &a->u.tool, *y = &b->u.tool;
        assert_int_equal(x->kind, y->kind);
        assert_int_equal(x->shape, y->shape);
        assert_int_equal(x->filter, y->filter);
        assert_int_equal(x->flags, y->flags);
        assert_f32s_equal(&x->radius_m, &y->radius_m, 1);
        assert_f32s_equal(&x->length_m, &y->length_m, 1);
        assert_f32s_equal(x->axis, y->axis, 3);
        assert_f32s_equal(&x->alpha, &y->alpha, 1);
        assert_f32s_equal(&x->contact_stiffness_n_per_m, &y->contact_stiffness_n_per_m, 1);
        assert_f32s_equal(&x->max_force_n, &y->max_force_n, 1);
        assert_f32s_equal(&x->iso, &y->iso, 1);
        assert_f32s_equal(&x->yield_force_n, &y->yield_force_n, 1);
        assert_f32s_equal(&x->friction, &y->friction, 1);
        assert_f32s_equal(&x->probe_gain, &y->probe_gain, 1);
        assert_f32s_equal(&x->rope_stiffness_n_per_m, &y->rope_stiffness_n_per_m, 1);
        assert_f32s_equal(&x->model_scale, &y->model_scale, 1);
        assert_f32s_equal(x->model_offset_m, y->model_offset_m, 3);
        break;
    }
    case MSG_FAULT:
        assert_true(a->u.fault.time_us == b->u.fault.time_us);
        assert_int_equal(a->u.fault.code, b->u.fault.code);
        assert_int_equal(a->u.fault.state, b->u.fault.state);
        assert_int_equal(a->u.fault.detail, b->u.fault.detail);
        break;
    case MSG_RT_STATS:
        assert_true(a->u.rt_stats.time_us == b->u.rt_stats.time_us);
        assert_int_equal(a->u.rt_stats.ticks, b->u.rt_stats.ticks);
        assert_int_equal(a->u.rt_stats.period_ns, b->u.rt_stats.period_ns);
        assert_int_equal(a->u.rt_stats.wake_min_ns, b->u.rt_stats.wake_min_ns);
        assert_int_equal(a->u.rt_stats.wake_mean_ns, b->u.rt_stats.wake_mean_ns);
        assert_int_equal(a->u.rt_stats.wake_max_ns, b->u.rt_stats.wake_max_ns);
        assert_int_equal(a->u.rt_stats.compute_min_ns, b->u.rt_stats.compute_min_ns);
        assert_int_equal(a->u.rt_stats.compute_mean_ns, b->u.rt_stats.compute_mean_ns);
        assert_int_equal(a->u.rt_stats.compute_max_ns, b->u.rt_stats.compute_max_ns);
        assert_int_equal(a->u.rt_stats.overruns, b->u.rt_stats.overruns);
        assert_int_equal(a->u.rt_stats.worst_streak, b->u.rt_stats.worst_streak);
        assert_memory_equal(a->u.rt_stats.wake_hist, b->u.rt_stats.wake_hist,
                            sizeof a->u.rt_stats.wake_hist);
        assert_memory_equal(a->u.rt_stats.compute_hist, b->u.rt_stats.compute_hist,
                            sizeof a->u.rt_stats.compute_hist);
        assert_int_equal(a->u.rt_stats.link.decode_errors, b->u.rt_stats.link.decode_errors);
        assert_int_equal(a->u.rt_stats.link.wrong_source, b->u.rt_stats.link.wrong_source);
        assert_int_equal(a->u.rt_stats.link.no_session, b->u.rt_stats.link.no_session);
        assert_int_equal(a->u.rt_stats.link.duplicate, b->u.rt_stats.link.duplicate);
        assert_int_equal(a->u.rt_stats.link.stale, b->u.rt_stats.link.stale);
        assert_int_equal(a->u.rt_stats.link.sessions, b->u.rt_stats.link.sessions);
        assert_int_equal(a->u.rt_stats.link.bad_mac, b->u.rt_stats.link.bad_mac);
        assert_int_equal(a->u.rt_stats.link.bad_nonce, b->u.rt_stats.link.bad_nonce);
        assert_int_equal(a->u.rt_stats.link.arm_refused, b->u.rt_stats.link.arm_refused);
        break;
    default:
        fail_msg("unexpected type %d", a->type);
    }
}

/* The messages behind the golden frames (docs/protocol.md lists the same values). */
static proto_msg_t golden_msg(uint8_t type)
{
    proto_msg_t m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.seq = type;
    switch (type) {
    case MSG_HELLO:
        m.u.hello.role = PROTO_ROLE_BOARD;
        m.u.hello.drives = 3;
        m.u.hello.window_max = 32;
        m.u.hello.tick_hz = 1000;
        memcpy(m.u.hello.name, "argil-board 0.1", 15); /* NUL-padded to 16 */
        break;
    case MSG_HEARTBEAT:
        m.u.heartbeat.time_us = 1234567890123u;
        m.u.heartbeat.window_version = 7;
        m.u.heartbeat.impulse_seq = 42;
        m.u.heartbeat.command = PROTO_CMD_ARM;
        break;
    case MSG_TELEMETRY: {
        msg_telemetry_t *t = &m.u.telemetry;
        t->time_us = 1000000u;
        t->tick = 1000;
        t->state = 3;
        t->tool_kind = TOOL_PUSH;
        t->buttons = 1;
        t->flags = 3;
        t->pos_m[0] = 0.125f;
        t->pos_m[1] = -0.25f;
        t->pos_m[2] = 0.5f;
        t->vel_m_s[0] = 0.0625f;
        t->vel_m_s[1] = 0.0f;
        t->vel_m_s[2] = -1.5f;
        t->force_n[0] = 0.0f;
        t->force_n[1] = 1.5f;
        t->force_n[2] = -2.25f;
        t->window_version = 7;
        t->compute_ns = 123456;
        t->deadline_misses = 0;
        break;
    }
    case MSG_IMPULSE:
        m.u.impulse.window_version = 7;
        m.u.impulse.impulse_seq = 43;
        m.u.impulse.count = 2;
        m.u.impulse.entries[0].node = 1057;
        m.u.impulse.entries[0].impulse_ns = 0.001953125f;
        m.u.impulse.entries[1].node = 1058;
        m.u.impulse.entries[1].impulse_ns = -0.5f;
        break;
    case MSG_WINDOW: {
        msg_window_t *w = &m.u.window;
        w->version = 8;
        w->chunk_index = 2;
        w->chunk_count = 3;
        w->dims[0] = 15;
        w->dims[1] = 15;
        w->dims[2] = 2;
        w->channels = 1;
        w->origin_m[0] = -0.0625f;
        w->origin_m[1] = 0.125f;
        w->origin_m[2] = 0.25f;
        w->spacing_m = 0.0078125f;
        w->iso = 0.5f;
        w->node_mass = 0.0009765625f;
        w->stiffness = 200.0f;
        w->damping = 2.5f;
        w->plastic_rate_hz = 0.5f;
        w->impulse_seq = 42;
        w->first_sample = 448;
        w->sample_count = 2;
        w->samples[0] = 0.25f;
        w->samples[1] = 0.75f;
        break;
    }
    case MSG_TOOL: {
        msg_tool_t *t = &m.u.tool;
        t->kind = TOOL_PUSH;
        t->shape = TOOL_SHAPE_CURVE;
        t->filter = BETA_GAUSSIAN;
        t->flags = TOOL_FLAG_ISO;
        t->radius_m = 0.0078125f;
        t->length_m = 0.015625f;
        t->axis[0] = 0.6f;
        t->axis[1] = 0.0f;
        t->axis[2] = 0.8f;
        t->alpha = 0.5f;
        t->contact_stiffness_n_per_m = 800.0f;
        t->max_force_n = 3.0f;
        t->iso = 0.375f;
        t->yield_force_n = 1.5f;
        t->friction = 0.25f;
        t->probe_gain = 0.125f;
        t->rope_stiffness_n_per_m = 400.0f;
        t->model_scale = 2.0f;
        t->model_offset_m[0] = 0.0f;
        t->model_offset_m[1] = -0.125f;
        t->model_offset_m[2] = 0.0625f;
        break;
    }
    case MSG_FAULT:
        m.u.fault.time_us = 5000000u;
        m.u.fault.code = 3;
        m.u.fault.state = 5;
        m.u.fault.detail = 0xDEADBEEFu;
        break;
    case MSG_RT_STATS: {
        static const uint32_t wake[PROTO_RT_HIST_BINS] = {2100, 640, 150, 60, 30, 12,
                                                          5,    2,   1,   0,  0,  0};
        static const uint32_t comp[PROTO_RT_HIST_BINS] = {0, 10, 2500, 400, 60, 20,
                                                          6, 1,  3,    0,   0,  0};
        msg_rt_stats_t *r = &m.u.rt_stats;
        r->time_us = 3000000u;
        r->ticks = 3000u;
        r->period_ns = 1000000u;
        r->wake_min_ns = 1200u;
        r->wake_mean_ns = 8500u;
        r->wake_max_ns = 612000u;
        r->compute_min_ns = 4100u;
        r->compute_mean_ns = 25600u;
        r->compute_max_ns = 1250000u;
        r->overruns = 3u;
        r->worst_streak = 2u;
        memcpy(r->wake_hist, wake, sizeof wake);
        memcpy(r->compute_hist, comp, sizeof comp);
        r->link.decode_errors = 5u;
        r->link.wrong_source = 2307u;
        r->link.no_session = 12u;
        r->link.duplicate = 300u;
        r->link.stale = 4u;
        r->link.sessions = 2u;
        r->link.bad_mac = 41u;
        r->link.bad_nonce = 3u;
        r->link.arm_refused = 1u;
        break;
    }
    default:
        break;
    }
    return m;
}

/* The message behind golden_window2: the only chunk of a two-channel 2x2x2 window. */
static proto_msg_t golden_window2_msg(void)
{
    proto_msg_t m;
    memset(&m, 0, sizeof m);
    m.type = MSG_WINDOW;
    m.seq = MSG_WINDOW;
    msg_window_t *w = &m.u.window;
    w->version = 9;
    w->chunk_index = 0;
    w->chunk_count = 1;
    w->dims[0] = 2;
    w->dims[1] = 2;
    w->dims[2] = 2;
    w->channels = 2;
    w->origin_m[0] = 0.25f;
    w->origin_m[1] = -0.125f;
    w->origin_m[2] = 0.0f;
    w->spacing_m = 0.0078125f;
    w->iso = 0.5f;
    w->node_mass = 0.0009765625f;
    w->stiffness = 200.0f;
    w->damping = 2.5f;
    w->plastic_rate_hz = 0.0f;
    w->impulse_seq = 43;
    w->first_sample = 0;
    w->sample_count = 16;
    const float stiff[8] = { 0.0f, 50.0f, 100.0f, 150.0f, 200.0f, 250.0f, 300.0f, 350.5f };
    for (int i = 0; i < 8; i++) {
        w->samples[i] = 0.125f * (float)i; /* densities */
        w->samples[8 + i] = stiff[i];      /* then each node's stiffness */
    }
    return m;
}

/* Encodes m and asserts the exact golden bytes; decodes the bytes back to m's fields. */
static void check_golden_msg(const proto_msg_t *mp, const uint8_t *gold, size_t gold_len)
{
    proto_msg_t m = *mp;
    uint8_t f[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, m.seq, f, sizeof f, &len), PROTO_OK);
    assert_int_equal(len, gold_len);
    assert_memory_equal(f, gold, gold_len);

    proto_msg_t back;
    size_t used = 0;
    assert_int_equal(proto_decode(gold, gold_len, &back, &used), PROTO_OK);
    assert_int_equal(used, gold_len);
    assert_msg_equal(&m, &back);
}

/* Encodes golden_msg(type) and asserts the exact golden bytes; decodes the bytes back. */
static void check_golden(uint8_t type, const uint8_t *gold, size_t gold_len)
{
    proto_msg_t m = golden_msg(type);
    check_golden_msg(&m, gold, gold_len);
}

/* Encodes m and decodes it back; asserts equality and returns the frame length. */
static size_t round_trip(const proto_msg_t *m)
{
    uint8_t f[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(m, m->seq, f, sizeof f, &len), PROTO_OK);
    assert_true(len <= PROTO_FRAME_MAX);
    proto_msg_t back;
    size_t used = 0;
    assert_int_equal(proto_decode(f, len, &back, &used), PROTO_OK);
    assert_int_equal(used, len);
    assert_msg_equal(m, &back);
    return len;
}

/* A one-channel window head (no samples) for dims, with plausible clay. */
static msg_window_t window_head(uint32_t version, uint8_t nx, uint8_t ny, uint8_t nz)
{
    msg_window_t h;
    memset(&h, 0, sizeof h);
    h.version = version;
    h.dims[0] = nx;
    h.dims[1] = ny;
    h.dims[2] = nz;
    h.channels = 1;
    h.origin_m[0] = -0.02f;
    h.origin_m[1] = 0.01f;
    h.origin_m[2] = 0.3f;
    h.spacing_m = 0.002f;
    h.iso = 0.5f;
    h.node_mass = 0.001f;
    h.stiffness = 150.0f;
    h.damping = 3.0f;
    h.plastic_rate_hz = 0.2f;
    h.impulse_seq = 99;
    return h;
}

/* Fills g_src for a window of n nodes: a density ramp that differs at every sample (and dips
 * below 0: densities need only be finite), then n stiffnesses in 50 … 250 N/m for channel 2. */
static void fill_source(uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        g_src[i] = (float)i / (float)n + 0.25f * sinf((float)i * 0.01f);
        g_src[n + i] = 150.0f + 100.0f * cosf((float)i * 0.003f);
    }
}

/* Chunk index of a window via encode + decode, as the board would receive it. */
static msg_window_t received_chunk(const msg_window_t *head, uint16_t index)
{
    proto_msg_t m, back;
    memset(&m, 0, sizeof m);
    m.type = MSG_WINDOW;
    m.seq = 1000u + index;
    assert_int_equal(window_chunk_fill(head, g_src, index, &m.u.window), PROTO_OK);
    uint8_t f[PROTO_FRAME_MAX];
    size_t len = 0, used = 0;
    assert_int_equal(proto_encode(&m, m.seq, f, sizeof f, &len), PROTO_OK);
    assert_true(len <= 1024u);
    g_frame_len = len;
    assert_int_equal(proto_decode(f, len, &back, &used), PROTO_OK);
    return back.u.window;
}

/* Feeds every chunk of head except skip (pass chunk_count to skip none). */
static void feed_all_but(window_asm_t *a, const msg_window_t *head, uint16_t skip)
{
    uint16_t n = window_chunk_count(head->dims, head->channels);
    for (uint16_t i = 0; i < n; i++) {
        if (i == skip)
            continue;
        msg_window_t c = received_chunk(head, i);
        assert_int_equal(window_asm_feed(a, &c), PROTO_OK);
    }
}

/* ---- CRC and golden frames ---- */

static void test_crc32c_gives_the_castagnoli_check_value(void **state)
{
    (void)state;
    assert_int_equal(crc32c(0u, "123456789", 9), 0xE3069283u);
    assert_int_equal(crc32c(0u, "", 0), 0u);
    /* continuing over pieces gives the same CRC as one pass */
    uint32_t c = crc32c(0u, "1234", 4);
    assert_int_equal(crc32c(c, "56789", 5), 0xE3069283u);
    /* 32 zero bytes: the iSCSI (RFC 3720 B.4) vector */
    static const uint8_t zeros[32];
    assert_int_equal(crc32c(0u, zeros, sizeof zeros), 0x8A9136AAu);
}

static void test_golden_hello_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_HELLO, golden_hello, sizeof golden_hello);
}

static void test_golden_heartbeat_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_HEARTBEAT, golden_heartbeat, sizeof golden_heartbeat);
}

static void test_golden_telemetry_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_TELEMETRY, golden_telemetry, sizeof golden_telemetry);
}

static void test_golden_impulse_frame_with_two_entries_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_IMPULSE, golden_impulse, sizeof golden_impulse);
}

static void test_golden_window_last_chunk_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_WINDOW, golden_window, sizeof golden_window);
}

static void test_golden_two_channel_window_frame_matches_the_spec(void **state)
{
    (void)state;
    proto_msg_t m = golden_window2_msg();
    check_golden_msg(&m, golden_window2, sizeof golden_window2);
}

static void test_golden_tool_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_TOOL, golden_tool, sizeof golden_tool);
}

static void test_golden_fault_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_FAULT, golden_fault, sizeof golden_fault);
}

static void test_golden_rt_stats_frame_matches_the_spec(void **state)
{
    (void)state;
    check_golden(MSG_RT_STATS, golden_rt_stats, sizeof golden_rt_stats);
}


/* ---- round trips ---- */

static void test_every_message_type_survives_a_round_trip_at_its_extremes(void **state)
{
    (void)state;
    proto_msg_t m = golden_msg(MSG_HELLO);
    m.seq = 0xFFFFFFFFu;
    m.u.hello.role = PROTO_ROLE_HOST;
    m.u.hello.tick_hz = 0;
    m.u.hello.window_max = 0xFFFF;
    memset(m.u.hello.name, 0xFF, PROTO_NAME_LEN); /* not terminated: copied as is */
    assert_int_equal(round_trip(&m), 12u + 22u + 4u);

    m = golden_msg(MSG_HEARTBEAT);
    m.u.heartbeat.time_us = UINT64_MAX;
    m.u.heartbeat.command = PROTO_CMD_DISARM;
    assert_int_equal(round_trip(&m), 12u + 17u + 4u);
    m.u.heartbeat.command = PROTO_CMD_END;
    assert_int_equal(round_trip(&m), 12u + 17u + 4u);

    m = golden_msg(MSG_TELEMETRY);
    m.u.telemetry.pos_m[0] = -0.0f;
    m.u.telemetry.vel_m_s[1] = 3.4e38f;
    m.u.telemetry.force_n[2] = 1e-45f; /* denormal */
    m.u.telemetry.tool_kind = TOOL_CARVE;
    m.u.telemetry.deadline_misses = 0xFFFFFFFFu;
    assert_int_equal(round_trip(&m), 12u + 64u + 4u);

    m = golden_msg(MSG_IMPULSE);
    m.u.impulse.count = 0;
    assert_int_equal(round_trip(&m), 12u + 10u + 4u);
    m.u.impulse.count = PROTO_IMPULSE_MAX;
    for (uint32_t i = 0; i < PROTO_IMPULSE_MAX; i++) {
        m.u.impulse.entries[i].node = ARGIL_WINDOW_SAMPLES_MAX - 1u - i;
        m.u.impulse.entries[i].impulse_ns = (float)i * -1e-4f;
    }
    assert_int_equal(round_trip(&m), 12u + 10u + 8u * PROTO_IMPULSE_MAX + 4u);

    m = golden_msg(MSG_WINDOW);
    m.u.window.chunk_index = 0;
    m.u.window.first_sample = 0;
    m.u.window.sample_count = PROTO_WINDOW_CHUNK_SAMPLES;
    m.u.window.stiffness = 0.0f;
    m.u.window.plastic_rate_hz = 0.0f;
    for (uint32_t i = 0; i < PROTO_WINDOW_CHUNK_SAMPLES; i++)
        m.u.window.samples[i] = (float)i / 224.0f - 0.5f;
    assert_int_equal(round_trip(&m), 12u + 58u + 4u * PROTO_WINDOW_CHUNK_SAMPLES + 4u);
    /* two channels: chunk 2 of 15x15x2 (900 samples) holds stiffnesses only */
    m.u.window.channels = 2;
    m.u.window.chunk_count = 5;
    for (uint32_t i = 0; i < PROTO_WINDOW_CHUNK_SAMPLES; i++)
        m.u.window.samples[i] = (float)i * 10.0f;
    m.u.window.samples[7] = -0.0f; /* >= 0 */
    assert_int_equal(round_trip(&m), 12u + 58u + 4u * PROTO_WINDOW_CHUNK_SAMPLES + 4u);
    m = golden_window2_msg();
    assert_int_equal(round_trip(&m), 12u + 58u + 4u * 16u + 4u);

    m = golden_msg(MSG_TOOL);
    m.u.tool.kind = TOOL_ROPE;
    m.u.tool.shape = TOOL_SHAPE_AREA;
    m.u.tool.filter = BETA_CONICAL;
    m.u.tool.flags = 0;
    m.u.tool.length_m = 0.0f;
    m.u.tool.axis[0] = -1.0f;
    m.u.tool.axis[2] = 0.0f;
    m.u.tool.alpha = 0.0f;
    m.u.tool.contact_stiffness_n_per_m = 0.0f;
    m.u.tool.iso = 1.0f;
    m.u.tool.yield_force_n = 0.0f;
    m.u.tool.friction = 0.0f;
    m.u.tool.probe_gain = 0.0f;
    m.u.tool.rope_stiffness_n_per_m = 3.4e38f;
    m.u.tool.model_offset_m[0] = -0.0f;
    assert_int_equal(round_trip(&m), 12u + 72u + 4u);
    m.u.tool.kind = TOOL_PROBE;
    m.u.tool.shape = TOOL_SHAPE_POINT;
    m.u.tool.filter = BETA_CONSTANT;
    m.u.tool.iso = 0.0f;
    assert_int_equal(round_trip(&m), 12u + 72u + 4u);

    m = golden_msg(MSG_FAULT);
    m.u.fault.code = 0xFFFF;
    m.u.fault.state = 0xFF;
    assert_int_equal(round_trip(&m), 12u + 15u + 4u);
}

/* ---- decoder error branches, in the order the decoder checks them ---- */

static void test_wrong_magic_is_refused_as_soon_as_four_bytes_arrive(void **state)
{
    (void)state;
    uint8_t f[sizeof golden_hello];
    memcpy(f, golden_hello, sizeof f);
    f[3] = 'X';
    assert_int_equal(decode_err(f, 4), PROTO_ERR_MAGIC);
    assert_int_equal(decode_err(f, sizeof f), PROTO_ERR_MAGIC);
    f[3] = golden_hello[3];
    f[0] = 0;
    assert_int_equal(decode_err(f, sizeof f), PROTO_ERR_MAGIC);
    /* fewer than four bytes cannot be judged yet */
    assert_int_equal(decode_err(f, 3), PROTO_ERR_TRUNCATED);
}

static void test_frame_shorter_than_its_header_is_truncated(void **state)
{
    (void)state;
    for (size_t n = 0; n < PROTO_HEADER_SIZE; n++)
        assert_int_equal(decode_err(golden_telemetry, n), PROTO_ERR_TRUNCATED);
}

static void test_frame_cut_inside_payload_or_crc_is_truncated(void **state)
{
    (void)state;
    for (size_t n = PROTO_HEADER_SIZE; n < sizeof golden_window; n++)
        assert_int_equal(decode_err(golden_window, n), PROTO_ERR_TRUNCATED);
    for (size_t n = PROTO_HEADER_SIZE; n < sizeof golden_fault; n++)
        assert_int_equal(decode_err(golden_fault, n), PROTO_ERR_TRUNCATED);
    /* one byte more than the frame is fine: the frame length says where the next one starts */
    uint8_t f[sizeof golden_fault + 1];
    memcpy(f, golden_fault, sizeof golden_fault);
    f[sizeof golden_fault] = 0x41;
    proto_msg_t m;
    size_t used = 0;
    assert_int_equal(proto_decode(f, sizeof f, &m, &used), PROTO_OK);
    assert_int_equal(used, sizeof golden_fault);
}

static void test_declared_payload_above_1008_bytes_is_oversize_before_any_wait(void **state)
{
    (void)state;
    uint8_t f[PROTO_FRAME_MAX + 8];
    memset(f, 0, sizeof f);
    memcpy(f, golden_hello, PROTO_HEADER_SIZE);
    put_u16(f + 6, (uint16_t)(PROTO_PAYLOAD_MAX + 1u));
    /* only the header has arrived: a receiver must not wait for 1 KiB+ that will never fit */
    assert_int_equal(decode_err(f, PROTO_HEADER_SIZE), PROTO_ERR_OVERSIZE);
    assert_int_equal(decode_err(f, sizeof f), PROTO_ERR_OVERSIZE);
    put_u16(f + 6, 0xFFFF);
    assert_int_equal(decode_err(f, sizeof f), PROTO_ERR_OVERSIZE);
}

static void test_any_flipped_bit_after_the_header_fields_fails_the_crc(void **state)
{
    (void)state;
    uint8_t f[sizeof golden_telemetry];
    /* sequence number, payload and CRC: every single-bit error is caught */
    for (size_t i = 8; i < sizeof f; i++) {
        for (int b = 0; b < 8; b++) {
            memcpy(f, golden_telemetry, sizeof f);
            f[i] ^= (uint8_t)(1u << b);
            assert_int_equal(decode_err(f, sizeof f), PROTO_ERR_CRC);
        }
    }
}

static void test_other_protocol_versions_are_refused(void **state)
{
    (void)state;
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 4, 0),
                     PROTO_ERR_VERSION);
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 4, 1),
                     PROTO_ERR_VERSION); /* v1: before host sessions */
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 4, 2),
                     PROTO_ERR_VERSION); /* v2: before the authenticated link's counts */
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 4, 4),
                     PROTO_ERR_VERSION);
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 4, 0xFF),
                     PROTO_ERR_VERSION);
}

static void test_unknown_message_types_are_refused(void **state)
{
    (void)state;
    assert_int_equal(decode_patched_u8(golden_fault, sizeof golden_fault, 5, 0), PROTO_ERR_TYPE);
    assert_int_equal(decode_patched_u8(golden_fault, sizeof golden_fault, 5, MSG_TYPE_LAST + 1),
                     PROTO_ERR_TYPE);
    assert_int_equal(decode_patched_u8(golden_fault, sizeof golden_fault, 5, 0xFF),
                     PROTO_ERR_TYPE);
}

/* Decoder verdict on gold's header and payload resized to plen (zero-extended), resealed. */
static proto_err_t decode_resized(const uint8_t *gold, size_t len, uint16_t plen)
{
    uint8_t f[PROTO_FRAME_MAX];
    memset(f, 0, sizeof f);
    size_t old = len - PROTO_CRC_SIZE;
    memcpy(f, gold, old < PROTO_HEADER_SIZE + plen ? old : PROTO_HEADER_SIZE + plen);
    size_t flen = reseal(f, plen);
    return decode_err(f, flen);
}

static void test_payload_length_that_does_not_fit_the_type_is_refused(void **state)
{
    (void)state;
    const struct {
        const uint8_t *gold;
        size_t len;
    } fixed[] = {
        { golden_hello, sizeof golden_hello },
        { golden_heartbeat, sizeof golden_heartbeat },
        { golden_telemetry, sizeof golden_telemetry },
        { golden_tool, sizeof golden_tool },
        { golden_fault, sizeof golden_fault },
        { golden_rt_stats, sizeof golden_rt_stats },
    };
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) {
        uint16_t plen = (uint16_t)(fixed[i].len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE);
        assert_int_equal(decode_resized(fixed[i].gold, fixed[i].len, plen), PROTO_OK);
        assert_int_equal(decode_resized(fixed[i].gold, fixed[i].len, plen - 1u),
                         PROTO_ERR_PAYLOAD);
        assert_int_equal(decode_resized(fixed[i].gold, fixed[i].len, plen + 1u),
                         PROTO_ERR_PAYLOAD);
        assert_int_equal(decode_resized(fixed[i].gold, fixed[i].len, 0), PROTO_ERR_PAYLOAD);
    }
    /* IMPULSE: says 2 entries, carries 3 or 1 or a broken one */
    uint16_t ip = (uint16_t)(sizeof golden_impulse - 16u);
    assert_int_equal(decode_resized(golden_impulse, sizeof golden_impulse, ip + 8u),
                     PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_impulse, sizeof golden_impulse, ip - 8u),
                     PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_impulse, sizeof golden_impulse, ip - 1u),
                     PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_impulse, sizeof golden_impulse, 9),
                     PROTO_ERR_PAYLOAD);
    /* WINDOW: shorter than its fixed part, or samples not matching sample_count */
    uint16_t wp = (uint16_t)(sizeof golden_window - 16u);
    assert_int_equal(decode_resized(golden_window, sizeof golden_window, 57), PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_window, sizeof golden_window, wp + 4u),
                     PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_window, sizeof golden_window, wp - 4u),
                     PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(golden_window, sizeof golden_window, wp + 1u),
                     PROTO_ERR_PAYLOAD);
}

static void test_non_finite_floats_are_refused_in_every_message(void **state)
{
    (void)state;
    const float bad[] = { NAN, INFINITY, -INFINITY };
    for (size_t k = 0; k < 3; k++) {
        float v = bad[k];
        for (size_t at = 28; at < 64; at += 4) /* pos, vel, force */
            assert_int_equal(decode_patched_f32(golden_telemetry, sizeof golden_telemetry, at, v),
                             PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_impulse, sizeof golden_impulse, 26, v),
                         PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_impulse, sizeof golden_impulse, 34, v),
                         PROTO_ERR_VALUE);
        for (size_t at = 24; at < 60; at += 4) /* origin, spacing, iso, material */
            assert_int_equal(decode_patched_f32(golden_window, sizeof golden_window, at, v),
                             PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_window, sizeof golden_window, 74, v),
                         PROTO_ERR_VALUE); /* a sample */
        assert_int_equal(decode_patched_f32(golden_window2, sizeof golden_window2, 70, v),
                         PROTO_ERR_VALUE); /* a density of a two-channel window */
        assert_int_equal(decode_patched_f32(golden_window2, sizeof golden_window2, 102, v),
                         PROTO_ERR_VALUE); /* a stiffness */
        for (size_t at = 16; at < 84; at += 4) /* every tool float */
            assert_int_equal(decode_patched_f32(golden_tool, sizeof golden_tool, at, v),
                             PROTO_ERR_VALUE);
    }
}

static void test_out_of_range_fields_are_refused(void **state)
{
    (void)state;
    /* HELLO role, HEARTBEAT command, TELEMETRY tool kind */
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 12, 0), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u8(golden_hello, sizeof golden_hello, 12, 3), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u8(golden_heartbeat, sizeof golden_heartbeat, 28, 4),
                     PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u8(golden_heartbeat, sizeof golden_heartbeat, 28,
                                       PROTO_CMD_END),
                     PROTO_OK);
    assert_int_equal(decode_patched_u8(golden_telemetry, sizeof golden_telemetry, 25,
                                       TOOL_KIND_COUNT),
                     PROTO_ERR_VALUE);
    /* IMPULSE: more entries than a frame holds (even with a length to match), node outside */
    assert_int_equal(decode_patched_u16(golden_impulse, sizeof golden_impulse, 20,
                                        PROTO_IMPULSE_MAX + 1u),
                     PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u16(golden_impulse, sizeof golden_impulse, 20, 0xFFFF),
                     PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(golden_impulse, sizeof golden_impulse, 22,
                                        ARGIL_WINDOW_SAMPLES_MAX),
                     PROTO_ERR_VALUE);
    /* WINDOW: spacing <= 0, dims 0, 1 or above ARGIL_WINDOW_MAX, massless or negative clay */
    const size_t W = sizeof golden_window;
    assert_int_equal(decode_patched_f32(golden_window, W, 36, 0.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_f32(golden_window, W, 36, -0.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_f32(golden_window, W, 36, -0.001f), PROTO_ERR_VALUE);
    for (size_t axis = 0; axis < 3; axis++) {
        assert_int_equal(decode_patched_u8(golden_window, W, 20 + axis, 0), PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_u8(golden_window, W, 20 + axis, 1), PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_u8(golden_window, W, 20 + axis, ARGIL_WINDOW_MAX + 1),
                         PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_u8(golden_window, W, 20 + axis, 0xFF), PROTO_ERR_VALUE);
    }
    assert_int_equal(decode_patched_f32(golden_window, W, 44, 0.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_f32(golden_window, W, 48, -1.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_f32(golden_window, W, 52, -1.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_f32(golden_window, W, 56, -1.0f), PROTO_ERR_VALUE);
    /* accepted edge values stay accepted (TOOL: test_every_tool_rule_is_enforced_...) */
    assert_int_equal(decode_patched_u8(golden_window, W, 20, ARGIL_WINDOW_MAX), PROTO_ERR_CHUNK);
}

static void test_window_chunk_numbering_that_contradicts_itself_is_refused(void **state)
{
    (void)state;
    /* golden: 15x15x2 = 450 samples, chunks of 224, 224, 2; this is chunk 2 of 3 */
    const size_t W = sizeof golden_window;
    assert_int_equal(decode_patched_u16(golden_window, W, 16, 3), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u16(golden_window, W, 16, 0xFFFF), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u16(golden_window, W, 18, 4), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u16(golden_window, W, 18, 2), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u16(golden_window, W, 18, 0), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u32(golden_window, W, 64, 447), PROTO_ERR_CHUNK);
    assert_int_equal(decode_patched_u32(golden_window, W, 64, 0), PROTO_ERR_CHUNK);
    /* the same frame claiming two channels: 900 samples make 5 chunks, not 3 */
    assert_int_equal(decode_patched_u8(golden_window, W, 23, 2), PROTO_ERR_CHUNK);
    /* chunk 1 claiming the samples of chunk 2 */
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, golden_window, W);
    put_u16(f + 16, 1);
    reseal(f, (uint16_t)(W - 16u));
    assert_int_equal(decode_err(f, W), PROTO_ERR_CHUNK);

    /* sample_count wrong for its chunk, with a payload length that matches it */
    memset(f, 0, sizeof f);
    memcpy(f, golden_window, W - 4u);
    put_u16(f + 68, 3);
    size_t flen = reseal(f, (uint16_t)(58u + 3u * 4u));
    assert_int_equal(decode_err(f, flen), PROTO_ERR_CHUNK);
    put_u16(f + 68, 1);
    flen = reseal(f, (uint16_t)(58u + 1u * 4u));
    assert_int_equal(decode_err(f, flen), PROTO_ERR_CHUNK);
    put_u16(f + 68, 0);
    flen = reseal(f, 58u);
    assert_int_equal(decode_err(f, flen), PROTO_ERR_CHUNK);
    /* chunk 0 of the same window must hold 224 samples, not 223 and not 225 */
    put_u16(f + 16, 0);
    put_u32(f + 64, 0);
    put_u16(f + 68, 223);
    flen = reseal(f, (uint16_t)(58u + 223u * 4u));
    assert_int_equal(decode_err(f, flen), PROTO_ERR_CHUNK);
    put_u16(f + 68, 225);
    flen = reseal(f, (uint16_t)(58u + 225u * 4u));
    assert_int_equal(decode_err(f, flen), PROTO_ERR_CHUNK);
    put_u16(f + 68, 224);
    flen = reseal(f, (uint16_t)(58u + 224u * 4u));
    assert_int_equal(decode_err(f, flen), PROTO_OK);
}

/* ---- encoder ---- */

static void test_encoder_reports_a_buffer_too_small_and_writes_nothing_past_it(void **state)
{
    (void)state;
    proto_msg_t m = golden_msg(MSG_WINDOW);
    uint8_t f[sizeof golden_window + 8];
    size_t len = 12345;
    memset(f, 0xAA, sizeof f);
    assert_int_equal(proto_encode(&m, m.seq, f, sizeof golden_window - 1u, &len),
                     PROTO_ERR_NOSPACE);
    assert_int_equal(proto_encode(&m, m.seq, f, 0, &len), PROTO_ERR_NOSPACE);
    assert_int_equal(len, 12345);
    assert_int_equal(f[sizeof golden_window - 1u], 0xAA);
    assert_int_equal(proto_encode(&m, m.seq, f, sizeof golden_window, &len), PROTO_OK);
    assert_int_equal(len, sizeof golden_window);
    assert_int_equal(f[sizeof golden_window], 0xAA);
}

/* Encoder verdict on m. */
static proto_err_t encode_err(const proto_msg_t *m)
{
    uint8_t f[PROTO_FRAME_MAX];
    size_t len = 0;
    return proto_encode(m, m->seq, f, sizeof f, &len);
}

static void test_encoder_refuses_what_the_decoder_would_refuse(void **state)
{
    (void)state;
    proto_msg_t m = golden_msg(MSG_FAULT);
    m.type = 0;
    assert_int_equal(encode_err(&m), PROTO_ERR_TYPE);
    m.type = MSG_TYPE_LAST + 1;
    assert_int_equal(encode_err(&m), PROTO_ERR_TYPE);

    m = golden_msg(MSG_HELLO);
    m.u.hello.role = 0;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_HEARTBEAT);
    m.u.heartbeat.command = PROTO_CMD_END + 1;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TELEMETRY);
    m.u.telemetry.force_n[1] = NAN;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TELEMETRY);
    m.u.telemetry.tool_kind = TOOL_KIND_COUNT;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);

    m = golden_msg(MSG_IMPULSE);
    m.u.impulse.count = PROTO_IMPULSE_MAX + 1u;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_IMPULSE);
    m.u.impulse.entries[1].impulse_ns = INFINITY;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_IMPULSE);
    m.u.impulse.entries[0].node = ARGIL_WINDOW_SAMPLES_MAX;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);

    m = golden_msg(MSG_WINDOW);
    m.u.window.spacing_m = 0.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_WINDOW);
    m.u.window.dims[1] = ARGIL_WINDOW_MAX + 1;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_WINDOW);
    m.u.window.node_mass = -1.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_WINDOW);
    m.u.window.samples[1] = NAN;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_WINDOW);
    m.u.window.channels = 0;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_window2_msg();
    m.u.window.samples[9] = -50.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_WINDOW);
    m.u.window.channels = 2;
    assert_int_equal(encode_err(&m), PROTO_ERR_CHUNK);
    m = golden_msg(MSG_WINDOW);
    m.u.window.chunk_index = 3;
    assert_int_equal(encode_err(&m), PROTO_ERR_CHUNK);
    m = golden_msg(MSG_WINDOW);
    m.u.window.sample_count = PROTO_WINDOW_CHUNK_SAMPLES + 1u;
    assert_int_equal(encode_err(&m), PROTO_ERR_CHUNK);
    m = golden_msg(MSG_WINDOW);
    m.u.window.first_sample = 0;
    assert_int_equal(encode_err(&m), PROTO_ERR_CHUNK);

    m = golden_msg(MSG_TOOL);
    m.u.tool.kind = TOOL_KIND_COUNT;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TOOL);
    m.u.tool.radius_m = 0.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TOOL);
    m.u.tool.max_force_n = -1.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TOOL);
    m.u.tool.model_scale = 0.0f;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TOOL);
    m.u.tool.model_offset_m[2] = -INFINITY;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_TOOL);
    m.u.tool.axis[1] = NAN;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
}

/* ---- TOOL rules ---- */

/* The float of t at frame offset at of a TOOL frame (docs/protocol.md: payload offset + 12). */
static float *tool_float(msg_tool_t *t, size_t at)
{
    switch (at) {
    case 16: return &t->radius_m;
    case 20: return &t->length_m;
    case 24: return &t->axis[0];
    case 28: return &t->axis[1];
    case 32: return &t->axis[2];
    case 36: return &t->alpha;
    case 40: return &t->contact_stiffness_n_per_m;
    case 44: return &t->max_force_n;
    case 48: return &t->iso;
    case 52: return &t->yield_force_n;
    case 56: return &t->friction;
    case 60: return &t->probe_gain;
    case 64: return &t->rope_stiffness_n_per_m;
    case 68: return &t->model_scale;
    case 72: return &t->model_offset_m[0];
    case 76: return &t->model_offset_m[1];
    case 80: return &t->model_offset_m[2];
    default: fail_msg("no tool float at %zu", at);
    }
    return NULL;
}

/* Verdicts of the decoder on the golden TOOL frame with the float at `at` set to v, and of
 * the encoder on the golden tool with the same field set; asserts both are want. */
static void check_tool_float(size_t at, float v, proto_err_t want)
{
    assert_int_equal(decode_patched_f32(golden_tool, sizeof golden_tool, at, v), want);
    proto_msg_t m = golden_msg(MSG_TOOL);
    *tool_float(&m.u.tool, at) = v;
    assert_int_equal(encode_err(&m), want);
}

/* The same for the byte at `at` (kind 12, shape 13, filter 14, flags 15). */
static void check_tool_byte(size_t at, uint8_t v, proto_err_t want)
{
    assert_int_equal(decode_patched_u8(golden_tool, sizeof golden_tool, at, v), want);
    proto_msg_t m = golden_msg(MSG_TOOL);
    uint8_t *field[4] = { &m.u.tool.kind, &m.u.tool.shape, &m.u.tool.filter, &m.u.tool.flags };
    *field[at - 12u] = v;
    assert_int_equal(encode_err(&m), want);
}

/* The same for the whole axis. */
static void check_tool_axis(float x, float y, float z, proto_err_t want)
{
    uint8_t f[sizeof golden_tool];
    memcpy(f, golden_tool, sizeof f);
    put_f32(f + 24, x);
    put_f32(f + 28, y);
    put_f32(f + 32, z);
    reseal(f, (uint16_t)(sizeof f - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    assert_int_equal(decode_err(f, sizeof f), want);
    proto_msg_t m = golden_msg(MSG_TOOL);
    m.u.tool.axis[0] = x;
    m.u.tool.axis[1] = y;
    m.u.tool.axis[2] = z;
    assert_int_equal(encode_err(&m), want);
}

static void test_every_tool_rule_is_enforced_by_decoder_and_encoder(void **state)
{
    (void)state;
    const proto_err_t V = PROTO_ERR_VALUE;
    /* enumerations: kind < 6, shape < 3, filter < 5; flags: only TOOL_FLAG_ISO */
    check_tool_byte(12, TOOL_KIND_COUNT, V);
    check_tool_byte(12, 0xFF, V);
    check_tool_byte(13, TOOL_SHAPE_COUNT, V);
    check_tool_byte(13, 0xFF, V);
    check_tool_byte(14, BETA_FILTER_COUNT, V);
    check_tool_byte(14, 0xFF, V);
    for (unsigned bit = 1; bit < 8; bit++) {
        check_tool_byte(15, (uint8_t)(1u << bit), V);
        check_tool_byte(15, (uint8_t)(TOOL_FLAG_ISO | (1u << bit)), V);
    }
    check_tool_byte(12, TOOL_ROPE, PROTO_OK);
    check_tool_byte(12, TOOL_PROBE, PROTO_OK);
    check_tool_byte(12, TOOL_TOUCH, PROTO_OK);
    check_tool_byte(13, TOOL_SHAPE_AREA, PROTO_OK);
    check_tool_byte(13, TOOL_SHAPE_POINT, PROTO_OK);
    check_tool_byte(14, BETA_CONICAL, PROTO_OK);
    check_tool_byte(14, BETA_CONSTANT, PROTO_OK);
    check_tool_byte(15, 0, PROTO_OK);

    /* > 0: radius, max force, model scale */
    const size_t positive[] = { 16, 44, 68 };
    for (size_t i = 0; i < 3; i++) {
        check_tool_float(positive[i], 0.0f, V);
        check_tool_float(positive[i], -0.0f, V);
        check_tool_float(positive[i], -2.0f, V);
        check_tool_float(positive[i], 1e-30f, PROTO_OK);
    }
    /* >= 0: length, alpha, contact stiffness, yield, friction, probe gain, rope stiffness */
    const size_t nonneg[] = { 20, 36, 40, 52, 56, 60, 64 };
    for (size_t i = 0; i < sizeof nonneg / sizeof nonneg[0]; i++) {
        check_tool_float(nonneg[i], -1e-6f, V);
        check_tool_float(nonneg[i], -1.0f, V);
        check_tool_float(nonneg[i], 0.0f, PROTO_OK);
        check_tool_float(nonneg[i], 3.4e38f, PROTO_OK);
    }
    /* iso in 0 … 1 */
    check_tool_float(48, -0.001f, V);
    check_tool_float(48, 1.001f, V);
    check_tool_float(48, 2.0f, V);
    check_tool_float(48, 0.0f, PROTO_OK);
    check_tool_float(48, 1.0f, PROTO_OK);
    /* the model offset may be anything finite */
    check_tool_float(76, -1000.0f, PROTO_OK);
    /* every float must be finite */
    for (size_t at = 16; at < 84; at += 4) {
        check_tool_float(at, NAN, V);
        check_tool_float(at, INFINITY, V);
        check_tool_float(at, -INFINITY, V);
    }
    /* the axis is a unit vector within 1e-3 */
    check_tool_axis(0.0f, 0.0f, 0.0f, V);
    check_tool_axis(0.0f, 0.0f, 1.0011f, V);
    check_tool_axis(0.0f, 0.0f, 0.9989f, V);
    check_tool_axis(1.0f, 1.0f, 0.0f, V);
    check_tool_axis(0.6f, 0.0f, 0.0f, V);
    check_tool_axis(3e38f, 3e38f, 0.0f, V); /* |a|^2 overflows */
    check_tool_axis(0.0f, 0.0f, 1.0009f, PROTO_OK);
    check_tool_axis(0.0f, 0.0f, 0.9991f, PROTO_OK);
    check_tool_axis(0.0f, -1.0f, 0.0f, PROTO_OK);
    check_tool_axis(0.577f, -0.577f, 0.5775f, PROTO_OK);
}

static void test_every_error_has_its_own_readable_name(void **state)
{
    (void)state;
    const proto_err_t all[] = { PROTO_OK,          PROTO_ERR_TRUNCATED, PROTO_ERR_OVERSIZE,
                                PROTO_ERR_MAGIC,   PROTO_ERR_CRC,       PROTO_ERR_VERSION,
                                PROTO_ERR_TYPE,    PROTO_ERR_PAYLOAD,   PROTO_ERR_VALUE,
                                PROTO_ERR_CHUNK,   PROTO_ERR_NOSPACE };
    const size_t n = sizeof all / sizeof all[0];
    for (size_t i = 0; i < n; i++) {
        const char *s = proto_strerror(all[i]);
        assert_non_null(s);
        assert_true(strlen(s) > 0);
        for (size_t j = 0; j < i; j++)
            assert_string_not_equal(s, proto_strerror(all[j]));
    }
    assert_string_equal(proto_strerror((proto_err_t)-99), "unknown error");
}

/* ---- WINDOW channels and per-node stiffness ---- */

static void test_window_channels_other_than_1_or_2_are_refused(void **state)
{
    (void)state;
    const uint8_t bad[] = { 0, 3, 0xFF };
    for (size_t i = 0; i < sizeof bad; i++) {
        /* decoder: the channels byte (frame offset 23) of both golden windows */
        assert_int_equal(decode_patched_u8(golden_window, sizeof golden_window, 23, bad[i]),
                         PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_u8(golden_window2, sizeof golden_window2, 23, bad[i]),
                         PROTO_ERR_VALUE);
        /* encoder, counting, cutting, assembling */
        proto_msg_t m = golden_msg(MSG_WINDOW);
        m.u.window.channels = bad[i];
        assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
        assert_int_equal(window_chunk_count(m.u.window.dims, bad[i]), 0);
        msg_window_t head = window_head(1, 4, 4, 4), c;
        head.channels = bad[i];
        fill_source(64);
        assert_int_equal(window_chunk_fill(&head, g_src, 0, &c), PROTO_ERR_VALUE);
        window_asm_t a;
        window_asm_init(&a, g_dst, ARRAY_MAX);
        m = golden_msg(MSG_WINDOW);
        m.u.window.channels = bad[i];
        assert_int_equal(window_asm_feed(&a, &m.u.window), PROTO_ERR_VALUE);
        assert_false(a.started);
    }
    assert_int_equal(decode_patched_u8(golden_window2, sizeof golden_window2, 23, 2), PROTO_OK);
}

/* Frame of chunk index of head (samples from g_src) with array element `element` set to v,
 * resealed; returns its decoder verdict. */
static proto_err_t decode_chunk_with(const msg_window_t *head, uint16_t index, uint32_t element,
                                     float v)
{
    proto_msg_t m;
    memset(&m, 0, sizeof m);
    m.type = MSG_WINDOW;
    assert_int_equal(window_chunk_fill(head, g_src, index, &m.u.window), PROTO_OK);
    uint8_t f[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, 1, f, sizeof f, &len), PROTO_OK);
    uint32_t k = element - m.u.window.first_sample;
    assert_true(k < m.u.window.sample_count);
    put_f32(f + PROTO_HEADER_SIZE + 58u + 4u * k, v);
    reseal(f, (uint16_t)(len - PROTO_HEADER_SIZE - PROTO_CRC_SIZE));
    return decode_err(f, len);
}

static void test_negative_or_non_finite_node_stiffness_is_refused(void **state)
{
    (void)state;
    const size_t W2 = sizeof golden_window2;
    /* golden 2x2x2 two-channel chunk: samples 0…7 densities (frame offset 70…98), 8…15
     * stiffnesses (102…130) */
    for (size_t k = 0; k < 8; k++) {
        size_t dens = 70u + 4u * k, stiff = 102u + 4u * k;
        assert_int_equal(decode_patched_f32(golden_window2, W2, stiff, -1.0f), PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_window2, W2, stiff, -1e-30f),
                         PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_window2, W2, stiff, NAN), PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_window2, W2, stiff, -INFINITY),
                         PROTO_ERR_VALUE);
        assert_int_equal(decode_patched_f32(golden_window2, W2, stiff, 0.0f), PROTO_OK);
        /* a density only needs to be finite */
        assert_int_equal(decode_patched_f32(golden_window2, W2, dens, -1.0f), PROTO_OK);
        assert_int_equal(decode_patched_f32(golden_window2, W2, dens, NAN), PROTO_ERR_VALUE);
    }
    /* a one-channel window has densities only: a negative sample is fine */
    assert_int_equal(decode_patched_f32(golden_window, sizeof golden_window, 74, -1.0f),
                     PROTO_OK);

    /* 10x10x3 two channels (N = 300, 600 samples): chunk 1 holds elements 224…447, the
     * densities up to 299 and the stiffnesses from 300 on */
    msg_window_t head = window_head(3, 10, 10, 3);
    head.channels = 2;
    fill_source(300);
    assert_int_equal(decode_chunk_with(&head, 1, 299, -1.0f), PROTO_OK);
    assert_int_equal(decode_chunk_with(&head, 1, 300, -1.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_chunk_with(&head, 1, 447, -1.0f), PROTO_ERR_VALUE);
    assert_int_equal(decode_chunk_with(&head, 1, 300, NAN), PROTO_ERR_VALUE);
    assert_int_equal(decode_chunk_with(&head, 0, 0, -1.0f), PROTO_OK);
    assert_int_equal(decode_chunk_with(&head, 2, 599, -0.5f), PROTO_ERR_VALUE);
    assert_int_equal(decode_chunk_with(&head, 2, 599, 0.0f), PROTO_OK);

    /* the encoder and the assembly refuse it too, and the assembly does not start */
    g_src[300] = -1.0f;
    proto_msg_t m;
    memset(&m, 0, sizeof m);
    m.type = MSG_WINDOW;
    assert_int_equal(window_chunk_fill(&head, g_src, 1, &m.u.window), PROTO_OK);
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARRAY_MAX);
    assert_int_equal(window_asm_feed(&a, &m.u.window), PROTO_ERR_VALUE);
    assert_false(a.started);
    g_src[300] = NAN;
    assert_int_equal(window_chunk_fill(&head, g_src, 1, &m.u.window), PROTO_OK);
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    g_src[300] = 0.0f;
    g_src[299] = -5.0f;
    assert_int_equal(window_chunk_fill(&head, g_src, 1, &m.u.window), PROTO_OK);
    assert_int_equal(encode_err(&m), PROTO_OK);
}

/* ---- window chunking and reassembly ---- */

static void test_chunk_count_follows_the_window_size(void **state)
{
    (void)state;
    const uint8_t full[3] = { 32, 32, 32 }, tiny[3] = { 2, 2, 2 }, gold[3] = { 15, 15, 2 };
    const uint8_t exact[3] = { 14, 16, 2 }, flat[3] = { 1, 32, 32 }, big[3] = { 33, 2, 2 };
    assert_int_equal(window_chunk_count(full, 1), 147);
    assert_int_equal(window_chunk_count(full, 2), 293); /* 65536 samples */
    assert_int_equal(window_chunk_count(full, 2), PROTO_WINDOW_CHUNKS_MAX);
    assert_int_equal(window_chunk_count(tiny, 1), 1);
    assert_int_equal(window_chunk_count(tiny, 2), 1);
    assert_int_equal(window_chunk_count(gold, 1), 3);
    assert_int_equal(window_chunk_count(gold, 2), 5); /* 900 samples */
    assert_int_equal(window_chunk_count(exact, 1), 2); /* 448 samples: two full chunks */
    assert_int_equal(window_chunk_count(exact, 2), 4);
    assert_int_equal(window_chunk_count(flat, 1), 0);
    assert_int_equal(window_chunk_count(big, 2), 0);

    msg_window_t head = window_head(1, 15, 15, 2), c;
    fill_source(450);
    assert_int_equal(window_chunk_fill(&head, g_src, 2, &c), PROTO_OK);
    assert_int_equal(c.first_sample, 448);
    assert_int_equal(c.sample_count, 2);
    assert_int_equal(c.chunk_count, 3);
    assert_int_equal(c.channels, 1);
    assert_f32s_equal(c.samples, g_src + 448, 2);
    assert_int_equal(window_chunk_fill(&head, g_src, 3, &c), PROTO_ERR_VALUE);
    /* two channels: the array is 450 densities then 450 stiffnesses */
    head.channels = 2;
    assert_int_equal(window_chunk_fill(&head, g_src, 2, &c), PROTO_OK);
    assert_int_equal(c.sample_count, 224);
    assert_int_equal(c.chunk_count, 5);
    assert_int_equal(c.channels, 2);
    assert_f32s_equal(c.samples, g_src + 448, 224); /* 2 densities, then 222 stiffnesses */
    assert_int_equal(window_chunk_fill(&head, g_src, 4, &c), PROTO_OK);
    assert_int_equal(c.first_sample, 896);
    assert_int_equal(c.sample_count, 4);
    assert_f32s_equal(c.samples, g_src + 896, 4);
    assert_int_equal(window_chunk_fill(&head, g_src, 5, &c), PROTO_ERR_VALUE);
    head.dims[0] = 0;
    assert_int_equal(window_chunk_fill(&head, g_src, 0, &c), PROTO_ERR_VALUE);
}

/* Sends a channels-channel 32^3 window as frames, each chunk once in a shuffled order (fixed
 * LCG) plus repeats, and asserts every frame fits in 1 KiB and the assembly is exact. */
static void check_full_window(uint8_t channels, uint16_t want_chunks)
{
    msg_window_t head = window_head(7, 32, 32, 32);
    head.channels = channels;
    fill_source(WINDOW_SAMPLES_32);
    const uint32_t total = channels * WINDOW_SAMPLES_32;
    uint16_t n = window_chunk_count(head.dims, head.channels);
    assert_int_equal(n, want_chunks);

    static msg_window_t chunks[PROTO_WINDOW_CHUNKS_MAX];
    for (uint16_t i = 0; i < n; i++) {
        chunks[i] = received_chunk(&head, i);
        assert_int_equal(chunks[i].chunk_index, i);
        assert_true(g_frame_len <= PROTO_FRAME_MAX);
        if (i + 1u < n)
            assert_int_equal(g_frame_len, 12u + 58u + 4u * 224u + 4u); /* 970 */
    }
    /* the last chunk holds what is left of the array */
    assert_int_equal(chunks[n - 1u].sample_count, total - (n - 1u) * 224u);

    uint16_t order[PROTO_WINDOW_CHUNKS_MAX];
    for (uint16_t i = 0; i < n; i++)
        order[i] = i;
    uint32_t seed = 12345u;
    for (uint16_t i = (uint16_t)(n - 1u); i > 0; i--) {
        seed = seed * 1664525u + 1013904223u;
        uint16_t j = (uint16_t)((seed >> 8) % (i + 1u));
        uint16_t t = order[i];
        order[i] = order[j];
        order[j] = t;
    }

    window_asm_t a;
    memset(g_dst, 0, sizeof g_dst);
    window_asm_init(&a, g_dst, ARRAY_MAX);
    assert_false(window_asm_complete(&a));
    for (uint16_t k = 0; k < n; k++) {
        assert_false(window_asm_complete(&a));
        assert_int_equal(window_asm_feed(&a, &chunks[order[k]]), PROTO_OK);
        if (k % 5u == 0u) {
            assert_int_equal(window_asm_feed(&a, &chunks[order[k]]), PROTO_OK);
            assert_int_equal(window_asm_feed(&a, &chunks[order[k / 2u]]), PROTO_OK);
        }
        assert_int_equal(a.received, k + 1u);
    }
    assert_true(window_asm_complete(&a));
    assert_int_equal(a.version, 7);
    assert_f32s_equal(g_dst, g_src, total);
    assert_memory_equal(a.head.dims, head.dims, 3);
    assert_int_equal(a.head.channels, channels);
    assert_int_equal(a.head.impulse_seq, head.impulse_seq);
    /* late duplicates keep it complete and unchanged */
    assert_int_equal(window_asm_feed(&a, &chunks[100]), PROTO_OK);
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(g_dst, g_src, total);
}

static void test_full_window_arrives_in_any_order_with_duplicates_and_is_exact(void **state)
{
    (void)state;
    check_full_window(1, 147);
}

static void test_full_two_channel_window_arrives_in_any_order_and_is_exact(void **state)
{
    (void)state;
    check_full_window(2, 293);
    /* node i's stiffness is array element N + i: chunk 146 holds both channels */
    assert_f32s_equal(g_dst + WINDOW_SAMPLES_32, g_src + WINDOW_SAMPLES_32, WINDOW_SAMPLES_32);
    assert_true(g_dst[WINDOW_SAMPLES_32] >= 50.0f && g_dst[2u * WINDOW_SAMPLES_32 - 1u] <= 250.0f);
}

static void test_window_is_complete_only_when_the_last_missing_chunk_arrives(void **state)
{
    (void)state;
    msg_window_t head = window_head(3, 20, 20, 20); /* 8000 samples, 36 chunks */
    fill_source(8000);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    feed_all_but(&a, &head, 17);
    assert_false(window_asm_complete(&a));
    msg_window_t c = received_chunk(&head, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK); /* a repeat does not fill the gap */
    assert_false(window_asm_complete(&a));
    c = received_chunk(&head, 17);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(g_dst, g_src, 8000);
}

/* Starts a window of 15x15x4 (900 samples, 5 chunks) with all chunks but the last, then
 * feeds sibling as that last chunk; asserts CHUNK, incomplete, and that the version stays
 * abandoned even when the genuine last chunk follows. */
static void check_sibling_refused(const msg_window_t *sibling_head)
{
    msg_window_t head = window_head(11, 15, 15, 4);
    fill_source(900);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    feed_all_but(&a, &head, 4);
    uint16_t idx =
        (uint16_t)(window_chunk_count(sibling_head->dims, sibling_head->channels) - 1u);
    msg_window_t odd = received_chunk(sibling_head, idx);
    assert_int_equal(window_asm_feed(&a, &odd), PROTO_ERR_CHUNK);
    assert_false(window_asm_complete(&a));
    msg_window_t last = received_chunk(&head, 4);
    assert_int_equal(window_asm_feed(&a, &last), PROTO_ERR_CHUNK);
    assert_false(window_asm_complete(&a));
    /* the next version assembles normally */
    msg_window_t next = window_head(12, 15, 15, 4);
    for (uint16_t i = 0; i < 5; i++) {
        msg_window_t c = received_chunk(&next, i);
        assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    }
    assert_true(window_asm_complete(&a));
}

static void test_sibling_chunk_describing_another_window_spoils_that_version(void **state)
{
    (void)state;
    msg_window_t s = window_head(11, 15, 15, 4);
    s.dims[2] = 5; /* other dims and so another chunk_count */
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.dims[0] = 20; /* same 5 chunks, other dims */
    s.dims[1] = 9;
    s.dims[2] = 5;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.origin_m[1] += 0.002f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.spacing_m = 0.0025f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.iso = 0.4f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.node_mass = 0.002f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.stiffness = 151.0f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.damping = 0.0f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.plastic_rate_hz = 0.0f;
    check_sibling_refused(&s);
    s = window_head(11, 15, 15, 4);
    s.impulse_seq = 100;
    check_sibling_refused(&s);
}

static void test_sibling_chunk_with_other_channels_spoils_that_version(void **state)
{
    (void)state;
    /* 15x15x4 with two channels: 1800 samples, 9 chunks instead of 5 */
    msg_window_t s = window_head(11, 15, 15, 4);
    s.channels = 2;
    check_sibling_refused(&s);
    /* 4x4x4 (64 nodes) is one chunk with either channel count: only channels differ */
    msg_window_t one = window_head(20, 4, 4, 4), two = window_head(20, 4, 4, 4);
    two.channels = 2;
    assert_int_equal(window_chunk_count(one.dims, 1), window_chunk_count(two.dims, 2));
    fill_source(64);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARRAY_MAX);
    msg_window_t c = received_chunk(&one, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_true(window_asm_complete(&a));
    c = received_chunk(&two, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_false(window_asm_complete(&a));
    assert_f32s_equal(g_dst, g_src, 64);
    /* and the other way round, at the next version */
    one.version = two.version = 21;
    c = received_chunk(&two, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_true(window_asm_complete(&a));
    assert_int_equal(a.head.channels, 2);
    c = received_chunk(&one, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_false(window_asm_complete(&a));
}

static void test_repeated_chunk_with_other_samples_spoils_that_version(void **state)
{
    (void)state;
    msg_window_t head = window_head(5, 10, 10, 10);
    fill_source(1000);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    feed_all_but(&a, &head, 4);
    msg_window_t c = received_chunk(&head, 2);
    c.samples[10] += 0.5f;
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    c = received_chunk(&head, 4);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_false(window_asm_complete(&a));
}

static void test_chunk_with_a_broken_chunk_number_is_refused_by_the_assembly(void **state)
{
    (void)state;
    msg_window_t head = window_head(5, 10, 10, 10);
    fill_source(1000);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    msg_window_t c = received_chunk(&head, 1);
    c.chunk_count = 4;
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    c = received_chunk(&head, 1);
    c.first_sample = 0;
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    c = received_chunk(&head, 1);
    c.spacing_m = NAN;
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_VALUE);
    assert_false(a.started);
}

static void test_newer_window_version_restarts_the_assembly(void **state)
{
    (void)state;
    msg_window_t v1 = window_head(1, 10, 10, 10);
    msg_window_t v2 = window_head(2, 12, 12, 12); /* the tool moved: other window */
    v2.origin_m[0] = 0.05f;
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    fill_source(1000);
    for (uint16_t i = 0; i < 3; i++) {
        msg_window_t c = received_chunk(&v1, i);
        assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    }
    fill_source(1728);
    msg_window_t c = received_chunk(&v2, 7);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_int_equal(a.version, 2);
    assert_int_equal(a.received, 1);
    assert_int_equal(a.chunk_count, 8);
    assert_false(window_asm_complete(&a));
    /* the rest of version 1 is now stale */
    fill_source(1000);
    c = received_chunk(&v1, 3);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    fill_source(1728);
    for (uint16_t i = 0; i < 7; i++) {
        c = received_chunk(&v2, i);
        assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    }
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(g_dst, g_src, 1728);
    assert_int_equal(a.head.dims[0], 12);
}

static void test_older_window_version_is_refused_and_changes_nothing(void **state)
{
    (void)state;
    msg_window_t v5 = window_head(5, 8, 8, 8); /* 512 samples, 3 chunks */
    msg_window_t v4 = window_head(4, 8, 8, 8);
    fill_source(512);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    msg_window_t c = received_chunk(&v5, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    c = received_chunk(&v4, 1);
    c.samples[0] = 123.0f;
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_int_equal(a.version, 5);
    assert_int_equal(a.received, 1);
    assert_true(g_dst[224] != 123.0f);
    for (uint16_t i = 1; i < 3; i++) {
        c = received_chunk(&v5, i);
        assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    }
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(g_dst, g_src, 512);
    /* a complete window refuses an older version too */
    c = received_chunk(&v4, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_true(window_asm_complete(&a));
}

static void test_window_version_counter_may_wrap_around(void **state)
{
    (void)state;
    msg_window_t last = window_head(0xFFFFFFFFu, 2, 2, 2);
    msg_window_t first = window_head(0u, 2, 2, 2);
    fill_source(8);
    window_asm_t a;
    window_asm_init(&a, g_dst, ARGIL_WINDOW_SAMPLES_MAX);
    msg_window_t c = received_chunk(&last, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_true(window_asm_complete(&a));
    c = received_chunk(&first, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    assert_int_equal(a.version, 0);
    c = received_chunk(&last, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
}

static void test_window_larger_than_the_storage_is_refused(void **state)
{
    (void)state;
    static float small[1000];
    msg_window_t big = window_head(1, 32, 32, 32);
    msg_window_t fits = window_head(2, 10, 10, 10); /* exactly 1000 samples */
    fill_source(WINDOW_SAMPLES_32);
    window_asm_t a;
    window_asm_init(&a, small, 1000);
    msg_window_t c = received_chunk(&big, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_false(a.started);
    assert_false(window_asm_complete(&a));
    for (uint16_t i = 0; i < 5; i++) {
        c = received_chunk(&fits, i);
        assert_int_equal(window_asm_feed(&a, &c), PROTO_OK);
    }
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(small, g_src, 1000);
    /* a newer but too large version leaves the finished one in place */
    big.version = 3;
    c = received_chunk(&big, 146);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_true(window_asm_complete(&a));
    assert_int_equal(a.version, 2);
    /* two channels need twice the storage: 10x10x5 fills it exactly, 10x10x10 does not fit */
    msg_window_t two = window_head(4, 10, 10, 10);
    two.channels = 2;
    fill_source(1000);
    c = received_chunk(&two, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
    assert_int_equal(a.version, 2);
    assert_true(window_asm_complete(&a));
    msg_window_t half = window_head(5, 10, 10, 5);
    half.channels = 2;
    fill_source(500);
    feed_all_but(&a, &half, 0xFFFF);
    assert_true(window_asm_complete(&a));
    assert_f32s_equal(small, g_src, 1000);
    /* no storage at all */
    window_asm_init(&a, NULL, 1000);
    c = received_chunk(&fits, 0);
    assert_int_equal(window_asm_feed(&a, &c), PROTO_ERR_CHUNK);
}

/* RT_STATS payload offsets (docs/protocol.md). */
#define RT_AT(off) (PROTO_HEADER_SIZE + (off))

static void test_rt_stats_fields_that_contradict_each_other_are_refused(void **state)
{
    (void)state;
    const uint8_t *g = golden_rt_stats;
    const size_t n = sizeof golden_rt_stats;
    /* period 0 */
    assert_int_equal(decode_patched_u32(g, n, RT_AT(12), 0u), PROTO_ERR_VALUE);
    /* wake: min > mean, mean > max; compute: the same */
    assert_int_equal(decode_patched_u32(g, n, RT_AT(16), 8501u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(20), 612001u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(28), 25601u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(32), 1250001u), PROTO_ERR_VALUE);
    /* the edges of each rule are accepted: min = mean = max */
    assert_int_equal(decode_patched_u32(g, n, RT_AT(16), 8500u), PROTO_OK);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(20), 612000u), PROTO_OK);
    /* more overruns than ticks; a worst streak longer than the overruns */
    assert_int_equal(decode_patched_u32(g, n, RT_AT(40), 3001u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(44), 4u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(44), 3u), PROTO_OK);
    /* a histogram that does not sum to the ticks: wake bin 0, compute bin 11, ticks */
    assert_int_equal(decode_patched_u32(g, n, RT_AT(48), 2101u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(48 + 4 * 23), 1u), PROTO_ERR_VALUE);
    assert_int_equal(decode_patched_u32(g, n, RT_AT(8), 2999u), PROTO_ERR_VALUE);
    /* counts whose sum wraps a u32 round to the ticks: still refused (the sum is 64-bit) */
    uint8_t f[sizeof golden_rt_stats];
    memcpy(f, g, n);
    put_u32(f + RT_AT(48), 2101u);
    put_u32(f + RT_AT(48 + 4 * 11), 0xFFFFFFFFu);
    reseal(f, 180u);
    assert_int_equal(decode_err(f, n), PROTO_ERR_VALUE);
    /* the wrong payload length for the type (168: a v2 report) */
    assert_int_equal(decode_resized(g, n, 168u), PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(g, n, 179u), PROTO_ERR_PAYLOAD);
    assert_int_equal(decode_resized(g, n, 181u), PROTO_ERR_PAYLOAD);
    /* the encoder refuses the same */
    proto_msg_t m = golden_msg(MSG_RT_STATS);
    m.u.rt_stats.compute_hist[0] = 1u;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    m = golden_msg(MSG_RT_STATS);
    m.u.rt_stats.period_ns = 0u;
    assert_int_equal(encode_err(&m), PROTO_ERR_VALUE);
    /* an empty record (no tick measured yet) is valid: all zeros but the period */
    memset(&m.u.rt_stats, 0, sizeof m.u.rt_stats);
    m.u.rt_stats.period_ns = 250000u;
    assert_int_equal(round_trip(&m), 12u + 180u + 4u);
}

static void test_decoded_chunk_assembles_the_same_without_repeated_checks(void **state)
{
    (void)state;
    proto_msg_t m;
    size_t used = 0;
    assert_int_equal(proto_decode(golden_window2, sizeof golden_window2, &m, &used), PROTO_OK);
    static float a_store[16], b_store[16];
    window_asm_t a, b;
    window_asm_init(&a, a_store, 16);
    window_asm_init(&b, b_store, 16);
    assert_int_equal(window_asm_feed(&a, &m.u.window), PROTO_OK);
    assert_int_equal(window_asm_feed_decoded(&b, &m.u.window), PROTO_OK);
    assert_true(window_asm_complete(&a) && window_asm_complete(&b));
    assert_memory_equal(a_store, b_store, sizeof a_store);
    assert_float_equal(b_store[15], 350.5f, 0.0f);
    /* the assembly's own rules still hold: an older version is refused, a larger window too */
    msg_window_t older = m.u.window;
    older.version = 8u;
    assert_int_equal(window_asm_feed_decoded(&b, &older), PROTO_ERR_CHUNK);
    window_asm_t c;
    window_asm_init(&c, b_store, 15);
    assert_int_equal(window_asm_feed_decoded(&c, &m.u.window), PROTO_ERR_CHUNK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32c_gives_the_castagnoli_check_value),
        cmocka_unit_test(test_golden_hello_frame_matches_the_spec),
        cmocka_unit_test(test_golden_heartbeat_frame_matches_the_spec),
        cmocka_unit_test(test_golden_telemetry_frame_matches_the_spec),
        cmocka_unit_test(test_golden_impulse_frame_with_two_entries_matches_the_spec),
        cmocka_unit_test(test_golden_window_last_chunk_frame_matches_the_spec),
        cmocka_unit_test(test_golden_two_channel_window_frame_matches_the_spec),
        cmocka_unit_test(test_golden_tool_frame_matches_the_spec),
        cmocka_unit_test(test_golden_fault_frame_matches_the_spec),
        cmocka_unit_test(test_golden_rt_stats_frame_matches_the_spec),
        cmocka_unit_test(test_decoded_chunk_assembles_the_same_without_repeated_checks),
        cmocka_unit_test(test_rt_stats_fields_that_contradict_each_other_are_refused),
        cmocka_unit_test(test_every_message_type_survives_a_round_trip_at_its_extremes),
        cmocka_unit_test(test_wrong_magic_is_refused_as_soon_as_four_bytes_arrive),
        cmocka_unit_test(test_frame_shorter_than_its_header_is_truncated),
        cmocka_unit_test(test_frame_cut_inside_payload_or_crc_is_truncated),
        cmocka_unit_test(test_declared_payload_above_1008_bytes_is_oversize_before_any_wait),
        cmocka_unit_test(test_any_flipped_bit_after_the_header_fields_fails_the_crc),
        cmocka_unit_test(test_other_protocol_versions_are_refused),
        cmocka_unit_test(test_unknown_message_types_are_refused),
        cmocka_unit_test(test_payload_length_that_does_not_fit_the_type_is_refused),
        cmocka_unit_test(test_non_finite_floats_are_refused_in_every_message),
        cmocka_unit_test(test_out_of_range_fields_are_refused),
        cmocka_unit_test(test_window_chunk_numbering_that_contradicts_itself_is_refused),
        cmocka_unit_test(test_encoder_reports_a_buffer_too_small_and_writes_nothing_past_it),
        cmocka_unit_test(test_encoder_refuses_what_the_decoder_would_refuse),
        cmocka_unit_test(test_every_tool_rule_is_enforced_by_decoder_and_encoder),
        cmocka_unit_test(test_window_channels_other_than_1_or_2_are_refused),
        cmocka_unit_test(test_negative_or_non_finite_node_stiffness_is_refused),
        cmocka_unit_test(test_every_error_has_its_own_readable_name),
        cmocka_unit_test(test_chunk_count_follows_the_window_size),
        cmocka_unit_test(test_full_window_arrives_in_any_order_with_duplicates_and_is_exact),
        cmocka_unit_test(test_full_two_channel_window_arrives_in_any_order_and_is_exact),
        cmocka_unit_test(test_window_is_complete_only_when_the_last_missing_chunk_arrives),
        cmocka_unit_test(test_sibling_chunk_describing_another_window_spoils_that_version),
        cmocka_unit_test(test_sibling_chunk_with_other_channels_spoils_that_version),
        cmocka_unit_test(test_repeated_chunk_with_other_samples_spoils_that_version),
        cmocka_unit_test(test_chunk_with_a_broken_chunk_number_is_refused_by_the_assembly),
        cmocka_unit_test(test_newer_window_version_restarts_the_assembly),
        cmocka_unit_test(test_older_window_version_is_refused_and_changes_nothing),
        cmocka_unit_test(test_window_version_counter_may_wrap_around),
        cmocka_unit_test(test_window_larger_than_the_storage_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
