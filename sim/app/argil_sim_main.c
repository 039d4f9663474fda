/* argil-sim: the simulated arm as a device on a real CAN bus. Every millisecond (absolute
 * clock_nanosleep) it reads the board's frames from a SocketCAN interface and the board's
 * DRIVE_ENABLE / WDOG_KICK outputs, runs sim_runner_tick (the same per-tick function the SIL
 * fault matrix runs: three CiA 402 drives, arm dynamics, hand, scenario, fault injection), and
 * writes the drives' frames and the input lines back. Events go to an event log on
 * CLOCK_REALTIME, so they line up with `candump -l`. Usage: docs/sim.md. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <glob.h>
#include <gpiod.h>
#include <inttypes.h>
#include <linux/can.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "firmware/hal/can_socket.h"
#include "firmware/hal/gpio_port.h"
#include "shared/gpio_lines.h"
#include "sim/scenario.h"
#include "sim/sim_runner.h"

#define TICK_US 1000u
#define MAX_STEP_US 20000u /* longest device step when ticks come late */
#define EXIT_RUN 1   /* could not open the bus or GPIO, or I/O failed while running */
#define EXIT_USAGE 2 /* bad option or scenario */

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static void usage(FILE *to)
{
    fputs("usage: argil-sim --can IFACE [--gpio-chip CHIP] [--scenario FILE] [--log-dir DIR]\n"
          "                 [--seconds S] [--help]\n"
          "  The simulated arm (3 CiA 402 drives, arm dynamics, GPIO, a scripted hand) on a\n"
          "  SocketCAN interface, in real time at 1 kHz.\n"
          "  --can IFACE       CAN interface the board is on (vcan0, can0)\n"
          "  --gpio-chip CHIP  GPIO chip with the board's named lines: a gpio-sim chip is driven\n"
          "                    through sysfs (pull/value), any other chip through libgpiod with\n"
          "                    the inputs of the board as this side's outputs; none: no GPIO\n"
          "                    (e-stop released, drives taken as enabled)\n"
          "  --scenario FILE   hil/scenarios/*.scn: hand moves, faults (docs/sim.md); none: hold\n"
          "  --log-dir DIR     write DIR/events.log (default: events to stdout)\n"
          "  --seconds S       stop after S seconds (default: the scenario's duration, else\n"
          "                    until SIGINT/SIGTERM)\n"
          "exit: 0 ran to the end, 1 bus/GPIO could not be opened or failed, 2 bad usage\n",
          to);
}

/* ---- event log ---- */

static FILE *event_log;

static void log_event(void *ctx, int64_t t_us, const char *event)
{
    (void)ctx;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    fprintf(event_log, "(%lld.%06ld) %s t=%" PRId64 ".%06" PRId64 "\n", (long long)ts.tv_sec,
            ts.tv_nsec / 1000, event, t_us / 1000000, t_us % 1000000);
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

/* Sends the tick's frames: data frames through can_socket_send, SocketCAN error frames (the
 * bus-off fault) written with their CAN_ERR_FLAG id, which vcan delivers to the board's socket
 * as an error frame. */
static argil_err_t can_send_all(int fd, const can_batch_t *tx, can_socket_stats_t *st)
{
    can_batch_t data = {0};
    for (uint8_t i = 0; i < tx->n; i++) {
        if (tx->f[i].id & CAN_ERR_FLAG) {
            struct can_frame cf;
            memset(&cf, 0, sizeof(cf));
            cf.can_id = tx->f[i].id & (CAN_ERR_FLAG | CAN_ERR_MASK);
            cf.can_dlc = 8;
            memcpy(cf.data, tx->f[i].data, 8);
            if (send(fd, &cf, sizeof(cf), MSG_DONTWAIT) != (ssize_t)sizeof(cf))
                st->tx_errors++;
        } else {
            (void)can_batch_push(&data, &tx->f[i]);
        }
    }
    return data.n ? can_socket_send(fd, &data, st) : ARGIL_OK;
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
    const char *iface = NULL, *chip = NULL, *scn_path = NULL, *log_dir = NULL;
    double seconds = -1.0;
    static const struct option opts[] = {
        {"can", required_argument, NULL, 'c'},      {"gpio-chip", required_argument, NULL, 'g'},
        {"scenario", required_argument, NULL, 's'}, {"log-dir", required_argument, NULL, 'l'},
        {"seconds", required_argument, NULL, 't'},  {"help", no_argument, NULL, 'h'},
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
    sim_params_t sp;
    sim_params_default(&sp);
    sim_runner_init(&run, &sp, scn_path ? &scn : NULL, gpio.mode != GPIO_NONE, log_event, NULL);
    const int64_t end_us = seconds > 0.0 ? (int64_t)(seconds * 1e6)
                           : scn_path ? scn.duration_us
                                      : INT64_MAX;
    char line[160];
    snprintf(line, sizeof(line), "start scenario %s can %s gpio %s", scn_path ? scn.name : "none",
             iface, gpio.mode == GPIO_SYSFS ? "gpio-sim" : gpio.mode == GPIO_GPIOD ? "gpiod" : "none");
    log_event(NULL, 0, line);

    can_socket_stats_t st;
    memset(&st, 0, sizeof(st));
    uint32_t next_host = 0, late_ticks = 0;
    int rc = 0;
    struct timespec next, prev;
    clock_gettime(CLOCK_MONOTONIC, &next);
    prev = next;
    uint32_t dt_us = TICK_US;
    while (!stop_requested && run.now_us < end_us) {
        /* host-side steps are the host rig's; log them so the record is complete */
        while (scn_path && next_host < scn.n_steps && scn.step[next_host].t_us <= run.now_us) {
            const scn_step_t *s = &scn.step[next_host++];
            if (scenario_action_is_host_side(s->action)) {
                snprintf(line, sizeof(line), "host line=%u (for the host side) %s",
                         (unsigned)s->line, s->text);
                log_event(NULL, run.now_us, line);
            }
        }
        can_batch_t rx, tx;
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
        sim_runner_tick(&run, &rx, out, &tx, dt_us);
        const argil_err_t se = can_send_all(fd, &tx, &st);
        if (se == ARGIL_ERR_IO) {
            fprintf(stderr, "argil-sim: CAN %s: send failed (%s)\n", iface,
                    strerror(st.last_errno));
            rc = EXIT_RUN;
            break;
        }
        if (gpio.mode != GPIO_NONE && !gpio_write_inputs(&gpio, sim_runner_gpio_in(&run))) {
            fprintf(stderr, "argil-sim: GPIO: cannot drive the board's inputs (%s)\n",
                    strerror(errno));
            rc = EXIT_RUN;
            break;
        }
        add_us(&next, TICK_US);
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if (now.tv_sec > next.tv_sec || (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec)) {
            late_ticks++;
            next = now; /* a late tick is not made up by a burst: resynchronise */
        }
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR &&
               !stop_requested) {
        }
        /* The arm is physics: the next step covers the wall time that really passed (at
         * most MAX_STEP_US), so the scenario clock stays on the wall clock when ticks are
         * late (a loaded machine, an emulated VM). */
        clock_gettime(CLOCK_MONOTONIC, &now);
        const int64_t el_us = (int64_t)(now.tv_sec - prev.tv_sec) * 1000000 +
                              (now.tv_nsec - prev.tv_nsec) / 1000;
        prev = now;
        dt_us = el_us < 1 ? 1u : el_us > MAX_STEP_US ? MAX_STEP_US : (uint32_t)el_us;
    }
    snprintf(line, sizeof(line),
             "end frames_rx=%u frames_tx=%u tx_busy=%u late_ticks=%u dropped=%u/%u silenced=%u",
             st.rx_frames, st.tx_frames, st.tx_busy, late_ticks, run.faults.dropped_to_board,
             run.faults.dropped_from_board, run.faults.silenced);
    log_event(NULL, run.now_us, line);
    if (event_log != stdout)
        fclose(event_log);
    gpio_close(&gpio);
    close(fd);
    return rc;
}
