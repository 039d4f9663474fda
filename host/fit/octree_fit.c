/* Hierarchical octree B-spline fitting (Hua & Qin §4): per node a regularised least-squares
 * fit solved by Cholesky on the OCTFIT_NCOEF-square normal equations, split while the node's
 * MSE exceeds the bound (never below the cloud's estimated noise); evaluation blends the leaves
 * with C1 bump weights. */
#include "host/fit/octree_fit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/fit/knn.h"
#include "host/fit/normals.h"
#include "host/mesh/mc.h"

#define OF_FIT_SAMPLES_MAX 600u  /* data used per node's normal equations (spread evenly) */
#define OF_SPLIT_MIN 32u         /* a node holding fewer data is not split */
#define OF_LAMBDA_REL 1e-3       /* prior weight relative to the mean diagonal of A^T A */
#define OF_PRIOR_FLOOR_REL 0.05  /* a coefficient whose data weigh less leans on the prior */
#define OF_SMOOTH_REL 1e-4       /* thin-plate weight (relative, as above) on clean data ... */
#define OF_SMOOTH_NOISE 30.0     /* ... plus this x (noise / knot spacing)^2 */
#define OF_NOISE_OFFSET 3.0f     /* automatic offset e >= this x noise */
#define OF_BINS 4                /* per axis: the bins of a node's local bias test */
#define OF_BIN_MIN 8u            /* data a bin needs to take part */
#define OF_NOISE_BIAS 1.5        /* a noisy node is split where a bin is off by this x noise */
#define OF_NOISE_SPLIT 1.5       /* a node whose RMS residual is within this x noise is a leaf */
#define OF_VOLUME_SAMPLES_MAX (1u << 20)

typedef float (*of_prior_fn)(const void *ctx, const double p[3]);

typedef struct {
    const float *pos; /* 3 per datum */
    const float *val;
    size_t n;
    of_prior_fn prior;
    const void *prior_ctx;
    double noise; /* estimated noise (sigma) of the data, in their units; 0 for none */
} of_data_t;

void octfit_opts_default(octfit_opts_t *o)
{
    memset(o, 0, sizeof(*o));
    o->max_depth = 5;
}

void octfit_free(octfit_model_t *m)
{
    if (m->leaf != NULL)
        for (uint32_t i = 0; i < m->n_leaves; i++)
            bspline_free(&m->leaf[i]);
    free(m->leaf);
    free(m->child);
    free(m->leaf_of);
    memset(m, 0, sizeof(*m));
}

/* The widened cube of a node: lo and edge of the spline's domain. */
static void of_widen(const double lo[3], double size, double wlo[3], double whi[3])
{
    for (int a = 0; a < 3; a++) {
        wlo[a] = lo[a] - OCTFIT_OVERLAP * size;
        whi[a] = lo[a] + (1.0 + OCTFIT_OVERLAP) * size;
    }
}

static void of_child_lo(const double lo[3], double size, int c, double out[3])
{
    for (int a = 0; a < 3; a++)
        out[a] = lo[a] + ((c >> a) & 1) * 0.5 * size;
}

argil_err_t octfit_alloc(octfit_model_t *m, uint32_t n_nodes, const uint32_t *child,
                         const float origin_m[3], float size_m)
{
    memset(m, 0, sizeof(*m));
    if (n_nodes < 1 || n_nodes > OCTFIT_NODES_MAX || child == NULL || !(size_m > 0) ||
        !isfinite(size_m) || !isfinite(origin_m[0]) || !isfinite(origin_m[1]) ||
        !isfinite(origin_m[2]))
        return ARGIL_ERR_ARG;
    m->child = malloc(n_nodes * sizeof(uint32_t));
    m->leaf_of = malloc(n_nodes * sizeof(uint32_t));
    uint8_t *depth = calloc(n_nodes, 1), *has_parent = calloc(n_nodes, 1);
    argil_err_t e = ARGIL_OK;
    if (m->child == NULL || m->leaf_of == NULL || depth == NULL || has_parent == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    memcpy(m->child, child, n_nodes * sizeof(uint32_t));
    m->n_nodes = n_nodes;
    for (uint32_t i = 0; i < n_nodes && e == ARGIL_OK; i++) {
        const uint32_t c = child[i];
        if (i > 0 && !has_parent[i]) {
            e = ARGIL_ERR_ARG; /* an orphan: parents always come before their children */
        } else if (c == 0) {
            m->leaf_of[i] = m->n_leaves++;
        } else if (c <= i || n_nodes < 9 || c > n_nodes - 8 || depth[i] >= OCTFIT_DEPTH_MAX) {
            e = ARGIL_ERR_ARG;
        } else {
            m->leaf_of[i] = UINT32_MAX;
            for (uint32_t k = c; k < c + 8; k++) {
                if (has_parent[k])
                    e = ARGIL_ERR_ARG;
                has_parent[k] = 1;
                depth[k] = (uint8_t)(depth[i] + 1);
            }
            if (depth[i] + 1u > m->depth)
                m->depth = depth[i] + 1u;
        }
    }
    if (e != ARGIL_OK)
        goto out;
    m->leaf = calloc(m->n_leaves, sizeof(bspline_t));
    if (m->leaf == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    memcpy(m->origin_m, origin_m, sizeof(m->origin_m));
    m->size_m = size_m;
    /* each leaf's spline over its widened cube: walk the tree to find the cubes */
    uint32_t stack[8 * (OCTFIT_DEPTH_MAX + 1) + 1];
    double slo[8 * (OCTFIT_DEPTH_MAX + 1) + 1][3], ssize[8 * (OCTFIT_DEPTH_MAX + 1) + 1];
    int sp = 0;
    stack[sp] = 0;
    ssize[sp] = size_m;
    for (int a = 0; a < 3; a++)
        slo[sp][a] = origin_m[a];
    sp++;
    const int32_t nn[3] = {OCTFIT_N, OCTFIT_N, OCTFIT_N};
    while (sp > 0 && e == ARGIL_OK) {
        sp--;
        const uint32_t i = stack[sp];
        double lo[3] = {slo[sp][0], slo[sp][1], slo[sp][2]};
        const double size = ssize[sp];
        if (m->child[i] == 0) {
            double wlo[3], whi[3];
            of_widen(lo, size, wlo, whi);
            e = bspline_init_uniform(&m->leaf[m->leaf_of[i]], nn, wlo, whi);
        } else {
            for (int c = 0; c < 8; c++) {
                stack[sp] = m->child[i] + (uint32_t)c;
                of_child_lo(lo, size, c, slo[sp]);
                ssize[sp] = 0.5 * size;
                sp++;
            }
        }
    }
out:
    free(depth);
    free(has_parent);
    if (e != ARGIL_OK)
        octfit_free(m);
    return e;
}

/* Adds the blend terms of the leaves under node i (cube lo, size) whose widened cube holds p. */
static void of_accum(const octfit_model_t *m, uint32_t i, const double lo[3], double size,
                     const double p[3], double *sw, double *swf)
{
    double w = 1.0;
    for (int a = 0; a < 3; a++) {
        const double t = (p[a] - (lo[a] + 0.5 * size)) / ((0.5 + OCTFIT_OVERLAP) * size);
        if (!(fabs(t) < 1.0))
            return;
        w *= (1.0 - t * t) * (1.0 - t * t);
    }
    if (m->child[i] == 0) {
        *sw += w;
        *swf += w * bspline_eval(&m->leaf[m->leaf_of[i]], p, NULL);
        return;
    }
    for (int c = 0; c < 8; c++) {
        double clo[3];
        of_child_lo(lo, size, c, clo);
        of_accum(m, m->child[i] + (uint32_t)c, clo, 0.5 * size, p, sw, swf);
    }
}

static double of_eval_d(const octfit_model_t *m, const double p_in[3])
{
    double p[3], out2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double lo = m->origin_m[a], hi = lo + m->size_m;
        p[a] = p_in[a] < lo ? lo : (p_in[a] > hi ? hi : p_in[a]);
        out2 += (p[a] - p_in[a]) * (p[a] - p_in[a]);
    }
    const double root_lo[3] = {m->origin_m[0], m->origin_m[1], m->origin_m[2]};
    double sw = 0.0, swf = 0.0;
    of_accum(m, 0, root_lo, m->size_m, p, &sw, &swf);
    const double f = sw > 0.0 ? swf / sw : 0.0;
    return m->kind == OCTFIT_SIGNED_DISTANCE ? f - sqrt(out2) : f;
}

float octfit_eval(const octfit_model_t *m, vec3_t p)
{
    if (m->n_nodes == 0 || !vec3_isfinite(p))
        return 0.0f;
    const double q[3] = {p.x, p.y, p.z};
    return (float)of_eval_d(m, q);
}

/* Cholesky solve of the SPD system held in the upper triangle of a (n x n), right-looking so
 * the inner loop runs along rows; false if a is not positive definite. */
static bool of_cholesky(double *a, double *b, int n)
{
    for (int k = 0; k < n; k++) {
        double *rk = a + (size_t)k * (size_t)n;
        if (!(rk[k] > 0.0))
            return false;
        const double d = sqrt(rk[k]), inv = 1.0 / d;
        rk[k] = d;
        for (int j = k + 1; j < n; j++)
            rk[j] *= inv;
        for (int i = k + 1; i < n; i++) {
            const double u = rk[i];
            if (u == 0.0)
                continue;
            double *ri = a + (size_t)i * (size_t)n;
            for (int j = i; j < n; j++)
                ri[j] -= u * rk[j];
        }
    }
    for (int i = 0; i < n; i++) { /* U^T y = b */
        const double y = b[i] / a[(size_t)i * (size_t)n + (size_t)i];
        b[i] = y;
        const double *ri = a + (size_t)i * (size_t)n;
        for (int j = i + 1; j < n; j++)
            b[j] -= ri[j] * y;
    }
    for (int i = n - 1; i >= 0; i--) { /* U x = y */
        const double *ri = a + (size_t)i * (size_t)n;
        double s = b[i];
        for (int k = i + 1; k < n; k++)
            s -= ri[k] * b[k];
        b[i] = s / ri[i];
    }
    return true;
}

/* The prior at Greville points, by lattice position: the nodes of one depth share their
 * Greville lattice (a node's points are 4 of its neighbour's 6 per axis), so each value is
 * asked of the prior once instead of up to 27 times. Open addressing; key 0 = empty. */
typedef struct {
    uint64_t *key;
    float *val;
    size_t cap, n;
} of_cache_t;

static void of_cache_free(of_cache_t *c)
{
    free(c->key);
    free(c->val);
    memset(c, 0, sizeof(*c));
}

static size_t of_cache_slot(const of_cache_t *c, uint64_t key)
{
    size_t i = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (c->cap - 1);
    while (c->key[i] != 0 && c->key[i] != key)
        i = (i + 1) & (c->cap - 1);
    return i;
}

/* Doubles the table (or makes its first one); false when out of memory (then it is unchanged). */
static bool of_cache_grow(of_cache_t *c)
{
    of_cache_t g = {NULL, NULL, c->cap ? 2 * c->cap : 4096, c->n};
    g.key = calloc(g.cap, sizeof(uint64_t));
    g.val = malloc(g.cap * sizeof(float));
    if (g.key == NULL || g.val == NULL) {
        of_cache_free(&g);
        return false;
    }
    for (size_t i = 0; i < c->cap; i++)
        if (c->key[i] != 0) {
            const size_t j = of_cache_slot(&g, c->key[i]);
            g.key[j] = c->key[i];
            g.val[j] = c->val[i];
        }
    of_cache_free(c);
    *c = g;
    return true;
}

/* The prior at g, the Greville point with lattice key key (non-zero). */
static float of_prior_at(const of_data_t *d, of_cache_t *c, uint64_t key, const double g[3])
{
    if (c->cap > 0) {
        const size_t i = of_cache_slot(c, key);
        if (c->key[i] == key)
            return c->val[i];
    }
    const float v = d->prior(d->prior_ctx, g);
    if (2 * (c->n + 1) > c->cap && !of_cache_grow(c))
        return v; /* no room: uncached, same value */
    const size_t i = of_cache_slot(c, key);
    c->key[i] = key;
    c->val[i] = v;
    c->n++;
    return v;
}

typedef struct {
    double *ata, *atb; /* OCTFIT_NCOEF^2 and OCTFIT_NCOEF scratch */
    double *smooth;    /* OCTFIT_NCOEF^2: the thin-plate energy's matrix (of_smooth_init) */
    of_cache_t prior;
} of_scratch_t;

/* S such that c^T S c = sum over the coefficient lattice of the squared second differences
 * c_aa^2 + 2 c_ab^2 (a != b): on uniform knots, h^4 times the thin-plate energy density
 * f_xx^2 + f_yy^2 + f_zz^2 + 2 (f_xy^2 + f_xz^2 + f_yz^2) of the spline, up to the spline's
 * lower-degree smoothing. Zero on linear functions, so planes are not biased. */
static void of_smooth_init(double *S)
{
    const int n = (int)OCTFIT_N, nc = (int)OCTFIT_NCOEF;
    memset(S, 0, sizeof(double) * (size_t)nc * (size_t)nc);
    for (int a = 0; a < 3; a++)
        for (int b = a; b < 3; b++)
            for (int c = 0; c < nc; c++) {
                int q[3] = {c % n, c / n % n, c / (n * n)}, id[4], m = 0;
                double w[4];
                const int st[3] = {1, n, n * n};
                if (a == b) { /* c[i-1] - 2 c[i] + c[i+1] along a */
                    if (q[a] < 1 || q[a] > n - 2)
                        continue;
                    id[0] = c - st[a], id[1] = c, id[2] = c + st[a];
                    w[0] = 1.0, w[1] = -2.0, w[2] = 1.0;
                    m = 3;
                } else { /* the mixed difference over the lattice square at c, weight 2 */
                    if (q[a] > n - 2 || q[b] > n - 2)
                        continue;
                    id[0] = c, id[1] = c + st[a], id[2] = c + st[b], id[3] = c + st[a] + st[b];
                    w[0] = w[3] = M_SQRT2, w[1] = w[2] = -M_SQRT2;
                    m = 4;
                }
                for (int x = 0; x < m; x++)
                    for (int y = 0; y < m; y++)
                        if (id[y] >= id[x])
                            S[(size_t)id[x] * (size_t)nc + (size_t)id[y]] += w[x] * w[y];
            }
}

typedef struct {
    uint32_t node, depth;
    uint32_t cell[3]; /* the cube's index among its depth's cubes */
    double lo[3], size;
    uint32_t *idx;
    size_t n_idx;
} of_task_t;

/* Least-squares fit of b (already initialised over the node's widened cube) to the data of t,
 * pulled towards the prior at the Greville points (weight lambda, more where data are thin) and
 * smoothed by a thin-plate term weighted by the noise; the MSE over all of t's data and the
 * largest local bias (mean residual of a bin of t's cube beyond 3 standard errors of noise). */
static argil_err_t of_fit_node(const of_data_t *d, const of_task_t *t, bspline_t *b,
                               of_scratch_t *s, double *mse, double *bias)
{
    const uint32_t *idx = t->idx, depth = t->depth, *cell = t->cell;
    const size_t n_idx = t->n_idx;
    const int nc = (int)OCTFIT_NCOEF, n = (int)OCTFIT_N;
    memset(s->ata, 0, sizeof(double) * (size_t)nc * (size_t)nc);
    memset(s->atb, 0, sizeof(double) * (size_t)nc);
    const size_t used = n_idx < OF_FIT_SAMPLES_MAX ? n_idx : OF_FIT_SAMPLES_MAX;
    for (size_t u = 0; u < used; u++) {
        const uint32_t j = idx[used == n_idx ? u : u * n_idx / used];
        const double p[3] = {d->pos[3 * (size_t)j], d->pos[3 * (size_t)j + 1], d->pos[3 * (size_t)j + 2]};
        double N[3][4];
        int32_t span[3];
        bool in = true;
        for (int a = 0; a < 3 && in; a++) {
            span[a] = bspline_span(b->knots[a], b->n[a], p[a]);
            if (span[a] < 0)
                in = false;
            else
                bspline_basis(b->knots[a], span[a], p[a], N[a], NULL);
        }
        if (!in)
            continue;
        double w[64];
        int id[64], q = 0;
        for (int kz = 0; kz < 4; kz++)
            for (int ky = 0; ky < 4; ky++)
                for (int kx = 0; kx < 4; kx++, q++) {
                    w[q] = N[0][kx] * N[1][ky] * N[2][kz];
                    id[q] = (span[0] - 3 + kx) + n * ((span[1] - 3 + ky) + n * (span[2] - 3 + kz));
                }
        const double v = d->val[j];
        for (int x = 0; x < 64; x++) {
            double *row = s->ata + (size_t)id[x] * (size_t)nc;
            const double wx = w[x];
            s->atb[id[x]] += wx * v;
            for (int y = x; y < 64; y++)
                row[id[y]] += wx * w[y];
        }
    }
    double tr = 0.0;
    for (int c = 0; c < nc; c++)
        tr += s->ata[(size_t)c * (size_t)nc + (size_t)c];
    const double mean = tr > 0.0 ? tr / nc : 1.0, lambda = OF_LAMBDA_REL * mean;
    /* Tikhonov: the thin-plate energy, stronger the larger the noise against the knot spacing,
     * so that noise is averaged over several spans instead of followed */
    const double h = b->knots[0][4] - b->knots[0][3], nr = d->noise / h;
    const double smooth = used > 0 ? (OF_SMOOTH_REL + OF_SMOOTH_NOISE * nr * nr) * mean : 0.0;
    for (int x = 0; x < nc; x++)
        for (int y = x; y < nc; y++)
            s->ata[(size_t)x * (size_t)nc + (size_t)y] += smooth * s->smooth[(size_t)x * (size_t)nc + (size_t)y];
    /* Greville abscissa of coefficient i on a uniform cubic knot vector: knot i + 2 */
    for (int kz = 0; kz < n; kz++)
        for (int ky = 0; ky < n; ky++)
            for (int kx = 0; kx < n; kx++) {
                const int c = kx + n * (ky + n * kz);
                const double g[3] = {b->knots[0][kx + 2], b->knots[1][ky + 2], b->knots[2][kz + 2]};
                /* Greville point (kx, ky, kz) of cell (i, j, k) at this depth is lattice point
                 * (2i + kx, 2j + ky, 2k + kz): knots are half a cell apart */
                const uint64_t key = ((uint64_t)(depth + 1) << 60) |
                                     ((uint64_t)(2 * cell[0] + (uint32_t)kx) << 40) |
                                     ((uint64_t)(2 * cell[1] + (uint32_t)ky) << 20) |
                                     (uint64_t)(2 * cell[2] + (uint32_t)kz);
                /* a coefficient the data barely reach follows the prior, not the extrapolation
                 * of data at the edge of its support (the floating blobs of an unweighted fit) */
                double *acc = &s->ata[(size_t)c * (size_t)nc + (size_t)c];
                const double lc = lambda + fmax(0.0, OF_PRIOR_FLOOR_REL * mean - *acc);
                *acc += lc;
                s->atb[c] += lc * of_prior_at(d, &s->prior, key, g);
            }
    if (used == 0) { /* no data: A diagonal, the prior itself */
        for (int c = 0; c < nc; c++)
            s->atb[c] /= s->ata[(size_t)c * (size_t)nc + (size_t)c];
    } else if (!of_cholesky(s->ata, s->atb, nc)) {
        return ARGIL_ERR_STATE;
    }
    for (int c = 0; c < nc; c++)
        b->coef[c] = (float)s->atb[c];
    /* the MSE, and the mean residual in each of OF_BINS^3 bins of the node's own cube: noise
     * averages out of a bin's mean, a systematic error (a rounded edge) does not */
    double sum = 0.0, bsum[OF_BINS * OF_BINS * OF_BINS] = {0};
    uint32_t bn[OF_BINS * OF_BINS * OF_BINS] = {0};
    for (size_t u = 0; u < n_idx; u++) {
        const uint32_t j = idx[u];
        const double p[3] = {d->pos[3 * (size_t)j], d->pos[3 * (size_t)j + 1], d->pos[3 * (size_t)j + 2]};
        const double r = bspline_eval(b, p, NULL) - d->val[j];
        sum += r * r;
        int bin = 0;
        for (int a = 2; a >= 0 && bin >= 0; a--) {
            const double x = (p[a] - t->lo[a]) / t->size * OF_BINS;
            bin = x >= 0.0 && x < OF_BINS ? bin * OF_BINS + (int)x : -1;
        }
        if (bin >= 0) {
            bsum[bin] += r;
            bn[bin]++;
        }
    }
    *mse = n_idx > 0 ? sum / (double)n_idx : 0.0; /* Hua & Qin §4 step 3 */
    /* the largest bin bias beyond what noise alone gives its mean (3 standard errors) */
    *bias = 0.0;
    for (int k = 0; k < OF_BINS * OF_BINS * OF_BINS; k++)
        if (bn[k] >= OF_BIN_MIN)
            *bias = fmax(*bias, fabs(bsum[k]) / bn[k] - 3.0 * d->noise / sqrt((double)bn[k]));
    return ARGIL_OK;
}

static bool of_in_box(const float *p, const double lo[3], const double hi[3])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
           p[2] <= hi[2];
}

/* The octree fit proper over data d with the root cube (lo, size). */
static argil_err_t of_fit(const of_data_t *d, const double root_lo[3], double root_size,
                          const octfit_opts_t *o, octfit_model_t *out)
{
    memset(out, 0, sizeof(*out));
    /* Hua & Qin's MSE bound, but never below the noise: a node already fitted to within the
     * noise has nothing left to fit but the noise itself */
    const double tol = fmax((double)o->tolerance, OF_NOISE_SPLIT * d->noise), bound = tol * tol;
    /* ... but that average over the node hides what is local: a node of a noisy cloud is also
     * split where a part of it is off by more than the noise */
    const bool noisy = d->noise > (double)o->tolerance;
    size_t cap = 1024, n_nodes = 1, head = 0, tail = 0;
    uint32_t *child = calloc(OCTFIT_NODES_MAX, sizeof(uint32_t));
    bspline_t *spl = calloc(OCTFIT_NODES_MAX, sizeof(bspline_t));
    of_task_t *q = malloc(cap * sizeof(of_task_t));
    of_scratch_t s = {malloc(sizeof(double) * OCTFIT_NCOEF * OCTFIT_NCOEF),
                      malloc(sizeof(double) * OCTFIT_NCOEF),
                      malloc(sizeof(double) * OCTFIT_NCOEF * OCTFIT_NCOEF), {NULL, NULL, 0, 0}};
    argil_err_t e = ARGIL_OK;
    if (child == NULL || spl == NULL || q == NULL || s.ata == NULL || s.atb == NULL ||
        s.smooth == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    of_smooth_init(s.smooth);
    q[tail].node = 0;
    q[tail].depth = 0;
    memset(q[tail].cell, 0, sizeof(q[tail].cell));
    q[tail].size = root_size;
    memcpy(q[tail].lo, root_lo, sizeof(q[tail].lo));
    q[tail].idx = malloc((d->n + 1) * sizeof(uint32_t));
    if (q[tail].idx == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    q[tail].n_idx = d->n;
    for (size_t i = 0; i < d->n; i++)
        q[tail].idx[i] = (uint32_t)i;
    tail++;
    double done_mass = 0.0;
    const int32_t nn[3] = {OCTFIT_N, OCTFIT_N, OCTFIT_N};
    while (head < tail) {
        of_task_t t = q[head++];
        if (o->stop != NULL && *o->stop) {
            free(t.idx);
            e = ARGIL_ERR_STATE;
            break;
        }
        double wlo[3], whi[3];
        of_widen(t.lo, t.size, wlo, whi);
        double mse = 0.0, bias = 0.0;
        e = bspline_init_uniform(&spl[t.node], nn, wlo, whi);
        if (e == ARGIL_OK)
            e = of_fit_node(d, &t, &spl[t.node], &s, &mse, &bias);
        if (e != ARGIL_OK) {
            free(t.idx);
            break;
        }
        const bool off = mse > bound || (noisy && bias > OF_NOISE_BIAS * d->noise);
        if (off && t.depth < o->max_depth && t.n_idx >= OF_SPLIT_MIN &&
            n_nodes + 8 <= OCTFIT_NODES_MAX) {
            if (tail + 8 > cap) {
                /* compact the queue, then grow it */
                memmove(q, q + head, (tail - head) * sizeof(of_task_t));
                tail -= head;
                head = 0;
                if (tail + 8 > cap) {
                    of_task_t *nq = realloc(q, 2 * cap * sizeof(of_task_t));
                    if (nq == NULL) {
                        free(t.idx);
                        e = ARGIL_ERR_NOMEM;
                        break;
                    }
                    q = nq;
                    cap *= 2;
                }
            }
            child[t.node] = (uint32_t)n_nodes;
            bspline_free(&spl[t.node]);
            for (int c = 0; c < 8 && e == ARGIL_OK; c++) {
                of_task_t *ct = &q[tail];
                ct->node = (uint32_t)n_nodes + (uint32_t)c;
                ct->depth = t.depth + 1;
                for (int a = 0; a < 3; a++)
                    ct->cell[a] = 2 * t.cell[a] + (uint32_t)((c >> a) & 1);
                ct->size = 0.5 * t.size;
                of_child_lo(t.lo, t.size, c, ct->lo);
                double clo[3], chi[3];
                of_widen(ct->lo, ct->size, clo, chi);
                size_t m = 0;
                for (size_t u = 0; u < t.n_idx; u++)
                    m += of_in_box(d->pos + 3 * (size_t)t.idx[u], clo, chi);
                ct->idx = malloc((m + 1) * sizeof(uint32_t));
                if (ct->idx == NULL) {
                    e = ARGIL_ERR_NOMEM;
                    break;
                }
                ct->n_idx = 0;
                for (size_t u = 0; u < t.n_idx; u++)
                    if (of_in_box(d->pos + 3 * (size_t)t.idx[u], clo, chi))
                        ct->idx[ct->n_idx++] = t.idx[u];
                tail++;
            }
            n_nodes += 8;
        } else {
            /* a leaf: its own cube's share of the data is final */
            double hi[3];
            for (int a = 0; a < 3; a++)
                hi[a] = t.lo[a] + t.size;
            size_t own = 0;
            for (size_t u = 0; u < t.n_idx; u++)
                own += of_in_box(d->pos + 3 * (size_t)t.idx[u], t.lo, hi);
            done_mass += (double)own;
            if (o->progress != NULL && d->n > 0)
                o->progress(o->progress_ctx, 0.9 * fmin(1.0, done_mass / (double)d->n));
        }
        free(t.idx);
    }
    if (e == ARGIL_OK) {
        const float org[3] = {(float)root_lo[0], (float)root_lo[1], (float)root_lo[2]};
        e = octfit_alloc(out, (uint32_t)n_nodes, child, org, (float)root_size);
    }
    if (e == ARGIL_OK)
        for (uint32_t i = 0; i < out->n_nodes; i++)
            if (out->child[i] == 0)
                memcpy(out->leaf[out->leaf_of[i]].coef, spl[i].coef, sizeof(float) * OCTFIT_NCOEF);
out:
    while (head < tail)
        free(q[head++].idx);
    if (spl != NULL)
        for (size_t i = 0; i < n_nodes; i++)
            bspline_free(&spl[i]);
    free(spl);
    free(child);
    free(q);
    free(s.ata);
    free(s.atb);
    free(s.smooth);
    of_cache_free(&s.prior);
    return e;
}

/* ------------------------------------------------------------------ point clouds */

#define OF_PRIOR_SAMPLES_MAX 4096u /* the prior looks at this many samples at most */

typedef struct {
    knn_grid_t g;
    float *pos, *normal; /* an even subsample of the cloud */
} of_cloud_prior_t;

/* Distance to the nearest sample, positive when p lies behind the normals of its 8 nearest
 * samples (summed offsets along each normal: robust at edges, where normals disagree). */
static float of_cloud_prior(const void *ctx, const double p[3])
{
    const of_cloud_prior_t *c = ctx;
    uint32_t i[8];
    float d2[8];
    const uint32_t got = knn_grid_query(&c->g, vec3_from_d(p), 8, i, d2);
    if (got == 0)
        return 0.0f;
    double s = 0.0;
    for (uint32_t k = 0; k < got; k++) {
        const float *q = c->g.pos + 3 * (size_t)i[k], *nn = c->normal + 3 * (size_t)i[k];
        s += (p[0] - q[0]) * nn[0] + (p[1] - q[1]) * nn[1] + (p[2] - q[2]) * nn[2];
    }
    return s > 0.0 ? -sqrtf(d2[0]) : sqrtf(d2[0]);
}

/* The bounding box of a cloud's (finite) points; returns its diagonal. */
static float of_bounds(const mesh_t *pts, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < pts->n_vert; i++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fminf(lo[a], pts->pos[3 * i + (size_t)a]);
            hi[a] = fmaxf(hi[a], pts->pos[3 * i + (size_t)a]);
        }
    return sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                 (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

static bool of_opts_ok(const octfit_opts_t *o)
{
    return o != NULL && isfinite(o->tolerance) && o->tolerance > 0.0f &&
           o->max_depth <= OCTFIT_DEPTH_MAX && isfinite(o->offset_m) && o->offset_m >= 0.0f;
}

/* A cube around lo..hi with a 15 % margin of the longest extent on every side. */
static void of_root(const float lo[3], const float hi[3], double root_lo[3], double *size)
{
    double ext = 0.0;
    for (int a = 0; a < 3; a++)
        ext = fmax(ext, (double)hi[a] - lo[a]);
    if (!(ext > 0.0))
        ext = 1e-3;
    *size = 1.3 * ext;
    for (int a = 0; a < 3; a++)
        root_lo[a] = 0.5 * ((double)lo[a] + hi[a]) - 0.5 * *size;
}

octfit_cloud_t octfit_check_points(const mesh_t *pts, float *thickness_m, float *noise_m)
{
    if (thickness_m != NULL)
        *thickness_m = 0.0f;
    if (noise_m != NULL)
        *noise_m = 0.0f;
    if (pts == NULL || pts->n_vert < 4)
        return OCTFIT_CLOUD_FEW;
    if (pts->n_vert > UINT32_MAX / 3)
        return OCTFIT_CLOUD_MANY;
    const size_t n = pts->n_vert;
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(pts->pos[i]) || (pts->normal != NULL && !isfinite(pts->normal[i])))
            return OCTFIT_CLOUD_NONFINITE;
    /* four distinct positions, found in one pass */
    const float *first[4] = {pts->pos, NULL, NULL, NULL};
    int distinct = 1;
    for (size_t i = 1; i < n && distinct < 4; i++) {
        const float *p = pts->pos + 3 * i;
        bool seen = false;
        for (int k = 0; k < distinct && !seen; k++)
            seen = p[0] == first[k][0] && p[1] == first[k][1] && p[2] == first[k][2];
        if (!seen)
            first[distinct++] = p;
    }
    if (distinct < 4)
        return OCTFIT_CLOUD_DUPLICATES;
    float noise = 0.0f;
    const float thick = normals_thickness(pts);
    if (normals_noise(pts, 0, &noise) != ARGIL_OK)
        noise = 0.0f;
    if (thickness_m != NULL)
        *thickness_m = thick;
    if (noise_m != NULL)
        *noise_m = noise;
    float lo[3], hi[3];
    const float diag = of_bounds(pts, lo, hi);
    return thick <= OCTFIT_FLAT_NOISE * noise + 1e-6f * diag ? OCTFIT_CLOUD_FLAT : OCTFIT_CLOUD_OK;
}

argil_err_t octfit_points(const mesh_t *pts, const octfit_opts_t *o, octfit_model_t *out)
{
    memset(out, 0, sizeof(*out));
    float noise = 0.0f;
    if (pts == NULL || pts->normal == NULL || !of_opts_ok(o) ||
        octfit_check_points(pts, NULL, &noise) != OCTFIT_CLOUD_OK)
        return ARGIL_ERR_ARG;
    const size_t n = pts->n_vert;
    float lo[3], hi[3];
    const float diag = of_bounds(pts, lo, hi);
    /* off-surface points must stand clear of the noise, or their +-e values say nothing */
    const float eps = o->offset_m > 0.0f ? o->offset_m : fmaxf(0.005f * diag, OF_NOISE_OFFSET * noise);
    float *pos = malloc(9 * n * sizeof(float)), *val = malloc(3 * n * sizeof(float));
    of_cloud_prior_t pr;
    memset(&pr, 0, sizeof(pr));

    argil_err_t e = pos != NULL && val != NULL ? ARGIL_OK : ARGIL_ERR_NOMEM;
    const size_t np = n < OF_PRIOR_SAMPLES_MAX ? n : OF_PRIOR_SAMPLES_MAX;
    pr.pos = malloc(3 * np * sizeof(float));
    pr.normal = malloc(3 * np * sizeof(float));
    if (e == ARGIL_OK && (pr.pos == NULL || pr.normal == NULL))
        e = ARGIL_ERR_NOMEM;
    if (e != ARGIL_OK)
        goto out;
    for (size_t k = 0; k < np; k++) {
        const size_t i = k * n / np;
        memcpy(pr.pos + 3 * k, pts->pos + 3 * i, 3 * sizeof(float));
        memcpy(pr.normal + 3 * k, pts->normal + 3 * i, 3 * sizeof(float));
    }
    e = knn_grid_build(&pr.g, pr.pos, np);
    if (e != ARGIL_OK)
        goto out;
    for (size_t i = 0; i < n; i++) {
        const float *p = pts->pos + 3 * i, *nn = pts->normal + 3 * i;
        const float len = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        const float s = len > 0.0f ? eps / len : 0.0f;
        for (int a = 0; a < 3; a++) {
            pos[3 * i + (size_t)a] = p[a];                           /* on the surface: 0 */
            pos[3 * (n + i) + (size_t)a] = p[a] - s * nn[a];         /* inside: +e */
            pos[3 * (2 * n + i) + (size_t)a] = p[a] + s * nn[a];     /* outside: -e */
        }
        val[i] = 0.0f;
        val[n + i] = len > 0.0f ? eps : 0.0f;
        val[2 * n + i] = len > 0.0f ? -eps : 0.0f;
    }
    const of_data_t d = {pos, val, 3 * n, of_cloud_prior, &pr, noise};
    double root_lo[3], size;
    of_root(lo, hi, root_lo, &size);
    e = of_fit(&d, root_lo, size, o, out);
    if (e != ARGIL_OK)
        goto out;
    out->kind = OCTFIT_SIGNED_DISTANCE;
    out->noise_m = noise;
    /* distance estimate |f| / |grad f| at every surface sample */
    double sum2 = 0.0, mx = 0.0;
    const double h = 1e-4 * size;
    for (size_t i = 0; i < n; i++) {
        if ((i & 1023) == 0 && o->progress != NULL)
            o->progress(o->progress_ctx, 0.9 + 0.1 * (double)i / (double)n);
        const double p[3] = {pts->pos[3 * i], pts->pos[3 * i + 1], pts->pos[3 * i + 2]};
        const double f = of_eval_d(out, p);
        double g2 = 0.0;
        for (int a = 0; a < 3; a++) { /* forward differences: an estimate, at 4 evaluations */
            double pp[3] = {p[0], p[1], p[2]};
            pp[a] += h;
            const double g = (of_eval_d(out, pp) - f) / h;
            g2 += g * g;
        }
        const double dist = g2 > 1e-12 ? fabs(f) / sqrt(g2) : fabs(f);
        sum2 += dist * dist;
        mx = fmax(mx, dist);
    }
    out->rms_err = (float)sqrt(sum2 / (double)n);
    out->max_err = (float)mx;
out:
    knn_grid_free(&pr.g);
    free(pr.pos);
    free(pr.normal);
    free(pos);
    free(val);
    if (e != ARGIL_OK)
        octfit_free(out);
    return e;
}

/* ------------------------------------------------------------------ volumes */

typedef struct {
    const float *v;
    int32_t dims[3];
    double spacing, origin[3];
    float lo, scale, iso;
} of_vol_prior_t;

/* The normalised trilinear intensity minus iso (samples clamped to the volume). */
static float of_vol_prior(const void *ctx, const double p[3])
{
    const of_vol_prior_t *c = ctx;
    int32_t i0[3];
    double f[3];
    for (int a = 0; a < 3; a++) {
        double t = (p[a] - c->origin[a]) / c->spacing;
        const double top = (double)(c->dims[a] - 1);
        t = t < 0.0 ? 0.0 : (t > top ? top : t);
        i0[a] = (int32_t)t;
        if (i0[a] >= c->dims[a] - 1)
            i0[a] = c->dims[a] > 1 ? c->dims[a] - 2 : 0;
        f[a] = c->dims[a] > 1 ? t - i0[a] : 0.0;
    }
    double v = 0.0;
    for (int k = 0; k < 8; k++) {
        int32_t q[3];
        double w = 1.0;
        for (int a = 0; a < 3; a++) {
            const int bit = (k >> a) & 1;
            q[a] = i0[a] + (c->dims[a] > 1 ? bit : 0);
            w *= bit ? f[a] : 1.0 - f[a];
        }
        if (w != 0.0)
            v += w * c->v[(size_t)q[0] + (size_t)c->dims[0] * ((size_t)q[1] + (size_t)c->dims[1] * (size_t)q[2])];
    }
    return (float)((v - c->lo) * c->scale - c->iso);
}

argil_err_t octfit_volume(const float *v, const int32_t dims[3], float spacing_m, vec3_t origin_m,
                          float lo, float hi, float iso_norm, const octfit_opts_t *o,
                          octfit_model_t *out)
{
    memset(out, 0, sizeof(*out));
    if (v == NULL || dims == NULL || !of_opts_ok(o) || !(spacing_m > 0) || !isfinite(spacing_m) ||
        !vec3_isfinite(origin_m) || !isfinite(lo) || !isfinite(hi) || !(hi > lo) ||
        !isfinite(iso_norm))
        return ARGIL_ERR_ARG;
    uint64_t total;
    if (!mc_grid_samples(dims, &total))
        return ARGIL_ERR_ARG;
    /* at most about 2^20 data: every step-th sample along each axis */
    int32_t step = 1;
    while (total / ((uint64_t)step * step * step) > OF_VOLUME_SAMPLES_MAX)
        step++;
    int32_t m[3];
    size_t n = 1;
    for (int a = 0; a < 3; a++) {
        m[a] = (dims[a] + step - 1) / step;
        n *= (size_t)m[a];
    }
    float *pos = malloc(3 * n * sizeof(float)), *val = malloc(n * sizeof(float));
    if (pos == NULL || val == NULL) {
        free(pos);
        free(val);
        return ARGIL_ERR_NOMEM;
    }
    const of_vol_prior_t pr = {v, {dims[0], dims[1], dims[2]}, spacing_m,
                               {origin_m.x, origin_m.y, origin_m.z}, lo, 1.0f / (hi - lo), iso_norm};
    size_t i = 0;
    for (int32_t z = 0; z < dims[2]; z += step)
        for (int32_t y = 0; y < dims[1]; y += step)
            for (int32_t x = 0; x < dims[0]; x += step, i++) {
                pos[3 * i] = origin_m.x + spacing_m * (float)x;
                pos[3 * i + 1] = origin_m.y + spacing_m * (float)y;
                pos[3 * i + 2] = origin_m.z + spacing_m * (float)z;
                const float s = v[(size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z)];
                val[i] = (s - lo) / (hi - lo) - iso_norm;
            }
    const of_data_t d = {pos, val, n, of_vol_prior, &pr, 0.0};
    const float blo[3] = {origin_m.x, origin_m.y, origin_m.z};
    const float bhi[3] = {origin_m.x + spacing_m * (float)(dims[0] - 1),
                          origin_m.y + spacing_m * (float)(dims[1] - 1),
                          origin_m.z + spacing_m * (float)(dims[2] - 1)};
    double root_lo[3], size;
    of_root(blo, bhi, root_lo, &size);
    argil_err_t e = of_fit(&d, root_lo, size, o, out);
    if (e == ARGIL_OK) {
        out->kind = OCTFIT_INTENSITY;
        double sum2 = 0.0, mx = 0.0;
        for (size_t k = 0; k < n; k++) {
            const double p[3] = {pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]};
            const double r = fabs(of_eval_d(out, p) - val[k]);
            sum2 += r * r;
            mx = fmax(mx, r);
        }
        out->rms_err = (float)sqrt(sum2 / (double)n);
        out->max_err = (float)mx;
    }
    free(pos);
    free(val);
    return e;
}
