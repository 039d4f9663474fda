/* argil-board: the board daemon. Reads the configuration (defaults, INI file, command line),
 * opens the drives' CAN bus, the GPIO lines and the host link, then runs the core's tick in a
 * SCHED_FIFO thread on absolute CLOCK_MONOTONIC deadlines while a lower-priority thread moves
 * host frames through SPSC rings. See docs/board.md. */
#define _GNU_SOURCE
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include "board_config.h"
#include "firmware/core/board_hal.h"
#include "firmware/core/rt_stats.h"
#include "firmware/hal/hal_linux.h"
#include "firmware/hal/hal_sim_bus.h"
#include "firmware/hal/link_io.h"
#include "firmware/hal/link_key.h"

#define PROG "argil-board"
#define VERSION "argil-board 1 (protocol v3)"
#define PREFAULT_STACK_BYTES (256u * 1024u)

/* ---- command line ---- */

static void usage(FILE *out)
{
    fprintf(out,
            "usage: " PROG " [--config FILE] [OPTION VALUE]...\n"
            "Runs the haptic arm's real-time loop: CiA 402 drives over SocketCAN, GPIO lines\n"
            "through libgpiod, and the host link over UDP or a USB FunctionFS gadget.\n"
            "Settings come from the defaults, then the INI file, then the options, in that\n"
            "order; every option is also a key of the file ([section] key = value).\n\n"
            "  --config FILE            INI file (example: firmware/board/argil-board.ini)\n"
            "  --set SECTION.KEY=VALUE  any file setting from the command line\n"
            "  --help, --version\n\n");
    const char *section = "";
    for (size_t i = 0; i < board_settings_count; i++) {
        const board_setting_t *s = &board_settings[i];
        if (strcmp(section, s->section) != 0) {
            fprintf(out, "[%s]\n", s->section);
            section = s->section;
        }
        char left[64];
        snprintf(left, sizeof(left), "--%s%s%s", s->flag, s->arg ? " " : "", s->arg ? s->arg : "");
        fprintf(out, "  %-24s %s\n  %-24s   (file: %s = ...)\n", left, s->help, "", s->key);
    }
    fprintf(out, "\nExit status: 0 after a clean stop (SIGINT/SIGTERM or --duration-s), 2 for a\n"
                 "bad option or setting, 3 when a device cannot be opened or the real-time\n"
                 "setup is refused, 4 when the CAN bus stays off past bus_recovery_ms.\n");
}

static const board_setting_t *setting_by_flag(const char *flag, size_t n)
{
    for (size_t i = 0; i < board_settings_count; i++)
        if (strlen(board_settings[i].flag) == n && strncmp(board_settings[i].flag, flag, n) == 0)
            return &board_settings[i];
    return NULL;
}

/* Prints one line of error and returns status, for main to exit with. */
__attribute__((format(printf, 2, 3))) static int fail(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, PROG ": ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return status;
}

static argil_err_t load_file(board_daemon_cfg_t *c, const char *path, char *why, size_t why_len)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        snprintf(why, why_len, "config file '%s': %s", path, strerror(errno));
        return ARGIL_ERR_IO;
    }
    static char text[64 * 1024];
    const size_t n = fread(text, 1, sizeof(text), f);
    const bool more = !feof(f);
    fclose(f);
    if (more) {
        snprintf(why, why_len, "config file '%s': larger than %zu bytes", path, sizeof(text));
        return ARGIL_ERR_PARSE;
    }
    uint32_t line = 0;
    char inner[160];
    const board_config_err_t rc = board_config_parse_ini(c, text, n, &line, inner, sizeof(inner));
    if (rc != BOARD_CONFIG_OK)
        snprintf(why, why_len, "%s:%u: %s", path, line, inner);
    return board_config_err_argil(rc);
}

/* Returns -1 to run, or the exit status. */
static int parse_args(board_daemon_cfg_t *c, int argc, char **argv)
{
    char why[256];
    /* The file first, so options override it wherever they appear. */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        if (strcmp(argv[i], "--version") == 0) {
            puts(VERSION);
            return 0;
        }
        const char *path = NULL;
        if (strcmp(argv[i], "--config") == 0) {
            if (i + 1 >= argc)
                return fail(2, "--config needs a FILE%s%s", "", "");
            path = argv[++i];
        } else if (strncmp(argv[i], "--config=", 9) == 0) {
            path = argv[i] + 9;
        }
        if (path && load_file(c, path, why, sizeof(why)) != ARGIL_OK)
            return fail(2, "%s%s", why, "");
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--config") == 0) {
            i++;
            continue;
        }
        if (strncmp(a, "--config=", 9) == 0)
            continue;
        if (strncmp(a, "--", 2) != 0)
            return fail(2, "unexpected argument '%s' (options start with --; see --help)%s", a, "");
        const char *name = a + 2;
        const char *eq = strchr(name, '=');
        const size_t n = eq ? (size_t)(eq - name) : strlen(name);
        const char *value = eq ? eq + 1 : NULL;
        if (n == 3 && strncmp(name, "set", 3) == 0) {
            if (!value) {
                if (i + 1 >= argc)
                    return fail(2, "--set needs SECTION.KEY=VALUE%s%s", "", "");
                value = argv[++i];
            }
            char sec[32], key[64];
            const char *dot = strchr(value, '.');
            const char *veq = strchr(value, '=');
            if (!dot || !veq || dot > veq || (size_t)(dot - value) >= sizeof(sec) ||
                (size_t)(veq - dot - 1) >= sizeof(key))
                return fail(2, "--set '%s': expected SECTION.KEY=VALUE%s", value, "");
            memcpy(sec, value, (size_t)(dot - value));
            sec[dot - value] = '\0';
            memcpy(key, dot + 1, (size_t)(veq - dot - 1));
            key[veq - dot - 1] = '\0';
            if (board_config_set(c, sec, key, veq + 1, why, sizeof(why)) != BOARD_CONFIG_OK)
                return fail(2, "%s%s", why, "");
            continue;
        }
        const board_setting_t *s = setting_by_flag(name, n);
        if (s == NULL)
            return fail(2, "unknown option '%s' (see --help)%s", a, "");
        if (!value && s->arg == NULL) {
            value = "yes"; /* a flag */
        } else if (!value) {
            if (i + 1 >= argc)
                return fail(2, "option '%s' needs a value (%s)", a, s->arg);
            value = argv[++i];
        }
        if (board_config_set(c, s->section, s->key, value, why, sizeof(why)) != BOARD_CONFIG_OK)
            return fail(2, "%s%s", why, "");
    }
    if (board_config_check(c, why, sizeof(why)) != BOARD_CONFIG_OK)
        return fail(2, "%s%s", why, "");
    return -1;
}

/* ---- shared state between the threads ---- */

/* What the fast loop saw at the tick its host session lapsed (FAULT "host heartbeat lost"),
 * for the log: whether the host fell silent, the link thread was held off, or datagrams
 * reached the link thread and not the loop (hil/plan.txt: rt-scenario-link-nan). */
typedef struct {
    uint32_t seq;                  /* 0: none yet; +1 at each host-lost fault */
    uint32_t tick;
    uint32_t silence_us;           /* since the last host frame the core took in */
    uint64_t at_ns;                /* CLOCK_MONOTONIC when the tick noted it */
    uint64_t link_turn_ns;         /* the link thread's latest turn then (0: no UDP thread) */
    uint64_t link_rx_ns;           /* … when it last queued a datagram for the loop */
    uint32_t link_rx_count;        /* datagrams it had queued so far */
} host_lost_t;

typedef struct {
    _Atomic uint32_t seq;          /* odd while the fast loop writes the snapshot */
    rt_stats_t stats;
    uint32_t ticks;
    uint32_t state;
    uint32_t fault;
    uint32_t can_tx_errors;
    uint32_t link_tx_dropped;
    proto_link_counts_t link;      /* host frames refused, by reason; sessions */
    uint8_t nmt[ARGIL_DRIVES];
    uint8_t power[ARGIL_DRIVES];
    uint8_t bus;
    bool window;
    bool tool;
    host_lost_t lost;              /* the latest host-lost fault, as the fast loop saw it */
} snapshot_t;

typedef struct {
    board_daemon_cfg_t cfg;
    hal_t *hal;
    board_t *board;
    board_io_t io;
    link_udp_t udp;
    link_ffs_t ffs;
    _Atomic bool stop;
    _Atomic bool ffs_enabled;
    _Atomic int loop_status;       /* 0 running/clean, else the exit status */
    _Atomic uint64_t link_turn_ns; /* the UDP link thread's latest turn */
    _Atomic uint64_t link_rx_ns;   /* … when it last queued a datagram for the loop */
    _Atomic uint32_t link_rx_count;
    host_lost_t lost;              /* fast loop only; published in the snapshot */
    snapshot_t snap;
    rt_stats_t rt;                 /* fast loop only */
    char loop_err[160];
} daemon_t;

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static struct timespec to_ts(uint64_t ns)
{
    struct timespec ts = {(time_t)(ns / 1000000000u), (long)(ns % 1000000000u)};
    return ts;
}

static void publish(daemon_t *d)
{
    snapshot_t *s = &d->snap;
    atomic_fetch_add_explicit(&s->seq, 1u, memory_order_acq_rel);
    s->stats = d->rt;
    s->ticks = d->board->stats.ticks;
    s->state = (uint32_t)d->board->safety.state;
    s->fault = (uint32_t)d->board->safety.fault;
    s->can_tx_errors = d->io.can_tx_errors;
    s->link_tx_dropped = atomic_load_explicit(&d->hal->link_tx.dropped, memory_order_relaxed);
    board_link_counts(d->board, &s->link);
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        s->nmt[j] = (uint8_t)d->board->drives.d[j].nmt;
        s->power[j] = (uint8_t)d->board->drives.d[j].power;
    }
    s->bus = (uint8_t)d->board->drives.bus;
    s->window = window_active(&d->board->window) != NULL;
    s->tool = d->board->tool_valid;
    s->lost = d->lost;
    atomic_fetch_add_explicit(&s->seq, 1u, memory_order_release);
}

/* Copies the latest snapshot without ever making the fast loop wait. */
static void read_snapshot(daemon_t *d, snapshot_t *out)
{
    for (int tries = 0; tries < 1000; tries++) {
        const uint32_t a = atomic_load_explicit(&d->snap.seq, memory_order_acquire);
        if (a & 1u)
            continue;
        out->stats = d->snap.stats;
        out->ticks = d->snap.ticks;
        out->state = d->snap.state;
        out->fault = d->snap.fault;
        out->can_tx_errors = d->snap.can_tx_errors;
        out->link_tx_dropped = d->snap.link_tx_dropped;
        out->link = d->snap.link;
        out->lost = d->snap.lost;
        memcpy(out->nmt, d->snap.nmt, sizeof(out->nmt));
        memcpy(out->power, d->snap.power, sizeof(out->power));
        out->bus = d->snap.bus;
        out->window = d->snap.window;
        out->tool = d->snap.tool;
        atomic_thread_fence(memory_order_acquire);
        if (atomic_load_explicit(&d->snap.seq, memory_order_relaxed) == a)
            return;
    }
}

/* ---- the fast loop ---- */

static void prefault_stack(void)
{
    volatile uint8_t buf[PREFAULT_STACK_BYTES];
    for (size_t i = 0; i < sizeof(buf); i += 4096u)
        buf[i] = 0;
}

/* Latches what the link looked like at the tick the host session lapsed. */
static void note_host_lost(daemon_t *d)
{
    d->lost.seq++;
    d->lost.tick = d->board->stats.ticks;
    d->lost.silence_us = d->board->session.silence_us;
    /* The link thread's times first, then the clock: each was read from the clock before it
     * was stored, so neither is later than at_ns (the link thread may run while this tick does) */
    d->lost.link_turn_ns = atomic_load_explicit(&d->link_turn_ns, memory_order_acquire);
    d->lost.link_rx_ns = atomic_load_explicit(&d->link_rx_ns, memory_order_acquire);
    d->lost.link_rx_count = atomic_load_explicit(&d->link_rx_count, memory_order_relaxed);
    d->lost.at_ns = now_ns();
    publish(d);
}

static void *fast_loop(void *arg)
{
    daemon_t *d = arg;
    prefault_stack();
    const uint32_t period_ns = 1000000000u / d->cfg.rate_hz;
    const uint64_t stop_at = d->cfg.duration_s > 0.0f
                                 ? now_ns() + (uint64_t)((double)d->cfg.duration_s * 1e9)
                                 : UINT64_MAX;
    uint64_t next = now_ns() + period_ns;
    uint32_t since_publish = 0;
    while (!atomic_load_explicit(&d->stop, memory_order_relaxed)) {
        const struct timespec ts = to_ts(next);
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
        }
        const uint64_t woke = now_ns();
        const uint32_t wake_ns = woke > next ? (uint32_t)(woke - next < 0xFFFFFFFFu ? woke - next
                                                                                    : 0xFFFFFFFFu)
                                             : 0u;
        const bool was_lost = d->board->safety.state == SAFETY_FAULT &&
                              d->board->safety.fault == FAULT_HOST_LOST;
        const uint32_t compute_ns = board_run_tick(d->board, &d->io, d->hal);
        if (!was_lost && d->board->safety.state == SAFETY_FAULT &&
            d->board->safety.fault == FAULT_HOST_LOST)
            note_host_lost(d);
        /* The core sees the whole tick, release to done (wake-up latency + compute), so a late
         * wake counts as overrun; it records both in its RT_STATS for the host. */
        d->io.prev_wake_ns = wake_ns;
        (void)rt_stats_add(&d->rt, wake_ns, compute_ns, period_ns);
        if (drives_bus_unrecoverable(&d->board->drives, &d->board->cfg.drives)) {
            snprintf(d->loop_err, sizeof(d->loop_err),
                     "CAN bus-off not recovered within %u ms (is restart-ms set on %s?)",
                     d->cfg.bus_recovery_ms, d->cfg.can_if);
            atomic_store(&d->loop_status, 4);
            break;
        }
        if (++since_publish >= d->cfg.rate_hz / 100u) { /* 100 Hz */
            publish(d);
            since_publish = 0;
        }
        if (woke >= stop_at)
            break;
        next += period_ns;
        const uint64_t after = now_ns();
        if (after > next) /* missed whole periods: re-align, do not burst */
            next += ((after - next) / period_ns + 1u) * period_ns;
    }
    /* Leave the drives safe: zero torque, disable voltage, NMT stop; lines low. */
    can_batch_t tx = {0};
    drives_shutdown(&d->board->drives, &tx);
    (void)hal_linux_can_flush(d->hal, &tx);
    hal_gpio_write(d->hal, 0);
    /* A last RT_STATS for the host, so it sees the whole run (the link thread drains its ring
     * after the stop). */
    static proto_msg_t rt_msg;
    static uint8_t rt_frame[PROTO_FRAME_MAX];
    size_t rt_len = 0;
    board_rt_stats_msg(d->board, &rt_msg);
    if (proto_encode(&rt_msg, d->board->tx_seq, rt_frame, sizeof(rt_frame), &rt_len) == PROTO_OK) {
        d->board->tx_seq++;
        (void)hal_link_send(d->hal, rt_frame, rt_len);
    }
    publish(d);
    atomic_store(&d->stop, true);
    return NULL;
}

/* ---- the link thread ---- */

static void drain_tx(daemon_t *d, uint8_t *buf, size_t cap)
{
    size_t n;
    while (spsc_pop(&d->hal->link_tx, buf, cap, &n) == ARGIL_OK) {
        if (d->cfg.link == BOARD_LINK_UDP) {
            (void)link_udp_send(&d->udp, buf, n); /* no host yet: dropped */
        } else if (atomic_load(&d->ffs_enabled)) {
            /* A blocking bulk write is fine here: only this thread waits on it. */
            if (write(d->ffs.ep_in, buf, n) < 0 && errno != EINTR)
                atomic_store(&d->ffs_enabled, false);
        }
    }
}

static void *udp_thread(void *arg)
{
    daemon_t *d = arg;
    static uint8_t rx[PROTO_FRAME_MAX * 2];
    static uint8_t tx[BOARD_LINK_TX_MAX];
    const struct timespec nap = {0, 250000};
    while (!atomic_load(&d->stop)) {
        size_t n;
        const uint64_t turn_ns = now_ns();
        const uint64_t now_us = turn_ns / 1000u;
        atomic_store_explicit(&d->link_turn_ns, turn_ns, memory_order_release);
        while ((n = link_udp_receive(&d->udp, rx, sizeof(rx), now_us)) > 0) {
            (void)spsc_push(&d->hal->link_rx, rx, n);
            atomic_store_explicit(&d->link_rx_ns, now_ns(), memory_order_release);
            atomic_fetch_add_explicit(&d->link_rx_count, 1u, memory_order_relaxed);
        }
        const hal_link_refusals_t refused = {d->udp.bind.refused_source,
                                             d->udp.bind.refused_no_session, d->udp.bad_mac,
                                             d->udp.bad_nonce};
        hal_linux_link_refusals_set(d->hal, &refused);
        /* Frames first, then the session: those of the tick that ended it still go out. */
        drain_tx(d, tx, sizeof(tx));
        hal_session_state_t state;
        uint32_t epoch;
        hal_linux_link_session_get(d->hal, &state, &epoch);
        link_udp_session(&d->udp, state, epoch, now_ns() / 1000u);
        nanosleep(&nap, NULL);
    }
    drain_tx(d, tx, sizeof(tx));
    return NULL;
}

static void *ffs_ep0_thread(void *arg)
{
    daemon_t *d = arg;
    struct usb_functionfs_event_raw {
        uint8_t setup[8];
        uint8_t type;
        uint8_t pad[3];
    } ev[4];
    while (!atomic_load(&d->stop)) {
        const ssize_t n = read(d->ffs.ep0, ev, sizeof(ev));
        if (n < 0) {
            if (errno == EINTR)
                continue;
            break;
        }
        for (ssize_t i = 0; i < n / (ssize_t)sizeof(ev[0]); i++) {
            if (ev[i].type == 2) { /* FUNCTIONFS_ENABLE: the host configured us */
                atomic_store(&d->ffs_enabled, true);
                d->ffs.enables++;
            } else if (ev[i].type == 3 || ev[i].type == 1) { /* DISABLE, UNBIND */
                atomic_store(&d->ffs_enabled, false);
                d->ffs.disables++;
            }
        }
    }
    return NULL;
}

static void *ffs_reader_thread(void *arg)
{
    daemon_t *d = arg;
    static link_framer_t fr;
    static uint8_t chunk[4096], frame[PROTO_FRAME_MAX];
    link_framer_init(&fr);
    const struct timespec nap = {0, 10000000};
    while (!atomic_load(&d->stop)) {
        const ssize_t n = read(d->ffs.ep_out, chunk, sizeof(chunk));
        if (n <= 0) {
            nanosleep(&nap, NULL); /* not enabled yet, or the host went away */
            continue;
        }
        size_t at = 0;
        while (at < (size_t)n) {
            at += link_framer_feed(&fr, chunk + at, (size_t)n - at);
            size_t f;
            while ((f = link_framer_next(&fr, frame, sizeof(frame))) > 0)
                (void)spsc_push(&d->hal->link_rx, frame, f);
            if (fr.len == sizeof(fr.buf))
                link_framer_init(&fr); /* cannot happen with valid frames; never wedge */
        }
    }
    return NULL;
}

static void *ffs_writer_thread(void *arg)
{
    daemon_t *d = arg;
    static uint8_t tx[BOARD_LINK_TX_MAX];
    const struct timespec nap = {0, 250000};
    while (!atomic_load(&d->stop)) {
        drain_tx(d, tx, sizeof(tx));
        nanosleep(&nap, NULL);
    }
    return NULL;
}

/* ---- start-up ---- */

static int start_thread(pthread_t *t, void *(*fn)(void *), void *arg, int prio, int cpu,
                        char *why, size_t why_len)
{
    pthread_attr_t a;
    pthread_attr_init(&a);
    if (prio > 0) {
        struct sched_param sp = {.sched_priority = prio};
        pthread_attr_setinheritsched(&a, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&a, SCHED_FIFO);
        pthread_attr_setschedparam(&a, &sp);
    }
    if (cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cpu, &set);
        pthread_attr_setaffinity_np(&a, sizeof(set), &set);
    }
    const int rc = pthread_create(t, &a, fn, arg);
    pthread_attr_destroy(&a);
    if (rc != 0) {
        snprintf(why, why_len, "%s", strerror(rc));
        return -1;
    }
    return 0;
}

/* What the UDP link checks, for the start line and every stats line; NULL when nothing to say. */
static const char *link_auth_note(const board_daemon_cfg_t *c)
{
    if (c->link != BOARD_LINK_UDP || c->link_key[0] != '\0')
        return NULL;
    return c->link_insecure
               ? "INSECURE: the UDP link has no key and may arm (--insecure): anyone who can "
                 "reach its port may command the arm"
               : "the UDP link has no key: ARM over it is refused (start with --key FILE, made "
                 "by 'argil keygen FILE'; or --insecure)";
}

static void print_stats(const char *when, const snapshot_t *s, const board_daemon_cfg_t *cfg)
{
    const uint32_t rate_hz = cfg->rate_hz;
    const char *note = link_auth_note(cfg);
    if (note)
        fprintf(stderr, PROG ": %s: %s\n", when, note);
    const rt_series_t *w = &s->stats.wake, *c = &s->stats.compute;
    fprintf(stderr,
            PROG ": %s: %u ticks at %u Hz, state %s (last fault: %s); wake latency min/mean/max "
            "%.1f/%.1f/%.1f us; compute min/mean/max %.1f/%.1f/%.1f us; overruns %u (worst "
            "streak %u); CAN send errors %u; link frames dropped %u\n",
            when, s->ticks, rate_hz, safety_state_name((safety_state_t)s->state),
            safety_fault_name((fault_code_t)s->fault), w->count ? w->min_ns / 1e3 : 0.0,
            rt_series_mean_ns(w) / 1e3, w->max_ns / 1e3, c->count ? c->min_ns / 1e3 : 0.0,
            rt_series_mean_ns(c) / 1e3, c->max_ns / 1e3, s->stats.overruns,
            s->stats.worst_streak, s->can_tx_errors, s->link_tx_dropped);
    static const char *const power[] = {"not ready", "switch-on disabled", "ready", "switched on",
                                        "enabled", "quick stop", "fault reaction", "fault"};
    fprintf(stderr, PROG ": %s: CAN %s; drives (NMT 0x%02x/0x%02x/0x%02x):", when,
            drives_bus_state_name((can_bus_state_t)s->bus), s->nmt[0], s->nmt[1], s->nmt[2]);
    for (int j = 0; j < ARGIL_DRIVES; j++)
        fprintf(stderr, " %s", s->power[j] < 8 ? power[s->power[j]] : "?");
    fprintf(stderr, "; window %s, tool %s\n", s->window ? "yes" : "no", s->tool ? "yes" : "no");
    fprintf(stderr,
            PROG ": %s: host sessions %u; host frames refused: wrong source %u, no session %u, "
            "duplicate %u, stale %u, decode errors %u, bad tag %u, bad nonce %u; ARM refused "
            "%u\n",
            when, s->link.sessions, s->link.wrong_source, s->link.no_session, s->link.duplicate,
            s->link.stale, s->link.decode_errors, s->link.bad_mac, s->link.bad_nonce,
            s->link.arm_refused);
    fprintf(stderr, PROG ": %s: wake latency histogram (us):", when);
    for (uint32_t i = 0; i < RT_HIST_BINS; i++) {
        const uint32_t e = rt_hist_edge_us(i);
        if (e)
            fprintf(stderr, " <%u:%u", e, w->hist[i]);
        else
            fprintf(stderr, " >=%u:%u", rt_hist_edge_us(i - 1u), w->hist[i]);
    }
    fputc('\n', stderr);
}

/* One log line when datagrams with a bad tag, or ARM commands, start being refused after a
 * quiet second: a burst is logged once, not once per datagram. */
typedef struct {
    uint32_t count;   /* as of the last change */
    uint64_t at_ns;   /* when it last changed */
} refusal_burst_t;

typedef struct {
    refusal_burst_t bad_mac, arm_refused;
} refusal_bursts_t;

/* True when count starts a new burst (it changed after a quiet second). */
static bool burst_starts(refusal_burst_t *b, uint32_t count, uint64_t now)
{
    if (count == b->count)
        return false;
    const bool starts = now - b->at_ns >= 1000000000u;
    b->count = count;
    b->at_ns = now;
    return starts;
}

/* One line per host-lost fault: who went quiet, the host, the link thread or the hand-over. */
static void log_host_lost(const host_lost_t *l)
{
    const double ms_before = (double)l->silence_us / 1e3;
    if (l->link_turn_ns == 0) {
        fprintf(stderr, PROG ": host lost at tick %u: its last frame taken in %.1f ms before\n",
                l->tick, ms_before);
        return;
    }
    const double turn_ms = (double)(l->at_ns - l->link_turn_ns) / 1e6;
    if (l->link_rx_ns == 0) {
        fprintf(stderr, PROG ": host lost at tick %u: its last frame taken in %.1f ms before; "
                "the link thread last ran %.1f ms before and has queued no datagram\n",
                l->tick, ms_before, turn_ms);
        return;
    }
    fprintf(stderr, PROG ": host lost at tick %u: its last frame taken in %.1f ms before; the "
            "link thread last ran %.1f ms before and last queued a datagram %.1f ms before "
            "(%u so far)\n", l->tick, ms_before, turn_ms,
            (double)(l->at_ns - l->link_rx_ns) / 1e6, l->link_rx_count);
}

static void log_refusal_bursts(const snapshot_t *s, refusal_bursts_t *b, uint64_t now)
{
    if (burst_starts(&b->bad_mac, s->link.bad_mac, now))
        fprintf(stderr, PROG ": refusing UDP datagrams whose tag does not verify (%u so far): a "
                "sender with another key or none; the host needs this board's key file "
                "(argil connect --key FILE)\n", s->link.bad_mac);
    if (burst_starts(&b->arm_refused, s->link.arm_refused, now))
        fprintf(stderr, PROG ": ARM refused (%u so far): the board refuses to arm over UDP "
                "without a link key: start it with --key FILE (argil keygen FILE), or "
                "--insecure\n", s->link.arm_refused);
}

int main(int argc, char **argv)
{
    static daemon_t d;
    board_config_default(&d.cfg);
    const int st = parse_args(&d.cfg, argc, argv);
    if (st >= 0)
        return st;
    const board_daemon_cfg_t *c = &d.cfg;
    char why[256];

    /* Block the signals in every thread; main waits for them. */
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &sigs, NULL);

    if (!link_auth_init())
        return fail(3, "libsodium cannot start (no random source?)%s%s", "", "");
    link_key_t key;
    if (c->link == BOARD_LINK_UDP && c->link_key[0] != '\0' &&
        link_key_load(c->link_key, &key, why, sizeof(why)) != LINK_KEY_OK)
        return fail(2, "%s%s", why, "");

    d.hal = calloc(1, sizeof(*d.hal));
    d.board = calloc(1, sizeof(*d.board));
    if (!d.hal || !d.board)
        return fail(3, "out of memory%s%s", "", "");
    const uint32_t tick_us = 1000000u / c->rate_hz;
    argil_err_t rc = c->bus == BOARD_BUS_SIM
                         ? hal_linux_open_sim(d.hal, &c->gpio, tick_us, why, sizeof(why))
                         : hal_linux_open(d.hal, c->can_if, &c->gpio, why, sizeof(why));
    if (rc != ARGIL_OK)
        return fail(3, "%s%s", why, "");
    rc = c->link == BOARD_LINK_UDP ? link_udp_open(&d.udp, c->link_target, why, sizeof(why))
                                   : link_ffs_open(&d.ffs, c->link_target, why, sizeof(why));
    if (rc != ARGIL_OK) {
        hal_linux_close(d.hal);
        return fail(rc == ARGIL_ERR_ARG ? 2 : 3, "%s%s", why, "");
    }
    if (c->link == BOARD_LINK_UDP && c->link_key[0] != '\0')
        link_udp_set_key(&d.udp, &key);
    link_auth_wipe(&key, sizeof(key));

    board_cfg_t bc;
    board_cfg_default(&bc);
    bc.tick_us = tick_us;
    bc.max_force_n = c->max_force_n;
    bc.max_velocity_m_s = c->max_velocity_m_s;
    bc.refuse_arm = c->link == BOARD_LINK_UDP && c->link_key[0] == '\0' && !c->link_insecure;
    bc.safety.host_timeout_us = c->host_timeout_ms * 1000u;
    bc.safety.host_fade_us = c->host_fade_ms * 1000u;
    bc.safety.overrun_streak = c->overrun_streak;
    bc.drives.heartbeat_timeout_us = c->drive_heartbeat_ms * 1000u;
    bc.drives.bus_recovery_us = c->bus_recovery_ms * 1000u;
    if (board_init(d.board, &bc) != ARGIL_OK)
        return fail(2, "the core refused the configuration (rate %s Hz?)%s", "", "");
    /* The configured transform holds until the host's TOOL frame brings its own. */
    d.board->tool.model_scale = c->model_scale;
    memcpy(d.board->tool.model_offset_m, c->model_offset_m, sizeof(c->model_offset_m));
    board_io_init(&d.io);
    rt_stats_init(&d.rt);

    if (c->rt_priority > 0) {
        if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
            return fail(3, "mlockall failed (%s): raise LimitMEMLOCK / ulimit -l, or run with "
                           "--rt-priority 0 for a non-real-time test run%s", strerror(errno), "");
        if (c->cpu >= 0 && c->cpu >= sysconf(_SC_NPROCESSORS_CONF))
            return fail(3, "--cpu %s: this machine has fewer CPUs%s", "", "");
    }

    pthread_t loop_t, link_t, extra_t[2];
    const int link_prio = c->rt_priority <= 0        ? 0
                          : c->link_rt_priority > 0 ? c->link_rt_priority
                          : c->rt_priority > 10     ? c->rt_priority - 10
                                                    : 0;
    if (c->link == BOARD_LINK_UDP) {
        if (start_thread(&link_t, udp_thread, &d, link_prio, -1, why, sizeof(why)) != 0)
            return fail(3, "cannot start the link thread (%s)%s", why, "");
    } else {
        if (start_thread(&link_t, ffs_ep0_thread, &d, link_prio, -1, why, sizeof(why)) != 0 ||
            start_thread(&extra_t[0], ffs_reader_thread, &d, link_prio, -1, why, sizeof(why)) != 0 ||
            start_thread(&extra_t[1], ffs_writer_thread, &d, link_prio, -1, why, sizeof(why)) != 0)
            return fail(3, "cannot start the link threads (%s)%s", why, "");
    }
    if (start_thread(&loop_t, fast_loop, &d, c->rt_priority, c->cpu, why, sizeof(why)) != 0)
        return fail(3, "cannot start the fast loop with SCHED_FIFO priority %s (%s): run as "
                       "root or with CAP_SYS_NICE, or pass --rt-priority 0",
                    c->rt_priority > 0 ? "as configured" : "0", why);
    fprintf(stderr, PROG ": running at %u Hz, bus %s, link %s:%s, rt priority %d, cpu %d\n",
            c->rate_hz, c->bus == BOARD_BUS_SIM ? "sim" : c->can_if,
            c->link == BOARD_LINK_UDP ? "udp" : "ffs", c->link_target, c->rt_priority, c->cpu);
    if (c->link == BOARD_LINK_UDP && c->link_key[0] != '\0')
        fprintf(stderr, PROG ": UDP link key %s: every datagram carries a BLAKE2b tag\n",
                c->link_key);
    else if (link_auth_note(c))
        fprintf(stderr, PROG ": %s\n", link_auth_note(c));

    /* Main thread: signals, state changes and periodic statistics; never touches the loop. */
    uint32_t last_state = 0xFFFFFFFFu;
    uint32_t lost_seen = 0;
    uint64_t next_stats = now_ns() + (uint64_t)c->stats_period_s * 1000000000u;
    const struct timespec wait = {0, 20000000};
    snapshot_t s;
    memset(&s, 0, sizeof(s));
    refusal_bursts_t bursts;
    memset(&bursts, 0, sizeof(bursts));
    while (!atomic_load(&d.stop)) {
        const int sig = sigtimedwait(&sigs, NULL, &wait);
        if (sig == SIGINT || sig == SIGTERM) {
            atomic_store(&d.stop, true);
            break;
        }
        read_snapshot(&d, &s);
        if (s.ticks > 0 && s.state != last_state) {
            fprintf(stderr, PROG ": state %s%s%s\n", safety_state_name((safety_state_t)s.state),
                    s.state == SAFETY_FAULT || s.state == SAFETY_ESTOP ? " — " : "",
                    s.state == SAFETY_FAULT || s.state == SAFETY_ESTOP
                        ? safety_fault_name((fault_code_t)s.fault) : "");
            last_state = s.state;
        }
        if (s.lost.seq != lost_seen) {
            log_host_lost(&s.lost);
            lost_seen = s.lost.seq;
        }
        log_refusal_bursts(&s, &bursts, now_ns());
        if (c->stats_period_s > 0 && now_ns() >= next_stats) {
            print_stats("stats", &s, c);
            next_stats += (uint64_t)c->stats_period_s * 1000000000u;
        }
    }
    pthread_join(loop_t, NULL);
    if (c->link == BOARD_LINK_UDP)
        pthread_join(link_t, NULL); /* the FFS threads may sit in a bulk read: exit leaves them */
    read_snapshot(&d, &s);
    print_stats("exit", &s, c);
    const int status = atomic_load(&d.loop_status);
    if (status != 0)
        fprintf(stderr, PROG ": %s\n", d.loop_err);
    if (c->link == BOARD_LINK_UDP)
        link_udp_close(&d.udp);
    hal_linux_close(d.hal);
    return status;
}
