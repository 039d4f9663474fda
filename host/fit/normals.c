/* Point-cloud normals: PCA of the k-neighbourhood covariance (smallest eigenvector by Jacobi
 * rotations), then orientation along a Prim minimum spanning tree over the k-NN graph. */
#include "host/fit/normals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/fit/knn.h"

/* Eigenvector of the smallest eigenvalue of the symmetric 3x3 matrix a (cyclic Jacobi); returns
 * that eigenvalue. */
static double sym3_min_eigvec(double a[3][3], double v_out[3])
{
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 32; sweep++) {
        const double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        if (off < 1e-30 * (fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2])) || off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0)
                    continue;
                const double th = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int best = 0;
    for (int i = 1; i < 3; i++)
        if (a[i][i] < a[best][best])
            best = i;
    for (int k = 0; k < 3; k++)
        v_out[k] = v[k][best];
    return a[best][best];
}

/* The least-squares plane through the points idx[0..got) of pos (idx NULL: the first got): its
 * unit normal (PCA, Hoppe et al. 1992) into n_out; returns the mean square distance to it. */
static double nm_plane_fit(const float *pos, const uint32_t *idx, size_t got, float n_out[3])
{
    double c[3] = {0, 0, 0}, cov[3][3] = {{0}};
    for (size_t j = 0; j < got; j++)
        for (int a = 0; a < 3; a++)
            c[a] += pos[3 * (size_t)(idx != NULL ? idx[j] : j) + (size_t)a] / (double)got;
    for (size_t j = 0; j < got; j++) {
        double d[3];
        for (int a = 0; a < 3; a++)
            d[a] = pos[3 * (size_t)(idx != NULL ? idx[j] : j) + (size_t)a] - c[a];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                cov[a][b] += d[a] * d[b];
    }
    double v[3];
    const double lmin = sym3_min_eigvec(cov, v);
    const double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; a++)
        n_out[a] = len > 0 ? (float)(v[a] / len) : (a == 0);
    return got > 0 && lmin > 0.0 ? lmin / (double)got : 0.0;
}

static int nm_cmp_f(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* The RMS residual of the height-field quadric h = a u^2 + b uv + c v^2 + d u + e v + f fitted
 * by least squares to points idx[0..got) of pos in the frame (u, v, n) of their plane (normal n
 * through centroid c), unbiased for its 6 degrees of freedom: what is left is noise, not the
 * surface's curvature. 0 when got <= 6 or the system is singular. */
static double nm_quadric_rms(const float *pos, const uint32_t *idx, uint32_t got, const float n[3])
{
    if (got <= 6)
        return 0.0;
    double c[3] = {0, 0, 0}, u[3], v[3];
    for (uint32_t j = 0; j < got; j++)
        for (int a = 0; a < 3; a++)
            c[a] += pos[3 * (size_t)idx[j] + (size_t)a] / (double)got;
    const int ax = fabsf(n[0]) < 0.6f ? 0 : 1; /* u = n x e_ax, v = n x u */
    const double e[3] = {ax == 0, ax == 1, 0};
    u[0] = n[1] * e[2] - n[2] * e[1], u[1] = n[2] * e[0] - n[0] * e[2], u[2] = n[0] * e[1] - n[1] * e[0];
    const double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; a++)
        u[a] /= ul;
    v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
    double A[6][6] = {{0}}, b[6] = {0}, x[KNN_K_MAX][7];
    for (uint32_t j = 0; j < got; j++) {
        double d[3], pu = 0, pv = 0, h = 0;
        for (int a = 0; a < 3; a++) {
            d[a] = pos[3 * (size_t)idx[j] + (size_t)a] - c[a];
            pu += d[a] * u[a], pv += d[a] * v[a], h += d[a] * n[a];
        }
        const double row[7] = {pu * pu, pu * pv, pv * pv, pu, pv, 1.0, h};
        for (int r = 0; r < 6; r++) {
            for (int q = 0; q < 6; q++)
                A[r][q] += row[r] * row[q];
            b[r] += row[r] * h;
        }
        memcpy(x[j], row, sizeof(row));
    }
    for (int k = 0; k < 6; k++) { /* Cholesky, in place in the lower triangle */
        for (int q = 0; q < k; q++)
            A[k][k] -= A[k][q] * A[k][q];
        if (!(A[k][k] > 1e-30))
            return 0.0;
        A[k][k] = sqrt(A[k][k]);
        for (int r = k + 1; r < 6; r++) {
            for (int q = 0; q < k; q++)
                A[r][k] -= A[r][q] * A[k][q];
            A[r][k] /= A[k][k];
        }
    }
    for (int r = 0; r < 6; r++) { /* L y = b, then L^T x = y */
        for (int q = 0; q < r; q++)
            b[r] -= A[r][q] * b[q];
        b[r] /= A[r][r];
    }
    for (int r = 5; r >= 0; r--) {
        for (int q = r + 1; q < 6; q++)
            b[r] -= A[q][r] * b[q];
        b[r] /= A[r][r];
    }
    double ss = 0.0;
    for (uint32_t j = 0; j < got; j++) {
        double f = -x[j][6];
        for (int q = 0; q < 6; q++)
            f += b[q] * x[j][q];
        ss += f * f;
    }
    return sqrt(ss / (double)(got - 6));
}

/* Over up to NORMALS_NOISE_SAMPLES evenly spread points of m (binned in g): the median of the
 * quadric residual of their k nearest neighbours (nm_quadric_rms) into *sigma_m, and the median
 * distance to the k-th neighbour into *radius_m. */
static argil_err_t nm_noise_stats(const mesh_t *m, const knn_grid_t *g, uint32_t k, float *sigma_m,
                                  float *radius_m)
{
    const uint32_t n = (uint32_t)m->n_vert, ns = n < NORMALS_NOISE_SAMPLES ? n : NORMALS_NOISE_SAMPLES;
    if (k > n)
        k = n;
    float *r = malloc(2 * (size_t)ns * sizeof(float));
    if (r == NULL)
        return ARGIL_ERR_NOMEM;
    uint32_t nb[KNN_K_MAX];
    float d2[KNN_K_MAX];
    for (uint32_t s = 0; s < ns; s++) {
        const float *p = m->pos + 3 * ((size_t)s * n / ns);
        const uint32_t got = knn_grid_query(g, vec3(p[0], p[1], p[2]), k, nb, d2);
        float nrm[3];
        nm_plane_fit(m->pos, nb, got, nrm);
        r[s] = (float)nm_quadric_rms(m->pos, nb, got, nrm);
        r[ns + s] = got > 0 ? sqrtf(d2[got - 1]) : 0.0f;
    }
    qsort(r, ns, sizeof(float), nm_cmp_f);
    qsort(r + ns, ns, sizeof(float), nm_cmp_f);
    *sigma_m = r[ns / 2];
    *radius_m = r[ns + ns / 2];
    free(r);
    return ARGIL_OK;
}

float normals_thickness(const mesh_t *m)
{
    float nrm[3];
    return m->n_vert > 0 ? (float)sqrt(nm_plane_fit(m->pos, NULL, m->n_vert, nrm)) : 0.0f;
}

argil_err_t normals_noise(const mesh_t *m, uint32_t k, float *sigma_m)
{
    *sigma_m = 0.0f;
    if (k == 0)
        k = NORMALS_NOISE_K_DEFAULT;
    if (m == NULL || m->n_vert < 4 || m->n_vert >= UINT32_MAX || k < 4 || k > KNN_K_MAX)
        return ARGIL_ERR_ARG;
    knn_grid_t g;
    argil_err_t e = knn_grid_build(&g, m->pos, m->n_vert);
    float radius;
    if (e == ARGIL_OK)
        e = nm_noise_stats(m, &g, k, sigma_m, &radius);
    knn_grid_free(&g);
    return e;
}

typedef struct {
    float w;
    uint32_t to, from;
} nm_edge_t;

/* Binary min-heap of candidate tree edges. */
typedef struct {
    nm_edge_t *e;
    size_t n, cap;
} nm_heap_t;

static bool nm_push(nm_heap_t *h, nm_edge_t x)
{
    if (h->n == h->cap) {
        const size_t cap = h->cap ? 2 * h->cap : 1024;
        nm_edge_t *e = realloc(h->e, cap * sizeof(*e));
        if (e == NULL)
            return false;
        h->e = e;
        h->cap = cap;
    }
    size_t i = h->n++;
    while (i > 0 && h->e[(i - 1) / 2].w > x.w) {
        h->e[i] = h->e[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->e[i] = x;
    return true;
}

static nm_edge_t nm_pop(nm_heap_t *h)
{
    const nm_edge_t top = h->e[0], last = h->e[--h->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && h->e[c + 1].w < h->e[c].w)
            c++;
        if (!(h->e[c].w < last.w))
            break;
        h->e[i] = h->e[c];
        i = c;
    }
    if (h->n > 0)
        h->e[i] = last;
    return top;
}

static float nm_weight(const float *nrm, uint32_t i, uint32_t j)
{
    const float *a = nrm + 3 * (size_t)i, *b = nrm + 3 * (size_t)j;
    return 1.0f - fabsf(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

argil_err_t normals_estimate(mesh_t *m, const normals_opts_t *o, uint32_t *parts)
{
    if (parts != NULL)
        *parts = 0;
    if (m == NULL || m->n_vert < 4 || m->n_vert >= UINT32_MAX)
        return ARGIL_ERR_ARG;
    uint32_t k = o != NULL && o->k != 0 ? o->k : NORMALS_K_DEFAULT;
    if (k < 4 || k > KNN_K_MAX)
        return ARGIL_ERR_ARG;
    const uint32_t n = (uint32_t)m->n_vert;
    knn_grid_t g;
    argil_err_t e = knn_grid_build(&g, m->pos, n);
    if (e != ARGIL_OK)
        return e;
    if (o == NULL || o->k == 0) {
        /* a plane through noise of sigma tilts by about sigma / radius: widen a noisy cloud's
         * neighbourhood (area ~ k) until its radius is NORMALS_NOISE_RADII sigma */
        float sigma, radius;
        e = nm_noise_stats(m, &g, k, &sigma, &radius);
        if (e != ARGIL_OK) {
            knn_grid_free(&g);
            return e;
        }
        const double want = radius > 0.0f ? NORMALS_NOISE_RADII * sigma / radius : 1.0;
        if (want > 1.0)
            k = (uint32_t)fmin((double)KNN_K_MAX, ceil((double)k * want * want));
    }
    if (k > n)
        k = n;
    uint32_t *nb = malloc((size_t)n * k * sizeof(uint32_t));
    uint8_t *done = calloc(n, 1);
    nm_heap_t h = {NULL, 0, 0};
    if (nb == NULL || done == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    for (uint32_t i = 0; i < n; i++) {
        if ((i & 4095) == 0 && o != NULL) {
            if (o->stop != NULL && *o->stop) {
                e = ARGIL_ERR_STATE;
                goto out;
            }
            if (o->progress != NULL)
                o->progress(o->progress_ctx, 0.8 * (double)i / (double)n);
        }
        const float *p = m->pos + 3 * (size_t)i;
        uint32_t *ni = nb + (size_t)i * k;
        const uint32_t got = knn_grid_query(&g, vec3(p[0], p[1], p[2]), k, ni, NULL);
        for (uint32_t j = got; j < k; j++)
            ni[j] = i;
        nm_plane_fit(m->pos, ni, got, m->normal + 3 * (size_t)i);
    }
    /* Prim over the k-NN graph, one tree per connected part, each rooted at its largest x */
    uint32_t n_parts = 0, left = n;
    while (left > 0) {
        uint32_t root = UINT32_MAX;
        for (uint32_t i = 0; i < n; i++)
            if (!done[i] && (root == UINT32_MAX || m->pos[3 * (size_t)i] > m->pos[3 * (size_t)root]))
                root = i;
        float *rn = m->normal + 3 * (size_t)root;
        if (rn[0] < 0.0f)
            for (int a = 0; a < 3; a++)
                rn[a] = -rn[a];
        n_parts++;
        h.n = 0;
        if (!nm_push(&h, (nm_edge_t){0.0f, root, root})) {
            e = ARGIL_ERR_NOMEM;
            goto out;
        }
        while (h.n > 0) {
            const nm_edge_t ed = nm_pop(&h);
            if (done[ed.to])
                continue;
            done[ed.to] = 1;
            left--;
            if ((left & 4095) == 0 && o != NULL) {
                if (o->stop != NULL && *o->stop) {
                    e = ARGIL_ERR_STATE;
                    goto out;
                }
                if (o->progress != NULL)
                    o->progress(o->progress_ctx, 0.8 + 0.2 * (double)(n - left) / (double)n);
            }
            float *a = m->normal + 3 * (size_t)ed.to;
            const float *b = m->normal + 3 * (size_t)ed.from;
            if (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < 0.0f)
                for (int q = 0; q < 3; q++)
                    a[q] = -a[q];
            for (uint32_t j = 0; j < k; j++) {
                const uint32_t t = nb[(size_t)ed.to * k + j];
                if (!done[t] && !nm_push(&h, (nm_edge_t){nm_weight(m->normal, ed.to, t), t, ed.to})) {
                    e = ARGIL_ERR_NOMEM;
                    goto out;
                }
            }
        }
    }
    if (parts != NULL)
        *parts = n_parts;
out:
    free(h.e);
    free(done);
    free(nb);
    knn_grid_free(&g);
    return e;
}
