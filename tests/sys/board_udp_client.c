/* A host for tests/sys/test_board_daemon.sh: talks to a running argil-board over real UDP on
 * 127.0.0.1 with the host's protocol peer, and checks what a person would notice:
 *   1. HELLO → the board answers, takes the window, arms and goes ACTIVE;
 *   2. the host falls silent → FAULT (host lost) 50 ms of board ticks after the board's last
 *      host heartbeat and the force zero, sculpting off, 20 ms of ticks later (50 + 20 ticks at
 *      1 kHz, 100 + 40 at 2 kHz: the rate is the one the board's HELLO gives), counted in the
 *      board's own ticks (its telemetry's tick), so the bounds hold on
 *      a board that ticks slower than 1 kHz (the HIL VM) as on a real one;
 *   3. a new host (new socket) says HELLO → window re-sent, re-arm → ACTIVE again, no restart.
 * Usage: board_udp_client PORT [LINK_TICKS]. LINK_TICKS (default 1): board ticks the link may
 * take each way (heartbeat in, telemetry out). With ARGIL_LINK_KEY=FILE in the environment every
 * datagram is sealed with that link key and the board's verified (docs/link.md). Prints one line
 * per phase; exit 0 when all hold. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <math.h>
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

/* The daemon's defaults (firmware/board/board_config.c), which the test runs with. */
#define HOST_TIMEOUT_MS 50
#define HOST_FADE_MS 20

typedef struct {
    int fd;
    struct sockaddr_in board;
    peer_t peer;
    grid_t grid;
    msg_telemetry_t tm;
    uint32_t tm_count;
    uint32_t hello_from_board;
} host_t;

static bool g_keyed;              /* ARGIL_LINK_KEY given: every datagram sealed and verified */
static link_auth_host_t g_auth;

static bool udp_send(void *ctx, const uint8_t *f, size_t len)
{
    host_t *h = ctx;
    uint8_t sealed[LINK_AUTH_DGRAM_MAX];
    if (g_keyed && (len = link_auth_host_seal(&g_auth, f, len, sealed, sizeof(sealed))) == 0)
        return false;
    return sendto(h->fd, g_keyed ? sealed : f, len, 0, (struct sockaddr *)&h->board,
                  sizeof(h->board)) == (ssize_t)len;
}

/* The next datagram's frames from the board (keyed: verified, the trailer off); <= 0: none. */
static ssize_t udp_recv(host_t *h, uint8_t *buf, size_t cap)
{
    for (;;) {
        const ssize_t n = recv(h->fd, buf, cap, 0);
        size_t flen = 0;
        if (n <= 0 || !g_keyed)
            return n;
        if (link_auth_host_open(&g_auth, buf, (size_t)n, &flen) == LINK_AUTH_OK)
            return (ssize_t)flen;
    }
}

static void on_tm(void *ctx, const msg_telemetry_t *t)
{
    host_t *h = ctx;
    h->tm = *t;
    h->tm_count++;
}

static uint64_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

/* A HELLO or a heartbeat with a command, numbered in the peer's one sequence (the board's
 * session refuses a number it has seen). */
static void send_simple(host_t *h, uint8_t type, uint8_t command)
{
    if (type == MSG_HELLO)
        (void)peer_send_hello(&h->peer, "udp-test-host");
    else
        (void)peer_send_command(&h->peer, command);
}

static void host_open(host_t *h, int port)
{
    memset(h, 0, sizeof(*h));
    g_auth.nonce = 0; /* a new host: it learns its session's nonce from the board's answer */
    h->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    h->board.sin_family = AF_INET;
    h->board.sin_port = htons((uint16_t)port);
    inet_pton(AF_INET, "127.0.0.1", &h->board.sin_addr);
    const int32_t dims[3] = {72, 72, 72};
    const float half = 0.5f * 71 * 0.00125f;
    if (grid_init(&h->grid, dims, 0.00125f, vec3(-half, -half, 0.174f - half)) != ARGIL_OK)
        exit(2);
    grid_fill_sphere(&h->grid, vec3(0, 0, 0.174f - 0.040f), 0.030f);
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.window_edge = 16;
    /* No global solve in this loop: it would stall the heartbeats (the real host solves on its
     * own thread); this client tests the link. */
    pc.solve_period_us = UINT32_MAX;
    if (peer_init(&h->peer, &pc, &h->grid, udp_send, on_tm, h) != ARGIL_OK)
        exit(2);
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_TOUCH;
    t.radius_m = 0.004f;
    t.axis[2] = 1.0f; /* unit axis (a point tool ignores it; the decoder checks it) */
    t.alpha = 12000.0f;
    t.contact_stiffness_n_per_m = 800.0f;
    t.max_force_n = 3.3f;
    t.model_scale = 1.0f;
    peer_set_tool(&h->peer, &t);
    peer_request_arm(&h->peer);
}

static void host_close(host_t *h)
{
    peer_free(&h->peer);
    grid_free(&h->grid);
    close(h->fd);
}

/* One millisecond of host: receive, tick the peer (if talking), sleep to the next ms. */
static void host_ms(host_t *h, bool talking, uint64_t *next)
{
    static uint8_t buf[65536];
    ssize_t n;
    while ((n = udp_recv(h, buf, sizeof(buf))) > 0) {
        if (n >= 6 && buf[5] == MSG_HELLO)
            h->hello_from_board++;
        peer_receive(&h->peer, buf, (size_t)n);
    }
    if (talking)
        peer_tick(&h->peer, 1000);
    *next += 1000;
    struct timespec ts = {(time_t)(*next / 1000000u), (long)(*next % 1000000u) * 1000};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
}

/* Talks until the board is ACTIVE; returns ms taken or -1. rearm: send ARM ourselves once the
 * window is current (after a fault the peer, like a person, does not re-arm on its own). */
static int until_active(host_t *h, int max_ms, bool rearm)
{
    uint64_t next = now_us();
    for (int ms = 0; ms < max_ms; ms++) {
        if (!h->peer.board_seen && ms % 50 == 0)
            send_simple(h, MSG_HELLO, 0);
        if (rearm && h->peer.have_current && h->tm_count > 0 && h->tm.state == SAFETY_FAULT &&
            ms % 20 == 0)
            send_simple(h, MSG_HEARTBEAT, PROTO_CMD_ARM);
        host_ms(h, true, &next);
        if (h->tm_count > 0 && h->tm.state == SAFETY_ACTIVE)
            return ms + 1;
    }
    return -1;
}

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 3)
        return 2;
    const int port = atoi(argv[1]);
    const int link_ticks = argc == 3 ? atoi(argv[2]) : 1;
    if (link_ticks < 0 || link_ticks > 50)
        return 2;
    link_key_t key;
    char err[400];
    if (link_key_file_load_env("ARGIL_LINK_KEY", &key, &g_keyed, err, sizeof(err)) != LINK_KEY_OK) {
        fprintf(stderr, "board_udp_client: ARGIL_LINK_KEY: %s\n", err);
        return 2;
    }
    if (g_keyed)
        link_auth_host_init(&g_auth, &key, link_crypto_mac);
    static host_t h;
    host_open(&h, port);
    const int t1 = until_active(&h, 4000, false);
    printf("phase 1: ACTIVE after %d ms (board HELLOs %u, telemetry frames %u)\n", t1,
           h.hello_from_board, h.tm_count);
    if (t1 < 0) {
        printf("FAIL: board state %u, never ACTIVE\n", h.tm.state);
        return 1;
    }
    if (h.peer.board_tick_hz == 0) {
        printf("FAIL: the board's HELLO gave no loop rate\n");
        return 1;
    }
    /* ACTIVE for 300 ms more, heartbeats every 5 ms (no solve, which would stall this loop):
     * the window's frames are through and our view of the board's tick is as fresh as the
     * link makes it (right after ACTIVE it lagged 24 ticks in the VM while they queued). */
    uint64_t next = now_us();
    for (int ms = 0; ms < 300; ms++) {
        if (ms % 5 == 0)
            send_simple(&h, MSG_HEARTBEAT, PROTO_CMD_NONE);
        host_ms(&h, false, &next);
    }
    if (h.tm.state != SAFETY_ACTIVE) {
        printf("FAIL: board state %u while the host kept up its heartbeats\n", h.tm.state);
        return 1;
    }
    /* 2: silence after one last heartbeat, sent right after the newest telemetry was read:
     * the board takes it in at tick0 (the tick that telemetry reported) or later. Keep
     * listening (3 s of wall time at most, and 300 board ticks); find the board ticks at which
     * the state is FAULT and the force zero. */
    static uint8_t drain[65536];
    ssize_t got;
    while ((got = udp_recv(&h, drain, sizeof(drain))) > 0)
        peer_receive(&h.peer, drain, (size_t)got);
    send_simple(&h, MSG_HEARTBEAT, PROTO_CMD_NONE);
    const int64_t tick0 = h.tm.tick;
    next = now_us();
    const uint64_t t0 = next;
    int64_t fault_tick = -1, zero_tick = -1;
    int fault_ms = -1;
    float peak_after_fault = 0.0f;
    for (int ms = 0; ms < 3000 && (int64_t)h.tm.tick - tick0 < 300; ms++) {
        host_ms(&h, false, &next);
        const float f = sqrtf(h.tm.force_n[0] * h.tm.force_n[0] + h.tm.force_n[1] * h.tm.force_n[1] +
                              h.tm.force_n[2] * h.tm.force_n[2]);
        const int64_t tick = (int64_t)h.tm.tick - tick0;
        if (fault_tick < 0 && h.tm.state == SAFETY_FAULT) {
            fault_tick = tick;
            fault_ms = (int)((now_us() - t0) / 1000u);
        }
        if (fault_tick >= 0 && zero_tick < 0 && f == 0.0f && (h.tm.flags & 2u) == 0)
            zero_tick = tick;
        if (zero_tick >= 0 && tick > zero_tick && f > peak_after_fault)
            peak_after_fault = f;
    }
    /* The board took our last heartbeat in no earlier than tick0, and no later than the link's
     * delivery after the tick it was at when we sent it, which our view (tick0) trails by the
     * link's delivery of telemetry: FAULT (50 ms of silence in the board's ticks at the rate its
     * HELLO gave: 50 at 1 kHz, 100 at 2 kHz) within timeout .. timeout + 2 links + 1, and the
     * force zero once the 20 ms fade has run too. */
    const int64_t timeout_ticks = (int64_t)HOST_TIMEOUT_MS * h.peer.board_tick_hz / 1000;
    const int64_t fade_ticks = (int64_t)HOST_FADE_MS * h.peer.board_tick_hz / 1000;
    const int64_t fault_lo = timeout_ticks, fault_hi = timeout_ticks + 2 * link_ticks + 1;
    const int64_t zero_hi = timeout_ticks + fade_ticks + 2 * link_ticks + 1;
    printf("phase 2: host silent: FAULT (host lost) after %lld board ticks (%d ms), force zero "
           "and sculpting off after %lld ticks, peak force after that %.3f N (bounds: FAULT "
           "%lld..%lld, zero by %lld ticks)\n", (long long)fault_tick, fault_ms,
           (long long)zero_tick, (double)peak_after_fault, (long long)fault_lo,
           (long long)fault_hi, (long long)zero_hi);
    if (fault_tick < fault_lo || fault_tick > fault_hi || zero_tick < 0 || zero_tick > zero_hi ||
        peak_after_fault != 0.0f) {
        printf("FAIL: host-loss timing\n");
        return 1;
    }
    host_close(&h);
    /* 3: a new host. */
    host_open(&h, port);
    const int t3 = until_active(&h, 4000, true);
    printf("phase 3: reconnected host: board HELLO %s, windows sent %u, ACTIVE again after %d ms\n",
           h.hello_from_board ? "received" : "missing", h.peer.stats.windows_sent, t3);
    if (t3 < 0 || h.hello_from_board == 0 || h.peer.stats.windows_sent == 0) {
        printf("FAIL: no resynchronisation (state %u)\n", h.tm.state);
        return 1;
    }
    host_close(&h);
    printf("ok\n");
    return 0;
}
