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

#include "host/app/peer.h"
#include "host/app/script.h"
#include "host/app/session_undo.h"
#include "shared/argil_err.h"

/* What a per-tick hook sees of the running session (e.g. the live window, docs/render.md). */
typedef struct {
    double t_s;                   /* simulated time at the end of this tick */
    bool active;                  /* the board has become ACTIVE (the script is playing) */
    bool script_done;             /* every script command has finished */
    peer_t *peer;                 /* grid, telemetry, tool, window; the hook may clear
                                   * peer->dirty_lo/hi (they only record what to re-mesh) */
    script_player_t *player;      /* the hook may change tool, filter and params (setting
                                   * params_changed: the same path as script commands) and,
                                   * once script_done, the hand (pos_m, vel_m_s, buttons) */
    vec3_t model_offset_m;        /* model = device + offset */
    session_undo_t *undo;         /* undo / redo: the hook may queue requests
                                   * (session_undo_request) and read counts and note */
} session_frame_t;

typedef struct {
    void (*on_tick)(void *ctx, session_frame_t *f);  /* called after every board tick */
    void *ctx;
    bool hold_open;               /* after the script, keep running until *stop */
} session_hook_t;

typedef struct {
    const char *script_path;      /* NULL: no script (the hook drives the hand) */
    const char *out_dir;          /* NULL: write nothing */
    int window_edge;              /* 16 or 32 */
    uint32_t tick_us;             /* the board's loop period: 1000, 500 or 250 (--rate-hz) */
    peer_global_solve_t global_solve; /* what the host's global solve steps (docs/model.md) */
    int knot_ratio;               /* B-spline: grid samples per knot span at the start, 1, 2 or
                                   * 4 (--knot-ratio; each script 'refine' halves it) */
    bool progress;                /* a progress line on stderr */
    float settle_s;               /* time allowed for the board to become ACTIVE */
    bool deadline_faults;         /* an overrun streak faults the board (off only for profiling) */
    volatile sig_atomic_t *stop;  /* set (e.g. by SIGINT) to end early and keep what was made */
    const session_hook_t *hook;   /* NULL: none; a hook that changes nothing changes no result */
    /* Autosave journal in out_dir (host/io/journal.h, docs/files.md). */
    bool journal;                 /* on by default; removed again at a clean end */
    float autosave_s;             /* records become durable within this (sim or real) time */
    float checkpoint_s;           /* rotation onto a new base snapshot, simulated seconds */
    uint32_t debug_dump_record;   /* tests: at journal record N (1-based; 0 = never) write the */
    const char *debug_dump_path;  /* model as of it to this .argil and end the session */
    uint32_t undo_mb;             /* undo journal budget, MiB (--undo-mb; 0: no undo) */
    /* Called (session thread) with a one-line message for each undo / redo a script asked for
     * that was refused ("FILE: line N: undo refused: nothing to undo"); the session goes on.
     * NULL: not told (the summary counts them). */
    void (*on_note)(void *ctx, const char *msg);
    void *note_ctx;
} session_opts_t;

#define SESSION_PREEMPTED_KEPT 8u

typedef struct {
    double sim_seconds;
    uint32_t board_ticks;
    uint32_t tick_hz;
    uint32_t worst_compute_ns;
    uint32_t median_compute_ns;   /* of every timed tick, 1 µs resolution */
    uint32_t p99_compute_ns;
    uint32_t deadline_misses;
    uint32_t deadline_miss_tick[SESSION_PREEMPTED_KEPT]; /* the first ones' tick numbers */
    uint32_t preempted_ticks;     /* ticks the machine preempted: not timed, in no figure above */
    uint32_t preempted_over_period; /* … of them charged past the period; the first ones: */
    uint32_t preempted_over_tick[SESSION_PREEMPTED_KEPT];
    uint32_t rt_stats_frames;     /* RT_STATS reports the host received from the board */
    msg_rt_stats_t rt;            /* the newest one (wake-up latency, compute, overruns) */
    float peak_force_n;            /* the board's command (clamped by the board itself) */
    float peak_delivered_force_n;  /* what the simulated arm's motors delivered at the tip */
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
    uint32_t journal_records;     /* edit steps journaled */
    uint32_t journal_syncs;       /* write + fdatasync rounds */
    uint32_t journal_checkpoints; /* rotations onto a new base snapshot */
    uint64_t journal_bytes;       /* record bytes appended */
    uint32_t journal_stray_records; /* changes found outside the peer's dirty box (should be 0) */
    double journal_real_s;        /* wall time spent diffing, appending and syncing */
    double journal_cpu_s;         /* CPU time of the same work */
    size_t journal_peak_bytes;    /* most memory the journal held (journal_bytes) */
    uint32_t solves;              /* global solve steps */
    double solve_median_ms;       /* thread CPU time per solve step (10 µs resolution) */
    double solve_p99_ms;
    double solve_max_ms;
    uint32_t solve_errors;        /* B-spline steps that failed and were skipped */
    uint32_t refines;             /* knot insertions done (script 'refine', the live key) */
    int knot_ratio_end;           /* samples per knot span at the end (0: springs solve) */
    float refine_max_dd;          /* the largest |density change| a refinement made (grid) */
    double real_seconds;          /* wall time of the lockstep loop */
    bool undo_on;                 /* the session recorded undo steps */
    uint32_t undo_steps;          /* steps recorded (one per stroke) */
    uint32_t undos, redos;        /* done */
    uint32_t undo_refused;        /* undo / redo requests refused */
    size_t undo_bytes;            /* journal bytes the steps held at the end */
    size_t undo_max_step_bytes;   /* the largest step */
    size_t undo_shadow_bytes;     /* the shadow of the model at the last boundary */
    double undo_max_work_ms;      /* thread CPU time of the slowest stroke boundary or undo */
    char undo_note[96];           /* why undo is off, or what it did last */
    size_t grid_bytes_start;      /* the sparse grid's memory after the sphere fill */
    size_t grid_bytes_end;        /* ... at the end (after grid_compact) */
    size_t grid_dense_bytes_end;  /* a dense grid of the end bounds (4 channels of floats) */
    int32_t grid_lo[3], grid_hi[3]; /* the grid's bounds at the end (samples; nominal 0..88) */
} session_summary_t;

void session_opts_default(session_opts_t *o);

/* Runs the whole session. On failure err says what went wrong and nothing half-written is
 * left in out_dir (files appear by rename once complete). */
argil_err_t session_run(const session_opts_t *opts, session_summary_t *sum, char *err,
                        size_t err_len);

#endif
