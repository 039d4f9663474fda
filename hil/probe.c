/* hil-probe: the HIL rig's measuring tool, run next to argil-board (in the VM or on a board).
 * Timestamps are CLOCK_REALTIME seconds with microseconds, the clock candump -l uses, so the
 * daemon's lines, GPIO edges and CAN frames of one run share one time axis.
 *   hil-probe now                      print the current time
 *   hil-probe stamp                    copy stdin to stdout, each line prefixed by its time
 *   hil-probe set FILE TEXT            write TEXT to FILE (a stimulus, e.g. gpio-sim's pull) and
 *                                      print the times just before and after the write
 *   hil-probe watch FILE MS [PERIOD_US] sample a sysfs GPIO value file (gpio-sim's
 *       sim_gpioN/value) every PERIOD_US (default 500) for MS ms and print
 *       "samples=N high=N edges=N first_edge=T last_edge=T final=V start=T end=T
 *        first_edge_lo=T last_edge_lo=T": an edge happened after its _lo time (the sample
 *       before) and no later than its time (the sample that saw it); start/end: the first and
 *       last sample, so a caller can count board ticks in between; with HIL_WATCH_READY=PATH
 *       in the environment it creates PATH once the first sample is taken, so a caller can
 *       apply its stimulus after the watch has begun however late a busy rig started it; with
 *       HIL_WATCH_AFTER_EDGE_MS=M it ends M ms after the first edge (MS is then the most it waits
 *       for one)
 *   hil-probe fifo PRIO CMD [ARG...]    run CMD under SCHED_FIFO at PRIO (busybox has no chrt):
 *                                      the rig's CAN logger must not lose frames to a busy CPU
 *   hil-probe chrt PRIO PID            set a running task SCHED_FIFO at PRIO (the VM raises
 *                                      ksoftirqd so UDP on loopback is delivered under load)
 * With HIL_FIFO_PRIO=N in the environment it runs SCHED_FIFO at N (samples on time even when
 * the rig is busy; keep it below argil-board's threads). */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

static int usage(void)
{
    fprintf(stderr, "usage: hil-probe now | stamp | set FILE TEXT | watch FILE MS [PERIOD_US] | "
                    "fifo PRIO CMD [ARG...] | chrt PRIO PID\n");
    return 2;
}

/* SCHED_FIFO at $HIL_FIFO_PRIO when set (1-98); a failure is reported, not fatal. */
static void maybe_fifo(void)
{
    const char *e = getenv("HIL_FIFO_PRIO");
    const int prio = e ? atoi(e) : 0;
    if (prio < 1 || prio > 98)
        return;
    struct sched_param sp = {.sched_priority = prio};
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
        fprintf(stderr, "hil-probe: SCHED_FIFO %d: %s (running unprioritised)\n", prio, strerror(errno));
}

/* Writes text to path in one write(2), timed on both sides. */
static int set_file(const char *path, const char *text)
{
    const int fd = open(path, O_WRONLY);
    if (fd < 0) {
        fprintf(stderr, "hil-probe: cannot open '%s': %s\n", path, strerror(errno));
        return 1;
    }
    const size_t len = strlen(text);
    const double before = now_s();
    const ssize_t n = write(fd, text, len);
    const double after = now_s();
    const int err = errno;
    close(fd);
    if (n != (ssize_t)len) {
        fprintf(stderr, "hil-probe: write '%s' to '%s': %s\n", text, path, n < 0 ? strerror(err) : "short write");
        return 1;
    }
    printf("%.6f %.6f\n", before, after);
    return 0;
}

/* Copies stdin to stdout line by line, each prefixed with the time it was read. */
static int stamp(void)
{
    char line[1024];
    setvbuf(stdout, NULL, _IOLBF, 0);
    while (fgets(line, sizeof(line), stdin)) {
        printf("%.6f %s", now_s(), line);
        if (!strchr(line, '\n'))
            putchar('\n');
    }
    return 0;
}

/* Reads the first byte of a sysfs attribute: 1 for '1', 0 for '0', -1 on error. */
static int read_level(int fd)
{
    char c = 0;
    if (pread(fd, &c, 1, 0) != 1)
        return -1;
    return c == '1' ? 1 : c == '0' ? 0 : -1;
}

/* Creates $HIL_WATCH_READY (if set) holding the first sample's time. */
static void signal_ready(double t)
{
    const char *ready = getenv("HIL_WATCH_READY");
    if (!ready || !*ready)
        return;
    FILE *f = fopen(ready, "w");
    if (!f) {
        fprintf(stderr, "hil-probe: cannot create '%s': %s\n", ready, strerror(errno));
        return;
    }
    fprintf(f, "%.6f\n", t);
    fclose(f);
}

static int watch(const char *path, long ms, long period_us)
{
    const int fd = open(path, O_RDONLY);
    if (fd < 0) {
        fprintf(stderr, "hil-probe: cannot open '%s': %s\n", path, strerror(errno));
        return 1;
    }
    double end = now_s() + (double)ms / 1e3;
    const char *ae = getenv("HIL_WATCH_AFTER_EDGE_MS");
    const double after_edge_s = ae && *ae ? strtod(ae, NULL) / 1e3 : -1.0;
    long samples = 0, high = 0, edges = 0;
    double first = 0.0, last = 0.0, t_first = 0.0, t_last = 0.0;
    int prev = -1, v = -1;
    const struct timespec nap = {0, period_us * 1000L};
    double t_prev = 0.0, first_lo = 0.0, last_lo = 0.0;
    /* Each sample is stamped when its read has returned, so an edge lies in (the previous
     * sample's stamp, this sample's stamp] even if the prober was preempted in between. */
    while (now_s() < end) {
        v = read_level(fd);
        const double t = now_s();
        if (v < 0) {
            fprintf(stderr, "hil-probe: '%s' is not a 0/1 value\n", path);
            close(fd);
            return 1;
        }
        if (samples == 0) {
            t_first = t;
            signal_ready(t);
        }
        t_last = t;
        samples++;
        high += v;
        if (prev >= 0 && v != prev) {
            if (edges == 0) {
                first = t;
                first_lo = t_prev;
                if (after_edge_s >= 0.0 && t + after_edge_s < end)
                    end = t + after_edge_s;
            }
            last = t;
            last_lo = t_prev;
            edges++;
        }
        prev = v;
        t_prev = t;
        nanosleep(&nap, NULL);
    }
    close(fd);
    printf("samples=%ld high=%ld edges=%ld first_edge=%.6f last_edge=%.6f final=%d start=%.6f "
           "end=%.6f first_edge_lo=%.6f last_edge_lo=%.6f\n", samples, high, edges, first, last, v,
           t_first, t_last, first_lo, last_lo);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage();
    if (strcmp(argv[1], "now") == 0 && argc == 2) {
        printf("%.6f\n", now_s());
        return 0;
    }
    if (strcmp(argv[1], "stamp") == 0 && argc == 2)
        return stamp();
    if (strcmp(argv[1], "fifo") == 0 && argc >= 4) {
        char *e;
        const long prio = strtol(argv[2], &e, 10);
        if (*e || prio < 1 || prio > 98) {
            fprintf(stderr, "hil-probe: fifo needs PRIO in 1..98\n");
            return 2;
        }
        struct sched_param sp = {.sched_priority = (int)prio};
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
            fprintf(stderr, "hil-probe: SCHED_FIFO %ld: %s (running unprioritised)\n", prio,
                    strerror(errno));
        execvp(argv[3], argv + 3);
        fprintf(stderr, "hil-probe: cannot run '%s': %s\n", argv[3], strerror(errno));
        return 127;
    }
    if (strcmp(argv[1], "chrt") == 0 && argc == 4) {
        char *e1, *e2;
        const long prio = strtol(argv[2], &e1, 10), pid = strtol(argv[3], &e2, 10);
        if (*e1 || *e2 || prio < 1 || prio > 98 || pid < 1) {
            fprintf(stderr, "hil-probe: chrt needs PRIO in 1..98 and a PID\n");
            return 2;
        }
        struct sched_param sp = {.sched_priority = (int)prio};
        if (sched_setscheduler((pid_t)pid, SCHED_FIFO, &sp) != 0) {
            fprintf(stderr, "hil-probe: SCHED_FIFO %ld for pid %ld: %s\n", prio, pid, strerror(errno));
            return 1;
        }
        return 0;
    }
    if (strcmp(argv[1], "set") == 0 && argc == 4)
        return set_file(argv[2], argv[3]);
    if (strcmp(argv[1], "watch") == 0 && (argc == 4 || argc == 5)) {
        char *e1, *e2 = NULL;
        const long ms = strtol(argv[3], &e1, 10);
        const long period_us = argc == 5 ? strtol(argv[4], &e2, 10) : 500;
        if (*e1 || ms <= 0 || ms > 600000 || (e2 && *e2) || period_us < 50 || period_us > 1000000) {
            fprintf(stderr, "hil-probe: watch needs MS in 1..600000 and PERIOD_US in 50..1000000\n");
            return 2;
        }
        maybe_fifo();
        return watch(argv[2], ms, period_us);
    }
    return usage();
}
