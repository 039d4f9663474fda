/* A sculpting session on the simulated arm, in lockstep on a virtual clock: the script moves
 * the virtual hand, the simulated device answers the board over CAN, the board core ticks at
 * 1 kHz, and the host applies what the board sends to the global field. Same script, same
 * bytes out. */
#ifndef ARGIL_SESSION_H
#define ARGIL_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <signal.h>
#include <stdint.h>

#include "shared/argil_err.h"

typedef struct {
    const char *script_path;
    const char *out_dir;          /* NULL: write nothing */
    int window_edge;              /* 16 or 32 */
    bool progress;                /* a progress line on stderr */
    float settle_s;               /* time allowed for the board to become ACTIVE */
    bool deadline_faults;         /* an overrun streak faults the board (off only for profiling) */
    volatile sig_atomic_t *stop;  /* set (e.g. by SIGINT) to end early and keep what was made */
} session_opts_t;

typedef struct {
    double sim_seconds;
    uint32_t board_ticks;
    uint32_t tick_hz;
    uint32_t worst_compute_ns;
    uint32_t median_compute_ns;   /* of every tick, 1 µs resolution */
    uint32_t p99_compute_ns;
    uint32_t deadline_misses;
    float peak_force_n;
    float force_limit_n;
    double volume_before_m3;
    double volume_after_m3;
    size_t triangles;
    size_t vertices;
    bool watertight;
    int final_state;              /* safety_state_t */
    int fault_code;               /* fault_code_t of the last fault, 0 if none */
    uint32_t windows_sent;
    uint32_t impulse_frames;
    uint32_t link_errors;
    uint32_t telemetry_rows;
    bool interrupted;             /* ended early through opts->stop */
} session_summary_t;

void session_opts_default(session_opts_t *o);

/* Runs the whole session. On failure err says what went wrong and nothing half-written is
 * left in out_dir (files appear by rename once complete). */
argil_err_t session_run(const session_opts_t *opts, session_summary_t *sum, char *err,
                        size_t err_len);

#endif
