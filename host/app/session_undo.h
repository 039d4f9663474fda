/* Undo and redo in the live session (Ferley §3.3): one step per stroke — everything
 * the B-spline model did from one press of button 1 (or a script's paint) until the next,
 * the clay's springing back and settling after the release included — holding only the
 * coefficients and samples that changed (host/model/undo.h), within a memory budget.
 *
 * How: a shadow of the model's state at the last step boundary (coefficient p and the sample
 * channels d, rest, RGB, mass, damping, stiffness, rest length; velocity and external force
 * are not part of a state). Every writer of the field marks the blocks it changes dirty
 * (sparse_t.dirty; nothing else in the session takes those flags), so at a boundary only the
 * dirty blocks are compared with the shadow, each difference noted (undo_note), the step
 * committed and the shadow brought up to date. That diff does not stall the session: at a press
 * the dirty blocks only go on a pending list (their flags cleared) and are diffed a slice per
 * session tick (session_undo_observe: at most SESSION_UNDO_SLICE_VALUES changes noted); before
 * the field is next written (a solve step is due, an edit) the blocks not yet diffed are copied
 * aside (one memcpy each) and the slices go on from the copies, so the step holds exactly the
 * field at the press. An undo or redo, a new boundary or a knot insertion finishes the pending
 * diff first. A press that changes nothing (no impulse from the board, no host tool edit until
 * the next boundary: a press in the air) is no step: what changed meanwhile (the last stroke's
 * settling) is joined to the last stroke's step (undo_commit_joined), or stays drift after an
 * undo or redo. An undo or redo writes the field back, the
 * shadow follows, and every coefficient velocity is zeroed: a restored state is at rest.
 * Changes after an undo or redo (or the start) that are no stroke (the solver's round-off as
 * the window reopens) are dropped by the next undo or redo, so undo, redo gives the redone state
 * exactly; the next stroke keeps them and clears the redo steps. A knot insertion (field_refine) cuts
 * the history: older steps are refused (undo_undo: ARGIL_ERR_STATE).
 *
 * Runs in the thread that steps the model (the session thread); requests from the live
 * window's keys and from script verbs are queued and done right after a solve step, with
 * button 1 up as the host sees it. */
#ifndef ARGIL_SESSION_UNDO_H
#define ARGIL_SESSION_UNDO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/app/peer.h"
#include "host/model/field.h"
#include "host/model/sparse.h"
#include "host/model/undo.h"
#include "shared/argil_err.h"

#define SESSION_UNDO_MB_DEFAULT 256u  /* argil sculpt --undo-mb */
#define SESSION_UNDO_MB_MAX 65536u
#define SESSION_UNDO_QUEUE 16         /* requests waiting at most (more are refused) */
/* The journal ring is written (zeros) this far ahead of the furthest the steps reached, one
 * chunk per session tick, so a stroke boundary does not pay first-touch page faults (measured:
 * half of a 2.6 MB boundary's 40 ms; MADV_POPULATE_WRITE did not help on this VM, as
 * MAP_POPULATE did not for undo_init: docs/model.md) and the budget is not all resident from
 * the start. */
#define SESSION_UNDO_PREFAULT_AHEAD (16u << 20)
#define SESSION_UNDO_PREFAULT_CHUNK (64u << 10)
/* Sample channels a state holds: FS_D … FS_RESTLEN, the first ones of a sample block (not
 * FS_FORCE, the step's external force). */
#define SESSION_UNDO_SAMP_CH (FS_RESTLEN + 1)
/* One slice of a pending step (a session tick) first copies aside at most
 * SESSION_UNDO_SLICE_COPY_BYTES of its blocks, then, all copied, diffs: it notes at most about
 * SESSION_UNDO_SLICE_VALUES changes (a block new to the shadow counts half that; a block is
 * never split, so one block's up to 4608 more) over at most SESSION_UNDO_SLICE_BLOCKS blocks
 * (docs/model.md has the times). */
#define SESSION_UNDO_SLICE_VALUES 2048u
#define SESSION_UNDO_SLICE_BLOCKS 48u
#define SESSION_UNDO_SLICE_COPY_BYTES (2u << 20) /* copied aside per slice before the diff */
#define SESSION_UNDO_HIST_BINS 256u   /* per-tick work histogram, 10 us bins */

/* A block of a sealed step still to diff: its key, its store (0: coefficients, 1: samples)
 * and where its copy is in the pool (+1; 0: not copied, the field still holds it). */
typedef struct {
    int32_t key[3];
    uint32_t store;
    size_t copy;
} session_undo_pend_t;

typedef enum { SESSION_UNDO_OP_UNDO = 1, SESSION_UNDO_OP_REDO = 2 } session_undo_op_t;

/* What one queued request came to (session_undo_process). */
typedef enum {
    SESSION_UNDO_NONE = 0,            /* no request queued */
    SESSION_UNDO_WAIT,                /* not yet: button 1 still down at the host, no solve
                                       * step this tick, or the stroke's diff still pending */
    SESSION_UNDO_DONE,                /* the model is the earlier (later) state */
    SESSION_UNDO_REFUSED              /* nothing changed; the message says why */
} session_undo_result_t;

typedef struct {
    uint32_t steps;                   /* steps recorded */
    uint32_t undos, redos;            /* done */
    uint32_t refused;                 /* requests refused */
    uint32_t resets;                  /* histories lost (out of memory while recording) */
    size_t last_step_bytes, max_step_bytes; /* journal bytes of one step */
    size_t last_step_changes;         /* values it holds */
    double max_work_ms;               /* thread CPU time of the most recording work one session
                                       * tick did (a press, a slice, copying aside) */
    double max_request_ms;            /* ... of the slowest undo / redo (its diff finished first) */
    uint32_t work_ticks;              /* ticks that did recording work */
    uint32_t work_hist_10us[SESSION_UNDO_HIST_BINS]; /* their thread CPU time */
    uint32_t slices, copied_blocks;   /* slices run; blocks copied aside before a write */
    uint32_t air_presses;             /* presses that changed nothing (no step) */
} session_undo_stats_t;

typedef struct {
    bool on;                          /* a B-spline model and a budget > 0 */
    size_t budget_bytes;
    undo_t u;
    sparse_t sh_coef;                 /* the model at the last boundary: FC_P */
    sparse_t sh_samp;                 /* ... and the first SESSION_UNDO_SAMP_CH sample channels */
    bool sh_ready;
    uint32_t sh_gen;                  /* lattice_gen of the shadow */
    bool stroke_open;                 /* a stroke began since the last undo / redo (or the
                                       * start): what changed since the last boundary is its;
                                       * else it is drift (the solver's round-off) */
    bool stroke_real;                 /* ... and changed the clay (an edit, or touched) */
    bool stroke_after_drift;          /* ... and began with none open (its base holds drift) */
    bool pressed;                     /* button 1 at the host, as last observed */
    double press_impulse_ns;          /* the peer's Σ|J| and host tool edits at the press */
    uint32_t press_host_edits;
    /* the sealed step being diffed, a slice per tick */
    bool pend_open;                   /* its undo_t step is open */
    bool pend_joined;                 /* it joins the step before it (a press in the air) */
    session_undo_pend_t *pend;
    size_t npend, pend_next, pend_cap;
    size_t pend_copied;               /* pend[0, pend_copied) are diffed or copied aside */
    float *pool;                      /* copies of blocks set aside (mapped, grows) */
    size_t pool_cap, pool_used;       /* floats */
    size_t pool_pf;                   /* floats of the pool written ahead (prefault) */
    argil_err_t pend_err;
    struct {
        int op;                       /* session_undo_op_t */
        int line;                     /* script line, 0 for a key */
    } q[SESSION_UNDO_QUEUE];
    int nq;
    session_undo_stats_t stats;
    char note[96];                    /* what the last request or recording did (HUD) */
    char off_reason[64];              /* why undo is off (when !on) */
    const uint8_t *pf_ring;           /* the ring being faulted in ahead (prefault) */
    size_t pf_off, pf_head_max;       /* written ahead below pf_off; the steps' furthest end */
} session_undo_t;

/* Ready to record on field f (NULL: the springs solve, whose grid keeps no history: undo is
 * off) with a journal of budget_bytes (0: off; mapped, resident only as it fills). The shadow
 * is a copy of f now. ARGIL_ERR_NOMEM (then off, with the note saying so). */
argil_err_t session_undo_init(session_undo_t *su, const field_t *f, size_t budget_bytes);
void session_undo_free(session_undo_t *su);

/* An edit begins (a paint, a script's or a test's stroke) and writes the field at once: the open
 * stroke (what changed since the last boundary) is sealed as one step (joined to the step before
 * when it changed nothing), its blocks copied aside, diffed by later slices; with none open (the
 * start, after an undo or redo) instead the redo steps go and the drift joins the new stroke.
 * ARGIL_ERR_NOMEM: the history is lost (stats.resets), recording goes on. */
argil_err_t session_undo_edit_start(session_undo_t *su, field_t *f);

/* Button 1 went down: as session_undo_edit_start, but nothing is copied (call
 * session_undo_before_write before the field is written) and the new stroke counts only once
 * session_undo_touched says it changed the clay; an open stroke that never did is no boundary
 * (after an undo or redo) or is joined to the last step. */
argil_err_t session_undo_press(session_undo_t *su, field_t *f);

/* The open stroke changed the clay (the board's impulses, the host tool). */
void session_undo_touched(session_undo_t *su);

/* The field is about to be written: the pending blocks not yet diffed are copied aside. */
void session_undo_before_write(session_undo_t *su, field_t *f);

/* One slice of the pending diff (the step is committed after its last); true while some is
 * left. */
bool session_undo_slice(session_undo_t *su, field_t *f);

/* The pending diff to its end now. ARGIL_ERR_NOMEM: the history is lost. */
argil_err_t session_undo_finish(session_undo_t *su, field_t *f);

/* Undo (redo false) or redo one step on f: the open stroke is recorded first (or, after an
 * undo or redo, the drift dropped); then f holds exactly the earlier (later) state, coefficient
 * velocities zero. The sample box that changed goes to slo/shi (empty: slo = shi). Nothing
 * changes on ARGIL_ERR_EMPTY (no step), ARGIL_ERR_STATE (the step is older than a knot
 * insertion) or ARGIL_ERR_ARG (undo is off). */
argil_err_t session_undo_step(session_undo_t *su, field_t *f, bool redo, int32_t slo[3],
                              int32_t shi[3]);

/* Steps that can be undone (the open stroke counts) / redone now. */
size_t session_undo_undo_count(const session_undo_t *su);
size_t session_undo_redo_count(const session_undo_t *su);

/* The median thread CPU time of the ticks that did recording work (10 us bins, the bin's low
 * end), ms; 0 with none. */
double session_undo_work_median_ms(const session_undo_t *su);

/* Bytes held: the steps, and the shadow. */
size_t session_undo_bytes(const session_undo_t *su);
size_t session_undo_shadow_bytes(const session_undo_t *su);

/* ---- the session (host/app/session.c, the live window through session_frame_t) ---- */

/* Command lines typed to `argil connect` (its standard input): "undo" or "redo", blanks around
 * them ignored, one per line of at most SESSION_UNDO_LINE_MAX bytes. */
#define SESSION_UNDO_LINE_MAX 64
typedef enum {
    SESSION_UNDO_CMD_BAD = -1,        /* a line naming no command: bad holds it (printable) */
    SESSION_UNDO_CMD_NONE = 0,        /* no line ended yet, or it was blank */
    SESSION_UNDO_CMD_UNDO = SESSION_UNDO_OP_UNDO,
    SESSION_UNDO_CMD_REDO = SESSION_UNDO_OP_REDO
} session_undo_cmd_t;
typedef struct {
    char buf[SESSION_UNDO_LINE_MAX];
    size_t len;
    bool overlong;                    /* the line being read went past SESSION_UNDO_LINE_MAX */
    char bad[SESSION_UNDO_LINE_MAX + 8]; /* the last bad line, non-printable bytes as '?' */
} session_undo_lines_t;

/* Takes one byte of the command stream; at a line's end says what it asked for. */
session_undo_cmd_t session_undo_feed(session_undo_lines_t *l, char c);

/* Queues an undo or redo (line: the script line, 0 from a key); false when the queue is full
 * (the note says so). */
bool session_undo_request(session_undo_t *su, session_undo_op_t op, int line);

/* After the peer took in the board's frames, before peer_tick(p, dt_us): notices a knot
 * insertion (the shadow is taken again), the open stroke touching the clay, button 1 going down
 * at the host (a stroke begins); then copies aside what is pending when the tick's solve step
 * will write the field (peer_solve_due), else diffs one slice. */
void session_undo_observe(session_undo_t *su, peer_t *p, uint32_t dt_us);

/* A paint (or any edit not made with button 1) begins. */
void session_undo_peer_edit_start(session_undo_t *su, peer_t *p);

/* Works on the oldest queued request: refused at once while hand_pressed (the hand holds
 * button 1) or when undo is off; waits while the host still sees button 1 down or no solve
 * step ran this tick (solved false), and while the open stroke, sealed at the first tick that
 * got this far, is diffed (a slice per tick: session_undo_observe; what the solver changes
 * meanwhile is drift and dropped); else undone or redone, and then the grid view, the
 * board's window (re-sent), the re-mesh box and (through the peer's dirty box) the journal
 * follow. *line gets the request's script line; msg a one-line message (what was done, or
 * why not). */
session_undo_result_t session_undo_process(session_undo_t *su, peer_t *p, bool hand_pressed,
                                           bool solved, int *line, char *msg, size_t msg_len);

#endif
