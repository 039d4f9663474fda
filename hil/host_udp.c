/* hil-host: the smallest live host for the HIL rig's checks: over UDP it says HELLO, sends a
 * heartbeat every 5 ms and asks the board to ARM (until it is ARMED or ACTIVE once), and prints
 * every safety state the board's telemetry reports, with the CLOCK_REALTIME time it arrived
 * (the clock of candump -L and hil-probe) and the board's tick:
 *   1795387992.352639 tick=1234 state ARMED
 * It sends no window, so the board stops at ARMED (drives on, zero torque): enough to see
 * DRIVE_ENABLE high and every fault take it down. At the end it prints the time of its last
 * heartbeat ("T last-heartbeat") and falls silent, as a host that is unplugged.
 * Usage: hil-host PORT SECONDS [SCENARIO]. With HIL_FIFO_PRIO=N it runs SCHED_FIFO at N so a
 * busy rig does not starve it. Exit 0 when the board answered, 1 when it never did, 2 usage.
 *
 * With a SCENARIO (a hil/scenarios file) it is the scenario's host side instead: the host's
 * protocol peer (host/app/peer.c: tool, windows around the tool over a clay sphere, heartbeats,
 * ARM) so the board goes ACTIVE and sculpts, and at their times the host-side steps: rearm,
 * link lost / restore / delay / duplicate / reorder / garbage. Its clock starts when it starts
 * (start it together with argil-sim). It prints one line per step performed; a step it cannot
 * perform over UDP (overrun, nan_tool) is printed as "unsupported" and the exit status is 3. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/peer.h"
#include "host/model/grid.h"
#include "shared/proto.h"
#include "sim/scenario.h"

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

static void send_msg(int fd, const struct sockaddr_in *to, proto_msg_t *m, uint32_t *seq)
{
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    if (proto_encode(m, (*seq)++, buf, sizeof(buf), &len) == PROTO_OK)
        (void)sendto(fd, buf, len, 0, (const struct sockaddr *)to, sizeof(*to));
}


/* ---- scenario host ---- */
#define HELD_MAX 64u

typedef struct {
    uint64_t due_us;
    size_t len;
    uint8_t b[PROTO_FRAME_MAX];
} held_t;

typedef struct {
    int fd;
    struct sockaddr_in board;
    uint64_t t0_us;
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
} shost_t;

static void raw_send(shost_t *h, const uint8_t *f, size_t len)
{
    (void)sendto(h->fd, f, len, 0, (const struct sockaddr *)&h->board, sizeof(h->board));
    h->frames_sent++;
}

/* The peer's frames go through the scripted link faults. */
static bool shost_send(void *ctx, const uint8_t *f, size_t len)
{
    shost_t *h = ctx;
    if (h->lost || len > PROTO_FRAME_MAX) {
        h->frames_dropped++;
        return true;
    }
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

/* Performs one host-side step; false when this host cannot. */
static bool shost_step(shost_t *h, const scn_step_t *st, uint32_t *rearm_ms)
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
    default: return false;
    }
}

static int run_scenario(int fd, const struct sockaddr_in *board, long seconds, const char *path)
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
    h.last_state = 0xFFu;
    /* A clay sphere under the stylus's home, as the SIL rig and argil sculpt use. */
    const int32_t dims[3] = {72, 72, 72};
    const float cell_m = 0.00125f, half = 0.5f * 71.0f * cell_m;
    if (grid_init(&grid, dims, cell_m, vec3(-half, -half, 0.174f - half)) != ARGIL_OK)
        return 2;
    grid_fill_sphere(&grid, vec3(0, 0, 0.174f - 0.040f), 0.030f);
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.window_edge = 16;
    if (peer_init(&peer, &pc, &grid, shost_send, shost_on_tm, &h) != ARGIL_OK)
        return 2;
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_TOUCH;
    t.radius_m = 0.004f;
    t.axis[2] = 1.0f;
    t.alpha = 12000.0f;
    t.contact_stiffness_n_per_m = 800.0f;
    t.max_force_n = 3.3f;
    t.model_scale = 1.0f;
    peer_set_tool(&peer, &t);
    peer_request_arm(&peer);

    int unsupported = 0;
    uint32_t next_step = 0, rearm_ms = 0;
    static uint8_t buf[65536];
    h.t0_us = mono_us();
    const uint64_t t_end = h.t0_us + (uint64_t)seconds * 1000000u;
    uint64_t next = h.t0_us;
    for (uint32_t ms = 0; mono_us() < t_end; ms++) {
        const int64_t now_us = (int64_t)(mono_us() - h.t0_us);
        while (next_step < scn.n_steps && scn.step[next_step].t_us <= now_us) {
            const scn_step_t *st = &scn.step[next_step++];
            if (!scenario_action_is_host_side(st->action))
                continue;
            const bool ok = shost_step(&h, st, &rearm_ms);
            printf("%.6f step line=%u %s%s\n", realtime_s(), st->line, st->text,
                   ok ? "" : " unsupported");
            unsupported += !ok;
        }
        ssize_t n;
        while ((n = recv(fd, buf, sizeof(buf), 0)) > 0)
            if (!h.lost)
                peer_receive(&peer, buf, (size_t)n);
        if (!peer.board_seen && ms % 50 == 0)
            shost_simple(&h, MSG_HELLO, 0);
        if (rearm_ms > 0) {
            if (rearm_ms % 5 == 0)
                shost_simple(&h, MSG_HEARTBEAT, PROTO_CMD_ARM);
            rearm_ms--;
        }
        peer_tick(&peer, 1000);
        shost_release_held(&h, false);
        next += 1000;
        const uint64_t now = mono_us();
        if (next < now)
            next = now; /* late: do not burst */
        struct timespec ts = {(time_t)(next / 1000000u), (long)(next % 1000000u) * 1000};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
    }
    printf("%.6f telemetry=%u frames_sent=%u dropped=%u windows=%u\n", realtime_s(), h.tm_n,
           h.frames_sent, h.frames_dropped, peer.stats.windows_sent);
    peer_free(&peer);
    grid_free(&grid);
    if (h.tm_n == 0)
        return 1;
    return unsupported ? 3 : 0;
}

int main(int argc, char **argv)
{
    char *end1 = NULL, *end2 = NULL;
    const bool args_ok = argc == 3 || argc == 4;
    const long port = args_ok ? strtol(argv[1], &end1, 10) : 0;
    const long seconds = args_ok ? strtol(argv[2], &end2, 10) : 0;
    if (!args_ok || *end1 || *end2 || port < 1 || port > 65535 || seconds < 1 || seconds > 3600) {
        fprintf(stderr, "usage: hil-host PORT SECONDS [SCENARIO] (port 1-65535, 1-3600 s)\n");
        return 2;
    }
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    if (fd < 0) {
        perror("hil-host: socket");
        return 1;
    }
    struct sockaddr_in board = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    inet_pton(AF_INET, "127.0.0.1", &board.sin_addr);
    setvbuf(stdout, NULL, _IOLBF, 0);
    const char *prio_env = getenv("HIL_FIFO_PRIO");
    const int prio = prio_env ? atoi(prio_env) : 0;
    if (prio >= 1 && prio <= 98) {
        struct sched_param sp = {.sched_priority = prio};
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
            fprintf(stderr, "hil-host: SCHED_FIFO %d: %s\n", prio, strerror(errno));
    }

    if (argc == 4) {
        const int st = run_scenario(fd, &board, seconds, argv[3]);
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
        while ((n = recv(fd, buf, sizeof(buf), 0)) > 0) {
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
