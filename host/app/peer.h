/* The host's half of the board protocol: keeps the sculpted representation (host/model/rep.h) in
 * step with the board — applies the board's impulses, sends versioned windows around the tool,
 * the tool settings and heartbeats — and hands telemetry to whoever records it.
 * Transport-neutral: bytes in, frames out through a callback. */
#ifndef ARGIL_PEER_H
#define ARGIL_PEER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/model/grid.h"
#include "host/model/rep.h"
#include "host/solve/gsolve.h"
#include "host/solve/rep_bspline.h"
#include "host/solve/solve_sched.h"
#include "shared/proto.h"

#define PEER_VERSIONS_KEPT 32u        /* window versions whose layout is remembered */
#define PEER_CHUNKS_PER_TICK 2u       /* WINDOW chunks sent per millisecond at most (the board
                                       * decodes two per tick) */

typedef struct {
    int32_t lo[3], hi[3];             /* sample index box [lo, hi) */
} peer_box_t;

typedef struct {
    uint32_t version;
    int32_t corner[3];
    int32_t dims[3];
} peer_window_ref_t;

/* Sends one encoded frame; returns false when the link cannot take it now. */
typedef bool (*peer_send_fn)(void *ctx, const uint8_t *frame, size_t len);
/* Receives each telemetry message in arrival order. */
typedef void (*peer_telemetry_fn)(void *ctx, const msg_telemetry_t *t);

/* What the global solve steps (docs/model.md "In the session"). */
typedef enum {
    PEER_SOLVE_SPRINGS = 0,           /* explicit density springs on the dense grid */
    PEER_SOLVE_BSPLINE                /* implicit B-spline model (host/solve/gsolve.h) */
} peer_global_solve_t;

typedef struct {
    int32_t window_edge;              /* samples per axis of the board's window */
    peer_global_solve_t global_solve; /* PEER_SOLVE_SPRINGS by default here (argil connect,
                                       * hil-host, the SIL rig); argil sculpt's session chooses
                                       * PEER_SOLVE_BSPLINE (session_opts_default) */
    int32_t knot_ratio;               /* B-spline: grid samples per knot span at the start, 1, 2
                                       * or 4 (1 by default; peer_refine halves it) */
    uint32_t heartbeat_period_us;     /* 5 ms */
    uint32_t solve_period_us;         /* global solve at 100 Hz: 10 ms */
    uint32_t window_min_period_us;    /* refresh an edited window at most this often */
    bool adaptive_region;             /* real-time hosts (argil connect): slow solve steps shrink
                                       * the solve's margin around the board's window
                                       * (host/solve/solve_sched.h). Off for lockstep sessions,
                                       * which must stay reproducible. */
} peer_cfg_t;

typedef struct {
    uint32_t frames_rx;
    uint32_t decode_errors;
    uint32_t impulse_frames;
    uint32_t impulses_unmapped;       /* for a window version no longer remembered */
    uint32_t windows_sent;
    uint32_t chunks_sent;
    uint32_t solves;
    uint32_t faults;
    uint16_t last_fault_code;
    uint32_t rt_stats_frames;         /* RT_STATS frames received */
    double impulse_total_ns;          /* Σ|J| applied */
    uint32_t solve_errors;            /* B-spline steps that failed (the field kept its state) */
    argil_err_t last_solve_error;
    uint32_t refines;                 /* knot insertions (peer_refine) */
    float refine_max_dd;              /* the largest |density change| one of them made */
    uint32_t host_tool_edits;         /* host tool applications that changed the model */
} peer_stats_t;

typedef struct {
    peer_cfg_t cfg;
    rep_t rep;                        /* what is sculpted: every model access goes through it */
    rep_bspline_t own;                /* the representation peer_init made over a grid */
    bool owns_rep;
    grid_t *grid;                     /* rep's sample grid (NULL: it keeps none) */
    peer_send_fn send;
    peer_telemetry_fn on_telemetry;
    void *ctx;
    uint32_t tx_seq;
    uint64_t time_us;
    bool board_seen;
    uint16_t board_tick_hz;           /* the board's loop rate from its newest HELLO (0: none yet) */
    msg_telemetry_t last_tm;
    bool have_tm;
    msg_rt_stats_t last_rt;           /* the board's newest deadline statistics (RT_STATS) */
    msg_tool_t tool;
    bool tool_dirty;
    bool want_armed;
    bool arm_sent;
    peer_window_ref_t refs[PEER_VERSIONS_KEPT];
    uint32_t next_version;
    peer_window_ref_t sending;        /* window whose chunks are going out */
    bool sending_active;
    uint16_t next_chunk;
    msg_window_t head;                /* header fields of the window being sent */
    float *win_samples;               /* window_edge³ */
    peer_window_ref_t current;        /* newest window fully sent */
    bool have_current;
    bool field_dirty;
    uint32_t since_window_us;
    uint32_t since_heartbeat_us;
    uint32_t impulse_seq_received;    /* newest IMPULSE batch taken in */
    uint32_t impulse_seq_applied;     /* newest batch integrated by a solve step */
    int32_t dirty_lo[3], dirty_hi[3]; /* samples changed since the last mesh (lo > hi: none) */
    peer_box_t box;                   /* the solve's physical window now */
    bool have_box;
    peer_stats_t stats;
    proto_msg_t scratch;
    gsolve_t *gs;                     /* peer_init's B-spline model (PEER_SOLVE_BSPLINE), else
                                       * NULL; for the session's undo and live window */
    solve_sched_t sched;              /* when the solve steps, its margin, its step times */
    host_tool_t host_tool;            /* what the board's carve does on the host (B-spline) */
    vec3_t host_prev_m;               /* stylus at the last host tool application */
    bool host_prev_valid;             /* button 1 held since then */
} peer_t;

void peer_cfg_default(peer_cfg_t *cfg);

/* Sets up the peer over a grid; the grid stays the caller's. With PEER_SOLVE_BSPLINE the model
 * is seeded from the grid's densities and the grid becomes its view. */
argil_err_t peer_init(peer_t *p, const peer_cfg_t *cfg, grid_t *grid, peer_send_fn send,
                      peer_telemetry_fn on_telemetry, void *ctx);
/* Sets up the peer over any representation (the caller's, kept; cfg's global_solve and
 * knot_ratio are not used). ARGIL_ERR_ARG, ARGIL_ERR_NOMEM. */
argil_err_t peer_init_rep(peer_t *p, const peer_cfg_t *cfg, rep_t rep, peer_send_fn send,
                          peer_telemetry_fn on_telemetry, void *ctx);
void peer_free(peer_t *p);

/* Takes in bytes of whole frames from the board. */
void peer_receive(peer_t *p, const uint8_t *bytes, size_t len);

/* Changes the tool (sent to the board on the next tick). */
void peer_set_tool(peer_t *p, const msg_tool_t *tool);

/* Says HELLO as the host (name: up to PROTO_NAME_LEN bytes): the board starts a session for
 * this host and answers with its HELLO. Every frame the peer sends carries the next number of
 * one sequence (tx_seq), as the board's session requires. False when it could not be sent. */
bool peer_send_hello(peer_t *p, const char *name);

/* Sends a heartbeat now, carrying command (proto_cmd_t: ARM, DISARM, END). */
bool peer_send_command(peer_t *p, uint8_t command);

/* Asks the board to arm (once it reports IDLE) — the session's start. */
void peer_request_arm(peer_t *p);

/* Advances the host by dt_us: heartbeats, tool, global solve and carving, windows. */
void peer_tick(peer_t *p, uint32_t dt_us);

/* peer_tick(p, dt_us) will run a global solve step (the model may be written). */
bool peer_solve_due(const peer_t *p, uint32_t dt_us);

/* Material channels a session can paint and show. */
typedef enum { PEER_MAT_STIFFNESS, PEER_MAT_MASS } peer_material_t;

/* The material at x relative to the default (1.0 = default): the painted scale of the B-spline
 * model; 1.0 everywhere with the springs solve (its material is uniform). */
float peer_material_at(const peer_t *p, peer_material_t ch, vec3_t x_m);

/* Sets the global solve's period, clamped to SOLVE_PERIOD_MIN_US..SOLVE_PERIOD_MAX_US. */
void peer_set_solve_period_us(peer_t *p, uint32_t us);

/* Paints the stiffness or mass scale toward `scale` within radius of centre (linear falloff);
 * ARGIL_ERR_STATE with the springs solve (uniform material), ARGIL_ERR_ARG for bad values. */
argil_err_t peer_paint_material(peer_t *p, peer_material_t ch, vec3_t centre_m, float radius_m,
                                float scale);

/* Knot insertion in the B-spline model during the session (gsolve_refine): a knot in every
 * span, R halves, the shape stays (the grid, the mesh and the board's window do not change);
 * the physical window reopens on the finer lattice at the next solve. max_dd (may be NULL): the
 * largest |density change| over the grid. ARGIL_ERR_STATE with the springs solve or at R = 1
 * (already one coefficient per sample), nothing changed; ARGIL_ERR_NOMEM. */
argil_err_t peer_refine(peer_t *p, float *max_dd);

/* What the board's carve tool does on the host while button 1 is held (host/model/host_tool.h;
 * carve with a sphere, no mirror by default): one application per solve period at the stylus,
 * with the tool's radius and axis (gsolve_apply_tool). ARGIL_ERR_ARG for a setting out of
 * range; ARGIL_ERR_STATE for anything but the default with the springs solve (it carves the
 * grid directly); nothing changes on error. */
argil_err_t peer_set_host_tool(peer_t *p, const host_tool_t *t);

/* Grid samples per knot span of the B-spline model now (0 with the springs solve). */
int32_t peer_knot_ratio(const peer_t *p);

/* Median, 99th percentile (10 µs resolution) and max of the solve steps' thread CPU times, ms. */
void peer_solve_times_ms(const peer_t *p, double *median, double *p99, double *max);

/* The model was set back to an earlier state (undo or redo, host/app/session_undo.h) and the
 * grid follows in sample box [lo, hi): re-mesh it (dirty box; the journal records it with the
 * next solve step), send the board a fresh window (so its local window keeps no undone dent)
 * and let the host tool start a new stroke. */
void peer_model_restored(peer_t *p, const int32_t lo[3], const int32_t hi[3]);

#endif
