/* argil fit: a point cloud, a mesh or a volume becomes a model (.argil). Points are fitted with
 * the hierarchical octree B-spline of Hua & Qin §4 or the RBF implicit of Zhang et al. §5 and
 * sampled into the density grid, the compact form saved beside it; clouds without normals get
 * them by PCA + MST orientation; closed meshes become a signed distance grid directly; volumes
 * are normalised into densities, or octree-fitted from their intensities. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

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

static void progress_stage(progress_t *p, const char *stage)
{
    if (p->tty && p->stage != NULL)
        fputc('\n', stderr);
    p->stage = stage;
    p->last_pct = -1;
    p->t0 = now_s();
    p->last = 0;
}

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

static int num_arg(const char *opt, const char *v, double lo, double hi, double *out)
{
    char *end;
    const double d = v != NULL ? strtod(v, &end) : 0;
    if (v == NULL || end == v || *end != '\0' || !(d >= lo && d <= hi)) {
        fprintf(stderr, "argil fit: %s needs a number from %g to %g, got '%s'\n", opt, lo, hi,
                v != NULL ? v : "");
        return 0;
    }
    *out = d;
    return 1;
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
static int fit_mesh_sdf(const char *in, const char *out, const mesh_t *m, const float lo[3],
                        const float hi[3], int res, int quiet)
{
    argil_doc_t d;
    argil_doc_init(&d);
    int rc = 1;
    char err[1024];
    mesh_sdf_report_t rep;
    if (make_grid(&d, lo, hi, res) != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory for the grid\n");
    } else {
        grid_t *g = &d.grid;
        const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
        float *sd = malloc(n * sizeof(float));
        argil_err_t e = sd == NULL ? ARGIL_ERR_NOMEM
                                   : mesh_sdf(m, g->dims, g->spacing_m, g->origin_m, g->band_m,
                                              sd, &rep);
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
        } else {
            if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
                fprintf(stderr, "argil fit: %s\n", err);
            } else {
                rc = 0;
                if (!quiet)
                    printf("argil fit: %s: closed mesh of %zu triangles -> signed distance grid "
                           "%dx%dx%d (%zu degenerate triangles skipped)\n", out, m->n_tri,
                           g->dims[0], g->dims[1], g->dims[2], rep.degenerate);
            }
        }
    }
    argil_doc_free(&d);
    return rc;
}

/* Samples the document's fitted form (octree or RBF) into its grid; false when stopped. */
static bool sample_fit(argil_doc_t *d, progress_t *pr, int quiet)
{
    grid_t *g = &d->grid;
    for (int32_t z = 0; z < g->dims[2]; z++) {
        if (g_fit_stop)
            return false;
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
                if (grid_set(g, GRID_DENSITY, x, y, z, v) != ARGIL_OK ||
                    grid_set(g, GRID_REST, x, y, z, v) != ARGIL_OK)
                    return false;
            }
        if (!quiet)
            progress_cb(pr, (double)(z + 1) / (double)g->dims[2]);
    }
    return true;
}

/* The octree B-spline fit of an oriented cloud m, sampled into the grid and saved. Frees m. */
static int fit_points_octree(const char *in, const char *out, mesh_t *m, const float lo[3],
                             const float hi[3], float size, double tol, int depth, int res,
                             int quiet, progress_t *pr)
{
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = (float)tol;
    o.max_depth = (uint32_t)depth;
    o.stop = &g_fit_stop;
    if (!quiet) {
        o.progress = progress_cb;
        o.progress_ctx = pr;
        progress_stage(pr, "octree");
    }
    argil_doc_t d;
    argil_doc_init(&d);
    char err[1024];
    int rc = 1;
    const argil_err_t e = octfit_points(m, &o, &d.octree);
    if (e == ARGIL_OK)
        d.has_octree = true;
    if (g_fit_stop) {
        if (pr->tty)
            fputc('\n', stderr);
        fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
        rc = 130;
    } else if (e != ARGIL_OK) {
        if (pr->tty)
            fputc('\n', stderr);
        fprintf(stderr, "argil fit: %s: the octree fit failed (%s)\n", in,
                e == ARGIL_ERR_NOMEM ? "out of memory" : "a node's system could not be solved");
    } else if (make_grid(&d, lo, hi, res) != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory for the grid\n");
    } else {
        if (!quiet)
            progress_stage(pr, "sample");
        const bool done = sample_fit(&d, pr, quiet);
        if (pr->tty)
            fputc('\n', stderr);
        if (!done) {
            fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
            rc = 130;
        } else if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s\n", err);
        } else {
            rc = 0;
            const grid_t *g = &d.grid;
            if (!quiet)
                printf("argil fit: %s: %zu points (noise %.3g, %.3f %% of size) -> octree B-spline "
                       "of %u nodes (%u leaves, depth %u), error rms %.4g max %.4g (%.3f %% / %.3f %% "
                       "of size); grid %dx%dx%d\n",
                       out, m->n_vert, d.octree.noise_m, 100.0 * d.octree.noise_m / size,
                       d.octree.n_nodes, d.octree.n_leaves, d.octree.depth, d.octree.rms_err,
                       d.octree.max_err, 100.0 * d.octree.rms_err / size,
                       100.0 * d.octree.max_err / size, g->dims[0], g->dims[1], g->dims[2]);
        }
    }
    argil_doc_free(&d);
    mesh_free(m);
    return rc;
}

static int fit_points(const char *in, const char *out, fit_method_t method, double tol,
                      int depth, int res, int samples, int quiet)
{
    mesh_t m;
    mesh_init(&m);
    bool normals = false;
    char err[1024];
    if (mesh_import(in, &m, &normals, err, sizeof(err)) != IMPORT_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
        mesh_free(&m);
        return 1;
    }
    if (m.n_vert < 4) {
        fprintf(stderr, "argil fit: %s: fewer than 4 points\n", in);
        mesh_free(&m);
        return 1;
    }
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < m.n_vert; i++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fminf(lo[a], m.pos[3 * i + (size_t)a]);
            hi[a] = fmaxf(hi[a], m.pos[3 * i + (size_t)a]);
        }
    const float size = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
    if (!(tol > 0))
        tol = 0.002 * size;
    progress_t pr = {!quiet && isatty(STDERR_FILENO), 0, 0, -1, NULL};
    if (method == FIT_AUTO)
        method = m.n_tri > 0 ? FIT_SDF : (m.n_vert > FIT_AUTO_OCTREE_POINTS ? FIT_OCTREE : FIT_RBF);
    if (method == FIT_SDF) {
        const int rc = m.n_tri > 0 ? fit_mesh_sdf(in, out, &m, lo, hi, res, quiet) : 2;
        if (m.n_tri == 0)
            fprintf(stderr, "argil fit: %s: --method sdf needs a mesh with triangles\n", in);
        mesh_free(&m);
        return rc;
    }
    if (method == FIT_GRID) {
        fprintf(stderr, "argil fit: %s: --method grid is for volumes (.nrrd .nhdr)\n", in);
        mesh_free(&m);
        return 2;
    }
    float thick, noise;
    const octfit_cloud_t why = octfit_check_points(&m, &thick, &noise);
    if (why != OCTFIT_CLOUD_OK) {
        if (why == OCTFIT_CLOUD_FLAT)
            fprintf(stderr, "argil fit: %s: the points lie on one plane or line (%.3g off it, RMS, "
                            "against noise %.3g): they bound no solid\n", in, thick, noise);
        else
            fprintf(stderr, "argil fit: %s: %s\n", in,
                    why == OCTFIT_CLOUD_DUPLICATES ? "fewer than 4 distinct points (the rest repeat them)"
                    : why == OCTFIT_CLOUD_NONFINITE ? "a coordinate or normal is NaN or infinite"
                    : why == OCTFIT_CLOUD_MANY      ? "too many points"
                                                    : "fewer than 4 points");
        mesh_free(&m);
        return 1;
    }
    if (!normals) {
        normals_opts_t no = {0, &g_fit_stop, quiet ? NULL : progress_cb, &pr};
        if (!quiet)
            progress_stage(&pr, "normals");
        const argil_err_t ne = normals_estimate(&m, &no, NULL);
        if (ne != ARGIL_OK) {
            if (pr.tty)
                fputc('\n', stderr);
            if (g_fit_stop)
                fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
            else
                fprintf(stderr, "argil fit: %s: normals could not be estimated (%s)\n", in,
                        ne == ARGIL_ERR_NOMEM ? "out of memory" : "degenerate cloud");
            mesh_free(&m);
            return g_fit_stop ? 130 : 1;
        }
    }
    if (method == FIT_OCTREE)
        return fit_points_octree(in, out, &m, lo, hi, size, tol, depth, res, quiet, &pr);
    rbf_opts_t o;
    rbf_opts_default(&o);
    o.stop = &g_fit_stop;
    if (!quiet) {
        o.progress = progress_cb;
        o.progress_ctx = &pr;
    }
    argil_doc_t d;
    argil_doc_init(&d);
    argil_err_t e = ARGIL_OK;
    for (uint32_t s = (uint32_t)samples;; s *= 2) {
        if (s > RBF_CENTRES_MAX / 3)
            s = RBF_CENTRES_MAX / 3;
        o.max_surface_samples = s;
        if (!quiet)
            progress_stage(&pr, "rbf");
        rbf_free(&d.rbf);
        e = rbf_fit(&m, &o, &d.rbf);
        if (e != ARGIL_OK || d.rbf.rms_err_m <= tol || s >= RBF_CENTRES_MAX / 3 ||
            s >= m.n_vert)
            break;
    }
    int rc = 1;
    if (g_fit_stop) {
        if (pr.tty)
            fputc('\n', stderr);
        fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
        rc = 130;
    } else if (e != ARGIL_OK) {
        fprintf(stderr, "argil fit: %s: the RBF system could not be solved\n", in);
    } else if (make_grid(&d, lo, hi, res) != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory for the grid\n");
    } else {
        d.has_rbf = true;
        if (!quiet)
            progress_stage(&pr, "sample");
        grid_t *g = &d.grid;
        sample_fit(&d, &pr, quiet);
        if (pr.tty)
            fputc('\n', stderr);
        if (g_fit_stop) {
            fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
            rc = 130;
        } else if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s\n", err);
        } else {
            rc = 0;
            if (!quiet)
                printf("argil fit: %s: %zu points -> RBF of %u centres, error rms %.4g max %.4g "
                       "(%.3f %% / %.3f %% of size); grid %dx%dx%d\n", out, m.n_vert, d.rbf.n,
                       d.rbf.rms_err_m, d.rbf.max_err_m, 100.0 * d.rbf.rms_err_m / size,
                       100.0 * d.rbf.max_err_m / size, g->dims[0], g->dims[1], g->dims[2]);
        }
    }
    argil_doc_free(&d);
    mesh_free(&m);
    return rc;
}

static int fit_volume(const char *in, const char *out, fit_method_t method, double iso, double tol,
                      int depth, int res, int quiet)
{
    volume_t v;
    char err[1024];
    if (method == FIT_RBF || method == FIT_SDF) {
        fprintf(stderr, "argil fit: %s: a volume is fitted with --method grid or octree\n", in);
        return 2;
    }
    if (volume_read_nrrd(in, &v, err, sizeof(err)) != VOLUME_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
        return 1;
    }
    const size_t n = (size_t)v.dims[0] * (size_t)v.dims[1] * (size_t)v.dims[2];
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        lo = fminf(lo, v.value[i]);
        hi = fmaxf(hi, v.value[i]);
    }
    int rc = 1;
    if (!(hi > lo)) {
        fprintf(stderr, "argil fit: %s: every sample is %g; there is no surface\n", in, lo);
        volume_free(&v);
        return 1;
    }
    const double level = iso > -1e300 ? iso : 0.5 * (lo + hi);
    float iso_norm = (float)((level - lo) / (hi - lo));
    if (!(iso_norm > 0.0f && iso_norm < 1.0f))
        iso_norm = 0.5f;
    argil_doc_t d;
    argil_doc_init(&d);
    progress_t pr = {!quiet && isatty(STDERR_FILENO), 0, 0, -1, NULL};
    if (method == FIT_OCTREE) {
        octfit_opts_t o;
        octfit_opts_default(&o);
        o.tolerance = tol > 0 ? (float)tol : 0.01f; /* intensities are normalised to 0..1 */
        o.max_depth = (uint32_t)depth;
        o.stop = &g_fit_stop;
        if (!quiet) {
            o.progress = progress_cb;
            o.progress_ctx = &pr;
            progress_stage(&pr, "octree");
        }
        const argil_err_t e = octfit_volume(v.value, v.dims, v.spacing_m[0], v.origin_m, lo, hi,
                                            iso_norm, &o, &d.octree);
        d.has_octree = e == ARGIL_OK;
        const float blo[3] = {v.origin_m.x, v.origin_m.y, v.origin_m.z};
        const float bhi[3] = {v.origin_m.x + v.spacing_m[0] * (float)(v.dims[0] - 1),
                              v.origin_m.y + v.spacing_m[0] * (float)(v.dims[1] - 1),
                              v.origin_m.z + v.spacing_m[0] * (float)(v.dims[2] - 1)};
        if (g_fit_stop) {
            if (pr.tty)
                fputc('\n', stderr);
            fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
            rc = 130;
        } else if (e != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s: the octree fit failed (%s)\n", in,
                    e == ARGIL_ERR_NOMEM ? "out of memory" : "a node's system could not be solved");
        } else if (make_grid(&d, blo, bhi, res) != ARGIL_OK) {
            fprintf(stderr, "argil fit: out of memory for the grid\n");
        } else {
            d.grid.iso = iso_norm;
            if (!quiet)
                progress_stage(&pr, "sample");
            const bool done = sample_fit(&d, &pr, quiet);
            if (pr.tty)
                fputc('\n', stderr);
            if (!done) {
                fprintf(stderr, "argil fit: interrupted; %s not written\n", out);
                rc = 130;
            } else if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
                fprintf(stderr, "argil fit: %s\n", err);
            } else {
                rc = 0;
                if (!quiet)
                    printf("argil fit: %s: volume %dx%dx%d -> octree B-spline of %u nodes (%u "
                           "leaves, depth %u), intensity error rms %.4g max %.4g (of the range); "
                           "grid %dx%dx%d, surface at density %.3f\n", out, v.dims[0], v.dims[1],
                           v.dims[2], d.octree.n_nodes, d.octree.n_leaves, d.octree.depth,
                           d.octree.rms_err, d.octree.max_err, d.grid.dims[0], d.grid.dims[1],
                           d.grid.dims[2], d.grid.iso);
            }
        }
    } else if (grid_init(&d.grid, v.dims, v.spacing_m[0], v.origin_m) != ARGIL_OK) {
        fprintf(stderr, "argil fit: out of memory\n");
    } else {
        d.grid.iso = iso_norm;
        const int32_t zero[3] = {0, 0, 0};
        float *dn = malloc(n * sizeof(float));
        argil_err_t we = dn == NULL ? ARGIL_ERR_NOMEM : ARGIL_OK;
        for (size_t i = 0; dn != NULL && i < n; i++)
            dn[i] = (v.value[i] - lo) / (hi - lo);
        if (we == ARGIL_OK)
            we = grid_write_box(&d.grid, GRID_DENSITY, zero, v.dims, dn);
        if (we == ARGIL_OK)
            we = grid_write_box(&d.grid, GRID_REST, zero, v.dims, dn);
        free(dn);
        if (we != ARGIL_OK) {
            fprintf(stderr, "argil fit: out of memory\n");
        } else if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
            fprintf(stderr, "argil fit: %s\n", err);
        } else {
            rc = 0;
            if (!quiet)
                printf("argil fit: %s: volume %dx%dx%d, surface at intensity %g (density "
                       "%.3f)%s\n", out, v.dims[0], v.dims[1], v.dims[2], level, d.grid.iso,
                       v.spacing_m[0] != v.spacing_m[1] || v.spacing_m[0] != v.spacing_m[2]
                           ? "; anisotropic spacing: the x spacing is used"
                           : "");
        }
    }
    argil_doc_free(&d);
    volume_free(&v);
    return rc;
}

int cmd_fit(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    double tol = 0, res = 64, samples = 300, iso = -1e308, depth = 5;
    fit_method_t method = FIT_AUTO;
    int quiet = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage_fit(stdout);
            return 0;
        } else if (strcmp(a, "-o") == 0) {
            if (v == NULL) {
                fprintf(stderr, "argil fit: -o needs a value (see --help)\n");
                return 2;
            }
            out = v;
            i++;
        } else if (strcmp(a, "--method") == 0) {
            static const char *const names[] = {"auto", "octree", "rbf", "sdf", "grid"};
            int k = 0;
            while (k < 5 && (v == NULL || strcmp(v, names[k]) != 0))
                k++;
            if (k == 5) {
                fprintf(stderr, "argil fit: --method needs auto, octree, rbf, sdf or grid, got "
                                "'%s'\n", v != NULL ? v : "");
                return 2;
            }
            method = (fit_method_t)k;
            i++;
        } else if (strcmp(a, "--tolerance") == 0) {
            if (!num_arg(a, v, 1e-12, 1e12, &tol))
                return 2;
            i++;
        } else if (strcmp(a, "--max-depth") == 0) {
            if (!num_arg(a, v, 0, OCTFIT_DEPTH_MAX, &depth) || depth != floor(depth)) {
                if (depth != floor(depth))
                    fprintf(stderr, "argil fit: --max-depth needs a whole number\n");
                return 2;
            }
            i++;
        } else if (strcmp(a, "--resolution") == 0) {
            if (!num_arg(a, v, 8, 256, &res))
                return 2;
            i++;
        } else if (strcmp(a, "--samples") == 0) {
            if (!num_arg(a, v, 4, RBF_CENTRES_MAX / 3, &samples))
                return 2;
            i++;
        } else if (strcmp(a, "--iso") == 0) {
            if (!num_arg(a, v, -1e30, 1e30, &iso))
                return 2;
            i++;
        } else if (strcmp(a, "--quiet") == 0) {
            quiet = 1;
        } else if (a[0] == '-') {
            fprintf(stderr, "argil fit: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (in == NULL) {
            in = a;
        } else {
            fprintf(stderr, "argil fit: more than one input ('%s')\n", a);
            return 2;
        }
    }
    if (in == NULL || out == NULL) {
        fprintf(stderr, "argil fit: needs INPUT and -o MODEL.argil (see --help)\n");
        return 2;
    }
    signal(SIGINT, fit_on_signal);
    signal(SIGTERM, fit_on_signal);
    const char *dot = strrchr(in, '.');
    if (dot != NULL && (strcasecmp(dot, ".nrrd") == 0 || strcasecmp(dot, ".nhdr") == 0))
        return fit_volume(in, out, method, iso, tol, (int)depth, (int)res, quiet);
    return fit_points(in, out, method, tol, (int)depth, (int)res, (int)samples, quiet);
}
