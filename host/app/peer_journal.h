/* The autosave journal of a live session over a peer (argil sculpt's session, argil connect):
 * after each global solve step one record of what the step changed, durable within autosave_s
 * (host/io/journal.h, docs/files.md). */
#ifndef ARGIL_PEER_JOURNAL_H
#define ARGIL_PEER_JOURNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/app/peer.h"
#include "host/io/journal.h"

typedef struct {
    uint32_t solves_seen;         /* peer solves already looked at */
    uint32_t stray_records;       /* changes found outside the peer's dirty box (should be 0) */
    double real_s;                /* wall time spent diffing, appending and syncing */
    double cpu_s;                 /* CPU time of the same work (the calling thread's) */
    size_t peak_bytes;            /* most memory the journal held after a step (journal_bytes) */
    uint32_t dump_record;         /* tests: at record N (1-based; 0 = never) write the model as */
    const char *dump_path;        /* of it to this .argil and ask the session to stop */
} peer_journal_t;

/* Starts the journal in dir for the grid as it is now (journal_open with these intervals, at
 * session time 0); ARGIL_ERR_STATE when dir already holds one. */
argil_err_t peer_journal_open(journal_t *j, const char *dir, const grid_t *g, float autosave_s,
                              float checkpoint_s, char *err, size_t err_len);

/* After peer_tick: when a solve step ran since the last call, one record of what it changed
 * (the peer's dirty box; the whole grid before each write, counting strays), then the write
 * and fdatasync once due. t_s: session time. Sets *stop_now once the dump record is written. */
argil_err_t peer_journal_step(journal_t *j, peer_journal_t *pj, const peer_t *p, double t_s,
                              bool *stop_now, char *err, size_t err_len);

#endif
