/* argil fit: a point cloud, a mesh or a volume becomes a model (.argil). Points are fitted with
 * the hierarchical octree B-spline of Hua & Qin §4 or the RBF implicit of Zhang et al. §5 and
 * sampled into the density grid, the compact form saved beside it; clouds without normals get
 * them by PCA + MST orientation; closed meshes become a signed distance grid directly; volumes
 * are normalised into densities, or octree-fitted from their intensities. */
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/fit/normals.h"
#include "host/fit/octree_fit.h"
#include "host/fit/rbf.h"
#include "host/io/argil_file.h"
#include "host/io/mesh_import.h"
#include "host/io/mesh_sdf.h"
#include "host/io/volume.h"

#define FIT_AUTO_OCTREE_POINTS 1000u /* auto: the octree above this many points, RBF up to it */

typedef enum { FIT_AUTO, FIT_OCTREE, FIT_RBF, FIT_SDF, FIT_GRID } fit_method_t;

static volatile int g_fit_stop;

/* Ctrl-C or SIGTERM: the fit stops at its next check and writes nothing. */
static void fit_on_signal(int sig)
{
    (void)sig;
    g_fit_stop = 1;
}

typedef struct {
    int tty;
    double t0, last;
    int last_pct;
    const char *stage;
} progress_t;

/* The monotonic clock, seconds. */
static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A bar with percentage and ETA on a terminal; a plain line every 10 % otherwise. */
static void progress_cb(void *ctx, double frac)
{
    progress_t *p = ctx;
    const int pct = (int)(frac * 100.0);
    const double t = now_s();
    if (p->tty) {
        if (t - p->last < 0.1 && pct < 100)
            return;
        p->last = t;
        const double el = t - p->t0, eta = frac > 0.01 ? el * (1.0 - frac) / frac : 0.0;
        char bar[31];
        const int fill = (int)(frac * 30.0);
        for (int i = 0; i < 30; i++)
            bar[i] = i < fill ? '#' : '.';
        bar[30] = '\0';
        fprintf(stderr, "\r%-8s [%s] %3d%%  ETA %5.1f s ", p->stage, bar, pct, eta);
        fflush(stderr);
    } else if (pct / 10 > p->last_pct / 10) {
        fprintf(stderr, "%s: %d%%\n", p->stage, pct);
    }
    if (pct > p->last_pct)
        p->last_pct = pct;
}

/* Starts the progress of the next stage (its name on the bar or lines). */
static void progress_stage(progress_t *p, const char *stage)
{
    if (p->tty && p->stage != NULL)
        fputc('\n', stderr);
    p->stage = stage;
    p->last_pct = -1;
    p->t0 = now_s();
    p->last = 0;
}

/* The text of `argil fit --help`. */
static void usage_fit(FILE *f)
{
    fprintf(f,
            "usage: argil fit INPUT -o MODEL.argil [--method M] [--tolerance E] [--max-depth D]\n"
            "                 [--resolution N] [--samples S] [--iso V] [--quiet]\n"
            "\n"
            "Turns INPUT into a model. Point clouds (.ply .stl .obj .xyz .txt .pts) are fitted\n"
            "with an implicit function whose zero set is the surface; clouds without normals get\n"
            "them first (PCA over 12 neighbours, oriented along a minimum spanning tree). Closed\n"
            "meshes become a signed distance grid. Volumes (.nrrd .nhdr) are normalised into\n"
            "densities. Ctrl-C stops cleanly (exit 130, nothing written).\n"
            "\n"
            "options:\n"
            "  -o MODEL.argil  output model (written atomically)\n"
            "  --method M      octree: hierarchical octree B-spline fit (Hua & Qin 4);\n"
            "                  rbf: RBF implicit, phi = r^3 + linear (Zhang et al. 5);\n"
            "                  sdf: closed mesh -> signed distance grid; grid: volume as is.\n"
            "                  default: sdf for meshes with triangles, grid for volumes, rbf for\n"
            "                  clouds of up to 1000 points and octree above\n"
            "  --tolerance E   wanted RMS fitting error in the input's units (default 0.2 %% of\n"
            "                  the size; octree: the per-node bound, never below 1.5 x the noise\n"
            "                  read from the points; rbf: the sample count doubles until it is\n"
            "                  met or 1365)\n"
            "  --max-depth D   octree: deepest subdivision level, 0..10 (default 5)\n"
            "  --resolution N  grid samples along the longest axis, 8..256 (default 64)\n"
            "  --samples S     rbf: surface samples to start with, 4..1365 (default 300)\n"
            "  --iso V         for volumes: the intensity of the surface (default: mid-range)\n"
            "  --quiet         no progress and no summary\n"
            "  -h, --help      this text\n");
}

/* A grid covering lo..hi with a margin, n samples on the longest axis. */
static argil_err_t make_grid(argil_doc_t *d, const float lo[3], const float hi[3], int n)
{
    float ext = 0;
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, hi[a] - lo[a]);
    const float margin = 0.1f * ext + 1e-6f;
    const float spacing = (ext + 2 * margin) / (float)(n - 1);
    int32_t dims[3];
    for (int a = 0; a < 3; a++)
        dims[a] = (int32_t)((hi[a] - lo[a] + 2 * margin) / spacing) + 2;
    argil_err_t e = grid_init(&d->grid, dims, spacing,
                              vec3(lo[0] - margin, lo[1] - margin, lo[2] - margin));
    if (e == ARGIL_OK)
        d->grid.band_m = 2.0f * spacing;
    return e;
}

/* Turns a closed mesh into a density grid through its signed distance. */
static argil_err_t fit_mesh_sdf(const char *in, const char *out, const mesh_t *m,
                                const float lo[3], const float hi[3], int res, bool quiet,
                                int *exit_status)
{
    argil_doc_t d;
    argil_doc_init(&d);
    char err[1024];
    mesh_sdf_report_t rep;
    argil_err_t e = make_grid(&d, lo, hi, res);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory for the grid\n");
    } else {
        grid_t *g = &d.grid;
        const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
        float *sd = malloc(n * sizeof(float));
        e = sd == NULL ? ARGIL_ERR_NOMEM
                       : mesh_sdf(m, g->dims, g->spacing_m, g->origin_m, g->band_m, sd, &rep);
        if (e == ARGIL_OK) {
            const int32_t zero[3] = {0, 0, 0};
            for (size_t i = 0; i < n; i++)
                sd[i] = grid_profile(sd[i], g->band_m);
            e = grid_write_box(g, GRID_DENSITY, zero, g->dims, sd);
            if (e == ARGIL_OK)
                e = grid_write_box(g, GRID_REST, zero, g->dims, sd);
        }
        free(sd);
        if (e == ARGIL_ERR_STATE) {
            fprintf(stderr, "argil fit: %s: the mesh is not closed (%zu boundary, %zu non-manifold "
                            "edges), so it has no inside; fit its vertices with --method octree\n",
                    in, rep.boundary_edges, rep.nonmanifold_edges);
        } else if (e != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s: %s\n", in,
                    e == ARGIL_ERR_NOMEM ? "out of memory" : "the mesh has no usable triangles");
        } else if ((e = argil_file_write(out, &d, err, sizeof(err))) != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s\n", err);
        } else if (!quiet) {
            printf("argil fit: %s: closed mesh of %zu triangles -> signed distance grid "
                   "%dx%dx%d (%zu degenerate triangles skipped)\n", out, m->n_tri,
                   g->dims[0], g->dims[1], g->dims[2], rep.degenerate);
        }
    }
    argil_doc_free(&d);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}

/* Samples the document's fitted form (octree or RBF) into its grid; ARGIL_ERR_STATE when
 * stopped, else the grid's error. */
static argil_err_t sample_fit(argil_doc_t *d, progress_t *pr, bool quiet)
{
    grid_t *g = &d->grid;
    for (int32_t z = 0; z < g->dims[2]; z++) {
        if (g_fit_stop)
            return ARGIL_ERR_STATE;
        for (int32_t y = 0; y < g->dims[1]; y++)
            for (int32_t x = 0; x < g->dims[0]; x++) {
                const vec3_t p = vec3(g->origin_m.x + g->spacing_m * (float)x,
                                      g->origin_m.y + g->spacing_m * (float)y,
                                      g->origin_m.z + g->spacing_m * (float)z);
                float v;
                if (d->has_octree && d->octree.kind == OCTFIT_INTENSITY)
                    v = fminf(1.0f, fmaxf(0.0f, g->iso + octfit_eval(&d->octree, p)));
                else if (d->has_octree)
                    v = grid_profile(octfit_eval(&d->octree, p), g->band_m);
                else
                    v = grid_profile(rbf_eval(&d->rbf, p), g->band_m);
                argil_err_t e = grid_set(g, GRID_DENSITY, x, y, z, v);
                if (e == ARGIL_OK)
                    e = grid_set(g, GRID_REST, x, y, z, v);
                if (e != ARGIL_OK)
                    return e;
            }
        if (!quiet)
            progress_cb(pr, (double)(z + 1) / (double)g->dims[2]);
    }
    return ARGIL_OK;
}

/* After sampling (sampled: its result): ends the progress line and writes the model to out,
 * or says it was interrupted (exit 130). */
static argil_err_t fit_write(const argil_doc_t *d, const progress_t *pr, argil_err_t sampled,
                             const char *out, int *exit_status)
{
    if (pr->tty)
        fputc('\n', stderr);
    if (sampled != ARGIL_OK) {
        fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
        return cmd_end(exit_status, 130, sampled);
    }
    char err[1024];
    const argil_err_t e = argil_file_write(out, d, err, sizeof(err));
    if (e != ARGIL_OK)
        fprintf(stderr, "argil fit: %s\n", err);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}

/* What follows a fit that returned e: a stop (exit 130) or its failure (exit 1: "in: failure"
 * on stderr, after ending the progress line when tty_break) writes nothing; else the grid over
 * lo..hi with res samples is made. ARGIL_OK when it is there to sample. */
static argil_err_t fit_to_grid(argil_doc_t *d, const progress_t *pr, argil_err_t e,
                               const char *in, const char *out, const char *failure,
                               bool tty_break, const float lo[3], const float hi[3], int res,
                               int *exit_status)
{
    if (g_fit_stop) {
        if (pr->tty)
            fputc('\n', stderr);
        fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
        return cmd_end(exit_status, 130, ARGIL_ERR_STATE);
    }
    if (e != ARGIL_OK) {
        if (tty_break && pr->tty)
            fputc('\n', stderr);
        fprintf(stderr, "argil fit: %s: %s\n", in, failure);
        return cmd_end(exit_status, 1, e);
    }
    e = make_grid(d, lo, hi, res);
    if (e == ARGIL_OK)
        return ARGIL_OK;
    fprintf(stderr, "argil fit: out of memory for the grid\n");
    return cmd_end(exit_status, 1, e);
}

/* The words of an octree fit's failure e. */
static const char *octree_failure(argil_err_t e)
{
    return e == ARGIL_ERR_NOMEM ? "the octree fit failed (out of memory)"
                                : "the octree fit failed (a node's system could not be solved)";
}

/* What argil fit's command line asks for. */
typedef struct {
    const char *in, *out;
    fit_method_t method;
    double tol;                     /* wanted RMS error, input units (0: 0.2 % of the size) */
    double res, samples, iso, depth;
    bool quiet;
} fit_opts_t;

/* The octree B-spline fit of an oriented cloud m, sampled into the grid and saved. Frees m. */
static argil_err_t fit_points_octree(const fit_opts_t *fo, mesh_t *m, const float lo[3],
                                     const float hi[3], float size, double tol, progress_t *pr,
                                     int *exit_status)
{
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = (float)tol;
    o.max_depth = (uint32_t)(int)fo->depth;
    o.stop = &g_fit_stop;
    if (!fo->quiet) {
        o.progress = progress_cb;
        o.progress_ctx = pr;
        progress_stage(pr, "octree");
    }
    argil_doc_t d;
    argil_doc_init(&d);
    argil_err_t e = octfit_points(m, &o, &d.octree);
    if (e == ARGIL_OK)
        d.has_octree = true;
    e = fit_to_grid(&d, pr, e, fo->in, fo->out, octree_failure(e), true, lo, hi, (int)fo->res,
                    exit_status);
    if (e == ARGIL_OK) {
        if (!fo->quiet)
            progress_stage(pr, "sample");
        e = fit_write(&d, pr, sample_fit(&d, pr, fo->quiet), fo->out, exit_status);
    }
    const grid_t *g = &d.grid;
    if (e == ARGIL_OK && !fo->quiet)
        printf("argil fit: %s: %zu points (noise %.3g, %.3f %% of size) -> octree B-spline "
               "of %u nodes (%u leaves, depth %u), error rms %.4g max %.4g (%.3f %% / %.3f %% "
               "of size); grid %dx%dx%d\n",
               fo->out, m->n_vert, d.octree.noise_m, 100.0 * d.octree.noise_m / size,
               d.octree.n_nodes, d.octree.n_leaves, d.octree.depth, d.octree.rms_err,
               d.octree.max_err, 100.0 * d.octree.rms_err / size,
               100.0 * d.octree.max_err / size, g->dims[0], g->dims[1], g->dims[2]);
    argil_doc_free(&d);
    mesh_free(m);
    return e;
}

/* The RBF fit of an oriented cloud m (the samples doubling until the error meets tol),
 * sampled into the grid and saved. Frees m. */
static argil_err_t fit_points_rbf(const fit_opts_t *fo, mesh_t *m, const float lo[3],
                                  const float hi[3], float size, double tol, progress_t *pr,
                                  int *exit_status)
{
    rbf_opts_t o;
    rbf_opts_default(&o);
    o.stop = &g_fit_stop;
    if (!fo->quiet) {
        o.progress = progress_cb;
        o.progress_ctx = pr;
    }
    argil_doc_t d;
    argil_doc_init(&d);
    argil_err_t e = ARGIL_OK;
    for (uint32_t s = (uint32_t)(int)fo->samples;; s *= 2) {
        if (s > RBF_CENTRES_MAX / 3)
            s = RBF_CENTRES_MAX / 3;
        o.max_surface_samples = s;
        if (!fo->quiet)
            progress_stage(pr, "rbf");
        rbf_free(&d.rbf);
        e = rbf_fit(m, &o, &d.rbf);
        if (e != ARGIL_OK || d.rbf.rms_err_m <= tol || s >= RBF_CENTRES_MAX / 3 ||
            s >= m->n_vert)
            break;
    }
    e = fit_to_grid(&d, pr, e, fo->in, fo->out, "the RBF system could not be solved", false, lo,
                    hi, (int)fo->res, exit_status);
    if (e == ARGIL_OK) {
        d.has_rbf = true;
        if (!fo->quiet)
            progress_stage(pr, "sample");
        (void)sample_fit(&d, pr, fo->quiet);
        e = fit_write(&d, pr, g_fit_stop ? ARGIL_ERR_STATE : ARGIL_OK, fo->out, exit_status);
    }
    const grid_t *g = &d.grid;
    if (e == ARGIL_OK && !fo->quiet)
        printf("argil fit: %s: %zu points -> RBF of %u centres, error rms %.4g max %.4g "
               "(%.3f %% / %.3f %% of size); grid %dx%dx%d\n", fo->out, m->n_vert, d.rbf.n,
               d.rbf.rms_err_m, d.rbf.max_err_m, 100.0 * d.rbf.rms_err_m / size,
               100.0 * d.rbf.max_err_m / size, g->dims[0], g->dims[1], g->dims[2]);
    argil_doc_free(&d);
    mesh_free(m);
    return e;
}

/* Why the cloud m cannot be fitted (said on stderr), or ARGIL_OK. */
static argil_err_t check_cloud(const char *in, const mesh_t *m)
{
    float thick, noise;
    const octfit_cloud_t why = octfit_check_points(m, &thick, &noise);
    if (why == OCTFIT_CLOUD_OK)
        return ARGIL_OK;
    if (why == OCTFIT_CLOUD_FLAT)
        fprintf(stderr, "argil fit: %s: the points lie on one plane or line (%.3g off it, RMS, "
                        "against noise %.3g): they bound no solid\n", in, thick, noise);
    else
        fprintf(stderr, "argil fit: %s: %s\n", in,
                why == OCTFIT_CLOUD_DUPLICATES ? "fewer than 4 distinct points (the rest repeat them)"
                : why == OCTFIT_CLOUD_NONFINITE ? "a coordinate or normal is NaN or infinite"
                : why == OCTFIT_CLOUD_MANY      ? "too many points"
                                                : "fewer than 4 points");
    return ARGIL_ERR_PARSE;
}

/* A mesh becomes a signed distance grid, a cloud an octree or RBF fit (normals estimated first
 * when it has none); the model is written to fo->out. */
static argil_err_t fit_points(const fit_opts_t *fo, int *exit_status)
{
    const char *in = fo->in, *out = fo->out;
    mesh_t m;
    bool normals;
    float lo[3], hi[3];
    char err[1024];
    argil_err_t e = cmd_read_mesh(in, &m, &normals, lo, hi, err, sizeof(err));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
        return cmd_end(exit_status, 1, e);
    }
    if (m.n_vert < 4) {
        fprintf(stderr, "argil fit: %s: fewer than 4 points\n", in);
        mesh_free(&m);
        return cmd_end(exit_status, 1, ARGIL_ERR_PARSE);
    }
    const float size = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
    const double tol = fo->tol > 0 ? fo->tol : 0.002 * size;
    progress_t pr = {!fo->quiet && isatty(STDERR_FILENO), 0, 0, -1, NULL};
    fit_method_t method = fo->method;
    if (method == FIT_AUTO)
        method = m.n_tri > 0 ? FIT_SDF : (m.n_vert > FIT_AUTO_OCTREE_POINTS ? FIT_OCTREE : FIT_RBF);
    if (method == FIT_SDF) {
        const bool triangles = m.n_tri > 0;
        if (triangles)
            e = fit_mesh_sdf(in, out, &m, lo, hi, (int)fo->res, fo->quiet, exit_status);
        else
            fprintf(stderr, "argil fit: %s: --method sdf needs a mesh with triangles\n", in);
        mesh_free(&m);
        return triangles ? e : cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    if (method == FIT_GRID) {
        fprintf(stderr, "argil fit: %s: --method grid is for volumes (.nrrd .nhdr)\n", in);
        mesh_free(&m);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    if ((e = check_cloud(in, &m)) != ARGIL_OK) {
        mesh_free(&m);
        return cmd_end(exit_status, 1, e);
    }
    if (!normals) {
        normals_opts_t no = {0, &g_fit_stop, fo->quiet ? NULL : progress_cb, &pr};
        if (!fo->quiet)
            progress_stage(&pr, "normals");
        e = normals_estimate(&m, &no, NULL);
        if (e != ARGIL_OK) {
            if (pr.tty)
                fputc('\n', stderr);
            if (g_fit_stop)
                fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
            else
                fprintf(stderr, "argil fit: %s: normals could not be estimated (%s)\n", in,
                        e == ARGIL_ERR_NOMEM ? "out of memory" : "degenerate cloud");
            mesh_free(&m);
            return cmd_end(exit_status, g_fit_stop ? 130 : 1, e);
        }
    }
    if (method == FIT_OCTREE)
        return fit_points_octree(fo, &m, lo, hi, size, tol, &pr, exit_status);
    return fit_points_rbf(fo, &m, lo, hi, size, tol, &pr, exit_status);
}

/* The volume's intensities normalised into densities as they are; the model written to out. */
static argil_err_t fit_volume_grid(const volume_t *v, float lo, float hi, double level,
                                   float iso_norm, const char *out, bool quiet, int *exit_status)
{
    argil_doc_t d;
    argil_doc_init(&d);
    char err[1024];
    argil_err_t e = grid_init(&d.grid, v->dims, v->spacing_m[0], v->origin_m);
    if (e == ARGIL_OK) {
        const size_t n = (size_t)v->dims[0] * (size_t)v->dims[1] * (size_t)v->dims[2];
        d.grid.iso = iso_norm;
        const int32_t zero[3] = {0, 0, 0};
        float *dn = malloc(n * sizeof(float));
        e = dn == NULL ? ARGIL_ERR_NOMEM : ARGIL_OK;
        for (size_t i = 0; dn != NULL && i < n; i++)
            dn[i] = (v->value[i] - lo) / (hi - lo);
        if (e == ARGIL_OK)
            e = grid_write_box(&d.grid, GRID_DENSITY, zero, v->dims, dn);
        if (e == ARGIL_OK)
            e = grid_write_box(&d.grid, GRID_REST, zero, v->dims, dn);
        free(dn);
    }
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory\n");
    } else if ((e = argil_file_write(out, &d, err, sizeof(err))) != ARGIL_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
    } else if (!quiet) {
        printf("argil fit: %s: volume %dx%dx%d, surface at intensity %g (density "
               "%.3f)%s\n", out, v->dims[0], v->dims[1], v->dims[2], level, d.grid.iso,
               v->spacing_m[0] != v->spacing_m[1] || v->spacing_m[0] != v->spacing_m[2]
                   ? "; anisotropic spacing: the x spacing is used"
                   : "");
    }
    argil_doc_free(&d);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}

/* The octree B-spline fit of the volume's intensities (normalised to 0..1), sampled into the
 * grid with its surface at iso_norm and saved. */
static argil_err_t fit_volume_octree(const fit_opts_t *fo, const volume_t *v, float lo, float hi,
                                     float iso_norm, int *exit_status)
{
    progress_t pr = {!fo->quiet && isatty(STDERR_FILENO), 0, 0, -1, NULL};
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = fo->tol > 0 ? (float)fo->tol : 0.01f; /* intensities are normalised to 0..1 */
    o.max_depth = (uint32_t)(int)fo->depth;
    o.stop = &g_fit_stop;
    if (!fo->quiet) {
        o.progress = progress_cb;
        o.progress_ctx = &pr;
        progress_stage(&pr, "octree");
    }
    argil_doc_t d;
    argil_doc_init(&d);
    argil_err_t e = octfit_volume(v->value, v->dims, v->spacing_m[0], v->origin_m, lo, hi,
                                  iso_norm, &o, &d.octree);
    d.has_octree = e == ARGIL_OK;
    const float blo[3] = {v->origin_m.x, v->origin_m.y, v->origin_m.z};
    const float bhi[3] = {v->origin_m.x + v->spacing_m[0] * (float)(v->dims[0] - 1),
                          v->origin_m.y + v->spacing_m[0] * (float)(v->dims[1] - 1),
                          v->origin_m.z + v->spacing_m[0] * (float)(v->dims[2] - 1)};
    e = fit_to_grid(&d, &pr, e, fo->in, fo->out, octree_failure(e), false, blo, bhi,
                    (int)fo->res, exit_status);
    if (e == ARGIL_OK) {
        d.grid.iso = iso_norm;
        if (!fo->quiet)
            progress_stage(&pr, "sample");
        e = fit_write(&d, &pr, sample_fit(&d, &pr, fo->quiet), fo->out, exit_status);
    }
    if (e == ARGIL_OK && !fo->quiet)
        printf("argil fit: %s: volume %dx%dx%d -> octree B-spline of %u nodes (%u "
               "leaves, depth %u), intensity error rms %.4g max %.4g (of the range); "
               "grid %dx%dx%d, surface at density %.3f\n", fo->out, v->dims[0], v->dims[1],
               v->dims[2], d.octree.n_nodes, d.octree.n_leaves, d.octree.depth,
               d.octree.rms_err, d.octree.max_err, d.grid.dims[0], d.grid.dims[1],
               d.grid.dims[2], d.grid.iso);
    argil_doc_free(&d);
    return e;
}

/* A volume (.nrrd .nhdr) into a model: as it is (--method grid) or octree-fitted. */
static argil_err_t fit_volume(const fit_opts_t *fo, int *exit_status)
{
    volume_t v;
    char err[1024];
    if (fo->method == FIT_RBF || fo->method == FIT_SDF) {
        fprintf(stderr, "argil fit: %s: a volume is fitted with --method grid or octree\n", fo->in);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    argil_err_t e = volume_err_argil(volume_read_nrrd(fo->in, &v, err, sizeof(err)));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
        return cmd_end(exit_status, 1, e);
    }
    float lo, hi;
    cmd_volume_range(&v, &lo, &hi);
    if (!(hi > lo)) {
        fprintf(stderr, "argil fit: %s: every sample is %g; there is no surface\n", fo->in, lo);
        volume_free(&v);
        return cmd_end(exit_status, 1, ARGIL_ERR_PARSE);
    }
    const double level = fo->iso > -1e300 ? fo->iso : 0.5 * (lo + hi);
    float iso_norm = (float)((level - lo) / (hi - lo));
    if (!(iso_norm > 0.0f && iso_norm < 1.0f))
        iso_norm = 0.5f;
    e = fo->method == FIT_OCTREE
            ? fit_volume_octree(fo, &v, lo, hi, iso_norm, exit_status)
            : fit_volume_grid(&v, lo, hi, level, iso_norm, fo->out, fo->quiet, exit_status);
    volume_free(&v);
    return e;
}

/* --method NAME. */
static cli_opt_t take_fit_option(void *ctx, int argc, char **argv, int *i)
{
    fit_opts_t *fo = ctx;
    const char *a = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    if (strcmp(a, "--method") != 0)
        return CLI_OPT_OTHER;
    static const char *const names[] = {"auto", "octree", "rbf", "sdf", "grid"};
    int k = 0;
    while (k < 5 && (v == NULL || strcmp(v, names[k]) != 0))
        k++;
    if (k == 5) {
        fprintf(stderr, "argil fit: --method needs auto, octree, rbf, sdf or grid, got "
                        "'%s'\n", v != NULL ? v : "");
        return CLI_OPT_BAD;
    }
    fo->method = (fit_method_t)k;
    (*i)++;
    return CLI_OPT_TAKEN;
}

/* argil fit's command line (cli_parse). */
static const cli_flag_t FIT_FLAGS[] = {{"--quiet", offsetof(fit_opts_t, quiet), true}};
static const cli_number_t FIT_NUMBERS[] = {
    {"--tolerance", 1e-12, 1e12, offsetof(fit_opts_t, tol), 1, false},
    {"--max-depth", 0, OCTFIT_DEPTH_MAX, offsetof(fit_opts_t, depth), 1, true},
    {"--resolution", 8, 256, offsetof(fit_opts_t, res), 1, false},
    {"--samples", 4, RBF_CENTRES_MAX / 3, offsetof(fit_opts_t, samples), 1, false},
    {"--iso", -1e30, 1e30, offsetof(fit_opts_t, iso), 1, false},
};
static const cli_cmd_t FIT_CLI = {
    .name = "fit", .usage = usage_fit, .option = take_fit_option,
    .flags = FIT_FLAGS, .n_flags = 1, .numbers = FIT_NUMBERS, .n_numbers = 5,
    .out_needs = "a value", .out = offsetof(fit_opts_t, out),
    .inputs = true, .input = offsetof(fit_opts_t, in),
};

/* argil fit INPUT -o MODEL.argil: a point cloud, mesh or volume into a model. */
argil_err_t cmd_fit(int argc, char **argv, int *exit_status)
{
    fit_opts_t fo = {NULL, NULL, FIT_AUTO, 0, 64, 300, -1e308, 5, false};
    bool done;
    const argil_err_t pe = cli_parse(&FIT_CLI, &fo, argc, argv, &done, exit_status);
    if (done)
        return pe;
    if (fo.in == NULL || fo.out == NULL) {
        fprintf(stderr, "argil fit: needs INPUT and -o MODEL.argil (see --help)\n");
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    signal(SIGINT, fit_on_signal);
    signal(SIGTERM, fit_on_signal);
    const char *dot = strrchr(fo.in, '.');
    if (dot != NULL && (strcasecmp(dot, ".nrrd") == 0 || strcasecmp(dot, ".nhdr") == 0))
        return fit_volume(&fo, exit_status);
    return fit_points(&fo, exit_status);
}
