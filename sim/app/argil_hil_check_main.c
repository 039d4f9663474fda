/* argil-hil-check SCENARIO CANDUMP_LOG EVENT_LOG: decides a scenario's expectations from what a
 * rig recorded (a candump -l log and argil-sim's event log), one line per expectation, then
 * "N passed, N failed". Exit 0 all passed, 1 some failed, 2 bad usage or unreadable input. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/hil_check.h"
#include "sim/scenario.h"

#define LOG_MAX (256u * 1024u * 1024u)

/* Reads a whole file into a heap buffer; prints one line and returns NULL on failure. */
static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "argil-hil-check: cannot open %s (%s)\n", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1u << 20, n = 0;
    char *buf = malloc(cap);
    while (buf != NULL) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap || ferror(f))
            break;
        if (cap >= LOG_MAX) {
            fprintf(stderr, "argil-hil-check: %s is larger than 256 MiB\n", path);
            free(buf);
            buf = NULL;
            break;
        }
        char *more = realloc(buf, cap * 2u);
        if (more == NULL) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = more;
        cap *= 2u;
    }
    if (buf != NULL && ferror(f)) {
        fprintf(stderr, "argil-hil-check: cannot read %s\n", path);
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *len = n;
    return buf;
}

int main(int argc, char **argv)
{
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        puts("usage: argil-hil-check [--link-ticks N] [--heartbeat-ticks N] SCENARIO CANDUMP_LOG "
             "EVENT_LOG\n"
             "  Checks each expectation of SCENARIO (hil/scenarios/*.scn) against a candump -l\n"
             "  log and argil-sim's event log; prints one line per expectation and\n"
             "  'N passed, N failed'. Exit 0 all passed, 1 some failed, 2 bad usage or input.\n"
             "  --link-ticks N  board ticks (0-50, default 0) the host link may take to deliver a\n"
             "                  host-side step: added to the bounds anchored on one\n"
             "  --heartbeat-ticks N  the board's drive heartbeat consumer time in ticks (10-10000,\n"
             "                  default 250) for heartbeat_supervised");
        return 0;
    }
    uint32_t link_ticks = 0, heartbeat_ticks = 0;
    while (argc >= 3 && (strcmp(argv[1], "--link-ticks") == 0 ||
                         strcmp(argv[1], "--heartbeat-ticks") == 0)) {
        const bool link = strcmp(argv[1], "--link-ticks") == 0;
        const long lo = link ? 0 : 10, hi = link ? 50 : 10000;
        char *end = NULL;
        const long v = strtol(argv[2], &end, 10);
        if (end == argv[2] || *end != '\0' || v < lo || v > hi) {
            fprintf(stderr, "argil-hil-check: %s '%s': expected %ld-%ld\n", argv[1], argv[2], lo,
                    hi);
            return 2;
        }
        if (link)
            link_ticks = (uint32_t)v;
        else
            heartbeat_ticks = (uint32_t)v;
        argv += 2;
        argc -= 2;
    }
    if (argc != 4) {
        fprintf(stderr, "usage: argil-hil-check [--link-ticks N] [--heartbeat-ticks N] SCENARIO "
                        "CANDUMP_LOG EVENT_LOG (try --help)\n");
        return 2;
    }
    static scenario_t s;
    scn_error_t se;
    if (scenario_load(&s, argv[1], &se) != SCN_OK) {
        if (se.line > 0)
            fprintf(stderr, "argil-hil-check: %s:%u: %s\n", argv[1], se.line, se.msg);
        else
            fprintf(stderr, "argil-hil-check: %s: %s\n", argv[1], se.msg);
        return 2;
    }
    size_t can_len = 0, ev_len = 0;
    char *can = slurp(argv[2], &can_len);
    if (can == NULL)
        return 2;
    char *ev = slurp(argv[3], &ev_len);
    if (ev == NULL) {
        free(can);
        return 2;
    }
    hil_obs_t o;
    hil_obs_init(&o);
    o.link_ticks = link_ticks;
    if (heartbeat_ticks > 0)
        o.heartbeat_ticks = heartbeat_ticks;
    uint32_t line = 0;
    hil_err_t e = hil_obs_add_candump(&o, can, can_len, &line);
    if (e != HIL_OK) {
        fprintf(stderr, "argil-hil-check: %s:%u: %s\n", argv[2], line, hil_err_name(e));
    } else if ((e = hil_obs_add_events(&o, &s, ev, ev_len, &line)) != HIL_OK) {
        fprintf(stderr, "argil-hil-check: %s:%u: %s\n", argv[3], line, hil_err_name(e));
    }
    free(can);
    free(ev);
    if (e != HIL_OK) {
        hil_obs_free(&o);
        return 2;
    }
    unsigned passed = 0, failed = 0;
    for (uint32_t i = 0; i < s.n_expects; i++) {
        hil_result_t r;
        hil_check_expect(&s, &o, i, &r);
        printf("%s %s:%u: %s — %s\n", r.pass ? "PASS" : "FAIL", argv[1],
               (unsigned)s.expect[i].line, s.expect[i].text, r.msg);
        if (r.pass)
            passed++;
        else
            failed++;
    }
    printf("%u passed, %u failed\n", passed, failed);
    hil_obs_free(&o);
    return failed == 0 ? 0 : 1;
}
