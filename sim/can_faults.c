/* CAN fault injection at frame level (see can_faults.h). */
#include "can_faults.h"

#include <string.h>

#define ERR_FLAG 0x20000000u      /* <linux/can/error.h> CAN_ERR_FLAG */
#define ERR_BUSOFF 0x00000040u    /* CAN_ERR_BUSOFF */
#define ERR_RESTARTED 0x00000100u /* CAN_ERR_RESTARTED */

void can_faults_init(can_faults_t *cf)
{
    memset(cf, 0, sizeof(*cf));
    cf->seed = 1u;
}

void can_faults_set_drop(can_faults_t *cf, uint32_t ppm, uint32_t seed)
{
    cf->drop_ppm = ppm > 1000000u ? 1000000u : ppm;
    cf->seed = seed != 0 ? seed : 1u;
    memset(cf->frames_seen, 0, sizeof(cf->frames_seen));
}

void can_faults_set_delay(can_faults_t *cf, int64_t delay_us)
{
    cf->delay_us = delay_us > 0 ? delay_us : 0;
}

void can_faults_bus_off(can_faults_t *cf)
{
    cf->bus_off = true;
    cf->bus_off_frame_due = true;
    cf->restart_frame_due = false;
    cf->held_to_board.n = 0;
    cf->held_from_board.n = 0;
}

void can_faults_bus_restart(can_faults_t *cf)
{
    if (!cf->bus_off)
        return;
    cf->bus_off = false;
    cf->bus_off_frame_due = false;
    cf->restart_frame_due = true;
}

void can_faults_heartbeat(can_faults_t *cf, int node, bool on)
{
    if (node >= 1 && node <= ARGIL_DRIVES)
        cf->heartbeat_stopped[node - 1] = !on;
}

void can_faults_encoder_jump(can_faults_t *cf, int node, int32_t counts)
{
    if (node >= 1 && node <= ARGIL_DRIVES)
        cf->encoder_offset_counts[node - 1] += counts;
}

/* MurmurHash3's 32-bit finaliser (Appleby): every input bit reaches every output bit. */
static uint32_t mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
}

/* True with probability ppm / 1e6 for the n-th frame of this CAN id in this direction since
 * the drop began: a function of (seed, direction, id, n) alone, so the same frames are lost
 * whatever order the two directions' frames interleave in (SIL, argil-sim on a bus). */
static bool drop_now(can_faults_t *cf, int dir, uint32_t id)
{
    if (cf->drop_ppm == 0)
        return false;
    uint32_t *const n = &cf->frames_seen[dir][id & CAN_FAULTS_ID_MASK];
    (*n)++;
    const uint32_t h = mix32(cf->seed ^ mix32((uint32_t)dir << 27 ^ (id & CAN_FAULTS_ID_MASK) << 16 ^ *n));
    return h % 1000000u < cf->drop_ppm;
}

/* Holds f until due_us, or passes it when there is no delay; counts an overflow. */
static void pass(can_faults_t *cf, can_held_queue_t *q, const can_frame_t *f, can_batch_t *out,
                 int64_t now_us)
{
    if (cf->delay_us == 0 && q->n == 0) {
        (void)can_batch_push(out, f);
        return;
    }
    if (q->n == CAN_FAULTS_HELD_MAX) {
        cf->held_overflow++;
        return;
    }
    q->q[q->n].due_us = now_us + cf->delay_us;
    q->q[q->n].f = *f;
    q->n++;
}

/* Moves the frames whose time has come (in order) into out. */
static void release(can_faults_t *cf, can_held_queue_t *q, can_batch_t *out, int64_t now_us)
{
    uint32_t k = 0;
    while (k < q->n && (q->q[k].due_us <= now_us || cf->delay_us == 0) && out->n < CAN_BATCH_MAX) {
        (void)can_batch_push(out, &q->q[k].f);
        k++;
    }
    if (k > 0) {
        memmove(q->q, q->q + k, (q->n - k) * sizeof(q->q[0]));
        q->n -= k;
    }
}

static void error_frame(can_batch_t *out, uint32_t cls)
{
    can_frame_t f;
    memset(&f, 0, sizeof(f));
    f.id = ERR_FLAG | cls;
    f.len = 8;
    (void)can_batch_push(out, &f);
}

void can_faults_to_board(can_faults_t *cf, const can_batch_t *in, can_batch_t *out,
                         int64_t now_us)
{
    out->n = 0;
    if (cf->bus_off_frame_due) {
        error_frame(out, ERR_BUSOFF);
        cf->bus_off_frame_due = false;
        cf->error_frames_sent++;
    }
    if (cf->restart_frame_due) {
        error_frame(out, ERR_RESTARTED);
        cf->restart_frame_due = false;
        cf->error_frames_sent++;
    }
    release(cf, &cf->held_to_board, out, now_us);
    const uint8_t n = in && in->n <= CAN_BATCH_MAX ? in->n : 0;
    for (uint8_t i = 0; i < n; i++) {
        can_frame_t f = in->f[i];
        if (cf->bus_off) {
            cf->silenced++;
            continue;
        }
        uint8_t node;
        nmt_state_t st;
        uint16_t sw;
        int32_t pos;
        int16_t tq;
        if (canopen_heartbeat_decode(&f, &node, &st) && node >= 1 && node <= ARGIL_DRIVES &&
            cf->heartbeat_stopped[node - 1]) {
            cf->heartbeats_suppressed++;
            continue;
        }
        if (canopen_tpdo_decode(&f, &node, &sw, &pos, &tq) && node >= 1 && node <= ARGIL_DRIVES &&
            cf->encoder_offset_counts[node - 1] != 0) {
            const int64_t p = (int64_t)pos + cf->encoder_offset_counts[node - 1];
            const int32_t pc = p > INT32_MAX ? INT32_MAX : p < INT32_MIN ? INT32_MIN : (int32_t)p;
            canopen_tpdo_encode(&f, node, sw, pc, tq);
        }
        if (drop_now(cf, 0, f.id)) {
            cf->dropped_to_board++;
            continue;
        }
        pass(cf, &cf->held_to_board, &f, out, now_us);
    }
}

void can_faults_from_board(can_faults_t *cf, const can_batch_t *in, can_batch_t *out,
                           int64_t now_us)
{
    out->n = 0;
    release(cf, &cf->held_from_board, out, now_us);
    const uint8_t n = in && in->n <= CAN_BATCH_MAX ? in->n : 0;
    for (uint8_t i = 0; i < n; i++) {
        const can_frame_t *f = &in->f[i];
        if (cf->bus_off) {
            cf->silenced++;
            continue;
        }
        if (drop_now(cf, 1, f->id)) {
            cf->dropped_from_board++;
            continue;
        }
        pass(cf, &cf->held_from_board, f, out, now_us);
    }
}
