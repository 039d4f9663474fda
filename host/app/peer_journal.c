/* The live session's autosave journal step, shared by argil sculpt and argil connect. */
#define _POSIX_C_SOURCE 200809L
#include "host/app/peer_journal.h"

#include <time.h>

static double clock_now_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

argil_err_t peer_journal_open(journal_t *j, const char *dir, const grid_t *g, float autosave_s,
                              float checkpoint_s, char *err, size_t err_len)
{
    journal_cfg_t jcfg;
    journal_cfg_default(&jcfg);
    jcfg.autosave_s = autosave_s;
    jcfg.checkpoint_s = checkpoint_s;
    return journal_open(j, dir, g, &jcfg, 0.0, clock_now_s(CLOCK_MONOTONIC), err, err_len);
}

argil_err_t peer_journal_step(journal_t *j, peer_journal_t *pj, const peer_t *p, double t_s,
                              bool *stop_now, char *err, size_t err_len)
{
    /* Only a solve step (100 Hz) changes the field, inside the peer's dirty box (the box the
     * re-mesher relies on too; the window hook may clear it, but only after this call). The
     * clocks are read here only: on some virtual machines every read is a system call. */
    if (p->stats.solves == pj->solves_seen)
        return ARGIL_OK;
    pj->solves_seen = p->stats.solves;
    const double real0_s = clock_now_s(CLOCK_MONOTONIC);
    const double cpu0_s = clock_now_s(CLOCK_THREAD_CPUTIME_ID);
    const uint64_t wall_ms = (uint64_t)(clock_now_s(CLOCK_REALTIME) * 1e3);
    journal_box_t box;
    for (int a = 0; a < 3; a++) {
        box.lo[a] = p->dirty_lo[a];
        box.hi[a] = p->dirty_hi[a];
    }
    bool appended = false;
    argil_err_t e = journal_record(j, p->grid, &box, j->seq + 1u, t_s, real0_s, wall_ms,
                                   &appended, err, err_len);
    if (e == ARGIL_OK && journal_sync_due(j, t_s, real0_s)) {
        /* Before each write, the whole grid: a change outside the dirty box still gets saved
         * (and counted: there should be none). */
        bool stray = false;
        e = journal_record(j, p->grid, NULL, j->seq + 1u, t_s, real0_s, wall_ms, &stray, err,
                           err_len);
        pj->stray_records += stray;
        appended = appended || stray;
    }
    if (e == ARGIL_OK && appended && pj->dump_record == j->seq && pj->dump_path) {
        e = journal_write_model(j, p->grid, j->seq, pj->dump_path, err, err_len);
        *stop_now = true;
    }
    if (e == ARGIL_OK)
        e = journal_tick(j, t_s, real0_s, err, err_len);
    pj->real_s += clock_now_s(CLOCK_MONOTONIC) - real0_s;
    pj->cpu_s += clock_now_s(CLOCK_THREAD_CPUTIME_ID) - cpu0_s;
    const size_t held = journal_bytes(j);
    if (held > pj->peak_bytes)
        pj->peak_bytes = held;
    return e;
}
