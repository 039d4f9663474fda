/* make bench (host mesh + fit figures): full marching cubes of a 256³ sphere field, incremental
 * re-mesh after a 40³ tool stroke, the live mesher's memory and a stroke that grows the clay
 * past its box, RBF and octree B-spline fitting on Guo et al. Table 2 point counts, and octree
 * fits of 30,000-point scans with through-holes, sharp edges and noise (`bench_mesh scans` runs
 * only those). Single thread; medians of repeated runs. Built and run by tests/bench.sh. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "host/fit/normals.h"
#include "host/fit/octree_fit.h"
#include "host/fit/rbf.h"
#include "host/mesh/mc.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc_blocks.h"
#include "host/model/grid.h"
#include "tests/unit/fit_shapes.h"
#include "tests/unit/grid_view.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), cmp_d);
    return v[n / 2];
}

/* Writes a ball of clay (max with the density there) and returns its sample box. */
static void add_ball(grid_t *g, vec3_t c_m, float r_m, int32_t lo[3], int32_t hi[3])
{
    const float cc[3] = {c_m.x, c_m.y, c_m.z}, o[3] = {g->origin_m.x, g->origin_m.y, g->origin_m.z};
    int32_t n[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (int32_t)floorf((cc[a] - r_m - g->band_m - o[a]) / g->spacing_m) - 1;
        hi[a] = (int32_t)ceilf((cc[a] + r_m + g->band_m - o[a]) / g->spacing_m) + 2;
        n[a] = hi[a] - lo[a];
    }
    float *d = malloc((size_t)n[0] * (size_t)n[1] * (size_t)n[2] * sizeof(float));
    if (d == NULL)
        return;
    grid_read_box(g, GRID_DENSITY, lo, n, d);
    size_t i = 0;
    for (int32_t z = 0; z < n[2]; z++)
        for (int32_t y = 0; y < n[1]; y++)
            for (int32_t x = 0; x < n[0]; x++, i++) {
                const vec3_t p = vec3(o[0] + g->spacing_m * (float)(lo[0] + x),
                                      o[1] + g->spacing_m * (float)(lo[1] + y),
                                      o[2] + g->spacing_m * (float)(lo[2] + z));
                const float v = grid_profile(r_m - vec3_norm(vec3_sub(p, c_m)), g->band_m);
                d[i] = v > d[i] ? v : d[i];
            }
    grid_write_box(g, GRID_DENSITY, lo, n, d);
    grid_write_box(g, GRID_REST, lo, n, d);
    free(d);
}

/* A stroke that grows the clay: 6 mm balls from x = 25 to 125 mm on a r = 30 mm sphere in a
 * 176^3 box (edge at 87.5 mm); each step is published as the live window does (grow the mesher
 * when the bounds grew, mark the ball's box, update, assemble). */
static void bench_grow(void)
{
    enum { N = 176, STEPS = 51 };
    grid_t g;
    const int32_t dims[3] = {N, N, N};
    const float h = 1e-3f, half = 0.5f * (N - 1) * h;
    if (grid_init(&g, dims, h, vec3(-half, -half, -half)) != ARGIL_OK)
        return;
    grid_fill_sphere(&g, vec3(0, 0, 0), 0.03f);
    mc_blocks_t b;
    grid_mesh_view_t view;
    mesh_t m;
    mesh_init(&m);
    const double ti = now_s();
    grid_mesh_blocks_init(&b, &view, &g, 0.5f);
    mc_blocks_update_read(&b, grid_mesh_read, &view);
    printf("  live mesher set up and first mesh, 176^3 box, r=30 sphere: %.2f ms (%zu of %zu blocks "
           "read, the rest empty space skipped)\n", 1e3 * (now_s() - ti), b.blocks_read,
           b.blocks_meshed);
    mc_blocks_assemble(&b, &m);
    double tg[STEPS], tn[STEPS], total = 0.0;
    int ng = 0, nn = 0;
    size_t meshed = 0;
    for (int s = 0; s < STEPS; s++) {
        int32_t lo[3], hi[3];
        add_ball(&g, vec3(0.025f + 0.002f * (float)s, 0.0f, 0.0f), 0.006f, lo, hi);
        const double t0 = now_s();
        const bool grew = grid_mesh_view_stale(&view, &g);
        if (grew && grid_mesh_grow(&b, &view, &g) != ARGIL_OK) {
            printf("  growing stroke: grid_mesh_grow failed\n");
            break;
        }
        grid_mesh_mark(&b, &view, lo, hi);
        mc_blocks_update_read(&b, grid_mesh_read, &view);
        mc_blocks_assemble(&b, &m);
        const double dt = now_s() - t0;
        total += dt;
        if (grew) {
            tg[ng++] = dt;
            meshed = b.blocks_meshed;
        } else {
            tn[nn++] = dt;
        }
    }
    printf("  growing stroke (51 x 6 mm balls to 37 mm past a 176^3 box, r=30 sphere): publish "
           "(re-mesh + assemble) %.2f ms median on the %d steps that grew the box (%zu blocks "
           "meshed), %.2f ms on the %d others; whole stroke %.0f ms; %zu triangles, %.2f MB\n",
           ng > 0 ? 1e3 * median(tg, ng) : 0.0, ng, meshed, nn > 0 ? 1e3 * median(tn, nn) : 0.0,
           nn, 1e3 * total, m.n_tri, (double)mc_blocks_bytes(&b) / 1048576.0);
    mc_blocks_free(&b);
    mesh_free(&m);
    grid_free(&g);
}

/* The octree fit of 30,000-point scans (tests/unit/fit_shapes.h), with the CLI's defaults:
 * median time of 5 runs, nodes, and the meshed surface against the true one. */
static void bench_scans(void)
{
    enum { RUNS = 5, POINTS = 30000 };
    char load[64] = "?";
    FILE *la = fopen("/proc/loadavg", "r");
    if (la != NULL) {
        if (fgets(load, sizeof(load), la) != NULL)
            load[strcspn(load, " ")] = '\0';
        fclose(la);
    }
    printf("  octree fit of scanned solids, %d points, CLI defaults (tolerance 0.2 %% of the longest\n"
           "  extent, depth 5); median of %d runs; errors: mesh vertices (grid diagonal/64) to the true\n"
           "  surface, %% of the bounding-box diagonal; goal <= 2 s, max <= 2 %%, 1 component (load %s):\n",
           POINTS, RUNS, load);
    for (int s = 0; s < 2; s++)
        for (int noisy = 0; noisy < 2; noisy++)
            for (int given = 1; given >= 0; given--) {
                const fs_shape_t sh = (fs_shape_t)s;
                const float *h = fs_half[sh];
                mesh_t c;
                mesh_init(&c);
                if (fs_sample(sh, POINTS, noisy ? 0.005 * fs_diag(sh) : 0.0, 777 + (uint64_t)s, &c) != ARGIL_OK)
                    return;
                double tn[RUNS], tf[RUNS], cf[RUNS];
                for (int r = 0; r < RUNS && !given; r++) {
                    const double t0 = now_s();
                    normals_estimate(&c, NULL, NULL);
                    tn[r] = now_s() - t0;
                }
                struct timespec c0, c1;
                octfit_opts_t o;
                octfit_opts_default(&o);
                o.tolerance = 0.002f * 2.0f * fmaxf(h[0], fmaxf(h[1], h[2]));
                octfit_model_t of;
                argil_err_t e = ARGIL_OK;
                for (int r = 0; r < RUNS && e == ARGIL_OK; r++) {
                    const double t0 = now_s();
                    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
                    e = octfit_points(&c, &o, &of);
                    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
                    tf[r] = now_s() - t0;
                    cf[r] = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
                    if (r < RUNS - 1 && e == ARGIL_OK)
                        octfit_free(&of);
                }
                fs_measure_t d = {0};
                if (e == ARGIL_OK)
                    e = fs_measure(&of, fs_dist_cb, &sh, h, (float)fs_diag(sh), 64, &d);
                char nt[32] = "";
                if (!given)
                    snprintf(nt, sizeof(nt), " + normals %.3f s", median(tn, RUNS));
                if (e == ARGIL_OK)
                    printf("    %-14s %-5s %-7s: fit %.3f s (CPU %.3f s)%s, %5u nodes (depth %u); max %.3f %% mean %.3f %%, "
                           "%u component(s), Euler %ld\n", s == FS_HOLED_BOX ? "holed box" : "plate, 2 holes",
                           noisy ? "noisy" : "clean", given ? "normals" : "PCA", median(tf, RUNS),
                           median(cf, RUNS), nt,
                           of.n_nodes, of.depth, 100.0 * d.max, 100.0 * d.mean, d.components, d.euler);
                else
                    printf("    %-14s: FAILED (%d)\n", s == FS_HOLED_BOX ? "holed box" : "plate, 2 holes", (int)e);
                octfit_free(&of);
                mesh_free(&c);
            }
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "scans") == 0) {
        bench_scans();
        return 0;
    }
    enum { N = 256, RUNS = 5 };
    grid_t g;
    const int32_t dims[3] = {N, N, N};
    const float h = 1e-3f, half = 0.5f * (N - 1) * h;
    if (grid_init(&g, dims, h, vec3(-half, -half, -half)) != ARGIL_OK)
        return 1;
    grid_fill_sphere(&g, vec3(0, 0, 0), 0.1f);
    mesh_t m;
    mesh_init(&m);
    double t[RUNS], t2[RUNS], t3[RUNS];
    size_t tris = 0;
    for (int r = 0; r < RUNS; r++) {
        /* The meshers on a dense copy (the copy timed on its own: the sparse grid's cost). */
        double t0 = now_s();
        const float *dense = gv_dense(&g);
        t3[r] = now_s() - t0;
        t0 = now_s();
        mc_extract_region(dense, NULL, g.dims, h, g.origin_m, 0.5f, NULL, NULL, &m);
        t[r] = now_s() - t0;
        tris = m.n_tri;
        t0 = now_s();
        mc_extract(dense, g.dims, h, g.origin_m, 0.5f, &m);
        t2[r] = now_s() - t0;
    }
    printf("  dense copy of the sparse 256^3 grid (what grid_mesh_extract adds): %.3f s\n",
           median(t3, RUNS));
    const double cells = (double)(N + 1) * (N + 1) * (N + 1);
    const double tb = median(t, RUNS), ts = median(t2, RUNS);
    printf("  full MC, 256^3 sphere r=100: block mesher %.3f s (%.0f M cells/s, %zu triangles); "
           "whole-grid slab mesher %.3f s; goal <= 0.15 s\n", tb, cells / tb / 1e6, tris, ts);

    mc_blocks_t b;
    grid_mesh_view_t view;
    grid_mesh_blocks_init(&b, &view, &g, 0.5f);
    mc_blocks_update_read(&b, grid_mesh_read, &view);
    double inc[21];
    size_t blocks = 0;
    for (int r = 0; r < 21; r++) {
        /* a 40³ stroke: carve a sphere of radius 20 samples on the surface */
        int32_t lo[3], hi[3];
        const float a = 0.3f * (float)r;
        grid_carve_sphere(&g, vec3(0.1f * cosf(a), 0.1f * sinf(a), 0.0f), 0.0195f, lo, hi);
        const double t0 = now_s();
        grid_mesh_mark(&b, &view, lo, hi);
        mc_blocks_update_read(&b, grid_mesh_read, &view);
        inc[r] = now_s() - t0;
        blocks = b.blocks_meshed;
    }
    printf("  incremental re-mesh after a 40^3 stroke: %.3f ms (%zu of %zu blocks); goal <= 2 ms\n",
           1e3 * median(inc, 21), blocks, mc_blocks_box_blocks(&b));
    printf("  live mesher memory, 256^3 sphere r=100: %.2f MB (%zu block slots; per-block tables "
           "over the box alone: %.2f MB)\n", (double)mc_blocks_bytes(&b) / 1048576.0, b.blocks.count,
           (double)(mc_blocks_box_blocks(&b) * (sizeof(mc_block_mesh_t) + 1)) / 1048576.0);
    double ta[RUNS];
    for (int r = 0; r < RUNS; r++) {
        const double t0 = now_s();
        mc_blocks_assemble(&b, &m);
        ta[r] = now_s() - t0;
    }
    printf("  assembling all blocks into one indexed mesh (for export): %.3f ms\n",
           1e3 * median(ta, RUNS));
    mc_blocks_free(&b);
    mesh_free(&m);
    grid_free(&g);
    bench_grow();

    static const int counts[5] = {1442, 4500, 8000, 16002, 67038};
    static const double paper[5] = {2.575340, 8.177936, 15.378002, 30.161726, 134.427521};
    printf("  point-set fit, RBF of Zhang 5 with 900 centres (Guo et al. Table 2 sizes, 30 mm sphere):\n");
    for (int k = 0; k < 5; k++) {
        mesh_t p;
        mesh_init(&p);
        const int n = counts[k];
        for (int i = 0; i < n; i++) {
            const double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), th = i * M_PI * (3 - sqrt(5));
            const vec3_t nn = vec3((float)(rr * cos(th)), (float)(rr * sin(th)), (float)z);
            mesh_add_vertex(&p, vec3_scale(nn, 0.03f), nn, NULL);
        }
        rbf_opts_t o;
        rbf_opts_default(&o);
        rbf_model_t rb;
        const double t0 = now_s();
        const argil_err_t e = rbf_fit(&p, &o, &rb);
        const double dt = now_s() - t0;
        printf("    %6d points: %.3f s (paper %.2f s), rms error %.4f %% of size%s\n", n, dt,
               paper[k], e == ARGIL_OK ? 100.0 * rb.rms_err_m / 0.06 : -1.0,
               e == ARGIL_OK ? "" : " FAILED");
        rbf_free(&rb);
        mesh_free(&p);
    }
    printf("  octree B-spline fit, Hua & Qin 4 (tolerance 0.05 %% of the size, max depth 5; median of 3;\n"
           "  paper = Guo et al. Table 2; goal <= 2 s for 67,038 points):\n");
    for (int k = 0; k < 5; k++) {
        mesh_t p;
        mesh_init(&p);
        const int n = counts[k];
        for (int i = 0; i < n; i++) {
            const double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), th = i * M_PI * (3 - sqrt(5));
            const vec3_t nn = vec3((float)(rr * cos(th)), (float)(rr * sin(th)), (float)z);
            mesh_add_vertex(&p, vec3_scale(nn, 0.03f), nn, NULL);
        }
        octfit_opts_t o;
        octfit_opts_default(&o);
        o.tolerance = 0.0005f * 0.06f;
        double tf[3];
        octfit_model_t of;
        argil_err_t e = ARGIL_OK;
        for (int r = 0; r < 3; r++) {
            const double t0 = now_s();
            e = octfit_points(&p, &o, &of);
            tf[r] = now_s() - t0;
            if (r < 2 && e == ARGIL_OK)
                octfit_free(&of);
        }
        if (e == ARGIL_OK)
            printf("    %6d points: %.3f s (paper %.2f s), %u nodes, depth %u, error rms %.4f %% max "
                   "%.4f %% of size\n", n, median(tf, 3), paper[k], of.n_nodes, of.depth,
                   100.0 * of.rms_err / 0.06, 100.0 * of.max_err / 0.06);
        else
            printf("    %6d points: FAILED (%d)\n", n, (int)e);
        if (e == ARGIL_OK)
            octfit_free(&of);
        mesh_free(&p);
    }
    bench_scans();
    return 0;
}
