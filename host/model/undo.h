/* Undo/redo journal (Ferley et al. §3.3): every edit is one step holding only the coefficients
 * and samples it changed (index, value before, value after); unlimited depth within a memory
 * budget (oldest steps dropped first); a new edit clears the redo steps. */
#ifndef ARGIL_UNDO_H
#define ARGIL_UNDO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/model/field.h"
#include "shared/argil_err.h"

#define UNDO_STORE_COEF 0
#define UNDO_STORE_SAMP 1
#define UNDO_STORE_DREST 2   /* a sample's density and rest moved together (plastic edit) */

/* A run of changes at consecutive x indices of one store and channel, starting at ijk; it is
 * followed in the journal by n (before, after) float pairs: 16 B + 8 B per change; for
 * UNDO_STORE_DREST by n (d before, d after, rest before) triples: 16 B + 12 B per change. */
typedef struct {
    uint8_t store, ch;
    uint16_t n;
    int32_t ijk[3];
} undo_run_t;

/* One step: a contiguous stretch [off, off + len) of the ring (modulo its size). */
typedef struct {
    size_t off, len;
    size_t n;                 /* changes held */
    uint32_t lattice_gen;     /* the field's lattice_gen when the step was recorded */
    bool joined;              /* undone and redone together with the step before it (one unit:
                               * what followed a stroke without being one, e.g. a press in the air) */
} undo_step_t;

typedef struct {
    uint8_t *ring;            /* the journal: mapped and faulted in once, reused as a ring */
    size_t ring_cap;          /* bytes; the budget, or more after one step larger than it */
    undo_step_t *steps;       /* oldest first; consecutive in the ring */
    size_t nsteps;            /* steps held (done + redoable) */
    size_t done;              /* steps currently applied; steps[done..nsteps) can be redone */
    size_t cap;
    size_t bytes, budget_bytes; /* bytes held by the steps */
    bool open;                /* between undo_begin and undo_commit */
    int32_t clo[3], cdims[3], slo[3], sdims[3];
    uint32_t cmask, smask;    /* channels snapshotted */
    float *snap;
    size_t snap_cap;
    undo_step_t cur;          /* the open step */
    undo_run_t run;           /* its last run, header not yet written */
    size_t run_off;           /* where that header goes */
} undo_t;

/* An empty journal whose ring of budget_bytes is mapped and written once now (~10-20 ms per
 * 64 MB here, and that memory is resident from then on), so that recording a step never waits on
 * a first-touch page fault. ARGIL_ERR_NOMEM (the journal then grows on demand instead). */
argil_err_t undo_init(undo_t *u, size_t budget_bytes);
/* The same ring of budget_bytes, mapped but not faulted in: memory becomes resident only as
 * steps fill it (~4 us per first-touched 4 kB page while recording), for an owner that records
 * outside a real-time path and should not hold the whole budget from the start (the session's
 * undo: host/app/session_undo.h). ARGIL_ERR_NOMEM. */
argil_err_t undo_init_lazy(undo_t *u, size_t budget_bytes);
void undo_free(undo_t *u);

/* Snapshots the channels in cmask (coefficients, box [clo, chi)) and smask (samples, [slo, shi))
 * before an edit. ARGIL_ERR_STATE when a step is already open, ARGIL_ERR_ARG, ARGIL_ERR_NOMEM. */
argil_err_t undo_begin(undo_t *u, const field_t *f, const int32_t clo[3], const int32_t chi[3],
                       uint32_t cmask, const int32_t slo[3], const int32_t shi[3], uint32_t smask);

/* Adds one change the editor made itself (instead of a snapshotted box) to the open step; each
 * point must be noted at most once per step and not also lie in a snapshotted channel. Changes
 * noted in increasing x along a row share one run header. store is UNDO_STORE_COEF or
 * UNDO_STORE_SAMP (else ARGIL_ERR_ARG). ARGIL_ERR_STATE without undo_begin, ARGIL_ERR_NOMEM. */
argil_err_t undo_note(undo_t *u, int store, int ch, const int32_t ijk[3], float before, float after);

/* Notes one sample whose density went from d_before to d_after while its rest density moved by
 * the same amount from rest_before (rest_before + (d_after - d_before), the plastic edit of the
 * tools): 12 B instead of two 8 B changes; redo recomputes the rest with that same expression.
 * ARGIL_ERR_STATE without undo_begin, ARGIL_ERR_NOMEM. */
argil_err_t undo_note_drest(undo_t *u, const int32_t ijk[3], float d_before, float d_after, float rest_before);

/* Records what changed since undo_begin as one step (none when nothing changed), drops the redo
 * steps, then the oldest steps while over budget; the newest step is always kept, even when it
 * alone is larger than the budget. Oldest steps may already be dropped while the open step
 * grows. ARGIL_ERR_STATE without undo_begin, ARGIL_ERR_NOMEM. */
argil_err_t undo_commit(undo_t *u, const field_t *f);
/* The same; joined: the step becomes part of the unit of the newest done step (undo_undo and
 * undo_redo take them together; the redo steps are dropped as for any step); with no step done
 * it is not recorded (the field keeps the changes, with nothing to take them back). */
argil_err_t undo_commit_joined(undo_t *u, const field_t *f, bool joined);

/* Units (a step and the joined steps after it) among steps[0, n): what undo_undo can take back
 * with n = done, what undo_redo can bring back with the difference of nsteps and done. */
size_t undo_units(const undo_t *u, size_t n);

/* Reverts / re-applies one unit (a step and the steps joined to it, newest first when
 * reverting); ARGIL_ERR_EMPTY when there is none; ARGIL_ERR_STATE (nothing
 * changed) when the step was recorded before a knot insertion (field_refine), whose indices now
 * name other coefficients: the history cannot be crossed back over a refinement. Changed blocks
 * become dirty. */
argil_err_t undo_undo(undo_t *u, field_t *f);
argil_err_t undo_redo(undo_t *u, field_t *f);

/* Drops the redo steps now (a new edit has begun that will be recorded later); nothing when a
 * step is open (undo_commit drops them then) or there are none. */
void undo_clear_redo(undo_t *u);

#endif
