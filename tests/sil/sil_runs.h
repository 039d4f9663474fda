/* Two runs of the default session (scripts/default.scn) into fresh temp directories, for the
 * SIL tests that judge one run and compare it with another (test_session: the same run twice;
 * test_global_solve: B-spline against springs). Header-only: each test binary is one file. */
#ifndef ARGIL_SIL_RUNS_H
#define ARGIL_SIL_RUNS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "host/app/session.h"

typedef struct {
    char dir[2][64];
    session_summary_t sum[2];
} sil_runs_t;

/* Runs the default script into dir; deadline misses are counted (the tests assert them), not
 * turned into faults. solve NULL: the session's default global solve. 0 on success. */
static inline int sil_run_default(const char *dir, session_summary_t *sum,
                                  const peer_global_solve_t *solve)
{
    session_opts_t o;
    session_opts_default(&o);
    o.script_path = "scripts/default.scn";
    o.out_dir = dir;
    o.deadline_faults = false;
    if (solve)
        o.global_solve = *solve;
    char err[1024] = "";
    const argil_err_t rc = session_run(&o, sum, err, sizeof(err));
    if (rc != ARGIL_OK)
        fprintf(stderr, "session failed: %s\n", err);
    return rc == ARGIL_OK ? 0 : -1;
}

/* Two runs under /tmp/<prefix>-XXXXXX: run k with solve[k] (NULL entries or NULL solve: the
 * default). 0 on success. */
static inline int sil_runs_start(sil_runs_t *r, const char *prefix,
                                 const peer_global_solve_t *const solve[2])
{
    for (int k = 0; k < 2; k++) {
        snprintf(r->dir[k], sizeof(r->dir[k]), "/tmp/%s-XXXXXX", prefix);
        if (!mkdtemp(r->dir[k]))
            return -1;
    }
    for (int k = 0; k < 2; k++)
        if (sil_run_default(r->dir[k], &r->sum[k], solve ? solve[k] : NULL) != 0)
            return -1;
    return 0;
}

/* Removes the files a session writes and the two directories. */
static inline void sil_runs_remove(const sil_runs_t *r)
{
    const char *names[] = {"final.ply", "telemetry.csv", "session.scn", "model.argil"};
    char p[256];
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < 4; i++) {
            snprintf(p, sizeof(p), "%s/%s", r->dir[k], names[i]);
            unlink(p);
        }
        rmdir(r->dir[k]);
    }
}

#endif
