/* argil fit: a point cloud or mesh (with normals) or a volume becomes a model (.argil). Points
 * are fitted with the RBF implicit of Zhang et al. §5 and sampled into the density grid; the RBF
 * form is saved beside the grid. Volumes are normalised into densities directly. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "host/app/commands.h"
#include "host/fit/rbf.h"
#include "host/io/argil_file.h"
#include "host/io/mesh_import.h"
#include "host/io/volume.h"

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
            "usage: argil fit INPUT -o MODEL.argil [--tolerance E] [--resolution N]\n"
            "                 [--samples S] [--iso V] [--quiet]\n"
            "\n"
            "Turns INPUT into a model. Point clouds and meshes (.ply .stl .obj .xyz .txt .pts,\n"
            "with normals) are fitted with an RBF implicit (phi = r^3 + linear, one interior and\n"
            "one exterior constraint per sample, Zhang et al. 5); volumes (.nrrd .nhdr) are\n"
            "normalised into densities. Ctrl-C stops cleanly (exit 130, nothing written).\n"
            "\n"
            "options:\n"
            "  -o MODEL.argil  output model (written atomically)\n"
            "  --tolerance E   wanted RMS fitting error in the input's units (default 0.2 %% of\n"
            "                  the size); the sample count doubles until it is met or 1365\n"
            "  --resolution N  grid samples along the longest axis, 8..256 (default 64)\n"
            "  --samples S     surface samples to start with, 4..1365 (default 300)\n"
            "  --iso V         for volumes: the intensity of the surface (default: mid-range)\n"
            "  --quiet         no progress and no summary\n"
            "  -h, --help      this text\n"
            "\n"
            "Not in this build: the hierarchical octree B-spline fit (Hua & Qin 4, --max-depth)\n"
            "and fitting clouds without normals.\n");
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

static int fit_points(const char *in, const char *out, double tol, int res, int samples,
                      int quiet)
{
    mesh_t m;
    mesh_init(&m);
    bool normals = false;
    char err[1024];
    if (mesh_import(in, &m, &normals, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "argil fit: %s\n", err);
        mesh_free(&m);
        return 1;
    }
    if (!normals || m.n_vert < 4) {
        fprintf(stderr, "argil fit: %s: %s\n", in,
                m.n_vert < 4 ? "fewer than 4 points"
                             : "no normals (orienting an unoriented cloud is not in this build)");
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
        size_t i = 0;
        for (int32_t z = 0; z < g->dims[2] && !g_fit_stop; z++) {
            for (int32_t y = 0; y < g->dims[1]; y++)
                for (int32_t x = 0; x < g->dims[0]; x++, i++) {
                    const vec3_t p = vec3(g->origin_m.x + g->spacing_m * (float)x,
                                          g->origin_m.y + g->spacing_m * (float)y,
                                          g->origin_m.z + g->spacing_m * (float)z);
                    g->density[i] = g->rest[i] = grid_profile(rbf_eval(&d.rbf, p), g->band_m);
                }
            if (!quiet)
                progress_cb(&pr, (double)(z + 1) / (double)g->dims[2]);
        }
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

static int fit_volume(const char *in, const char *out, double iso, int quiet)
{
    volume_t v;
    char err[1024];
    if (volume_read_nrrd(in, &v, err, sizeof(err)) != ARGIL_OK) {
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
    } else {
        const double level = iso > -1e300 ? iso : 0.5 * (lo + hi);
        argil_doc_t d;
        argil_doc_init(&d);
        if (grid_init(&d.grid, v.dims, v.spacing_m[0], v.origin_m) != ARGIL_OK) {
            fprintf(stderr, "argil fit: out of memory\n");
        } else {
            d.grid.iso = (float)((level - lo) / (hi - lo));
            if (!(d.grid.iso > 0.0f && d.grid.iso < 1.0f))
                d.grid.iso = 0.5f;
            for (size_t i = 0; i < n; i++)
                d.grid.density[i] = d.grid.rest[i] = (v.value[i] - lo) / (hi - lo);
            if (argil_file_write(out, &d, err, sizeof(err)) != ARGIL_OK) {
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
    }
    volume_free(&v);
    return rc;
}

int cmd_fit(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    double tol = 0, res = 64, samples = 300, iso = -1e308;
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
        } else if (strcmp(a, "--tolerance") == 0) {
            if (!num_arg(a, v, 1e-12, 1e12, &tol))
                return 2;
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
        } else if (strcmp(a, "--max-depth") == 0) {
            fprintf(stderr, "argil fit: --max-depth belongs to the octree B-spline fit, which is "
                            "not in this build\n");
            return 2;
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
        return fit_volume(in, out, iso, quiet);
    return fit_points(in, out, tol, (int)res, (int)samples, quiet);
}
