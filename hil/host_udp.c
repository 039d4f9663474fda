/* hil-host: the smallest live host for the HIL rig's checks: over UDP it says HELLO, sends a
 * heartbeat every 5 ms and asks the board to ARM (until it is ARMED or ACTIVE once), and prints
 * every safety state the board's telemetry reports, with the CLOCK_REALTIME time it arrived
 * (the clock of candump -L and hil-probe) and the board's tick:
 *   1795387992.352639 tick=1234 state ARMED
 * It sends no window, so the board stops at ARMED (drives on, zero torque): enough to see
 * DRIVE_ENABLE high and every fault take it down. At the end it prints the time of its last
 * heartbeat ("T last-heartbeat") and falls silent, as a host that is unplugged.
 * Usage: hil-host PORT SECONDS [SCENARIO]. With HIL_FIFO_PRIO=N it runs SCHED_FIFO at N so a
 * busy rig does not starve it; with ARGIL_LINK_KEY=FILE every datagram is sealed with that link
 * key and the board's verified (docs/link.md). Exit 0 when the board answered, 1 when it never
 * did, 2 usage.
 *
 * With a SCENARIO (a hil/scenarios file) it is the scenario's host side instead: the host's
 * protocol peer (host/app/peer.c: tool, windows around the tool over a clay sphere, heartbeats,
 * ARM) so the board goes ACTIVE and sculpts, and at their times the host-side steps: rearm,
 * link lost / restore / delay / duplicate / reorder / garbage / nan_tool (a TOOL frame whose
 * radius is NaN, CRC valid). "--sync CAN_IF": its clock is the board's, one 1 ms step per SYNC
 * on the bus from the first drive frame (sim/scn_clock.h, as argil-sim's); "--follow EVENTS"
 * (argil-sim's event log, same machine): each step is performed when argil-sim's log says its
 * clock reached it, so both sides keep one clock; else the clock starts with the program. It
 * prints one line per step performed; a step it cannot perform over UDP (overrun) is printed
 * as "unsupported" and the exit status is 3. The clock, the steps and the heartbeats (every 5
 * ms of wall time) run in a thread at HIL_FIFO_PRIO, while the peer's loop (global solve
 * limited to 1 Hz here: this host tests the board, the solve is tested elsewhere; windows)
 * runs 9 below, under the board's link thread: on a slow emulated
 * rig neither the solve holds the heartbeats back nor the peer starves the board's link. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/peer.h"
#include "host/link/link_crypto.h"
#include "host/link/link_key_file.h"
#include "host/model/grid.h"
#include "shared/crc32c.h"
#include "shared/proto.h"
#include "sim/scenario.h"
#include "sim/scn_clock.h"
#include "sim/sim_device.h"

static double realtime_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

static uint64_t mono_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

/* ARGIL_LINK_KEY given: every datagram sealed, every one from the board verified (from any
 * thread: the heartbeats' and the peer's). */
static bool g_keyed;
static link_auth_host_t g_auth;
static pthread_mutex_t g_auth_mu; /* priority inheritance (main): the heartbeat thread must
                                     not wait behind the peer's loop sealing a window */

/* The datagram a frame goes out as (keyed: sealed) in out; its length, 0 when not sent. */
static size_t udp_wire(const uint8_t *f, size_t len, uint8_t *out, size_t cap)
{
    if (!g_keyed) {
        if (len > cap)
            return 0;
        memcpy(out, f, len);
        return len;
    }
    pthread_mutex_lock(&g_auth_mu);
    len = link_auth_host_seal(&g_auth, f, len, out, cap);
    pthread_mutex_unlock(&g_auth_mu);
    return len;
}

static void udp_out(int fd, const struct sockaddr_in *to, const uint8_t *f, size_t len)
{
    uint8_t wire[LINK_AUTH_DGRAM_MAX];
    len = udp_wire(f, len, wire, sizeof(wire));
    if (len > 0)
        (void)sendto(fd, wire, len, 0, (const struct sockaddr *)to, sizeof(*to));
}

/* The next datagram's frames from the board (keyed: verified, the trailer off); <= 0: none. */
static ssize_t udp_in(int fd, uint8_t *buf, size_t cap)
{
    for (;;) {
        const ssize_t n = recv(fd, buf, cap, 0);
        if (n <= 0 || !g_keyed)
            return n;
        size_t flen = 0;
        pthread_mutex_lock(&g_auth_mu);
        const link_auth_err_t e = link_auth_host_open(&g_auth, buf, (size_t)n, &flen);
        pthread_mutex_unlock(&g_auth_mu);
        if (e == LINK_AUTH_OK)
            return (ssize_t)flen;
    }
}

static void send_msg(int fd, const struct sockaddr_in *to, proto_msg_t *m, uint32_t *seq)
{
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    if (proto_encode(m, (*seq)++, buf, sizeof(buf), &len) == PROTO_OK)
        udp_out(fd, to, buf, len);
}


/* ---- scenario host ---- */
#define HELD_MAX 64u
#define HOST_LOOP_DROP 9            /* the peer loop's FIFO priority below the heartbeats':
                                       above argil-sim's and candump's, under the board's link
                                       thread; with its solve at 1 Hz the loop is short */

typedef struct {
    uint64_t due_us;
    size_t len;
    uint8_t b[PROTO_FRAME_MAX];
} held_t;

#define CAPTURED_MAX 64u

typedef struct {
    size_t len;
    uint8_t b[LINK_AUTH_DGRAM_MAX];
} wire_t;
#define STRANGER_ADDR "127.0.0.2"   /* another address on the host's network (loopback /8) */

typedef struct {
    int fd;
    struct sockaddr_in board;
    uint64_t t0_us;
    /* the stranger (`stranger KIND for D`): its own socket on STRANGER_ADDR, and what it has
     * captured of the host's datagrams (as sent) */
    int stranger_fd;
    int stranger_kind;              /* scn_stranger_t while active, -1 */
    uint64_t stranger_until_us, stranger_last_us;
    wire_t captured[CAPTURED_MAX];   /* datagrams as they went on the wire */
    uint32_t n_captured, replay_next;
    uint32_t replayed_other, replayed_own, forged, flooded, stranger_errors;
    bool lost;
    int64_t delay_us;
    int32_t duplicate_n, reorder_n;
    held_t held[HELD_MAX];          /* delayed frames, in send order */
    uint32_t n_held;
    held_t swap;                    /* the first of a pair to reorder */
    bool have_swap;
    msg_telemetry_t tm;
    uint32_t tm_n, last_state;
    uint32_t frames_sent, frames_dropped;
    pthread_mutex_t mu;             /* the link state and socket, shared with the beat thread */
    atomic_bool board_seen, stop;
    atomic_uint window_version, impulse_seq; /* the peer's, for the beat thread's heartbeats */
    atomic_uint beats;
    uint64_t rt_max_gap_us;         /* the real-time thread's longest time between two turns of
                                     * its 1 ms loop (heartbeats, held frames) once the board is
                                     * seen and heartbeats are due: how long the rig held the
                                     * host back */
    uint64_t rt_max_gap_at_us;      /* ... when that gap ended, from t0_us */
    uint64_t rt_first_turn_us;      /* the first turn: it reads every SYNC queued since the
                                     * socket opened (hundreds under TCG), no heartbeat due yet */
    /* the scenario clock and its steps, run by the real-time thread (shost_rt) */
    const scenario_t *scn;
    const msg_tool_t *tool;         /* the peer's tool, for nan_tool */
    int sync_fd;                    /* CAN socket for the clock, -1: wall clock */
    const char *follow_path;        /* argil-sim's event log: its clock decides the steps */
    int follow_fd;
    char follow_buf[4096];
    size_t follow_len;
    uint64_t end_seen_us;           /* when argil-sim's end line was read (0: not yet) */
    int64_t scn_end_us;             /* the clock stops the run here */
    scn_clock_t clk;
    bool synced;
    uint32_t next_step;
    atomic_uint rearm_ms;           /* ARM heartbeats wanted (ms), for the main loop */
    uint32_t next_seq;              /* every frame's number, one sequence (under mu) */
    atomic_int unsupported;
    atomic_bool synced_flag, done;
    atomic_llong now_us;            /* scenario time, for the main loop's prints */
    const char *ready_file;         /* written once the board is ACTIVE (argil-sim --start-when) */
    bool ready_written;
} shost_t;

static void raw_send(shost_t *h, const uint8_t *f, size_t len)
{
    /* sealed as it goes, and kept as a stranger on the network captures it */
    wire_t *c = &h->captured[h->n_captured % CAPTURED_MAX];
    c->len = udp_wire(f, len, c->b, sizeof(c->b));
    if (c->len > 0) {
        (void)sendto(h->fd, c->b, c->len, 0, (const struct sockaddr *)&h->board,
                     sizeof(h->board));
        h->n_captured++;
    }
    h->frames_sent++;
}

/* A datagram from the stranger's socket (another address), or from the host's own (a spoofed
 * source: on a real network a stranger can forge the host's address). */
static void stranger_sendto(shost_t *h, bool own, const uint8_t *f, size_t len)
{
    const int fd = own ? h->fd : h->stranger_fd;
    if (fd < 0 || sendto(fd, f, len, 0, (const struct sockaddr *)&h->board, sizeof(h->board)) !=
                      (ssize_t)len)
        h->stranger_errors++;
}

/* The stranger's socket on STRANGER_ADDR; -1 (and a line) when the address cannot be bound. */
static int stranger_open(void)
{
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    inet_pton(AF_INET, STRANGER_ADDR, &a.sin_addr);
    if (fd < 0 || bind(fd, (const struct sockaddr *)&a, sizeof(a)) != 0) {
        fprintf(stderr, "hil-host: cannot bind the stranger's socket on %s (%s)\n",
                STRANGER_ADDR, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

/* One CRC-valid command a stranger would send to take the arm, numbered far ahead of the
 * host: a HELLO, DISARM and END heartbeats, a four times stiffer TOOL. */
static size_t stranger_command(shost_t *h, uint8_t *buf, size_t cap)
{
    static proto_msg_t m;
    memset(&m, 0, sizeof(m));
    const uint32_t k = h->forged % 4u;
    if (k == 0) {
        m.type = MSG_HELLO;
        m.u.hello.role = PROTO_ROLE_HOST;
    } else if (k == 3) {
        m.type = MSG_TOOL;
        m.u.tool = *h->tool;
        m.u.tool.contact_stiffness_n_per_m *= 4.0f;
    } else {
        m.type = MSG_HEARTBEAT;
        m.u.heartbeat.command = k == 1 ? PROTO_CMD_DISARM : PROTO_CMD_END;
    }
    size_t len = 0;
    if (proto_encode(&m, h->next_seq + 1000u + h->forged, buf, cap, &len) != PROTO_OK)
        return 0;
    return len;
}

/* One millisecond of the stranger (the caller holds h->mu): replay sends one captured
 * datagram from its address and from the host's; forge one command every 5 ms from each;
 * flood 10 junk datagrams from its address. */
static void stranger_tick(shost_t *h)
{
    const uint64_t now = mono_us();
    if (h->stranger_kind < 0)
        return;
    if (now >= h->stranger_until_us) {
        h->stranger_kind = -1;
        return;
    }
    if (now < h->stranger_last_us + 1000u)
        return;
    h->stranger_last_us = now;
    switch (h->stranger_kind) {
    case SCN_STRANGER_REPLAY: {
        const uint32_t n = h->n_captured < CAPTURED_MAX ? h->n_captured : CAPTURED_MAX;
        if (n == 0)
            return;
        const wire_t *c = &h->captured[h->replay_next++ % n];
        stranger_sendto(h, false, c->b, c->len);
        h->replayed_other++;
        stranger_sendto(h, true, c->b, c->len);
        h->replayed_own++;
        return;
    }
    case SCN_STRANGER_FORGE: {
        if ((now / 1000u) % 5u != 0)
            return;
        uint8_t buf[PROTO_FRAME_MAX], sealed[LINK_AUTH_DGRAM_MAX];
        const size_t len = stranger_command(h, buf, sizeof(buf));
        if (len == 0)
            return;
        /* with no tag, and (on a keyed link) with a wrong key's tag over the session's own
         * nonce, from both addresses */
        stranger_sendto(h, false, buf, len);
        stranger_sendto(h, true, buf, len);
        if (g_keyed) {
            static const link_key_t wrong = {{0x5A}};
            pthread_mutex_lock(&g_auth_mu);
            const uint64_t nonce = g_auth.nonce;
            pthread_mutex_unlock(&g_auth_mu);
            const size_t n = link_auth_seal(link_crypto_mac, &wrong, LINK_AUTH_HOST_TO_BOARD,
                                            nonce, buf, len, sealed, sizeof(sealed));
            if (n > 0) {
                stranger_sendto(h, false, sealed, n);
                stranger_sendto(h, true, sealed, n);
            }
        }
        h->forged++;
        return;
    }
    case SCN_STRANGER_FLOOD: {
        uint32_t v = 0x9E3779B9u ^ (uint32_t)now;
        for (int k = 0; k < 10; k++) {
            uint8_t junk[1024];
            v ^= v << 13; v ^= v >> 17; v ^= v << 5;
            const size_t n = 1u + v % sizeof(junk);
            for (size_t i = 0; i < n; i++) {
                v ^= v << 13; v ^= v >> 17; v ^= v << 5;
                junk[i] = (uint8_t)v;
            }
            if (k % 2 == 0 && n >= 4)
                memcpy(junk, "ARGL", 4); /* starts like a frame */
            stranger_sendto(h, false, junk, n);
            h->flooded++;
        }
        return;
    }
    default: return;
    }
}

/* Gives a frame the next number of this host's one sequence (the board refuses a number it
 * has seen and one far behind its newest) and reseals its CRC; the caller holds h->mu. */
static void stamp_seq(shost_t *h, uint8_t *f, size_t len)
{
    if (len < PROTO_HEADER_SIZE + PROTO_CRC_SIZE)
        return;
    const uint32_t seq = h->next_seq++;
    for (int k = 0; k < 4; k++)
        f[8 + k] = (uint8_t)(seq >> (8 * k));
    const uint32_t crc = crc32c(0u, f, len - PROTO_CRC_SIZE);
    for (int k = 0; k < 4; k++)
        f[len - PROTO_CRC_SIZE + (size_t)k] = (uint8_t)(crc >> (8 * k));
}

/* The peer's frames go through the scripted link faults; the caller holds h->mu. */
static bool shost_send_locked(shost_t *h, const uint8_t *frame, size_t len)
{
    if (h->lost || len > PROTO_FRAME_MAX) {
        h->frames_dropped++;
        return true;
    }
    uint8_t f[PROTO_FRAME_MAX];
    memcpy(f, frame, len);
    stamp_seq(h, f, len);
    if (h->delay_us > 0) {
        if (h->n_held == HELD_MAX) {
            h->frames_dropped++;
            return true;
        }
        held_t *d = &h->held[h->n_held++];
        d->due_us = mono_us() + (uint64_t)h->delay_us;
        d->len = len;
        memcpy(d->b, f, len);
        return true;
    }
    if (h->reorder_n > 0) {
        if (!h->have_swap) {
            memcpy(h->swap.b, f, len);
            h->swap.len = len;
            h->have_swap = true;
            return true;
        }
        raw_send(h, f, len);
        raw_send(h, h->swap.b, h->swap.len);
        h->have_swap = false;
        h->reorder_n--;
        return true;
    }
    raw_send(h, f, len);
    if (h->duplicate_n > 0) {
        raw_send(h, f, len);
        h->duplicate_n--;
    }
    return true;
}

static bool shost_send(void *ctx, const uint8_t *f, size_t len)
{
    shost_t *h = ctx;
    pthread_mutex_lock(&h->mu);
    const bool ok = shost_send_locked(h, f, len);
    pthread_mutex_unlock(&h->mu);
    return ok;
}

static bool shost_step(shost_t *h, const scn_step_t *st, const msg_tool_t *tool,
                       uint32_t *rearm_ms);

/* Reads the clock's CAN socket: the first drive frame starts the scenario clock, each SYNC
 * after it is one tick; with nothing more, the wall clock may step (sim/scn_clock.h). */
static void shost_clock(shost_t *h)
{
    struct can_frame cf;
    while (h->sync_fd >= 0 && read(h->sync_fd, &cf, sizeof(cf)) == (ssize_t)sizeof(cf)) {
        const uint32_t id = cf.can_id & CAN_SFF_MASK;
        if (!h->synced && id != 0x080u && h->follow_path == NULL) {
            h->synced = true;
            scn_clock_init(&h->clk, true, (int64_t)mono_us());
            printf("%.6f scenario clock starts (drive frame 0x%03X)\n", realtime_s(),
                   (unsigned)id);
        } else if (h->synced && id == 0x080u) {
            (void)scn_clock_sync(&h->clk, (int64_t)mono_us());
        }
    }
    if (h->synced)
        (void)scn_clock_idle(&h->clk, (int64_t)mono_us());
}

/* Performs one host-side step, printed "T step line=N …" once done. */
static void shost_do(shost_t *h, const scn_step_t *st)
{
    uint32_t rearm_ms = 0;
    pthread_mutex_lock(&h->mu);
    const bool ok = shost_step(h, st, h->tool, &rearm_ms);
    pthread_mutex_unlock(&h->mu);
    if (rearm_ms > 0)
        atomic_store(&h->rearm_ms, rearm_ms);
    printf("%.6f step line=%u %s%s\n", realtime_s(), st->line, st->text, ok ? "" : " unsupported");
    if (!ok)
        atomic_fetch_add(&h->unsupported, 1);
}

/* With --follow: reads argil-sim's event log as it grows. Its start line starts the scenario,
 * each "host line=N" (argil-sim's clock passing a host-side step) is performed at once, and
 * its end line ends the run 100 ms later: one clock for both sides of the scenario. */
static void shost_follow(shost_t *h)
{
    if (h->follow_fd < 0) {
        h->follow_fd = open(h->follow_path, O_RDONLY | O_CLOEXEC);
        if (h->follow_fd < 0)
            return;
    }
    for (;;) {
        const ssize_t n = read(h->follow_fd, h->follow_buf + h->follow_len,
                               sizeof(h->follow_buf) - 1u - h->follow_len);
        if (n <= 0)
            break;
        h->follow_len += (size_t)n;
        h->follow_buf[h->follow_len] = '\0';
        char *line = h->follow_buf, *nl;
        while ((nl = strchr(line, '\n')) != NULL) {
            *nl = '\0';
            const char *host = strstr(line, ") host line=");
            if (strstr(line, ") start scenario ") != NULL && !h->synced) {
                h->synced = true;
                printf("%.6f scenario clock starts (argil-sim's start line)\n", realtime_s());
            } else if (host != NULL) {
                const unsigned long ln = strtoul(host + 12, NULL, 10);
                for (uint32_t i = 0; i < h->scn->n_steps; i++)
                    if (h->scn->step[i].line == ln &&
                        scenario_action_is_host_side(h->scn->step[i].action))
                        shost_do(h, &h->scn->step[i]);
            } else if (strstr(line, ") end ") != NULL && h->end_seen_us == 0) {
                h->end_seen_us = mono_us();
            }
            line = nl + 1;
        }
        h->follow_len = (size_t)(h->follow_buf + h->follow_len - line);
        memmove(h->follow_buf, line, h->follow_len);
        if (h->follow_len == sizeof(h->follow_buf) - 1u)
            h->follow_len = 0; /* a line longer than the buffer: not one of argil-sim's */
    }
}

/* Performs the host-side steps that are due on this host's own clock. */
static void shost_steps(shost_t *h)
{
    const scenario_t *scn = h->scn;
    while (h->synced && h->next_step < scn->n_steps &&
           scn->step[h->next_step].t_us <= h->clk.now_us) {
        const scn_step_t *st = &scn->step[h->next_step++];
        if (scenario_action_is_host_side(st->action))
            shost_do(h, st);
    }
}

/* The host's real-time side, at HIL_FIFO_PRIO: the scenario clock (it waits on the CAN socket,
 * so a SYNC is counted as it comes and a step lands in the tick it names, however busy the
 * peer is) and the host-side steps; and a heartbeat carrying the peer's window version and
 * impulse ack every 5 ms of CLOCK_MONOTONIC until h->stop, whatever the main loop is doing. */
static void shost_release_held(shost_t *h, bool all);

static void *shost_rt(void *arg)
{
    shost_t *h = arg;
    static proto_msg_t m;
    uint32_t seq = 0x20000000u;
    uint64_t next_beat = mono_us() + 5000u, last_turn = mono_us();
    uint32_t turns = 0;
    bool beats_due = false;
    uint64_t last_beat_us = 0;
    while (!atomic_load(&h->stop)) {
        const uint64_t turn = mono_us();
        if (beats_due && turn - last_turn > h->rt_max_gap_us) {
            h->rt_max_gap_us = turn - last_turn;
            h->rt_max_gap_at_us = turn - h->t0_us;
        }
        if (++turns == 2u)
            h->rt_first_turn_us = turn - last_turn;
        beats_due = atomic_load(&h->board_seen);
        last_turn = turn;
        if (h->sync_fd >= 0) {
            struct pollfd pfd = {.fd = h->sync_fd, .events = POLLIN};
            const uint64_t now = mono_us();
            (void)poll(&pfd, 1, next_beat > now ? 1 : 0);
        } else {
            const struct timespec nap = {0, 1000000L};
            nanosleep(&nap, NULL);
        }
        shost_clock(h);
        if (h->follow_path != NULL) {
            shost_follow(h);
            if (h->end_seen_us > 0 && mono_us() > h->end_seen_us + 100000u)
                atomic_store(&h->done, true);
        } else {
            shost_steps(h);
            if (h->synced && h->clk.now_us >= h->scn_end_us)
                atomic_store(&h->done, true);
        }
        if (h->stranger_kind >= 0) {
            pthread_mutex_lock(&h->mu);
            stranger_tick(h);
            pthread_mutex_unlock(&h->mu);
        }
        /* `link delay`: the held frames go when due from here, not from the peer's loop, which
         * a global solve under TCG holds for 100s of ms (the board then lost its host: the
         * heartbeats waited behind the solve, not behind the 30 ms delay) */
        pthread_mutex_lock(&h->mu);
        if (h->n_held > 0)
            shost_release_held(h, false);
        pthread_mutex_unlock(&h->mu);
        atomic_store(&h->synced_flag, h->synced);
        atomic_store(&h->now_us, (long long)h->clk.now_us);
        if (mono_us() < next_beat)
            continue;
        next_beat += 5000u;
        if (next_beat < mono_us())
            next_beat = mono_us() + 5000u; /* late: do not burst */
        if (!atomic_load(&h->board_seen))
            continue;
        memset(&m, 0, sizeof(m));
        m.type = MSG_HEARTBEAT;
        m.u.heartbeat.time_us = mono_us();
        m.u.heartbeat.window_version = atomic_load(&h->window_version);
        m.u.heartbeat.impulse_seq = atomic_load(&h->impulse_seq);
        m.u.heartbeat.command = PROTO_CMD_NONE;
        uint8_t buf[PROTO_FRAME_MAX];
        size_t len = 0;
        if (proto_encode(&m, seq++, buf, sizeof(buf), &len) == PROTO_OK) {
            (void)shost_send(h, buf, len);
            atomic_fetch_add(&h->beats, 1u);
            /* A gap of 4 heartbeats or more is printed when it ends, stamped like the board's
             * log, so a "host heartbeat lost" can be matched against what this host sent. */
            const uint64_t sent = mono_us();
            if (last_beat_us > 0 && sent - last_beat_us >= 20000u)
                printf("%.6f heartbeat gap %.1f ms\n", realtime_s(),
                       (double)(sent - last_beat_us) / 1e3);
            last_beat_us = sent;
        }
    }
    return NULL;
}

static void shost_on_tm(void *ctx, const msg_telemetry_t *t)
{
    shost_t *h = ctx;
    h->tm = *t;
    h->tm_n++;
    if (t->state != h->last_state) {
        printf("%.6f tick=%u state %s\n", realtime_s(), t->tick,
               safety_state_name((safety_state_t)t->state));
        h->last_state = t->state;
    }
    /* The board sculpts (drives enabled, window and tool in place): the scenario may start.
     * argil-sim holds its clock at 0 until this file exists. */
    if (h->ready_file != NULL && !h->ready_written && t->state == SAFETY_ACTIVE) {
        h->ready_written = true;
        const int fd = open(h->ready_file, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) {
            fprintf(stderr, "hil-host: cannot write %s (%s)\n", h->ready_file, strerror(errno));
            return;
        }
        char line[64];
        const int n = snprintf(line, sizeof(line), "ACTIVE tick=%u\n", t->tick);
        (void)!write(fd, line, (size_t)n);
        close(fd);
        printf("%.6f tick=%u ready: wrote %s\n", realtime_s(), t->tick, h->ready_file);
    }
}

static void shost_release_held(shost_t *h, bool all)
{
    const uint64_t now = mono_us();
    uint32_t k = 0;
    while (k < h->n_held && (all || h->held[k].due_us <= now))
        k++;
    for (uint32_t i = 0; i < k; i++)
        raw_send(h, h->held[i].b, h->held[i].len);
    memmove(h->held, h->held + k, (h->n_held - k) * sizeof(h->held[0]));
    h->n_held -= k;
}

static void shost_simple(shost_t *h, uint8_t type, uint8_t command)
{
    static proto_msg_t m;
    static uint32_t seq = 0x10000u;
    memset(&m, 0, sizeof(m));
    m.type = type;
    if (type == MSG_HELLO) {
        m.u.hello.role = PROTO_ROLE_HOST;
        memcpy(m.u.hello.name, "hil-host", 8);
    } else {
        m.u.heartbeat.time_us = mono_us();
        m.u.heartbeat.command = command;
    }
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    if (proto_encode(&m, seq++, buf, sizeof(buf), &len) == PROTO_OK)
        (void)shost_send(h, buf, len);
}

/* Sends the peer's TOOL with its radius replaced by a NaN and the CRC made valid again (proto
 * refuses to encode a non-finite field): what a broken host would send. False when the radius
 * is not where the layout puts it (after kind, shape, filter, flags). */
static bool shost_send_nan_tool(shost_t *h, const msg_tool_t *tool)
{
    static proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_TOOL;
    m.u.tool = *tool;
    m.u.tool.radius_m = 0.00123f; /* a marker to find at the radius's offset */
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    const size_t at = PROTO_HEADER_SIZE + 4u;
    uint8_t mark[4];
    memcpy(mark, &m.u.tool.radius_m, 4); /* little-endian host, as the wire */
    if (proto_encode(&m, 0x30000000u, buf, sizeof(buf), &len) != PROTO_OK ||
        len < at + 4u + PROTO_CRC_SIZE || memcmp(buf + at, mark, 4) != 0)
        return false;
    const float nan = NAN;
    memcpy(buf + at, &nan, 4);
    stamp_seq(h, buf, len); /* and the CRC made valid again */
    if (!h->lost)
        raw_send(h, buf, len);
    return true;
}

/* Performs one host-side step; false when this host cannot. */
static bool shost_step(shost_t *h, const scn_step_t *st, const msg_tool_t *tool,
                       uint32_t *rearm_ms)
{
    switch (st->action) {
    case SCN_REARM: *rearm_ms = 50; return true;         /* ARM for 50 ms of heartbeats */
    case SCN_LINK_LOST: h->lost = true; return true;
    case SCN_LINK_RESTORE:
        h->lost = false;
        h->delay_us = 0;
        h->duplicate_n = h->reorder_n = 0;
        shost_release_held(h, true);
        if (h->have_swap) {
            raw_send(h, h->swap.b, h->swap.len);
            h->have_swap = false;
        }
        return true;
    case SCN_LINK_DELAY: h->delay_us = st->dur_us; return true;
    case SCN_LINK_DUPLICATE: h->duplicate_n = st->a; return true;
    case SCN_LINK_REORDER: h->reorder_n = st->a; return true;
    case SCN_LINK_GARBAGE: {
        uint8_t junk[1024];
        uint32_t x = 0x9E3779B9u ^ (uint32_t)st->line;
        const size_t n = st->a > 0 && st->a <= 1024 ? (size_t)st->a : 1u;
        for (size_t i = 0; i < n; i++) {
            x ^= x << 13; x ^= x >> 17; x ^= x << 5;
            junk[i] = (uint8_t)x;
        }
        if (!h->lost)
            raw_send(h, junk, n);
        return true;
    }
    case SCN_LINK_NAN: return shost_send_nan_tool(h, tool);
    case SCN_STRANGER:
        if (h->stranger_fd < 0)
            return false;
        h->stranger_kind = st->a;
        h->stranger_until_us = mono_us() + (uint64_t)st->dur_us;
        h->stranger_last_us = 0;
        return true;
    default: return false;
    }
}

/* A raw CAN socket on iface that receives only the drives' NMT boot-up/heartbeat frames
 * (0x701-0x77F) and the board's SYNC (0x080); -1 with one line on stderr when it cannot be
 * opened. */
static int sync_can_open(const char *iface)
{
    const int s = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK, CAN_RAW);
    if (s < 0) {
        fprintf(stderr, "hil-host: CAN socket for --sync %s: %s\n", iface, strerror(errno));
        return -1;
    }
    const struct can_filter flt[2] = {{.can_id = 0x700u, .can_mask = CAN_SFF_MASK & ~0x7Fu},
                                      {.can_id = 0x080u, .can_mask = CAN_SFF_MASK}};
    (void)setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, flt, sizeof(flt));
    const int rcvbuf = 1 << 20; /* every SYNC counts: a starved moment must not drop one */
    if (setsockopt(s, SOL_SOCKET, SO_RCVBUFFORCE, &rcvbuf, sizeof(rcvbuf)) != 0)
        (void)setsockopt(s, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
    struct sockaddr_can addr = {.can_family = AF_CAN, .can_ifindex = (int)if_nametoindex(iface)};
    if (addr.can_ifindex == 0 || bind(s, (struct sockaddr *)&addr, sizeof(addr)) != 0) {
        fprintf(stderr, "hil-host: cannot bind CAN interface '%s' for the scenario clock\n", iface);
        close(s);
        return -1;
    }
    return s;
}

/* Runs the scenario's host side for `seconds` from its time 0: when sync_fd >= 0, the first
 * drive frame on it (argil-sim's drives boot when its scenario starts), else at once. */
static int run_scenario(int fd, const struct sockaddr_in *board, long seconds, const char *path,
                        int sync_fd, const char *follow, int beat_prio, const char *ready_file)
{
    static scenario_t scn;
    scn_error_t err;
    if (scenario_load(&scn, path, &err) != SCN_OK) {
        fprintf(stderr, "hil-host: %s:%u: %s\n", path, err.line, err.msg);
        return 2;
    }
    static shost_t h;
    static grid_t grid;
    static peer_t peer;
    memset(&h, 0, sizeof(h));
    h.fd = fd;
    h.board = *board;
    h.stranger_kind = -1;
    h.stranger_fd = -1;
    for (uint32_t i = 0; i < scn.n_steps; i++)
        if (scn.step[i].action == SCN_STRANGER && h.stranger_fd < 0)
            h.stranger_fd = stranger_open();
    h.last_state = 0xFFu;
    h.ready_file = ready_file;
    /* The SIL rig's clay and tool (tests/sil/rig.h): a 30 mm sphere at the model origin, the
     * stylus's home mapped 60 mm above its centre (the surface 26 mm under a 4 mm tool). */
    const int32_t dims[3] = {72, 72, 72};
    const float cell_m = 0.00125f, half = 0.5f * 71.0f * cell_m;
    if (grid_init(&grid, dims, cell_m, vec3(-half, -half, -half)) != ARGIL_OK)
        return 2;
    grid_fill_sphere(&grid, vec3(0, 0, 0), 0.030f);
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.window_edge = 16;
    /* The global solve once a second: this host tests the board, the solve is tested
     * elsewhere; under TCG a solve takes 100s of ms and held the windows back, so the board
     * sat ARMED without a window (no ACTIVE, no force) in the VM at 02:29 UTC. */
    pc.solve_period_us = 1000000u;
    if (peer_init(&peer, &pc, &grid, shost_send, shost_on_tm, &h) != ARGIL_OK)
        return 2;
    static sim_params_t arm_p;
    static sim_device_t dev;
    sim_params_default(&arm_p);
    sim_device_init(&dev, &arm_p);
    const vec3_t offset = vec3_sub(vec3(0, 0, 0.060f), sim_device_tip_m(&dev));
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_TOUCH;
    t.shape = TOOL_SHAPE_POINT;
    t.filter = BETA_GAUSSIAN;
    t.radius_m = 0.004f;
    t.axis[2] = 1.0f;
    t.alpha = 30000.0f;
    t.contact_stiffness_n_per_m = 800.0f;
    t.max_force_n = 3.3f;
    t.iso = 0.5f;
    t.yield_force_n = 0.5f;
    t.probe_gain = 0.02f;
    t.rope_stiffness_n_per_m = 200.0f;
    t.model_scale = 1.0f;
    t.model_offset_m[0] = offset.x;
    t.model_offset_m[1] = offset.y;
    t.model_offset_m[2] = offset.z;
    peer_set_tool(&peer, &t);
    peer_request_arm(&peer);

    static uint8_t buf[65536];
    /* Priority inheritance: the peer's loop (20 below) holds the link lock while it sends; a
     * thread between the two must not keep the heartbeats and steps waiting on it. */
    pthread_mutexattr_t mattr;
    pthread_mutexattr_init(&mattr);
    pthread_mutexattr_setprotocol(&mattr, PTHREAD_PRIO_INHERIT);
    pthread_mutex_init(&h.mu, &mattr);
    pthread_mutexattr_destroy(&mattr);
    /* Until the scenario clock starts, the peer runs (HELLO, windows, ARM) with no steps. With
     * --sync the clock is the board's: one 1 ms step per SYNC on the bus (sim/scn_clock.h, as
     * argil-sim's), so host-side steps land at the board tick the scenario names however slow
     * the board runs; the run ends 100 ms of scenario time after the scenario's end. `seconds`
     * of wall time bound the whole run. */
    h.scn = &scn;
    h.tool = &t;
    h.sync_fd = sync_fd;
    h.follow_path = follow;
    h.follow_fd = -1;
    h.synced = sync_fd < 0 && follow == NULL;
    h.scn_end_us = sync_fd >= 0 ? scn.duration_us + 100000 : (int64_t)seconds * 1000000;
    h.t0_us = mono_us();
    scn_clock_init(&h.clk, sync_fd >= 0, (int64_t)h.t0_us);
    pthread_t beat;
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    if (beat_prio > 0) {
        const struct sched_param sp = {.sched_priority = beat_prio};
        pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
        pthread_attr_setschedparam(&attr, &sp);
    }
    if (pthread_create(&beat, &attr, shost_rt, &h) != 0) {
        fprintf(stderr, "hil-host: cannot start the real-time thread at FIFO %d\n", beat_prio);
        pthread_attr_destroy(&attr);
        return 2;
    }
    pthread_attr_destroy(&attr);
    uint64_t last_tick_us = h.t0_us;
    const uint64_t t_end = h.t0_us + (uint64_t)seconds * 1000000u;
    uint64_t next = h.t0_us;
    uint32_t last_tm_print = 0, rearm_ms = 0;
    for (uint32_t ms = 0; mono_us() < t_end && !atomic_load(&h.done); ms++) {
        ssize_t n;
        while ((n = udp_in(fd, buf, sizeof(buf))) > 0)
            if (!h.lost)
                peer_receive(&peer, buf, (size_t)n);
        /* What the board renders, every 250 of its ticks: enough to see a press that gives
         * no force, and why. */
        if (h.tm_n > 0 && h.tm.tick - last_tm_print >= 250u) {
            last_tm_print = h.tm.tick;
            const float *f = h.tm.force_n;
            printf("%.6f tick=%u tm %s z=%.1f mm force %.2f N contact %u window %u scn_t=%.3f\n",
                   realtime_s(), h.tm.tick, safety_state_name((safety_state_t)h.tm.state),
                   (double)h.tm.pos_m[2] * 1e3,
                   sqrt((double)(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])), h.tm.flags & 1u,
                   h.tm.window_version, (double)atomic_load(&h.now_us) / 1e6);
        }
        if (!peer.board_seen && ms % 50 == 0)
            shost_simple(&h, MSG_HELLO, 0);
        const uint32_t want = atomic_exchange(&h.rearm_ms, 0u);
        if (want > 0)
            rearm_ms = want;
        if (rearm_ms > 0) {
            if (rearm_ms % 5 == 0)
                shost_simple(&h, MSG_HEARTBEAT, PROTO_CMD_ARM);
            rearm_ms--;
        }
        /* The peer's clock is wall time, however late this loop runs. */
        const uint64_t tick_now = mono_us();
        const uint64_t dt = tick_now - last_tick_us;
        last_tick_us = tick_now;
        peer_tick(&peer, dt > 100000u ? 100000u : (uint32_t)dt);
        atomic_store(&h.window_version, peer.have_current ? peer.current.version : 0u);
        atomic_store(&h.impulse_seq, peer.impulse_seq_applied);
        atomic_store(&h.board_seen, peer.board_seen);
        next += 1000;
        const uint64_t now = mono_us();
        if (next < now)
            next = now; /* late: do not burst */
        struct timespec ts = {(time_t)(next / 1000000u), (long)(next % 1000000u) * 1000};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
    }
    atomic_store(&h.stop, true);
    pthread_join(beat, NULL);
    printf("%.6f telemetry=%u frames_sent=%u dropped=%u windows=%u beats=%u solves=%u "
           "clock %s syncs=%u wall_steps=%u scn_t=%.3f rt_max_gap_ms=%.1f rt_max_gap_at_s=%.3f "
           "rt_first_turn_ms=%.1f\n",
           realtime_s(), h.tm_n, h.frames_sent, h.frames_dropped, peer.stats.windows_sent,
           atomic_load(&h.beats), peer.stats.solves, sync_fd >= 0 ? "ticks" : "wall", h.clk.syncs,
           h.clk.wall_steps, (double)h.clk.now_us / 1e6, (double)h.rt_max_gap_us / 1e3,
           (double)h.rt_max_gap_at_us / 1e6, (double)h.rt_first_turn_us / 1e3);
    if (h.stranger_fd >= 0) {
        /* what the stranger sent, and the board's refusals as its last RT_STATS counts them */
        const proto_link_counts_t *lc = &peer.last_rt.link;
        printf("%.6f stranger replayed_other=%u replayed_own=%u forged=%u flooded=%u "
               "send_errors=%u keyed=%d; board refused wrong_source=%u no_session=%u "
               "duplicate=%u stale=%u decode_errors=%u bad_mac=%u bad_nonce=%u sessions=%u "
               "(RT_STATS %u)\n",
               realtime_s(), h.replayed_other, h.replayed_own, h.forged, h.flooded,
               h.stranger_errors, g_keyed ? 1 : 0, lc->wrong_source, lc->no_session,
               lc->duplicate, lc->stale, lc->decode_errors, lc->bad_mac, lc->bad_nonce,
               lc->sessions, peer.stats.rt_stats_frames);
        close(h.stranger_fd);
    }
    peer_free(&peer);
    grid_free(&grid);
    if (h.follow_fd >= 0)
        close(h.follow_fd);
    if (!h.synced) {
        fprintf(stderr, "hil-host: no drive frame on the sync interface in %ld s: the scenario never started\n",
                seconds);
        return 1;
    }
    if (h.tm_n == 0)
        return 1;
    return atomic_load(&h.unsupported) ? 3 : 0;
}

int main(int argc, char **argv)
{
    char *end1 = NULL, *end2 = NULL;
    /* "--sync IFACE" after the scenario: its clock starts at the first drive frame on IFACE. */
    const char *sync_if = NULL, *follow = NULL, *ready_file = NULL;
    /* "--ready-file FILE" anywhere: written when the board goes ACTIVE (scenarios only). */
    for (int i = 1; i + 1 < argc; i++)
        if (strcmp(argv[i], "--ready-file") == 0) {
            ready_file = argv[i + 1];
            for (int k = i; k + 2 < argc; k++)
                argv[k] = argv[k + 2];
            argc -= 2;
            break;
        }
    if (argc == 8 && strcmp(argv[6], "--follow") == 0) {
        follow = argv[7];
        argc = 6;
    }
    if (argc == 6 && strcmp(argv[4], "--sync") == 0) {
        sync_if = argv[5];
        argc = 4;
    }
    const bool args_ok = argc == 3 || argc == 4;
    const long port = args_ok ? strtol(argv[1], &end1, 10) : 0;
    const long seconds = args_ok ? strtol(argv[2], &end2, 10) : 0;
    if (!args_ok || *end1 || *end2 || port < 1 || port > 65535 || seconds < 1 || seconds > 3600) {
        fprintf(stderr, "usage: hil-host PORT SECONDS [SCENARIO [--sync CAN_IF [--follow "
                        "EVENT_LOG]]] [--ready-file FILE] (port 1-65535, 1-3600 s)\n");
        return 2;
    }
    link_key_t key;
    char err[400];
    if (link_key_file_load_env("ARGIL_LINK_KEY", &key, &g_keyed, err, sizeof(err)) != LINK_KEY_OK) {
        fprintf(stderr, "hil-host: ARGIL_LINK_KEY: %s\n", err);
        return 2;
    }
    if (g_keyed)
        link_auth_host_init(&g_auth, &key, link_crypto_mac);
    pthread_mutexattr_t auth_attr;
    pthread_mutexattr_init(&auth_attr);
    pthread_mutexattr_setprotocol(&auth_attr, PTHREAD_PRIO_INHERIT);
    pthread_mutex_init(&g_auth_mu, &auth_attr);
    pthread_mutexattr_destroy(&auth_attr);
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    if (fd < 0) {
        perror("hil-host: socket");
        return 1;
    }
    struct sockaddr_in board = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &board.sin_addr);
    setvbuf(stdout, NULL, _IOLBF, 0);
    const char *prio_env = getenv("HIL_FIFO_PRIO");
    const int prio_in = prio_env ? atoi(prio_env) : 0;
    const int prio = prio_in >= 1 && prio_in <= 98 ? prio_in : 0;
    if (prio > 0) {
        /* A scenario host's heartbeats get prio; its peer (grid, solve, windows) runs
         * HOST_LOOP_DROP below, under the board's link thread, which must stay free to take
         * the heartbeats in. */
        struct sched_param sp = {.sched_priority = argc == 4 && prio > HOST_LOOP_DROP
                                                       ? prio - HOST_LOOP_DROP
                                                       : prio};
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
            fprintf(stderr, "hil-host: SCHED_FIFO %d: %s\n", prio, strerror(errno));
    }

    if (argc == 4) {
        const int sync_fd = sync_if ? sync_can_open(sync_if) : -1;
        if (sync_if != NULL && sync_fd < 0) {
            close(fd);
            return 1;
        }
        const int st = run_scenario(fd, &board, seconds, argv[3], sync_fd, follow, prio,
                                     ready_file);
        if (sync_fd >= 0)
            close(sync_fd);
        close(fd);
        return st;
    }
    static proto_msg_t m, rx;
    static uint8_t buf[65536];
    uint32_t seq = 0, telemetry_n = 0, last_state = 0xFFu;
    int armed_once = 0;
    double last_heartbeat_s = 0.0, max_gap_s = 0.0;
    /* Board ticks between two heartbeats, as the newest telemetry tells: what the board's
     * host timeout counts (the whole VM may stall; then no tick passes either). */
    uint32_t newest_tick = 0, tick_at_heartbeat = 0, max_gap_ticks = 0;
    uint64_t next_heartbeat_us = 0;
    const uint64_t t_end = mono_us() + (uint64_t)seconds * 1000000u;
    for (uint32_t ms = 0; mono_us() < t_end; ms++) {
        ssize_t n;
        while ((n = udp_in(fd, buf, sizeof(buf))) > 0) {
            size_t used = 0;
            if (proto_decode(buf, (size_t)n, &rx, &used) != PROTO_OK || rx.type != MSG_TELEMETRY)
                continue;
            telemetry_n++;
            const msg_telemetry_t *t = &rx.u.telemetry;
            if (t->tick > newest_tick)
                newest_tick = t->tick;
            if (t->state == SAFETY_ARMED || t->state == SAFETY_ACTIVE)
                armed_once = 1;
            if (t->state != last_state) {
                printf("%.6f tick=%u state %s\n", realtime_s(), t->tick,
                       safety_state_name((safety_state_t)t->state));
                last_state = t->state;
            }
        }
        memset(&m, 0, sizeof(m));
        if (telemetry_n == 0 && ms % 50 == 0) {
            m.type = MSG_HELLO;
            m.u.hello.role = PROTO_ROLE_HOST;
            memcpy(m.u.hello.name, "hil-host", 8);
            send_msg(fd, &board, &m, &seq);
        } else if (telemetry_n > 0 && mono_us() >= next_heartbeat_us) {
            /* Every 2 ms of wall time, however late this loop runs. */
            m.type = MSG_HEARTBEAT;
            m.u.heartbeat.time_us = mono_us();
            m.u.heartbeat.command = armed_once ? PROTO_CMD_NONE : PROTO_CMD_ARM;
            send_msg(fd, &board, &m, &seq);
            const double now_s = realtime_s();
            if (last_heartbeat_s > 0.0 && now_s - last_heartbeat_s > max_gap_s)
                max_gap_s = now_s - last_heartbeat_s;
            if (last_heartbeat_s > 0.0 && newest_tick - tick_at_heartbeat > max_gap_ticks)
                max_gap_ticks = newest_tick - tick_at_heartbeat;
            tick_at_heartbeat = newest_tick;
            last_heartbeat_s = now_s;
            next_heartbeat_us = mono_us() + 2000u;
        }
        const struct timespec nap = {0, 1000000L};
        nanosleep(&nap, NULL);
    }
    printf("%.6f last-heartbeat max-gap-ms=%.1f max-gap-ticks=%u\n", last_heartbeat_s,
           max_gap_s * 1e3, max_gap_ticks);
    printf("%.6f telemetry=%u\n", realtime_s(), telemetry_n);
    close(fd);
    return telemetry_n > 0 ? 0 : 1;
}
