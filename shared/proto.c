/* Wire protocol v2: frames between board and host, encoded field by field (docs/protocol.md),
 * and the reassembly of WINDOW chunks into one versioned local density window. */
#include "proto.h"

#include <math.h>
#include <string.h>

#include "crc32c.h"
#include "wire.h"

/* Payload sizes, bytes (docs/protocol.md lists every field with its offset). */
#define HELLO_SIZE 22u
#define HEARTBEAT_SIZE 17u
#define TELEMETRY_SIZE 64u
#define IMPULSE_HEAD_SIZE 10u
#define IMPULSE_ENTRY_SIZE 8u
#define WINDOW_HEAD_SIZE 58u
#define WINDOW_SAMPLE_SIZE 4u
#define TOOL_SIZE 72u
#define FAULT_SIZE 15u
#define RT_STATS_SIZE (48u + 8u * PROTO_RT_HIST_BINS + 36u)

_Static_assert(IMPULSE_HEAD_SIZE + IMPULSE_ENTRY_SIZE * PROTO_IMPULSE_MAX <= PROTO_PAYLOAD_MAX,
               "a full IMPULSE frame must fit in PROTO_FRAME_MAX");
_Static_assert(WINDOW_HEAD_SIZE + WINDOW_SAMPLE_SIZE * PROTO_WINDOW_CHUNK_SAMPLES <=
                   PROTO_PAYLOAD_MAX,
               "a full WINDOW chunk must fit in PROTO_FRAME_MAX");
_Static_assert(PROTO_PAYLOAD_MAX <= 0xFFFFu, "payload length is a u16 on the wire");
_Static_assert(PROTO_WINDOW_CHUNKS_MAX <= 32u * ((PROTO_WINDOW_CHUNKS_MAX + 31u) / 32u),
               "window_asm_t.got must hold one bit per chunk");
_Static_assert(PROTO_WINDOW_CHUNKS_MAX <= 0xFFFFu, "chunk_count is a u16 on the wire");

/* True when all n values are finite. */
static bool all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(v[i]))
            return false;
    }
    return true;
}

/* True when a and b have the same bit pattern (so -0 differs from +0, as on the wire). */
static bool same_bits(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Nodes in a window of these dims, or 0 when a dim is outside 2 … ARGIL_WINDOW_MAX. */
static uint32_t window_nodes(const uint8_t dims[3])
{
    uint32_t n = 1u;
    for (size_t i = 0; i < 3u; i++) {
        if (dims[i] < 2u || dims[i] > ARGIL_WINDOW_MAX)
            return 0u;
        n *= dims[i];
    }
    return n;
}

/* Samples in the whole array of a window (channels × nodes), or 0 when dims or channels are
 * out of range. */
static uint32_t window_samples(const uint8_t dims[3], uint8_t channels)
{
    if (channels < 1u || channels > PROTO_WINDOW_CHANNELS_MAX)
        return 0u;
    return window_nodes(dims) * channels;
}

/* Samples chunk index of a window with total samples holds (index must be in range). */
static uint16_t chunk_samples(uint32_t total, uint32_t index)
{
    uint32_t first = index * PROTO_WINDOW_CHUNK_SAMPLES;
    uint32_t left = total - first;
    return (uint16_t)(left < PROTO_WINDOW_CHUNK_SAMPLES ? left : PROTO_WINDOW_CHUNK_SAMPLES);
}

/* Number of chunks the channels × dims[0]*dims[1]*dims[2] samples of a window take; 0 for
 * dims or channels out of range. */
uint16_t window_chunk_count(const uint8_t dims[3], uint8_t channels)
{
    uint32_t total = window_samples(dims, channels);
    return (uint16_t)((total + PROTO_WINDOW_CHUNK_SAMPLES - 1u) / PROTO_WINDOW_CHUNK_SAMPLES);
}

/* PROTO_OK when the chunk's window fields are valid, otherwise VALUE (range) or CHUNK
 * (chunk numbering inconsistent with its own dims and channels). Reads samples only once
 * sample_count fits. */
static proto_err_t window_check(const msg_window_t *w)
{
    uint32_t nodes = window_nodes(w->dims);
    if (nodes == 0u || w->channels < 1u || w->channels > PROTO_WINDOW_CHANNELS_MAX)
        return PROTO_ERR_VALUE;
    uint32_t total = nodes * w->channels;
    if (!all_finite(w->origin_m, 3u) || !isfinite(w->spacing_m) || !(w->spacing_m > 0.0f) ||
        !isfinite(w->iso))
        return PROTO_ERR_VALUE;
    /* the material rules of spring_material_valid(): mass > 0, the others >= 0 */
    if (!isfinite(w->node_mass) || !(w->node_mass > 0.0f) || !isfinite(w->stiffness) ||
        !(w->stiffness >= 0.0f) || !isfinite(w->damping) || !(w->damping >= 0.0f) ||
        !isfinite(w->plastic_rate_hz) || !(w->plastic_rate_hz >= 0.0f))
        return PROTO_ERR_VALUE;
    if (w->chunk_count != window_chunk_count(w->dims, w->channels) ||
        w->chunk_index >= w->chunk_count)
        return PROTO_ERR_CHUNK;
    if (w->first_sample != (uint32_t)w->chunk_index * PROTO_WINDOW_CHUNK_SAMPLES ||
        w->sample_count != chunk_samples(total, w->chunk_index))
        return PROTO_ERR_CHUNK;
    if (!all_finite(w->samples, w->sample_count))
        return PROTO_ERR_VALUE;
    /* samples from index `nodes` of the array on are channel 2: spring stiffness, >= 0 */
    uint32_t k = nodes > w->first_sample ? nodes - w->first_sample : 0u;
    for (; k < w->sample_count; k++) {
        if (!(w->samples[k] >= 0.0f))
            return PROTO_ERR_VALUE;
    }
    return PROTO_OK;
}

/* True when the tool axis is unit length within 1e-3, compared squared (no square root):
 * (1 - 1e-3)^2 <= |a|^2 <= (1 + 1e-3)^2. A huge component squares to +Inf and fails. */
static bool unit_axis(const float a[3])
{
    float n2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    return n2 >= (1.0f - 1e-3f) * (1.0f - 1e-3f) && n2 <= (1.0f + 1e-3f) * (1.0f + 1e-3f);
}

/* True when v is finite and >= 0. */
static bool nonneg(float v)
{
    return isfinite(v) && v >= 0.0f;
}

/* True when v is finite and > 0. */
static bool positive(float v)
{
    return isfinite(v) && v > 0.0f;
}

/* PROTO_OK when every TOOL field is in range (docs/protocol.md, TOOL), otherwise VALUE. */
static proto_err_t tool_check(const msg_tool_t *t)
{
    if (t->kind >= TOOL_KIND_COUNT || t->shape >= TOOL_SHAPE_COUNT ||
        t->filter >= BETA_FILTER_COUNT || (t->flags & ~TOOL_FLAG_ISO) != 0u)
        return PROTO_ERR_VALUE;
    if (!positive(t->radius_m) || !nonneg(t->length_m) || !all_finite(t->axis, 3u) ||
        !unit_axis(t->axis))
        return PROTO_ERR_VALUE;
    if (!nonneg(t->alpha) || !nonneg(t->contact_stiffness_n_per_m) || !positive(t->max_force_n))
        return PROTO_ERR_VALUE;
    if (!isfinite(t->iso) || !(t->iso >= 0.0f && t->iso <= 1.0f))
        return PROTO_ERR_VALUE;
    if (!nonneg(t->yield_force_n) || !nonneg(t->friction) || !nonneg(t->probe_gain) ||
        !nonneg(t->rope_stiffness_n_per_m))
        return PROTO_ERR_VALUE;
    if (!positive(t->model_scale) || !all_finite(t->model_offset_m, 3u))
        return PROTO_ERR_VALUE;
    return PROTO_OK;
}

/* Sum of n histogram counts (u64: twelve u32 cannot overflow it). */
static uint64_t hist_sum(const uint32_t *h, size_t n)
{
    uint64_t sum = 0u;
    for (size_t i = 0; i < n; i++)
        sum += h[i];
    return sum;
}

/* PROTO_OK when the RT_STATS fields agree with each other (docs/protocol.md), else VALUE. */
static proto_err_t rt_stats_check(const msg_rt_stats_t *r)
{
    if (r->period_ns == 0u)
        return PROTO_ERR_VALUE;
    if (r->wake_min_ns > r->wake_mean_ns || r->wake_mean_ns > r->wake_max_ns)
        return PROTO_ERR_VALUE;
    if (r->compute_min_ns > r->compute_mean_ns || r->compute_mean_ns > r->compute_max_ns)
        return PROTO_ERR_VALUE;
    if (r->overruns > r->ticks || r->worst_streak > r->overruns)
        return PROTO_ERR_VALUE;
    if (hist_sum(r->wake_hist, PROTO_RT_HIST_BINS) != r->ticks ||
        hist_sum(r->compute_hist, PROTO_RT_HIST_BINS) != r->ticks)
        return PROTO_ERR_VALUE;
    return PROTO_OK;
}

/* PROTO_OK when msg may go on the wire; otherwise the error its decoding would give. */
static proto_err_t msg_check(const proto_msg_t *msg)
{
    switch (msg->type) {
    case MSG_HELLO: {
        const msg_hello_t *h = &msg->u.hello;
        if (h->role != PROTO_ROLE_BOARD && h->role != PROTO_ROLE_HOST)
            return PROTO_ERR_VALUE;
        return PROTO_OK;
    }
    case MSG_HEARTBEAT:
        return msg->u.heartbeat.command > PROTO_CMD_LAST ? PROTO_ERR_VALUE : PROTO_OK;
    case MSG_TELEMETRY: {
        const msg_telemetry_t *t = &msg->u.telemetry;
        if (t->tool_kind >= TOOL_KIND_COUNT || !all_finite(t->pos_m, 3u) ||
            !all_finite(t->vel_m_s, 3u) || !all_finite(t->force_n, 3u))
            return PROTO_ERR_VALUE;
        return PROTO_OK;
    }
    case MSG_IMPULSE: {
        const msg_impulse_t *im = &msg->u.impulse;
        if (im->count > PROTO_IMPULSE_MAX)
            return PROTO_ERR_VALUE;
        for (uint32_t i = 0; i < im->count; i++) {
            if (im->entries[i].node >= ARGIL_WINDOW_SAMPLES_MAX ||
                !isfinite(im->entries[i].impulse_ns))
                return PROTO_ERR_VALUE;
        }
        return PROTO_OK;
    }
    case MSG_WINDOW:
        return window_check(&msg->u.window);
    case MSG_TOOL:
        return tool_check(&msg->u.tool);
    case MSG_FAULT:
        return PROTO_OK;
    case MSG_RT_STATS:
        return rt_stats_check(&msg->u.rt_stats);
    default:
        return PROTO_ERR_TYPE;
    }
}

/* Payload bytes of a message that passed msg_check. */
static size_t payload_size(const proto_msg_t *msg)
{
    switch (msg->type) {
    case MSG_HELLO:
        return HELLO_SIZE;
    case MSG_HEARTBEAT:
        return HEARTBEAT_SIZE;
    case MSG_TELEMETRY:
        return TELEMETRY_SIZE;
    case MSG_IMPULSE:
        return IMPULSE_HEAD_SIZE + IMPULSE_ENTRY_SIZE * (size_t)msg->u.impulse.count;
    case MSG_WINDOW:
        return WINDOW_HEAD_SIZE + WINDOW_SAMPLE_SIZE * (size_t)msg->u.window.sample_count;
    case MSG_TOOL:
        return TOOL_SIZE;
    case MSG_FAULT:
        return FAULT_SIZE;
    case MSG_RT_STATS:
        return RT_STATS_SIZE;
    default:
        return 0u;
    }
}

/* Writes n floats. */
static void put_f32s(wire_writer_t *w, const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        wire_put_f32(w, v[i]);
}

/* Reads n floats. */
static void get_f32s(wire_reader_t *r, float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        v[i] = wire_get_f32(r);
}

/* Reads n floats with one bounds check for all of them (a WINDOW chunk's samples: the
 * per-value checks of get_f32s cost the 1 kHz tick ~9,000 instructions per chunk). */
static void get_f32s_span(wire_reader_t *r, float *v, size_t n)
{
    const uint8_t *p = wire_get_span(r, 4u * n);
    if (p == NULL) {
        memset(v, 0, n * sizeof *v);
        return;
    }
    for (size_t i = 0; i < n; i++, p += 4) {
        const uint32_t bits = le_get_u32(p);
        memcpy(&v[i], &bits, sizeof bits);
    }
}

/* Writes the payload of a checked message, field by field in docs/protocol.md order. */
static void put_payload(wire_writer_t *w, const proto_msg_t *msg)
{
    switch (msg->type) {
    case MSG_HELLO: {
        const msg_hello_t *h = &msg->u.hello;
        wire_put_u8(w, h->role);
        wire_put_u8(w, h->drives);
        wire_put_u16(w, h->window_max);
        wire_put_u16(w, h->tick_hz);
        wire_put_bytes(w, h->name, PROTO_NAME_LEN);
        break;
    }
    case MSG_HEARTBEAT: {
        const msg_heartbeat_t *h = &msg->u.heartbeat;
        wire_put_u64(w, h->time_us);
        wire_put_u32(w, h->window_version);
        wire_put_u32(w, h->impulse_seq);
        wire_put_u8(w, h->command);
        break;
    }
    case MSG_TELEMETRY: {
        const msg_telemetry_t *t = &msg->u.telemetry;
        wire_put_u64(w, t->time_us);
        wire_put_u32(w, t->tick);
        wire_put_u8(w, t->state);
        wire_put_u8(w, t->tool_kind);
        wire_put_u8(w, t->buttons);
        wire_put_u8(w, t->flags);
        put_f32s(w, t->pos_m, 3u);
        put_f32s(w, t->vel_m_s, 3u);
        put_f32s(w, t->force_n, 3u);
        wire_put_u32(w, t->window_version);
        wire_put_u32(w, t->compute_ns);
        wire_put_u32(w, t->deadline_misses);
        break;
    }
    case MSG_IMPULSE: {
        const msg_impulse_t *im = &msg->u.impulse;
        wire_put_u32(w, im->window_version);
        wire_put_u32(w, im->impulse_seq);
        wire_put_u16(w, im->count);
        for (uint32_t i = 0; i < im->count && i < PROTO_IMPULSE_MAX; i++) {
            wire_put_u32(w, im->entries[i].node);
            wire_put_f32(w, im->entries[i].impulse_ns);
        }
        break;
    }
    case MSG_WINDOW: {
        const msg_window_t *c = &msg->u.window;
        wire_put_u32(w, c->version);
        wire_put_u16(w, c->chunk_index);
        wire_put_u16(w, c->chunk_count);
        wire_put_bytes(w, c->dims, 3u);
        wire_put_u8(w, c->channels);
        put_f32s(w, c->origin_m, 3u);
        wire_put_f32(w, c->spacing_m);
        wire_put_f32(w, c->iso);
        wire_put_f32(w, c->node_mass);
        wire_put_f32(w, c->stiffness);
        wire_put_f32(w, c->damping);
        wire_put_f32(w, c->plastic_rate_hz);
        wire_put_u32(w, c->impulse_seq);
        wire_put_u32(w, c->first_sample);
        wire_put_u16(w, c->sample_count);
        put_f32s(w, c->samples,
                 c->sample_count < PROTO_WINDOW_CHUNK_SAMPLES ? c->sample_count
                                                              : PROTO_WINDOW_CHUNK_SAMPLES);
        break;
    }
    case MSG_TOOL: {
        const msg_tool_t *t = &msg->u.tool;
        wire_put_u8(w, t->kind);
        wire_put_u8(w, t->shape);
        wire_put_u8(w, t->filter);
        wire_put_u8(w, t->flags);
        wire_put_f32(w, t->radius_m);
        wire_put_f32(w, t->length_m);
        put_f32s(w, t->axis, 3u);
        wire_put_f32(w, t->alpha);
        wire_put_f32(w, t->contact_stiffness_n_per_m);
        wire_put_f32(w, t->max_force_n);
        wire_put_f32(w, t->iso);
        wire_put_f32(w, t->yield_force_n);
        wire_put_f32(w, t->friction);
        wire_put_f32(w, t->probe_gain);
        wire_put_f32(w, t->rope_stiffness_n_per_m);
        wire_put_f32(w, t->model_scale);
        put_f32s(w, t->model_offset_m, 3u);
        break;
    }
    case MSG_FAULT: {
        const msg_fault_t *f = &msg->u.fault;
        wire_put_u64(w, f->time_us);
        wire_put_u16(w, f->code);
        wire_put_u8(w, f->state);
        wire_put_u32(w, f->detail);
        break;
    }
    case MSG_RT_STATS: {
        const msg_rt_stats_t *r = &msg->u.rt_stats;
        wire_put_u64(w, r->time_us);
        wire_put_u32(w, r->ticks);
        wire_put_u32(w, r->period_ns);
        wire_put_u32(w, r->wake_min_ns);
        wire_put_u32(w, r->wake_mean_ns);
        wire_put_u32(w, r->wake_max_ns);
        wire_put_u32(w, r->compute_min_ns);
        wire_put_u32(w, r->compute_mean_ns);
        wire_put_u32(w, r->compute_max_ns);
        wire_put_u32(w, r->overruns);
        wire_put_u32(w, r->worst_streak);
        for (size_t i = 0; i < PROTO_RT_HIST_BINS; i++)
            wire_put_u32(w, r->wake_hist[i]);
        for (size_t i = 0; i < PROTO_RT_HIST_BINS; i++)
            wire_put_u32(w, r->compute_hist[i]);
        wire_put_u32(w, r->link.decode_errors);
        wire_put_u32(w, r->link.wrong_source);
        wire_put_u32(w, r->link.no_session);
        wire_put_u32(w, r->link.duplicate);
        wire_put_u32(w, r->link.stale);
        wire_put_u32(w, r->link.sessions);
        wire_put_u32(w, r->link.bad_mac);
        wire_put_u32(w, r->link.bad_nonce);
        wire_put_u32(w, r->link.arm_refused);
        break;
    }
    default:
        break;
    }
}

/* Encodes msg as one frame with sequence seq into buf; *len gets the frame size. */
proto_err_t proto_encode(const proto_msg_t *msg, uint32_t seq, uint8_t *buf, size_t cap,
                         size_t *len)
{
    proto_err_t err = msg_check(msg);
    if (err != PROTO_OK)
        return err;
    size_t plen = payload_size(msg);
    size_t flen = PROTO_HEADER_SIZE + plen + PROTO_CRC_SIZE;
    if (cap < flen)
        return PROTO_ERR_NOSPACE;

    wire_writer_t w = wire_writer(buf, flen);
    wire_put_u32(&w, PROTO_MAGIC);
    wire_put_u8(&w, (uint8_t)PROTO_VERSION);
    wire_put_u8(&w, msg->type);
    wire_put_u16(&w, (uint16_t)plen);
    wire_put_u32(&w, seq);
    put_payload(&w, msg);
    if (!w.ok || w.pos != PROTO_HEADER_SIZE + plen)
        return PROTO_ERR_VALUE; /* unreachable: payload_size and put_payload agree */
    wire_put_u32(&w, crc32c(0u, buf, w.pos));
    *len = flen;
    return PROTO_OK;
}

/* Reads a fixed-size payload of the given type; PAYLOAD when plen is not its size. */
static proto_err_t get_fixed(wire_reader_t *r, size_t plen, proto_msg_t *msg)
{
    switch (msg->type) {
    case MSG_HELLO: {
        msg_hello_t *h = &msg->u.hello;
        if (plen != HELLO_SIZE)
            return PROTO_ERR_PAYLOAD;
        h->role = wire_get_u8(r);
        h->drives = wire_get_u8(r);
        h->window_max = wire_get_u16(r);
        h->tick_hz = wire_get_u16(r);
        wire_get_bytes(r, h->name, PROTO_NAME_LEN);
        return PROTO_OK;
    }
    case MSG_HEARTBEAT: {
        msg_heartbeat_t *h = &msg->u.heartbeat;
        if (plen != HEARTBEAT_SIZE)
            return PROTO_ERR_PAYLOAD;
        h->time_us = wire_get_u64(r);
        h->window_version = wire_get_u32(r);
        h->impulse_seq = wire_get_u32(r);
        h->command = wire_get_u8(r);
        return PROTO_OK;
    }
    case MSG_TELEMETRY: {
        msg_telemetry_t *t = &msg->u.telemetry;
        if (plen != TELEMETRY_SIZE)
            return PROTO_ERR_PAYLOAD;
        t->time_us = wire_get_u64(r);
        t->tick = wire_get_u32(r);
        t->state = wire_get_u8(r);
        t->tool_kind = wire_get_u8(r);
        t->buttons = wire_get_u8(r);
        t->flags = wire_get_u8(r);
        get_f32s(r, t->pos_m, 3u);
        get_f32s(r, t->vel_m_s, 3u);
        get_f32s(r, t->force_n, 3u);
        t->window_version = wire_get_u32(r);
        t->compute_ns = wire_get_u32(r);
        t->deadline_misses = wire_get_u32(r);
        return PROTO_OK;
    }
    case MSG_TOOL: {
        msg_tool_t *t = &msg->u.tool;
        if (plen != TOOL_SIZE)
            return PROTO_ERR_PAYLOAD;
        t->kind = wire_get_u8(r);
        t->shape = wire_get_u8(r);
        t->filter = wire_get_u8(r);
        t->flags = wire_get_u8(r);
        t->radius_m = wire_get_f32(r);
        t->length_m = wire_get_f32(r);
        get_f32s(r, t->axis, 3u);
        t->alpha = wire_get_f32(r);
        t->contact_stiffness_n_per_m = wire_get_f32(r);
        t->max_force_n = wire_get_f32(r);
        t->iso = wire_get_f32(r);
        t->yield_force_n = wire_get_f32(r);
        t->friction = wire_get_f32(r);
        t->probe_gain = wire_get_f32(r);
        t->rope_stiffness_n_per_m = wire_get_f32(r);
        t->model_scale = wire_get_f32(r);
        get_f32s(r, t->model_offset_m, 3u);
        return PROTO_OK;
    }
    case MSG_FAULT: {
        msg_fault_t *f = &msg->u.fault;
        if (plen != FAULT_SIZE)
            return PROTO_ERR_PAYLOAD;
        f->time_us = wire_get_u64(r);
        f->code = wire_get_u16(r);
        f->state = wire_get_u8(r);
        f->detail = wire_get_u32(r);
        return PROTO_OK;
    }
    case MSG_RT_STATS: {
        msg_rt_stats_t *s = &msg->u.rt_stats;
        if (plen != RT_STATS_SIZE)
            return PROTO_ERR_PAYLOAD;
        s->time_us = wire_get_u64(r);
        s->ticks = wire_get_u32(r);
        s->period_ns = wire_get_u32(r);
        s->wake_min_ns = wire_get_u32(r);
        s->wake_mean_ns = wire_get_u32(r);
        s->wake_max_ns = wire_get_u32(r);
        s->compute_min_ns = wire_get_u32(r);
        s->compute_mean_ns = wire_get_u32(r);
        s->compute_max_ns = wire_get_u32(r);
        s->overruns = wire_get_u32(r);
        s->worst_streak = wire_get_u32(r);
        for (size_t i = 0; i < PROTO_RT_HIST_BINS; i++)
            s->wake_hist[i] = wire_get_u32(r);
        for (size_t i = 0; i < PROTO_RT_HIST_BINS; i++)
            s->compute_hist[i] = wire_get_u32(r);
        s->link.decode_errors = wire_get_u32(r);
        s->link.wrong_source = wire_get_u32(r);
        s->link.no_session = wire_get_u32(r);
        s->link.duplicate = wire_get_u32(r);
        s->link.stale = wire_get_u32(r);
        s->link.sessions = wire_get_u32(r);
        s->link.bad_mac = wire_get_u32(r);
        s->link.bad_nonce = wire_get_u32(r);
        s->link.arm_refused = wire_get_u32(r);
        return PROTO_OK;
    }
    default:
        return PROTO_ERR_TYPE;
    }
}

/* Reads an IMPULSE payload: a count above PROTO_IMPULSE_MAX is VALUE, a length that does not
 * match the count is PAYLOAD. */
static proto_err_t get_impulse(wire_reader_t *r, size_t plen, msg_impulse_t *im)
{
    if (plen < IMPULSE_HEAD_SIZE)
        return PROTO_ERR_PAYLOAD;
    im->window_version = wire_get_u32(r);
    im->impulse_seq = wire_get_u32(r);
    im->count = wire_get_u16(r);
    if (im->count > PROTO_IMPULSE_MAX)
        return PROTO_ERR_VALUE;
    if (plen != IMPULSE_HEAD_SIZE + IMPULSE_ENTRY_SIZE * (size_t)im->count)
        return PROTO_ERR_PAYLOAD;
    for (uint32_t i = 0; i < im->count; i++) {
        im->entries[i].node = wire_get_u32(r);
        im->entries[i].impulse_ns = wire_get_f32(r);
    }
    return PROTO_OK;
}

/* Reads a WINDOW payload; samples are read only when sample_count fits the chunk array
 * (window_check then reports a larger count as CHUNK). */
static proto_err_t get_window(wire_reader_t *r, size_t plen, msg_window_t *c)
{
    if (plen < WINDOW_HEAD_SIZE)
        return PROTO_ERR_PAYLOAD;
    c->version = wire_get_u32(r);
    c->chunk_index = wire_get_u16(r);
    c->chunk_count = wire_get_u16(r);
    wire_get_bytes(r, c->dims, 3u);
    c->channels = wire_get_u8(r);
    get_f32s(r, c->origin_m, 3u);
    c->spacing_m = wire_get_f32(r);
    c->iso = wire_get_f32(r);
    c->node_mass = wire_get_f32(r);
    c->stiffness = wire_get_f32(r);
    c->damping = wire_get_f32(r);
    c->plastic_rate_hz = wire_get_f32(r);
    c->impulse_seq = wire_get_u32(r);
    c->first_sample = wire_get_u32(r);
    c->sample_count = wire_get_u16(r);
    if (plen != WINDOW_HEAD_SIZE + WINDOW_SAMPLE_SIZE * (size_t)c->sample_count)
        return PROTO_ERR_PAYLOAD;
    if (c->sample_count <= PROTO_WINDOW_CHUNK_SAMPLES)
        get_f32s_span(r, c->samples, c->sample_count);
    else
        r->pos = r->len; /* skipped: too many samples for a chunk */
    return PROTO_OK;
}

/* Decodes the frame at the start of buf[0..len); on PROTO_OK *frame_len is its size. */
proto_err_t proto_decode(const uint8_t *buf, size_t len, proto_msg_t *msg, size_t *frame_len)
{
    wire_reader_t h = wire_reader(buf, len);
    if (len >= 4u && wire_get_u32(&h) != PROTO_MAGIC)
        return PROTO_ERR_MAGIC;
    if (len < PROTO_HEADER_SIZE)
        return PROTO_ERR_TRUNCATED;
    h = wire_reader(buf, PROTO_HEADER_SIZE);
    (void)wire_get_u32(&h);
    uint8_t version = wire_get_u8(&h);
    uint8_t type = wire_get_u8(&h);
    uint16_t plen = wire_get_u16(&h);
    uint32_t seq = wire_get_u32(&h);
    if (version != PROTO_VERSION)
        return PROTO_ERR_VERSION;
    if (type < MSG_HELLO || type > MSG_TYPE_LAST)
        return PROTO_ERR_TYPE;
    if (plen > PROTO_PAYLOAD_MAX)
        return PROTO_ERR_OVERSIZE;
    size_t body = PROTO_HEADER_SIZE + (size_t)plen;
    if (len < body + PROTO_CRC_SIZE)
        return PROTO_ERR_TRUNCATED;
    wire_reader_t c = wire_reader(buf + body, PROTO_CRC_SIZE);
    if (wire_get_u32(&c) != crc32c(0u, buf, body))
        return PROTO_ERR_CRC;

    memset(msg, 0, sizeof *msg);
    msg->type = type;
    msg->seq = seq;
    wire_reader_t r = wire_reader(buf + PROTO_HEADER_SIZE, plen);
    proto_err_t err;
    if (type == MSG_IMPULSE)
        err = get_impulse(&r, plen, &msg->u.impulse);
    else if (type == MSG_WINDOW)
        err = get_window(&r, plen, &msg->u.window);
    else
        err = get_fixed(&r, plen, msg);
    if (err != PROTO_OK)
        return err;
    if (!r.ok || r.pos != plen)
        return PROTO_ERR_PAYLOAD; /* unreachable: every layout above checks plen first */
    err = msg_check(msg);
    if (err != PROTO_OK)
        return err;
    *frame_len = body + PROTO_CRC_SIZE;
    return PROTO_OK;
}

/* A short English name of err, for logs. */
const char *proto_strerror(proto_err_t err)
{
    switch (err) {
    case PROTO_OK:
        return "ok";
    case PROTO_ERR_TRUNCATED:
        return "truncated frame";
    case PROTO_ERR_OVERSIZE:
        return "payload length above maximum";
    case PROTO_ERR_MAGIC:
        return "bad magic";
    case PROTO_ERR_CRC:
        return "CRC mismatch";
    case PROTO_ERR_VERSION:
        return "unsupported protocol version";
    case PROTO_ERR_TYPE:
        return "unknown message type";
    case PROTO_ERR_PAYLOAD:
        return "payload length does not match its type";
    case PROTO_ERR_VALUE:
        return "field value out of range";
    case PROTO_ERR_CHUNK:
        return "inconsistent window chunk";
    case PROTO_ERR_NOSPACE:
        return "output buffer too small";
    default:
        return "unknown error";
    }
}

/* Fills chunk number index of the window described by head from samples[], the whole array
 * (densities x fastest, then stiffnesses when head->channels = 2). */
proto_err_t window_chunk_fill(const msg_window_t *head, const float *samples, uint16_t index,
                              msg_window_t *chunk)
{
    uint32_t total = window_samples(head->dims, head->channels);
    uint16_t count = window_chunk_count(head->dims, head->channels);
    if (index >= count)
        return PROTO_ERR_VALUE;
    memset(chunk, 0, sizeof *chunk);
    chunk->version = head->version;
    chunk->chunk_index = index;
    chunk->chunk_count = count;
    memcpy(chunk->dims, head->dims, sizeof chunk->dims);
    chunk->channels = head->channels;
    memcpy(chunk->origin_m, head->origin_m, sizeof chunk->origin_m);
    chunk->spacing_m = head->spacing_m;
    chunk->iso = head->iso;
    chunk->node_mass = head->node_mass;
    chunk->stiffness = head->stiffness;
    chunk->damping = head->damping;
    chunk->plastic_rate_hz = head->plastic_rate_hz;
    chunk->impulse_seq = head->impulse_seq;
    chunk->first_sample = (uint32_t)index * PROTO_WINDOW_CHUNK_SAMPLES;
    chunk->sample_count = chunk_samples(total, index);
    memcpy(chunk->samples, samples + chunk->first_sample,
           (size_t)chunk->sample_count * sizeof chunk->samples[0]);
    return PROTO_OK;
}

/* Empties the assembly and gives it storage for capacity samples. */
void window_asm_init(window_asm_t *a, float *storage, uint32_t capacity)
{
    memset(a, 0, sizeof *a);
    a->samples = storage;
    a->capacity = storage != NULL ? capacity : 0u;
}

/* True when version v is newer than cur in serial-number order (RFC 1982), so the
 * version counter may wrap. */
static bool version_newer(uint32_t v, uint32_t cur)
{
    uint32_t d = v - cur;
    return d != 0u && d < 0x80000000u;
}

/* True when chunk describes the same window as the assembly's first chunk, bit for bit. */
static bool same_window(const window_asm_t *a, const msg_window_t *c)
{
    const msg_window_t *h = &a->head;
    return c->chunk_count == a->chunk_count && memcmp(c->dims, h->dims, sizeof h->dims) == 0 &&
           c->channels == h->channels &&
           same_bits(c->origin_m[0], h->origin_m[0]) &&
           same_bits(c->origin_m[1], h->origin_m[1]) &&
           same_bits(c->origin_m[2], h->origin_m[2]) && same_bits(c->spacing_m, h->spacing_m) &&
           same_bits(c->iso, h->iso) && same_bits(c->node_mass, h->node_mass) &&
           same_bits(c->stiffness, h->stiffness) && same_bits(c->damping, h->damping) &&
           same_bits(c->plastic_rate_hz, h->plastic_rate_hz) &&
           c->impulse_seq == h->impulse_seq;
}

/* Starts assembling the version of chunk c, forgetting any other. */
static void asm_restart(window_asm_t *a, const msg_window_t *c)
{
    a->started = true;
    a->version = c->version;
    a->chunk_count = c->chunk_count;
    a->received = 0u;
    memset(a->got, 0, sizeof a->got);
    memset(&a->head, 0, sizeof a->head);
    a->head.version = c->version;
    a->head.chunk_count = c->chunk_count;
    memcpy(a->head.dims, c->dims, sizeof a->head.dims);
    a->head.channels = c->channels;
    memcpy(a->head.origin_m, c->origin_m, sizeof a->head.origin_m);
    a->head.spacing_m = c->spacing_m;
    a->head.iso = c->iso;
    a->head.node_mass = c->node_mass;
    a->head.stiffness = c->stiffness;
    a->head.damping = c->damping;
    a->head.plastic_rate_hz = c->plastic_rate_hz;
    a->head.impulse_seq = c->impulse_seq;
}

/* Gives up the current version: its chunks disagreed, so it never completes; chunk_count 0
 * while started marks it, and only a newer version starts again. */
static void asm_abandon(window_asm_t *a)
{
    a->chunk_count = 0u;
    a->received = 0u;
    memset(a->got, 0, sizeof a->got);
}

/* Adds one chunk that passed window_check. */
static proto_err_t asm_feed_checked(window_asm_t *a, const msg_window_t *chunk)
{
    if (window_samples(chunk->dims, chunk->channels) > a->capacity)
        return PROTO_ERR_CHUNK;

    if (!a->started || version_newer(chunk->version, a->version)) {
        asm_restart(a, chunk);
    } else if (chunk->version != a->version || a->chunk_count == 0u) {
        return PROTO_ERR_CHUNK; /* older, or a version already abandoned */
    } else if (!same_window(a, chunk)) {
        asm_abandon(a);
        return PROTO_ERR_CHUNK;
    }

    uint32_t word = chunk->chunk_index / 32u;
    uint32_t bit = 1u << (chunk->chunk_index % 32u);
    float *dst = a->samples + chunk->first_sample;
    size_t bytes = (size_t)chunk->sample_count * sizeof *dst;
    if ((a->got[word] & bit) != 0u) {
        /* a duplicate must repeat its first copy exactly */
        if (memcmp(dst, chunk->samples, bytes) != 0) {
            asm_abandon(a);
            return PROTO_ERR_CHUNK;
        }
        return PROTO_OK;
    }
    memcpy(dst, chunk->samples, bytes);
    a->got[word] |= bit;
    a->received++;
    return PROTO_OK;
}

/* Adds one decoded chunk; a newer version restarts assembly, an older one is refused. */
proto_err_t window_asm_feed(window_asm_t *a, const msg_window_t *chunk)
{
    const proto_err_t err = window_check(chunk);
    if (err != PROTO_OK)
        return err;
    return asm_feed_checked(a, chunk);
}

/* window_asm_feed for a chunk proto_decode accepted (its checks are not repeated). */
proto_err_t window_asm_feed_decoded(window_asm_t *a, const msg_window_t *chunk)
{
    return asm_feed_checked(a, chunk);
}

/* True once every chunk of the current version has arrived. */
bool window_asm_complete(const window_asm_t *a)
{
    return a->started && a->chunk_count != 0u && a->received == a->chunk_count;
}
