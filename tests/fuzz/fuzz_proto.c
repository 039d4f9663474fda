/* libFuzzer target for the wire protocol: arbitrary bytes as one frame and as a stream,
 * with and without a repaired CRC; every decoded message must re-encode to the same bytes
 * and decode back to the same fields; WINDOW chunks go through a real window assembly. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "shared/crc32c.h"
#include "shared/proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_BUF_MAX 65536u

static float g_storage[PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX];
static float g_small[1000];
static uint8_t g_copy[FUZZ_BUF_MAX];

static void check(int ok)
{
    if (!ok)
        abort();
}

static int same_f32(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

/* True when a and b carry the same fields (bit-exact floats, used entries only). */
static int msg_equal(const proto_msg_t *a, const proto_msg_t *b)
{
    if (a->type != b->type || a->seq != b->seq)
        return 0;
    switch (a->type) {
    case MSG_HELLO: {
        const msg_hello_t *x = &a->u.hello, *y = &b->u.hello;
        return x->role == y->role && x->drives == y->drives && x->window_max == y->window_max &&
               x->tick_hz == y->tick_hz && memcmp(x->name, y->name, PROTO_NAME_LEN) == 0;
    }
    case MSG_HEARTBEAT: {
        const msg_heartbeat_t *x = &a->u.heartbeat, *y = &b->u.heartbeat;
        return x->time_us == y->time_us && x->window_version == y->window_version &&
               x->impulse_seq == y->impulse_seq && x->command == y->command;
    }
    case MSG_TELEMETRY: {
        const msg_telemetry_t *x = &a->u.telemetry, *y = &b->u.telemetry;
        return x->time_us == y->time_us && x->tick == y->tick && x->state == y->state &&
               x->tool_kind == y->tool_kind && x->buttons == y->buttons && x->flags == y->flags &&
               same_f32(x->pos_m, y->pos_m, 3) && same_f32(x->vel_m_s, y->vel_m_s, 3) &&
               same_f32(x->force_n, y->force_n, 3) && x->window_version == y->window_version &&
               x->compute_ns == y->compute_ns && x->deadline_misses == y->deadline_misses;
    }
    case MSG_IMPULSE: {
        const msg_impulse_t *x = &a->u.impulse, *y = &b->u.impulse;
        if (x->window_version != y->window_version || x->impulse_seq != y->impulse_seq ||
            x->count != y->count || x->count > PROTO_IMPULSE_MAX)
            return 0;
        for (size_t i = 0; i < x->count; i++) {
            if (x->entries[i].node != y->entries[i].node ||
                !same_f32(&x->entries[i].impulse_ns, &y->entries[i].impulse_ns, 1))
                return 0;
        }
        return 1;
    }
    case MSG_WINDOW: {
        const msg_window_t *x = &a->u.window, *y = &b->u.window;
        return x->version == y->version && x->chunk_index == y->chunk_index &&
               x->chunk_count == y->chunk_count && memcmp(x->dims, y->dims, 3) == 0 &&
               x->channels == y->channels &&
               same_f32(x->origin_m, y->origin_m, 3) && same_f32(&x->spacing_m, &y->spacing_m, 1) &&
               same_f32(&x->iso, &y->iso, 1) && same_f32(&x->node_mass, &y->node_mass, 1) &&
               same_f32(&x->stiffness, &y->stiffness, 1) && same_f32(&x->damping, &y->damping, 1) &&
               same_f32(&x->plastic_rate_hz, &y->plastic_rate_hz, 1) &&
               x->impulse_seq == y->impulse_seq && x->first_sample == y->first_sample &&
               x->sample_count == y->sample_count &&
               x->sample_count <= PROTO_WINDOW_CHUNK_SAMPLES &&
               same_f32(x->samples, y->samples, x->sample_count);
    }
    case MSG_TOOL: {
        const msg_tool_t *x = &a->u.tool, *y = &b->u.tool;
        return x->kind == y->kind && x->shape == y->shape && x->filter == y->filter &&
               x->flags == y->flags && same_f32(&x->radius_m, &y->radius_m, 1) &&
               same_f32(&x->length_m, &y->length_m, 1) && same_f32(x->axis, y->axis, 3) &&
               same_f32(&x->alpha, &y->alpha, 1) &&
               same_f32(&x->contact_stiffness_n_per_m, &y->contact_stiffness_n_per_m, 1) &&
               same_f32(&x->max_force_n, &y->max_force_n, 1) && same_f32(&x->iso, &y->iso, 1) &&
               same_f32(&x->yield_force_n, &y->yield_force_n, 1) &&
               same_f32(&x->friction, &y->friction, 1) &&
               same_f32(&x->probe_gain, &y->probe_gain, 1) &&
               same_f32(&x->rope_stiffness_n_per_m, &y->rope_stiffness_n_per_m, 1) &&
               same_f32(&x->model_scale, &y->model_scale, 1) &&
               same_f32(x->model_offset_m, y->model_offset_m, 3);
    }
    case MSG_FAULT: {
        const msg_fault_t *x = &a->u.fault, *y = &b->u.fault;
        return x->time_us == y->time_us && x->code == y->code && x->state == y->state &&
               x->detail == y->detail;
    }
    case MSG_RT_STATS: {
        const msg_rt_stats_t *x = &a->u.rt_stats, *y = &b->u.rt_stats;
        return x->time_us == y->time_us && x->ticks == y->ticks &&
               x->period_ns == y->period_ns && x->wake_min_ns == y->wake_min_ns &&
               x->wake_mean_ns == y->wake_mean_ns && x->wake_max_ns == y->wake_max_ns &&
               x->compute_min_ns == y->compute_min_ns &&
               x->compute_mean_ns == y->compute_mean_ns &&
               x->compute_max_ns == y->compute_max_ns && x->overruns == y->overruns &&
               x->worst_streak == y->worst_streak &&
               memcmp(x->wake_hist, y->wake_hist, sizeof x->wake_hist) == 0 &&
               memcmp(x->compute_hist, y->compute_hist, sizeof x->compute_hist) == 0 &&
               x->link.decode_errors == y->link.decode_errors &&
               x->link.wrong_source == y->link.wrong_source &&
               x->link.no_session == y->link.no_session && x->link.duplicate == y->link.duplicate &&
               x->link.stale == y->link.stale && x->link.sessions == y->link.sessions &&
               x->link.bad_mac == y->link.bad_mac && x->link.bad_nonce == y->link.bad_nonce &&
               x->link.arm_refused == y->link.arm_refused;
    }
    default:
        return 0;
    }
}

/* Checks what the decoder promises about a WINDOW chunk and a TOOL, independently of
 * proto.c's own checks: the ranges of docs/protocol.md. */
static void check_ranges(const proto_msg_t *m)
{
    if (m->type == MSG_HEARTBEAT)
        check(m->u.heartbeat.command <= 3u); /* none, arm, disarm, end (protocol v2) */
    if (m->type == MSG_RT_STATS) {
        const msg_rt_stats_t *r = &m->u.rt_stats;
        uint64_t wake = 0, comp = 0;
        for (size_t i = 0; i < PROTO_RT_HIST_BINS; i++) {
            wake += r->wake_hist[i];
            comp += r->compute_hist[i];
        }
        check(r->period_ns > 0u && wake == r->ticks && comp == r->ticks);
        check(r->wake_min_ns <= r->wake_mean_ns && r->wake_mean_ns <= r->wake_max_ns);
        check(r->compute_min_ns <= r->compute_mean_ns && r->compute_mean_ns <= r->compute_max_ns);
        check(r->worst_streak <= r->overruns && r->overruns <= r->ticks);
    }
    if (m->type == MSG_WINDOW) {
        const msg_window_t *w = &m->u.window;
        check(w->channels >= 1u && w->channels <= PROTO_WINDOW_CHANNELS_MAX);
        uint32_t nodes = (uint32_t)w->dims[0] * w->dims[1] * w->dims[2];
        check(w->chunk_count == window_chunk_count(w->dims, w->channels));
        check(w->chunk_count <= PROTO_WINDOW_CHUNKS_MAX);
        check(w->sample_count <= PROTO_WINDOW_CHUNK_SAMPLES);
        check(w->first_sample + w->sample_count <= nodes * w->channels);
        for (uint32_t k = 0; k < w->sample_count; k++) {
            check(isfinite(w->samples[k])); /* no NaN, no infinity */
            if (w->first_sample + k >= nodes)
                check(w->samples[k] >= 0.0f); /* a stiffness */
        }
    } else if (m->type == MSG_TOOL) {
        const msg_tool_t *t = &m->u.tool;
        check(t->kind < TOOL_KIND_COUNT && t->shape < TOOL_SHAPE_COUNT &&
              t->filter < BETA_FILTER_COUNT && (t->flags & ~TOOL_FLAG_ISO) == 0u);
        check(t->radius_m > 0.0f && t->max_force_n > 0.0f && t->model_scale > 0.0f);
        check(t->iso >= 0.0f && t->iso <= 1.0f);
        double n2 = (double)t->axis[0] * t->axis[0] + (double)t->axis[1] * t->axis[1] +
                    (double)t->axis[2] * t->axis[2];
        check(n2 > 0.9979 && n2 < 1.0021);
        check(t->length_m >= 0.0f && t->alpha >= 0.0f && t->contact_stiffness_n_per_m >= 0.0f &&
              t->yield_force_n >= 0.0f && t->friction >= 0.0f && t->probe_gain >= 0.0f &&
              t->rope_stiffness_n_per_m >= 0.0f);
    }
}

/* Feeds a decoded chunk to both assemblies and checks their invariants. */
static void feed_window(window_asm_t *big, window_asm_t *small, const msg_window_t *c)
{
    window_asm_t *all[2] = { big, small };
    for (size_t k = 0; k < 2; k++) {
        window_asm_t *a = all[k];
        proto_err_t err = window_asm_feed(a, c);
        check(err == PROTO_OK || err == PROTO_ERR_CHUNK);
        check(a->received <= a->chunk_count || a->chunk_count == 0);
        check(a->received <= PROTO_WINDOW_CHUNKS_MAX);
        if (err == PROTO_OK) {
            check(a->started && a->version == c->version);
            /* the chunk's samples are in storage now */
            check(same_f32(a->samples + c->first_sample, c->samples, c->sample_count));
        }
        if (window_asm_complete(a)) {
            /* re-chunk the finished window: every chunk must encode */
            uint8_t f[PROTO_FRAME_MAX];
            proto_msg_t m;
            memset(&m, 0, sizeof m);
            m.type = MSG_WINDOW;
            for (uint16_t i = 0; i < a->chunk_count; i++) {
                size_t len = 0;
                check(window_chunk_fill(&a->head, a->samples, i, &m.u.window) == PROTO_OK);
                check(proto_encode(&m, i, f, sizeof f, &len) == PROTO_OK);
                check(len <= PROTO_FRAME_MAX);
            }
        }
    }
}

/* Decodes at buf[0..len); on success checks the re-encoding and feeds windows. Returns the
 * frame length, or 0 when the bytes do not start a valid frame. */
static size_t decode_one(const uint8_t *buf, size_t len, window_asm_t *big, window_asm_t *small)
{
    proto_msg_t m, back;
    size_t flen = 0;
    proto_err_t err = proto_decode(buf, len, &m, &flen);
    check(err <= PROTO_OK && err >= PROTO_ERR_CHUNK);
    if (err != PROTO_OK)
        return 0;
    check(flen >= PROTO_HEADER_SIZE + PROTO_CRC_SIZE && flen <= len && flen <= PROTO_FRAME_MAX);

    uint8_t out[PROTO_FRAME_MAX];
    size_t olen = 0, blen = 0;
    check(proto_encode(&m, m.seq, out, sizeof out, &olen) == PROTO_OK);
    check(olen == flen && memcmp(out, buf, flen) == 0); /* the encoding is canonical */
    check(proto_encode(&m, m.seq, out, flen - 1u, &olen) == PROTO_ERR_NOSPACE);
    check(proto_decode(out, flen, &back, &blen) == PROTO_OK && blen == flen);
    check(msg_equal(&m, &back));
    check_ranges(&m);

    if (m.type == MSG_WINDOW)
        feed_window(big, small, &m.u.window);
    return flen;
}

/* Walks buf as a stream of frames: a valid frame is skipped whole, anything else by a byte. */
static void decode_stream(const uint8_t *buf, size_t len, window_asm_t *big, window_asm_t *small)
{
    size_t pos = 0;
    while (pos < len) {
        size_t flen = decode_one(buf + pos, len - pos, big, small);
        pos += flen != 0 ? flen : 1u;
    }
}

/* Rewrites the CRC of the frame that would start at buf[0] (if its declared length fits), so
 * mutations reach the payload checks instead of stopping at the CRC. */
static void repair_crc(uint8_t *buf, size_t len)
{
    if (len < PROTO_HEADER_SIZE)
        return;
    size_t body = PROTO_HEADER_SIZE + ((size_t)buf[6] | (size_t)buf[7] << 8);
    if (body + PROTO_CRC_SIZE > len)
        return;
    uint32_t c = crc32c(0u, buf, body);
    for (size_t i = 0; i < 4u; i++)
        buf[body + i] = (uint8_t)(c >> (8u * i));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    window_asm_t big, small;
    window_asm_init(&big, g_storage, PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX);
    window_asm_init(&small, g_small, 1000);

    /* as received: one frame, then as a stream */
    decode_one(data, size, &big, &small);
    decode_stream(data, size, &big, &small);

    /* with a valid CRC at every frame position, as a stream */
    size_t n = size < FUZZ_BUF_MAX ? size : FUZZ_BUF_MAX;
    memcpy(g_copy, data, n);
    size_t pos = 0;
    while (pos < n) {
        repair_crc(g_copy + pos, n - pos);
        size_t flen = decode_one(g_copy + pos, n - pos, &big, &small);
        pos += flen != 0 ? flen : 1u;
    }
    check(proto_strerror((proto_err_t)(size > 0 ? -(int)(data[0] % 12u) : 0))[0] != 0);
    return 0;
}
