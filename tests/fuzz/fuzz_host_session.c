/* libFuzzer target for who may command the arm: arbitrary bytes as a run of datagrams from up
 * to four senders (HELLO, heartbeats with any command, other frames, junk; any sequence
 * numbers) and of elapsed time, through the transport's binding (firmware/hal/link_bind.c) and
 * the core's session (firmware/core/host_session.c), as the UDP link and the board wire them.
 * Checked: no sequence number acts twice in a session (until its numbers have advanced by 2³¹
 * in all, after which serial-number order cannot tell old from new: docs/protocol.md), none
 * older than the window acts, and while a session lives only its bound sender gets through. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/host_session.h"
#include "firmware/hal/link_bind.h"
#include "shared/proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define SEEN_MAX 4096u

static void check(int ok)
{
    if (!ok)
        abort();
}

static hal_session_state_t to_hal(host_session_state_t s)
{
    return s == HOST_SESSION_LIVE ? HAL_SESSION_LIVE
           : s == HOST_SESSION_LAPSED ? HAL_SESSION_LAPSED : HAL_SESSION_NONE;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static uint32_t seen[SEEN_MAX];
    uint32_t n_seen = 0;
    uint64_t advance = 0; /* how far the session's newest number moved since seen[] began */
    link_bind_t lb;
    link_bind_init(&lb);
    host_session_t s;
    host_session_init(&s);
    uint64_t now_us = 0;
    for (size_t at = 0; at + 6u <= size; at += 6u) {
        const uint8_t op = data[at], sender = data[at + 1] % 4u;
        const uint32_t seq = (uint32_t)data[at + 2] | (uint32_t)data[at + 3] << 8 |
                             (uint32_t)data[at + 4] << 16 | (uint32_t)data[at + 5] << 24;
        if (op % 5u == 3u) {
            const uint32_t dt = seq % 2000000u;
            now_us += dt;
            (void)host_session_process(&s, dt, 50000u);
            link_bind_session(&lb, to_hal(s.state), s.epoch, now_us);
            continue;
        }
        proto_msg_t m;
        memset(&m, 0, sizeof(m));
        m.type = op % 5u == 0u ? MSG_HELLO : op % 5u == 1u ? MSG_HEARTBEAT : MSG_TOOL;
        m.u.hello.role = PROTO_ROLE_HOST;
        if (m.type == MSG_HEARTBEAT)
            m.u.heartbeat.command = (uint8_t)((op >> 3) % 4u);
        if (m.type == MSG_TOOL) {
            m.u.tool.radius_m = 0.004f;
            m.u.tool.axis[2] = 1.0f;
            m.u.tool.max_force_n = 1.0f;
            m.u.tool.model_scale = 1.0f;
        }
        uint8_t frame[PROTO_FRAME_MAX];
        size_t len = 0;
        check(proto_encode(&m, seq, frame, sizeof(frame), &len) == PROTO_OK);
        if (op % 5u == 4u)
            frame[len - 1u] ^= 0x5Au; /* a torn or forged frame: its CRC fails */
        const bool live = lb.bound && !lb.pending && lb.state == HAL_SESSION_LIVE;
        const uint64_t peer = lb.peer;
        if (!link_bind_admit(&lb, sender, frame, len, now_us))
            continue;
        check(!live || sender == peer);
        proto_msg_t d;
        size_t used = 0;
        if (proto_decode(frame, len, &d, &used) != PROTO_OK)
            continue; /* the board's decoder refuses it before the session sees it */
        const bool hello = d.type == MSG_HELLO;
        const host_session_state_t before = s.state;
        const uint32_t newest = s.newest_seq;
        const uint32_t ahead = d.seq - newest;
        if (s.state != HOST_SESSION_NONE && ahead != 0u && ahead < 0x80000000u) {
            advance += ahead;
            if (advance >= 0x80000000u) {
                n_seen = 0; /* the number space went round: no longer judged */
                advance = 0;
            }
        }
        const host_frame_verdict_t v = host_session_admit(&s, hello, hello || d.type == MSG_HEARTBEAT,
                                                          d.seq);
        if (v == HOST_FRAME_NEW_SESSION && before != HOST_SESSION_LIVE) {
            n_seen = 0; /* a new window */
            advance = 0;
        } else if (v >= 0) {
            check(before != HOST_SESSION_NONE);
            check((uint32_t)(newest - d.seq) < HOST_SESSION_WINDOW ||
                  (uint32_t)(d.seq - newest) < 0x80000000u);
            for (uint32_t k = 0; k < n_seen; k++)
                check(seen[k] != d.seq);
        }
        if (v >= 0 && n_seen < SEEN_MAX)
            seen[n_seen++] = d.seq;
        if (v >= 0 && d.type == MSG_HEARTBEAT && d.u.heartbeat.command == PROTO_CMD_END) {
            host_session_end(&s);
            n_seen = 0;
            advance = 0;
        }
        link_bind_session(&lb, to_hal(s.state), s.epoch, now_us);
    }
    return 0;
}
