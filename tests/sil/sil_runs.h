/* Scripted sessions for the SIL tests: a fresh temp directory with a script written into it,
 * the options every test run takes, the checks every clean run passes, the run's final mesh,
 * and removal of what a run wrote. Also two runs of the default session (scripts/default.scn)
 * for the tests that judge one run and compare it with another (test_session: the same run
 * twice; test_global_solve: B-spline against springs). Header-only: each test binary is one
 * file; the assert helpers use cmocka. */
#ifndef ARGIL_SIL_RUNS_H
#define ARGIL_SIL_RUNS_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/session.h"
#include "host/io/ply.h"

/* Makes /tmp/<prefix>-XXXXXX in dir (64 bytes) and writes the parts (NULL ends them) one after
 * the other to <dir>/<name>, whose path goes to script (128 bytes). 0 on success. */
static inline int sil_script_dir(char *dir, const char *prefix, const char *name,
                                 const char *const *parts, char *script)
{
    snprintf(dir, 64, "/tmp/%s-XXXXXX", prefix);
    if (!mkdtemp(dir))
        return -1;
    snprintf(script, 128, "%s/%s", dir, name);
    FILE *fp = fopen(script, "w");
    if (!fp)
        return -1;
    for (; *parts; parts++)
        fputs(*parts, fp);
    return fclose(fp) == 0 ? 0 : -1;
}

/* The session's default options for script (NULL: the default script) writing into out_dir,
 * deadline misses counted (the tests assert them), not turned into faults. */
static inline void sil_opts(session_opts_t *o, const char *script, const char *out_dir)
{
    session_opts_default(o);
    if (script)
        o->script_path = script;
    o->out_dir = out_dir;
    o->deadline_faults = false;
}

/* Runs the session o and fails the test with the session's error (prefixed by what) if the run
 * does not finish. */
static inline void sil_run(const session_opts_t *o, session_summary_t *sum, const char *what)
{
    char err[1024] = "";
    if (session_run(o, sum, err, sizeof(err)) != ARGIL_OK)
        fail_msg("%s: %s", what, err);
}

/* Removes the files in dir (not its subdirectories) and dir; rmdir's result (0: removed). */
static inline int sil_remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    struct dirent *e;
    char p[256];
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        snprintf(p, sizeof(p), "%s/%s", dir, e->d_name);
        unlink(p);
    }
    closedir(d);
    return rmdir(dir);
}

/* Runs the script text with the global solve `solve` in a fresh temp directory and asserts the
 * session refuses it (ARGIL_ERR_ARG); prints the refusal after "# <label>: ", leaves it in err
 * and the summary in sum, and removes the directory. */
static inline void sil_assert_refused(const char *text, peer_global_solve_t solve,
                                      const char *label, session_summary_t *sum, char *err,
                                      size_t err_len)
{
    char dir[64], path[128];
    const char *const parts[] = {text, NULL};
    assert_int_equal(sil_script_dir(dir, "argil-refused", "s.scn", parts, path), 0);
    session_opts_t o;
    sil_opts(&o, path, dir);
    o.global_solve = solve;
    err[0] = '\0';
    assert_int_equal(session_run(&o, sum, err, err_len), ARGIL_ERR_ARG);
    printf("# %s: %s\n", label, err);
    (void)sil_remove_dir(dir);
}

/* Asserts what every clean scripted run shows: no solve error, the board ACTIVE at the end, a
 * watertight mesh and every journal record inside the dirty box. */
static inline void sil_assert_clean(const session_summary_t *sum)
{
    assert_int_equal(sum->solve_errors, 0);
    assert_int_equal(sum->final_state, SAFETY_ACTIVE);
    assert_true(sum->watertight);
    assert_int_equal(sum->journal_stray_records, 0); /* every change inside the dirty box */
}

/* Reads <dir>/final.ply into m (initialised here); asserts it reads. */
static inline void sil_read_final(const char *dir, mesh_t *m)
{
    char path[128], err[512] = "";
    snprintf(path, sizeof(path), "%s/final.ply", dir);
    mesh_init(m);
    assert_int_equal(ply_read_mesh(path, m, err, sizeof(err)), PLY_OK);
}

/* The farthest vertex of m along sign·axis among those within 2 mm of that axis line, mm. */
static inline double sil_extent_mm(const mesh_t *m, int axis, int sign)
{
    double best = -1e9;
    for (size_t i = 0; i < m->n_vert; i++) {
        const float *p = &m->pos[3 * i];
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        if (sqrt((double)p[a1] * p[a1] + (double)p[a2] * p[a2]) * 1e3 > 2.0)
            continue;
        const double v = sign * (double)p[axis] * 1e3;
        best = v > best ? v : best;
    }
    return best;
}

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
    sil_opts(&o, "scripts/default.scn", dir);
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

/* Removes the files the two sessions wrote and their directories. */
static inline void sil_runs_remove(const sil_runs_t *r)
{
    for (int k = 0; k < 2; k++)
        (void)sil_remove_dir(r->dir[k]);
}

#endif
