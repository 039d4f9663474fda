/* make bench: the host model against Hua & Qin Tables 1-2 and Ferley et al.'s performance table.
 * Medians of repeated runs on this machine, wall time and this thread's CPU time (on a shared
 * machine the wall time also holds other processes' turns); the papers' figures and our goals are
 * printed beside ours. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "host/model/physwin.h"
#include "host/model/tools.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

/* CPU time of this thread: what the work costs while it has a core (the wall time also holds the
 * time other processes of a shared machine ran instead). */
static double cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), cmp);
    return v[n / 2];
}

/* "<= X ms" and "wall yes/NO, cpu yes/NO" (medians against the goal) for a row with a goal,
 * "-" for one without. */
static void goal_cols(double goal_ms, double wall_ms, double cpu_ms_, char *goal, size_t gn, char *meets,
                      size_t mn)
{
    if (goal_ms > 0.0) {
        snprintf(goal, gn, "<= %.1f ms", goal_ms);
        snprintf(meets, mn, "wall %s, cpu %s", wall_ms <= goal_ms ? "yes" : "NO", cpu_ms_ <= goal_ms ? "yes" : "NO");
    } else {
        snprintf(goal, gn, "-");
        snprintf(meets, mn, "-");
    }
}

static float g_radius;
static float sd_ball(void *ctx, vec3_t x)
{
    (void)ctx;
    return g_radius - vec3_norm(x);
}

/* Hua & Qin Table 1: geometric tool update (new coefficients, d = A p over the tool, dirty
 * blocks marked, undo step recorded) in a working space sampled at 128^3. */
static void table1(void)
{
    static const struct { int coefs, tool; double paper_ms, goal_ms; } rows[] = {
        {64, 10, 0.4, 0}, {64, 20, 3.0, 0}, {64, 40, 23.5, 0}, {128, 20, 8.3, 0}, {128, 40, 59.8, 2.0}};
    printf("== Hua & Qin Table 1: geometric tool (sphere carve), working space sampled at 128^3\n");
    printf("  coefficients  tool (samples)  paper (2.2 GHz PC)  ours wall: with undo / without  ours cpu: with undo / without  goal (with undo)  meets goal              coefs changed  dirty blocks\n");
    for (size_t r = 0; r < sizeof(rows) / sizeof(rows[0]); r++) {
        field_t f;
        const int ratio = 128 / rows[r].coefs;
        const float hc = 1.0f / (float)rows[r].coefs;
        g_radius = 0.4f;
        undo_t u; /* the journal's ring is mapped and faulted in here, once */
        if (undo_init(&u, (size_t)64 << 20) != ARGIL_OK) {
            fprintf(stderr, "bench_model: no memory for the undo journal\n");
            exit(1);
        }
        tool_shape_t t;
        memset(&t, 0, sizeof(t));
        t.kind = TOOL_SPHERE;
        tool_params_t p;
        tool_params_default(&p, TOOL_CARVE);
        enum { RUNS = 9 };
        double ms[2][RUNS], cms[2][RUNS];
        size_t changed[RUNS], dirty[RUNS];
        int32_t keys[1][3];
        for (int k = 0; k < 2; k++) { /* the same carves on a fresh ball, with and without undo */
            field_init(&f, hc, ratio, vec3(0, 0, 0));
            field_fill(&f, sd_ball, NULL, vec3(-0.5f, -0.5f, -0.5f), vec3(0.5f, 0.5f, 0.5f));
            t.radius_m = 0.5f * (float)rows[r].tool * f.sample_spacing_m;
            for (int i = 0; i < RUNS; i++) {
                tool_pose_t pose; /* points on the ball's equator: every application cuts material */
                const float a = 0.7f * (float)i;
                tool_pose_at(&pose, vec3(0.4f * cosf(a), 0.4f * sinf(a), 0.0f));
                (void)sparse_take_dirty(&f.samp, keys, 0); /* the mesher took the older blocks */
                tool_stats_t st = {0, 0, 0};
                const double t0 = now_ms(), c0 = cpu_ms();
                tool_apply(&f, &t, &pose, &p, k == 0 ? &u : NULL, &st); /* marks blocks dirty */
                ms[k][i] = now_ms() - t0;
                cms[k][i] = cpu_ms() - c0;
                changed[i] = st.coefs_changed;
                dirty[i] = sparse_take_dirty(&f.samp, NULL, 0);
            }
            if (k == 0)
                field_free(&f);
        }
        double c[RUNS], dd[RUNS];
        for (int i = 0; i < RUNS; i++) {
            c[i] = (double)changed[i];
            dd[i] = (double)dirty[i];
        }
        const double with_ms = median(ms[0], RUNS), without_ms = median(ms[1], RUNS);
        const double with_cpu = median(cms[0], RUNS), without_cpu = median(cms[1], RUNS);
        char goal[32], meets[40];
        goal_cols(rows[r].goal_ms, with_ms, with_cpu, goal, sizeof(goal), meets, sizeof(meets));
        printf("  %4d^3        %3d^3           %6.1f ms           %7.3f / %7.3f ms          %7.3f / %7.3f ms         %-16s  %-22s  %8.0f       %6.0f\n",
               rows[r].coefs, rows[r].tool, rows[r].paper_ms, with_ms, without_ms, with_cpu, without_cpu, goal,
               meets, median(c, RUNS), median(dd, RUNS));
        undo_free(&u);
        field_free(&f);
    }
}

/* The same carves with the least-squares fit of the coefficients (tool_params_t.fit = LSQ, 6 CGLS
 * iterations) instead of quasi-interpolation, without undo. */
static void table1_lsq(void)
{
    static const struct { int coefs, tool; } rows[] = {{64, 20}, {128, 20}, {128, 40}};
    printf("  least-squares fit (6 CGLS iterations), without undo:\n");
    for (size_t r = 0; r < sizeof(rows) / sizeof(rows[0]); r++) {
        field_t f;
        field_init(&f, 1.0f / (float)rows[r].coefs, 128 / rows[r].coefs, vec3(0, 0, 0));
        g_radius = 0.4f;
        field_fill(&f, sd_ball, NULL, vec3(-0.5f, -0.5f, -0.5f), vec3(0.5f, 0.5f, 0.5f));
        tool_shape_t t;
        memset(&t, 0, sizeof(t));
        t.kind = TOOL_SPHERE;
        t.radius_m = 0.5f * (float)rows[r].tool * f.sample_spacing_m;
        tool_params_t p;
        tool_params_default(&p, TOOL_CARVE);
        p.fit = TOOL_FIT_LSQ;
        enum { RUNS = 9 };
        double ms[RUNS];
        for (int i = 0; i < RUNS; i++) {
            tool_pose_t pose;
            const float a = 0.7f * (float)i;
            tool_pose_at(&pose, vec3(0.4f * cosf(a), 0.4f * sinf(a), 0.0f));
            const double t0 = now_ms();
            tool_apply(&f, &t, &pose, &p, NULL, NULL);
            ms[i] = now_ms() - t0;
        }
        printf("  %4d^3        %3d^3                                 %7.3f ms\n", rows[r].coefs, rows[r].tool,
               median(ms, RUNS));
        field_free(&f);
    }
}

/* Hua & Qin Table 2: one simulation loop (implicit step, ≤ 8 CG iterations) + d = A p. */
static void table2(void)
{
    static const struct { int coefs, samples; double paper_ms, goal_ms; } rows[] = {
        {5, 10, 1.0, 0}, {10, 10, 6.9, 0}, {10, 15, 15.8, 0}, {15, 15, 38.2, 0}, {15, 20, 74.9, 0.5}, {32, 64, -1.0, 16.0}};
    printf("== Hua & Qin Table 2: one implicit step (eq. 12, CG <= 8 iterations) + d = A p\n");
    printf("  coefficients  samples   paper (2.2 GHz PC)  ours wall / cpu median  goal          meets goal              CG iterations  residual   | early exit at cg_tol 1e-4: wall median, iterations, residual\n");
    for (size_t r = 0; r < sizeof(rows) / sizeof(rows[0]); r++) {
        bspline_t b;
        const int32_t n[3] = {rows[r].coefs, rows[r].coefs, rows[r].coefs};
        const int32_t ns[3] = {rows[r].samples, rows[r].samples, rows[r].samples};
        const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
        bspline_init_uniform(&b, n, lo, hi);
        for (int i = 0; i < n[0] * n[1] * n[2]; i++)
            b.coef[i] = 0.5f;
        solver_cfg_t cfg;
        solver_cfg_default(&cfg);
        cfg.dt_s = 0.01f;
        cfg.cg_tol = 0.0f; /* always the full 8 iterations: the worst case */
        solver_t s, se;
        solver_init_patch(&s, &b, ns, &cfg);
        cfg.cg_tol = 1e-4f; /* the default: CG stops once the relative residual is below it */
        solver_init_patch(&se, &b, ns, &cfg);
        for (size_t i = 0; i < s.nsamp; i += 7)
            s.force_n[i] = se.force_n[i] = 0.3f;
        float *d = malloc(sizeof(float) * s.nsamp);
        enum { RUNS = 15 };
        double ms[RUNS], cms[RUNS], mse[RUNS];
        for (int i = 0; i < RUNS; i++) { /* one solver at a time, as a session runs it */
            const double t0 = now_ms(), c0 = cpu_ms();
            solver_step_implicit(&s);
            solver_densities(&s, d);
            ms[i] = now_ms() - t0;
            cms[i] = cpu_ms() - c0;
        }
        for (int i = 0; i < RUNS; i++) {
            const double t1 = now_ms();
            solver_step_implicit(&se);
            solver_densities(&se, d);
            mse[i] = now_ms() - t1;
        }
        char paper[32], goal[32];
        if (rows[r].paper_ms > 0)
            snprintf(paper, sizeof(paper), "%6.1f ms", rows[r].paper_ms);
        else
            snprintf(paper, sizeof(paper), "-");
        const double ours_ms = median(ms, RUNS), ours_cpu = median(cms, RUNS);
        char meets[40];
        goal_cols(rows[r].goal_ms, ours_ms, ours_cpu, goal, sizeof(goal), meets, sizeof(meets));
        printf("  %4d^3        %3d^3     %-18s  %7.3f / %7.3f ms      %-12s  %-22s  %d              %.1e    | %7.3f ms  %d  %.1e\n",
               rows[r].coefs, rows[r].samples, paper, ours_ms, ours_cpu, goal, meets, s.stats.cg_iters,
               (double)s.stats.residual, median(mse, RUNS), se.stats.cg_iters, (double)se.stats.residual);
        free(d);
        solver_free(&s);
        solver_free(&se);
        bspline_free(&b);
    }
}

/* Ferley et al. §6: toothpaste tools touching ~200 / ~950 / ~2,100 corners. */
static void ferley(void)
{
    static const struct { const char *name; int corners; const char *paper; } rows[] = {
        {"small", 203, "19-23 frames/s (43-53 ms/frame)"},
        {"medium", 975, "7-8 frames/s (125-143 ms/frame)"},
        {"large", 2197, "3-4 frames/s (250-333 ms/frame)"}};
    printf("== Ferley et al. performance table: toothpaste, one application (SGI Onyx2 R10k 195 MHz)\n");
    printf("  tool    corners computed (paper / ours)  paper                              ours median  goal  meets goal\n");
    for (size_t r = 0; r < 3; r++) {
        field_t f;
        field_init(&f, 0.01f, 1, vec3(0, 0, 0));
        g_radius = 0.2f;
        field_fill(&f, sd_ball, NULL, vec3(-0.3f, -0.3f, -0.3f), vec3(0.3f, 0.3f, 0.3f));
        undo_t u;
        if (undo_init(&u, (size_t)64 << 20) != ARGIL_OK) {
            fprintf(stderr, "bench_model: no memory for the undo journal\n");
            exit(1);
        }
        /* a sphere whose influence ball holds ~corners lattice points: (4/3) pi R^3 / h^3 */
        tool_shape_t t;
        memset(&t, 0, sizeof(t));
        t.kind = TOOL_SPHERE;
        const float reach = cbrtf(3.0f * (float)rows[r].corners / (4.0f * (float)M_PI)) * f.coef_spacing_m;
        t.radius_m = reach - f.band_m;
        if (t.radius_m < 0.5f * f.coef_spacing_m)
            t.radius_m = 0.5f * f.coef_spacing_m;
        tool_params_t p;
        tool_params_default(&p, TOOL_TOOTHPASTE);
        p.strength = 0.2f;
        enum { RUNS = 15 };
        double ms[RUNS];
        tool_stats_t st;
        size_t computed = 0;
        for (int i = 0; i < RUNS; i++) {
            tool_pose_t pose;
            tool_pose_at(&pose, vec3(0.2f * cosf(0.4f * (float)i), 0.2f * sinf(0.4f * (float)i), 0.0f));
            memset(&st, 0, sizeof(st));
            const double t0 = now_ms();
            tool_apply(&f, &t, &pose, &p, &u, &st);
            ms[i] = now_ms() - t0;
            computed = st.coefs_changed;
        }
        printf("  %-6s  %4d / %4zu                       %-33s  %7.3f ms   -     -\n", rows[r].name, rows[r].corners,
               computed, rows[r].paper, median(ms, RUNS));
        undo_free(&u);
        field_free(&f);
    }
}

int main(void)
{
    /* the machine may be shared: its load average says how far the medians are inflated */
    FILE *la = fopen("/proc/loadavg", "r");
    double load1 = -1.0;
    if (la != NULL) {
        if (fscanf(la, "%lf", &load1) != 1)
            load1 = -1.0;
        fclose(la);
    }
    if (load1 >= 0.0)
        printf("(load average over the last minute: %.2f)\n", load1);
    table1();
    table1_lsq();
    table2();
    ferley();
    return 0;
}
