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

typedef struct {
    uint8_t store, ch;
    int32_t ijk[3];
    float before, after;
} undo_entry_t;

typedef struct {
    undo_entry_t *e;
    size_t n;
} undo_step_t;

typedef struct {
    undo_step_t *steps;
    size_t nsteps;            /* steps held (done + redoable) */
    size_t done;              /* steps currently applied; steps[done..nsteps) can be redone */
    size_t cap;
    size_t bytes, budget_bytes;
    bool open;                /* between undo_begin and undo_commit */
    int32_t clo[3], cdims[3], slo[3], sdims[3];
    uint32_t cmask, smask;    /* channels snapshotted */
    float *snap;
    size_t snap_cap;
    undo_entry_t *pend;       /* entries noted by the editor during the open step */
    size_t npend, pend_cap;
} undo_t;

void undo_init(undo_t *u, size_t budget_bytes);
void undo_free(undo_t *u);

/* Snapshots the channels in cmask (coefficients, box [clo, chi)) and smask (samples, [slo, shi))
 * before an edit. ARGIL_ERR_STATE when a step is already open, ARGIL_ERR_ARG, ARGIL_ERR_NOMEM. */
argil_err_t undo_begin(undo_t *u, const field_t *f, const int32_t clo[3], const int32_t chi[3],
                       uint32_t cmask, const int32_t slo[3], const int32_t shi[3], uint32_t smask);

/* Adds one change the editor made itself (instead of a snapshotted box) to the open step; each
 * point must be noted at most once per step and not also lie in a snapshotted channel.
 * ARGIL_ERR_STATE without undo_begin, ARGIL_ERR_NOMEM. */
argil_err_t undo_note(undo_t *u, int store, int ch, const int32_t ijk[3], float before, float after);

/* Records what changed since undo_begin as one step (none when nothing changed), drops the redo
 * steps, then the oldest steps while over budget. ARGIL_ERR_STATE without undo_begin. */
argil_err_t undo_commit(undo_t *u, const field_t *f);

/* Reverts / re-applies one step; ARGIL_ERR_EMPTY when there is none. Changed blocks become dirty. */
argil_err_t undo_undo(undo_t *u, field_t *f);
argil_err_t undo_redo(undo_t *u, field_t *f);

#endif
