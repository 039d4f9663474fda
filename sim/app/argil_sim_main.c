/* argil-sim: the simulated arm as a device on a real CAN bus. For each SYNC the board sends (or
 * each millisecond of wall time with --clock wall, or while the bus is silent) it takes the
 * board's frames from a SocketCAN interface and the board's DRIVE_ENABLE / WDOG_KICK outputs,
 * runs sim_runner_tick (the same per-tick function the SIL fault matrix runs: three CiA 402
 * drives, arm dynamics, hand, scenario, fault injection), and writes the drives' frames and the
 * input lines back. Events go to an event log on CLOCK_REALTIME, stamped when they took effect,
 * so they line up with `candump -l`. Usage: docs/sim.md. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <glob.h>
#include <gpiod.h>
#include <inttypes.h>
#include <poll.h>
#include <sched.h>
#include <linux/can.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bus/can_socket.h"
#include "bus/gpio_chip.h"
#include "shared/gpio_lines.h"
#include "sim/scenario.h"
#include "sim/scn_clock.h"
#include "sim/sim_runner.h"

#define TICK_US 1000u
#define EXIT_RUN 1   /* could not open the bus or GPIO, or I/O failed while running */
#define EXIT_USAGE 2 /* bad option or scenario */
#define EXIT_NOT_READY 3 /* --start-when: the board was not ready in time, nothing played */

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static void usage(FILE *to)
{
    fputs("usage: argil-sim --can IFACE [--gpio-chip CHIP] [--scenario FILE] [--log-dir DIR]\n"
          "                 [--seconds S] [--clock ticks|wall] [--start-when FILE]\n"
          "                 [--start-timeout S] [--run-prio N] [--arm-substep-us US] [--help]\n"
          "  The simulated arm (3 CiA 402 drives, arm dynamics, GPIO, a scripted hand) on a\n"
          "  SocketCAN interface, one 1 ms step per SYNC of the board (--clock).\n"
          "  --can IFACE       CAN interface the board is on (vcan0, can0)\n"
          "  --gpio-chip CHIP  GPIO chip with the board's named lines: a gpio-sim chip is driven\n"
          "                    through sysfs (pull/value), any other chip through libgpiod with\n"
          "                    the inputs of the board as this side's outputs; none: no GPIO\n"
          "                    (e-stop released, drives taken as enabled)\n"
          "  --scenario FILE   hil/scenarios/*.scn: hand moves, faults (docs/sim.md); none: hold\n"
          "  --log-dir DIR     write DIR/events.log (default: events to stdout)\n"
          "  --seconds S       stop after S seconds of scenario time (default: the scenario's\n"
          "                    duration, else until SIGINT/SIGTERM)\n"
          "  --clock ticks     (default) one 1 ms step per SYNC the board sends, so the arm and\n"
          "                    the scenario keep the board's time even when it ticks slower than\n"
          "                    1 kHz; the wall clock while the bus has no SYNC for 400 ms\n"
          "  --clock wall      1 ms steps on the wall clock, whatever the board does\n"
          "  --start-when FILE hold the scenario at time 0 (the device answers the board, the\n"
          "                    hand at home) until FILE exists: the rig's host writes it when the\n"
          "                    board is ACTIVE (docs/sim.md, \"Scenario time 0\")\n"
          "  --start-timeout S give up when FILE has not appeared after S s (default 60)\n"
          "  --run-prio N      SCHED_FIFO priority N (1-98) once set up, before the first SYNC\n"
          "                    is answered: the arm is its own hardware and answers in time\n"
          "  --arm-substep-us US  the arm dynamics' integration sub-step, 1 up to the longest\n"
          "                    that keeps its friction stable (default 50; docs/arm.md): longer\n"
          "                    sub-steps cost less CPU per SYNC, for a rig that cannot keep up\n"
          "exit: 0 ran to the end, 1 bus/GPIO could not be opened or failed, 2 bad usage,\n"
          "      3 --start-when's FILE never appeared (the board never got ready), or this\n"
          "        stand-in had not caught up with the board's SYNCs, within --start-timeout\n",
          to);
}

/* ---- event log ---- */

static FILE *event_log;

/* Events of the tick in progress wait here until its I/O is done: an injection is stamped
 * when its effect is on the bus and the lines (after the tick's frames were sent and the
 * inputs written), a DRIVE_ENABLE change when the output was read. */
#define EVENTS_MAX 48u
typedef struct {
    int64_t t_us;
    bool gpio_out;
    char text[SCN_TEXT_LEN + 48];
} pending_event_t;
static pending_event_t pending_ev[EVENTS_MAX];
static uint32_t n_pending_ev, lost_ev;
static bool defer_events;
static struct timespec prev_read; /* the board's outputs read before this tick's read */

static void write_event(const struct timespec *ts, int64_t t_us, const char *event)
{
    fprintf(event_log, "(%lld.%06ld) %s t=%" PRId64 ".%06" PRId64 "\n", (long long)ts->tv_sec,
            ts->tv_nsec / 1000, event, t_us / 1000000, t_us % 1000000);
}

static bool preroll;               /* before the start line: events are not logged */
static uint32_t preroll_events;

static void log_event(void *ctx, int64_t t_us, const char *event)
{
    (void)ctx;
    if (preroll) {
        preroll_events++;
        return;
    }
    if (defer_events) {
        if (n_pending_ev == EVENTS_MAX) {
            lost_ev++;
            return;
        }
        pending_event_t *e = &pending_ev[n_pending_ev++];
        e->t_us = t_us;
        e->gpio_out = strncmp(event, "gpio_out", 8) == 0;
        snprintf(e->text, sizeof(e->text), "%s", event);
        return;
    }
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    write_event(&ts, t_us, event);
}

/* Writes the held events: output changes stamped at `read` (with the read before it), the
 * rest now. */
static void flush_events(const struct timespec *read)
{
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t i = 0; i < n_pending_ev; i++)
            if (pending_ev[i].gpio_out == (pass == 0)) {
                if (pass == 0 && prev_read.tv_sec > 0) { /* the edge lies after the last read */
                    char text[sizeof(pending_ev[i].text) + 32];
                    snprintf(text, sizeof(text), "%s prev=(%lld.%06ld)", pending_ev[i].text,
                             (long long)prev_read.tv_sec, prev_read.tv_nsec / 1000);
                    write_event(read, pending_ev[i].t_us, text);
                } else {
                    write_event(pass == 0 ? read : &now, pending_ev[i].t_us, pending_ev[i].text);
                }
            }
    n_pending_ev = 0;
    fflush(event_log); /* hil-host --follow reads it as it grows */
}

/* ---- GPIO: the device side of the board's named lines ---- */

typedef enum { GPIO_NONE, GPIO_SYSFS, GPIO_GPIOD } gpio_mode_t;

typedef struct {
    gpio_mode_t mode;
    /* sysfs (gpio-sim): inputs of the board are driven by writing pull-up / pull-down */
    int pull_fd[GPIO_IN_COUNT];
    int value_fd[GPIO_OUT_COUNT];
    /* libgpiod: this side's lines wired to the board's */
    struct gpiod_chip *chip;
    struct gpiod_line *drive[GPIO_IN_COUNT];   /* we drive the board's inputs */
    struct gpiod_line *sense[GPIO_OUT_COUNT];  /* we read the board's outputs */
    uint32_t in_levels;                        /* last levels written */
    bool written;
} sim_gpio_t;

/* The sysfs directory of a gpio-sim chip (/sys/devices/platform/gpio-sim.N/gpiochipM), or
 * false when chip is not a gpio-sim chip. */
static bool gpio_sim_dir(const char *chip, char *dir, size_t cap)
{
    const char *base = strrchr(chip, '/') ? strrchr(chip, '/') + 1 : chip;
    char pattern[256];
    snprintf(pattern, sizeof(pattern), "/sys/devices/platform/gpio-sim.*/%s", base);
    glob_t g;
    const bool found = glob(pattern, 0, NULL, &g) == 0 && g.gl_pathc >= 1;
    if (found)
        snprintf(dir, cap, "%s", g.gl_pathv[0]);
    globfree(&g);
    return found;
}

static int open_line_file(const char *dir, unsigned offset, const char *file, int flags,
                          char *err, size_t cap)
{
    char path[512];
    snprintf(path, sizeof(path), "%s/sim_gpio%u/%s", dir, offset, file);
    const int fd = open(path, flags | O_CLOEXEC);
    if (fd < 0)
        snprintf(err, cap, "GPIO: cannot open %s (%s)", path, strerror(errno));
    return fd;
}

static bool gpio_open(sim_gpio_t *g, const char *chip_name, char *err, size_t cap)
{
    memset(g, 0, sizeof(*g));
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++)
        g->pull_fd[i] = -1;
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++)
        g->value_fd[i] = -1;
    if (chip_name == NULL) {
        g->mode = GPIO_NONE;
        return true;
    }
    gpio_names_t names;
    gpio_names_default(&names);
    const gpio_ops_t *ops = &gpio_ops_gpiod; /* the board's libgpiod wrapper */
    g->chip = ops->chip_open(NULL, chip_name);
    if (g->chip == NULL) {
        snprintf(err, cap, "GPIO chip '%s' not found (%s)", chip_name, strerror(errno));
        return false;
    }
    struct gpiod_line *in[GPIO_IN_COUNT], *out[GPIO_OUT_COUNT];
    for (uint32_t i = 0; i < GPIO_IN_COUNT + GPIO_OUT_COUNT; i++) {
        const char *name = i < GPIO_IN_COUNT ? names.in[i] : names.out[i - GPIO_IN_COUNT];
        struct gpiod_line *l = ops->line_find(NULL, g->chip, name);
        if (l == NULL) {
            snprintf(err, cap, "GPIO chip '%s' has no line named %s", chip_name, name);
            return false;
        }
        if (i < GPIO_IN_COUNT)
            in[i] = l;
        else
            out[i - GPIO_IN_COUNT] = l;
    }
    char dir[300];
    if (gpio_sim_dir(chip_name, dir, sizeof(dir))) {
        g->mode = GPIO_SYSFS;
        for (uint32_t i = 0; i < GPIO_IN_COUNT; i++)
            if ((g->pull_fd[i] = open_line_file(dir, gpiod_line_offset(in[i]), "pull", O_WRONLY,
                                                err, cap)) < 0)
                return false;
        for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++)
            if ((g->value_fd[i] = open_line_file(dir, gpiod_line_offset(out[i]), "value",
                                                 O_RDONLY, err, cap)) < 0)
                return false;
        ops->chip_close(NULL, g->chip); /* offsets known; the board owns the lines */
        g->chip = NULL;
        return true;
    }
    /* A real chip wired to the board's: the board's inputs are our outputs. */
    g->mode = GPIO_GPIOD;
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++) {
        if (ops->line_request_output(NULL, in[i], "argil-sim", 0) != 0) {
            snprintf(err, cap, "GPIO line %s: cannot request as output (%s)", names.in[i],
                     strerror(errno));
            return false;
        }
        g->drive[i] = in[i];
    }
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++) {
        if (ops->line_request_input(NULL, out[i], "argil-sim") != 0) {
            snprintf(err, cap, "GPIO line %s: cannot request as input (%s)", names.out[i],
                     strerror(errno));
            return false;
        }
        g->sense[i] = out[i];
    }
    return true;
}

/* The board's outputs as GPIO_OUT_* bits; false on a read error. */
static bool gpio_read_outputs(sim_gpio_t *g, uint32_t *levels)
{
    *levels = 0;
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++) {
        int v = 0;
        if (g->mode == GPIO_SYSFS) {
            char c = '0';
            if (pread(g->value_fd[i], &c, 1, 0) != 1)
                return false;
            v = c == '1';
        } else if (g->mode == GPIO_GPIOD) {
            v = gpio_ops_gpiod.line_get(NULL, g->sense[i]);
            if (v < 0)
                return false;
        }
        if (v)
            *levels |= 1u << i;
    }
    return true;
}

/* Drives the board's inputs to GPIO_IN_* levels (only changed lines); false on error. */
static bool gpio_write_inputs(sim_gpio_t *g, uint32_t levels)
{
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++) {
        const uint32_t bit = 1u << i;
        if (g->written && ((levels ^ g->in_levels) & bit) == 0)
            continue;
        const bool high = (levels & bit) != 0;
        if (g->mode == GPIO_SYSFS) {
            const char *s = high ? "pull-up" : "pull-down";
            if (pwrite(g->pull_fd[i], s, strlen(s), 0) != (ssize_t)strlen(s))
                return false;
        } else if (g->mode == GPIO_GPIOD) {
            if (gpio_ops_gpiod.line_set(NULL, g->drive[i], high ? 1 : 0) != 0)
                return false;
        }
    }
    g->in_levels = levels;
    g->written = true;
    return true;
}

static void gpio_close(sim_gpio_t *g)
{
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++)
        if (g->pull_fd[i] >= 0)
            close(g->pull_fd[i]);
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++)
        if (g->value_fd[i] >= 0)
            close(g->value_fd[i]);
    if (g->chip)
        gpio_ops_gpiod.chip_close(NULL, g->chip); /* releases requested lines */
}

/* ---- CAN ---- */

/* SocketCAN error frames (the bus-off fault and the restart) still to be written: each is a
 * state change of the board's bus that nothing repeats, so one the socket had no room for
 * (ENOBUFS under load) is written again at the next step instead of being lost. */
#define ERR_FRAMES_PENDING_MAX 4
static struct can_frame err_pending[ERR_FRAMES_PENDING_MAX];
static unsigned err_pending_n, err_frames_retried;

/* Writes the pending error frames in order; false on a hard error (not ENOBUFS/EAGAIN). */
static bool err_frames_flush(int fd, can_socket_stats_t *st)
{
    unsigned done = 0;
    for (; done < err_pending_n; done++) {
        if (send(fd, &err_pending[done], sizeof(err_pending[done]), MSG_DONTWAIT) ==
            (ssize_t)sizeof(err_pending[done])) {
            st->tx_frames++;
            continue;
        }
        if (errno == ENOBUFS || errno == EAGAIN || errno == EWOULDBLOCK) {
            st->tx_busy++;
            err_frames_retried++;
            break;
        }
        st->last_errno = errno;
        st->tx_errors++;
        return false;
    }
    memmove(err_pending, err_pending + done, (err_pending_n - done) * sizeof(err_pending[0]));
    err_pending_n -= done;
    return true;
}

/* Sends the tick's frames: SocketCAN error frames (the bus-off fault) first, written with
 * their CAN_ERR_FLAG id, which vcan delivers to the board's socket as an error frame; then the
 * data frames through can_socket_send. */
static argil_err_t can_send_all(int fd, const can_batch_t *tx, can_socket_stats_t *st)
{
    can_batch_t data = {0};
    for (uint8_t i = 0; i < tx->n; i++) {
        if (tx->f[i].id & CAN_ERR_FLAG) {
            if (err_pending_n == ERR_FRAMES_PENDING_MAX) {
                st->tx_errors++; /* four state changes unwritten: the bus is gone */
                continue;
            }
            struct can_frame *cf = &err_pending[err_pending_n++];
            memset(cf, 0, sizeof(*cf));
            cf->can_id = tx->f[i].id & (CAN_ERR_FLAG | CAN_ERR_MASK);
            cf->can_dlc = 8;
            memcpy(cf->data, tx->f[i].data, 8);
        } else {
            (void)can_batch_push(&data, &tx->f[i]);
        }
    }
    if (!err_frames_flush(fd, st))
        return ARGIL_ERR_IO;
    return data.n ? can_socket_send(fd, &data, st) : ARGIL_OK;
}

/* CPU time this process used (user + system), ms. */
static double cpu_ms(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return -1.0;
    return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * 1e3 +
           (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e3;
}

static int64_t mono_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void add_us(struct timespec *t, uint32_t us)
{
    t->tv_nsec += (long)us * 1000L;
    while (t->tv_nsec >= 1000000000L) {
        t->tv_nsec -= 1000000000L;
        t->tv_sec++;
    }
}

int main(int argc, char **argv)
{
    const char *iface = NULL, *chip = NULL, *scn_path = NULL, *log_dir = NULL, *gate = NULL;
    double seconds = -1.0, start_timeout_s = 60.0;
    int run_prio = 0;
    bool clock_ticks = true;
    sim_params_t sp;
    sim_params_default(&sp);
    static const struct option opts[] = {
        {"can", required_argument, NULL, 'c'},      {"gpio-chip", required_argument, NULL, 'g'},
        {"scenario", required_argument, NULL, 's'}, {"log-dir", required_argument, NULL, 'l'},
        {"seconds", required_argument, NULL, 't'},  {"clock", required_argument, NULL, 'k'},
        {"start-when", required_argument, NULL, 'w'},
        {"start-timeout", required_argument, NULL, 'T'},
        {"run-prio", required_argument, NULL, 'P'},
        {"arm-substep-us", required_argument, NULL, 'S'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        switch (c) {
        case 'c': iface = optarg; break;
        case 'g': chip = optarg; break;
        case 's': scn_path = optarg; break;
        case 'l': log_dir = optarg; break;
        case 't': {
            char *end = NULL;
            seconds = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !(seconds > 0.0) || seconds > 86400.0) {
                fprintf(stderr, "argil-sim: --seconds '%s': expected 0-86400\n", optarg);
                return EXIT_USAGE;
            }
            break;
        }
        case 'k':
            if (strcmp(optarg, "ticks") != 0 && strcmp(optarg, "wall") != 0) {
                fprintf(stderr, "argil-sim: --clock '%s': expected ticks or wall\n", optarg);
                return EXIT_USAGE;
            }
            clock_ticks = strcmp(optarg, "ticks") == 0;
            break;
        case 'w': gate = optarg; break;
        case 'T': {
            char *end = NULL;
            start_timeout_s = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !(start_timeout_s > 0.0) ||
                start_timeout_s > 3600.0) {
                fprintf(stderr, "argil-sim: --start-timeout '%s': expected 0-3600 s\n", optarg);
                return EXIT_USAGE;
            }
            break;
        }
        case 'P': {
            char *end = NULL;
            const long v = strtol(optarg, &end, 10);
            if (end == optarg || *end != '\0' || v < 1 || v > 98) {
                fprintf(stderr, "argil-sim: --run-prio '%s': expected 1-98\n", optarg);
                return EXIT_USAGE;
            }
            run_prio = (int)v;
            break;
        }
        case 'S': {
            char *end = NULL;
            const uint32_t hi = arm_sim_substep_max_us(&sp.arm);
            const long v = strtol(optarg, &end, 10);
            if (end == optarg || *end != '\0' || v < 1 || v > (long)hi) {
                fprintf(stderr, "argil-sim: --arm-substep-us '%s': expected 1-%u (longer makes "
                        "the arm's friction overshoot each sub-step; docs/arm.md)\n", optarg, hi);
                return EXIT_USAGE;
            }
            sp.arm.substep_us = (uint32_t)v;
            break;
        }
        case 'h': usage(stdout); return 0;
        default:
            fprintf(stderr, "argil-sim: unknown or incomplete option '%s' (try --help)\n",
                    argv[optind - 1]);
            return EXIT_USAGE;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "argil-sim: unexpected argument '%s' (try --help)\n", argv[optind]);
        return EXIT_USAGE;
    }
    if (iface == NULL) {
        fprintf(stderr, "argil-sim: --can IFACE is required (try --help)\n");
        return EXIT_USAGE;
    }
    static scenario_t scn;
    if (scn_path != NULL) {
        scn_error_t err;
        if (scenario_load(&scn, scn_path, &err) != SCN_OK) {
            if (err.line > 0)
                fprintf(stderr, "argil-sim: %s:%u: %s\n", scn_path, err.line, err.msg);
            else
                fprintf(stderr, "argil-sim: %s: %s\n", scn_path, err.msg);
            return EXIT_USAGE;
        }
    }
    event_log = stdout;
    if (log_dir != NULL) {
        char path[4096];
        struct stat sb;
        if (stat(log_dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "argil-sim: --log-dir '%s' is not a directory\n", log_dir);
            return EXIT_USAGE;
        }
        snprintf(path, sizeof(path), "%s/events.log", log_dir);
        event_log = fopen(path, "w");
        if (event_log == NULL) {
            fprintf(stderr, "argil-sim: cannot write %s (%s)\n", path, strerror(errno));
            return EXIT_RUN;
        }
    }
    char err[256];
    int fd = -1;
    if (can_socket_open(iface, &fd, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "argil-sim: %s\n", err);
        return EXIT_RUN;
    }
    /* Every SYNC is a step of the clock: a starved moment must not cost frames (4 MiB, as the
     * rig's candump; SO_RCVBUFFORCE needs CAP_NET_ADMIN, else the system's cap applies). */
    const int rcvbuf = 4 << 20;
    if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &rcvbuf, sizeof(rcvbuf)) != 0)
        (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
    static sim_gpio_t gpio;
    if (!gpio_open(&gpio, chip, err, sizeof(err))) {
        fprintf(stderr, "argil-sim: %s\n", err);
        gpio_close(&gpio);
        close(fd);
        return EXIT_RUN;
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);

    static sim_runner_t run;
    sim_runner_init(&run, &sp, scn_path ? &scn : NULL, gpio.mode != GPIO_NONE, log_event, NULL);
    const int64_t end_us = seconds > 0.0 ? (int64_t)(seconds * 1e6)
                           : scn_path ? scn.duration_us
                                      : INT64_MAX;
    char line[256];
    const char *gpio_name =
        gpio.mode == GPIO_SYSFS ? "gpio-sim" : gpio.mode == GPIO_GPIOD ? "gpiod" : "none";
    /* With --start-when the device runs from here (the drives boot, the board arms them), the
     * scenario waits at time 0 and its start line is written when FILE exists; else now. */
    preroll = gate != NULL;
    sim_runner_hold(&run, preroll);
    if (!preroll) {
        /* frames queued before the start line are not counted: SYNCs count from here */
        can_batch_t stale;
        do {
            can_socket_stats_t ignored = {0};
            if (can_socket_receive(fd, &stale, &ignored) != ARGIL_OK)
                break;
        } while (stale.n == CAN_BATCH_MAX);
        snprintf(line, sizeof(line), "start scenario %s can %s gpio %s",
                 scn_path ? scn.name : "none", iface, gpio_name);
        log_event(NULL, 0, line);
    }
    /* Set up (its heavy start-up under emulation done at the caller's priority): from the
     * first SYNC on the arm answers like hardware, ahead of the rig's host and logger. */
    if (run_prio > 0) {
        const struct sched_param fifo = {.sched_priority = run_prio};
        if (sched_setscheduler(0, SCHED_FIFO, &fifo) != 0)
            fprintf(stderr, "argil-sim: --run-prio %d: %s (running on)\n", run_prio,
                    strerror(errno));
    }
    const int64_t preroll_t0_us = mono_us();
    bool gate_seen = false;
    int64_t gate_seen_us = 0; /* when FILE was first seen: the start should follow at once */
    /* How long this stand-in ran behind the board without catching up: the SYNCs it read, one
     * batch after another, before its socket first came back short (not how many were waiting
     * at once; one read holds at most CAN_BATCH_MAX frames, about 8 ticks' worth, so a count per
     * read saturated there). */
    uint32_t backlog_syncs = 0, max_backlog_syncs = 0;

    can_socket_stats_t st;
    memset(&st, 0, sizeof(st));
    /* The scenario times argil-hil-check anchors its expectations on: each is logged as
     * "mark at T" when this clock passes it (the end too). */
    int64_t mark_us[2u * SCN_EXPECTS_MAX + 1u];
    uint32_t n_marks = 0, next_mark = 0;
    if (scn_path) {
        for (uint32_t i = 0; i < scn.n_expects; i++) {
            mark_us[n_marks++] = scn.expect[i].t_us;
            if (scn.expect[i].until == SCN_UNTIL_TIME)
                mark_us[n_marks++] = scn.expect[i].until_us;
        }
        mark_us[n_marks++] = scn.duration_us;
        for (uint32_t i = 1; i < n_marks; i++) /* insertion sort, few entries */
            for (uint32_t k = i; k > 0 && mark_us[k - 1] > mark_us[k]; k--) {
                const int64_t tmp = mark_us[k];
                mark_us[k] = mark_us[k - 1];
                mark_us[k - 1] = tmp;
            }
    }
    uint32_t next_host = 0, late_ticks = 0;
    int rc = 0;
    scn_clock_t clk;
    scn_clock_init(&clk, clock_ticks, mono_us());
    static can_batch_t held; /* the board's frames since its last SYNC */
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    defer_events = true;
    while (!stop_requested && (preroll || clk.now_us < end_us) && rc == 0) {
        if (preroll && !gate_seen) {
            gate_seen = access(gate, F_OK) == 0;
            if (gate_seen)
                gate_seen_us = mono_us();
        }
        if (preroll && mono_us() - preroll_t0_us > (int64_t)(start_timeout_s * 1e6)) {
            /* One budget for both waits. After the ready file, every read still finding frames
             * queued means this stand-in answers SYNCs barely faster (or slower) than the board
             * sends them: without a bound it read on for ever (make hil, 2026-12-03); a bound of
             * 5 s after the ready file failed 12 of 18 scenarios in a clean-clone run that day,
             * while runs with the old start rule, whose start came 1-25 s after it, passed. */
            if (!gate_seen)
                fprintf(stderr, "argil-sim: %s did not appear within %.0f s: the board never got "
                        "ready to sculpt (%u SYNCs seen), the scenario was not played\n",
                        gate, start_timeout_s, clk.syncs);
            else
                fprintf(stderr, "argil-sim: the board got ready %.1f s after the start, but this "
                        "arm stand-in had not caught up with its SYNCs %.0f s after the start "
                        "(its socket never ran empty; %u SYNCs seen): the machine is too slow to "
                        "play the scenario, nothing was played\n",
                        (double)(gate_seen_us - preroll_t0_us) / 1e6, start_timeout_s, clk.syncs);
            rc = EXIT_NOT_READY;
            break;
        }
        if (preroll && gate_seen) {
            /* The board is ready: read again at once, and the first read that finds the socket
             * empty (this stand-in has caught up) starts the scenario. Waiting for frames here
             * instead (poll or the wall tick) made "empty" mean 1 ms without a frame on the
             * bus, which a board sending a SYNC every 1 ms seldom leaves: the start came 12-25 s
             * of board ticks after the board was ready, or not within --start-timeout (CI,
             * 2026-12-02/03). */
        } else if (clock_ticks) {
            /* The board's SYNC starts each step: wait for frames (1 ms at most, so a silent
             * bus still lets the wall clock take over). */
            struct pollfd pfd = {.fd = fd, .events = POLLIN};
            (void)poll(&pfd, 1, 1);
        } else {
            add_us(&next, TICK_US);
            struct timespec now;
            clock_gettime(CLOCK_MONOTONIC, &now);
            if (now.tv_sec > next.tv_sec ||
                (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec)) {
                late_ticks++;
                next = now; /* a late tick is not made up by a burst: resynchronise */
            }
            while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR &&
                   !stop_requested) {
            }
        }
        struct timespec t_before_read;
        clock_gettime(CLOCK_REALTIME, &t_before_read);
        can_batch_t rx;
        if (can_socket_receive(fd, &rx, &st) != ARGIL_OK) {
            fprintf(stderr, "argil-sim: CAN %s: receive failed (%s)\n", iface,
                    strerror(st.last_errno));
            rc = EXIT_RUN;
            break;
        }
        uint32_t out = GPIO_OUT_DRIVE_ENABLE;
        if (gpio.mode != GPIO_NONE && !gpio_read_outputs(&gpio, &out)) {
            fprintf(stderr, "argil-sim: GPIO: cannot read the board's outputs (%s)\n",
                    strerror(errno));
            rc = EXIT_RUN;
            break;
        }
        for (uint8_t i = 0; i < rx.n; i++)
            backlog_syncs += scn_clock_is_tick(&rx.f[i]);
        if (backlog_syncs > max_backlog_syncs)
            max_backlog_syncs = backlog_syncs;
        if (rx.n < CAN_BATCH_MAX)
            backlog_syncs = 0; /* the socket is empty: caught up */
        struct timespec t_read;
        clock_gettime(CLOCK_REALTIME, &t_read);
        if (preroll && gate_seen && rx.n == 0) {
            /* The board is ready and nothing is queued: the scenario starts here. Its start
             * line is stamped before this (empty) read, so every SYNC the checker counts after
             * it is one this clock counts. */
            preroll = false;
            snprintf(line, sizeof(line),
                     "start scenario %s can %s gpio %s preroll_syncs=%u preroll_ms=%lld "
                     "catch_up_ms=%.1f",
                     scn_path ? scn.name : "none", iface, gpio_name, clk.syncs,
                     (long long)((mono_us() - preroll_t0_us) / 1000),
                     (double)(mono_us() - gate_seen_us) / 1000.0);
            write_event(&t_before_read, 0, line);
            fflush(event_log);
            scn_clock_init(&clk, clock_ticks, mono_us());
            clock_gettime(CLOCK_MONOTONIC, &next); /* the wall tick restarts here too */
            max_backlog_syncs = 0; /* the backlog of the scenario, not of the start-up */
            sim_runner_hold(&run, false);
            run.have_gpio_out = false; /* the next tick logs DRIVE_ENABLE's level */
            continue;
        }
        /* One device step per SYNC (with the frames the board sent before it), or one on the
         * wall clock when the bus has been silent; frames after the last SYNC wait for it. */
        uint32_t steps_this_read = 0;
        for (uint32_t i = 0; i <= rx.n && rc == 0; i++) {
            uint32_t dt_us = 0;
            if (i < rx.n) {
                const can_frame_t *f = &rx.f[i];
                (void)can_batch_push(&held, f);
                if (scn_clock_is_tick(f))
                    dt_us = scn_clock_sync(&clk, mono_us());
                else if (held.n < CAN_BATCH_MAX)
                    continue;
                /* a full batch without SYNC is handed over with a step of 0 */
            } else {
                dt_us = scn_clock_idle(&clk, mono_us());
                if (dt_us == 0)
                    break;
                if (dt_us > TICK_US)
                    late_ticks++;
            }
            /* host-side steps are the host rig's; log them so the record is complete */
            while (!preroll && scn_path && next_host < scn.n_steps &&
                   scn.step[next_host].t_us <= run.now_us) {
                const scn_step_t *s = &scn.step[next_host++];
                if (scenario_action_is_host_side(s->action)) {
                    snprintf(line, sizeof(line), "host line=%u (for the host side) %s",
                             (unsigned)s->line, s->text);
                    log_event(NULL, run.now_us, line);
                }
            }
            while (!preroll && next_mark < n_marks && mark_us[next_mark] <= run.now_us) {
                /* sync=N: this step began at the board's N-th SYNC since the start line, the
                 * instant the checker anchors on (this line is stamped later, after the I/O) */
                if (i < rx.n)
                    snprintf(line, sizeof(line), "mark at %" PRId64 ".%06" PRId64 " sync=%u",
                             mark_us[next_mark] / 1000000, mark_us[next_mark] % 1000000,
                             clk.syncs);
                else
                    snprintf(line, sizeof(line), "mark at %" PRId64 ".%06" PRId64,
                             mark_us[next_mark] / 1000000, mark_us[next_mark] % 1000000);
                log_event(NULL, run.now_us, line);
                next_mark++;
            }
            can_batch_t tx;
            run.outputs_reused = steps_this_read++ > 0;
            sim_runner_tick(&run, &held, out, &tx, dt_us);
            scn_clock_wall_while_bus_off(&clk, run.faults.bus_off); /* no SYNC until restart */
            held.n = 0;
            const argil_err_t se = can_send_all(fd, &tx, &st);
            if (se == ARGIL_ERR_IO) {
                fprintf(stderr, "argil-sim: CAN %s: send failed (%s)\n", iface,
                        strerror(st.last_errno));
                rc = EXIT_RUN;
            } else if (gpio.mode != GPIO_NONE &&
                       !gpio_write_inputs(&gpio, sim_runner_gpio_in(&run))) {
                fprintf(stderr, "argil-sim: GPIO: cannot drive the board's inputs (%s)\n",
                        strerror(errno));
                rc = EXIT_RUN;
            }
            flush_events(&t_read);
            if (!preroll && clk.now_us >= end_us)
                break;
        }
        prev_read = t_read;
    }
    while (!preroll && scn_path && next_mark < n_marks && mark_us[next_mark] <= run.now_us) {
        snprintf(line, sizeof(line), "mark at %" PRId64 ".%06" PRId64,
                 mark_us[next_mark] / 1000000, mark_us[next_mark] % 1000000);
        log_event(NULL, run.now_us, line);
        next_mark++;
    }
    defer_events = false;
    {
        struct timespec now;
        clock_gettime(CLOCK_REALTIME, &now);
        flush_events(&now);
    }
    if (lost_ev > 0)
        fprintf(stderr, "argil-sim: %u events not logged (more than %u in one tick)\n",
                lost_ev, EVENTS_MAX);
    snprintf(line, sizeof(line),
             "end frames_rx=%u frames_tx=%u tx_busy=%u tx_errors=%u error_frames_retried=%u "
             "error_frames_unsent=%u late_ticks=%u dropped=%u/%u silenced=%u "
             "clock %s syncs=%u wall_steps=%u max_backlog_syncs=%u cpu_ms=%.0f",
             st.rx_frames, st.tx_frames, st.tx_busy, st.tx_errors, err_frames_retried,
             err_pending_n, late_ticks, run.faults.dropped_to_board,
             run.faults.dropped_from_board, run.faults.silenced, clock_ticks ? "ticks" : "wall",
             clk.syncs, clk.wall_steps, max_backlog_syncs, cpu_ms());
    log_event(NULL, run.now_us, line);
    if (event_log != stdout)
        fclose(event_log);
    gpio_close(&gpio);
    close(fd);
    return rc;
}
