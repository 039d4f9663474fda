/* Closed mesh -> signed distance grid: per triangle, the samples within the band around it take
 * the exact point-triangle distance (Ericson, Real-Time Collision Detection §5.1.5) and remember
 * the closest feature; its angle-weighted pseudo-normal gives the sign (Baerentzen & Aanaes).
 * Samples beyond the band get their sign from the parity of +x ray crossings along their row. */
#include "host/io/mesh_sdf.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/mesh/mesh_check.h"

typedef struct {
    double x, y, z;
} dv_t;

static dv_t dv(double x, double y, double z) { dv_t v = {x, y, z}; return v; }
static dv_t dsub(dv_t a, dv_t b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static dv_t dadd(dv_t a, dv_t b) { return dv(a.x + b.x, a.y + b.y, a.z + b.z); }
static dv_t dscale(dv_t a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static double ddot(dv_t a, dv_t b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv_t dcross(dv_t a, dv_t b)
{
    return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static dv_t dnorm(dv_t a)
{
    const double l = sqrt(ddot(a, a));
    return l > 0.0 ? dscale(a, 1.0 / l) : a;
}

static dv_t vtx(const mesh_t *m, uint32_t i)
{
    return dv(m->pos[3 * (size_t)i], m->pos[3 * (size_t)i + 1], m->pos[3 * (size_t)i + 2]);
}

/* What closest_on_tri learns at corner q: the dot products of its two edge vectors e, f with
 * p - q, and the barycentric term v of the edge along e. */
typedef struct {
    double qe, qf, v;
} tri_corner_t;

/* Ericson's corner and edge regions at q (q = b with e = ab, f = ac, or q = c with e = ac,
 * f = ab; ep = e . (p - a), fp = f . (p - a)): true with *out and *feat (feat_q or feat_e) when
 * p is nearest q or the edge from a along e (Real-Time Collision Detection, 5.1.5). */
static bool tri_corner(dv_t p, dv_t a, dv_t q, dv_t e, dv_t f, double ep, double fp, int feat_q,
                       int feat_e, tri_corner_t *k, dv_t *out, int *feat)
{
    const dv_t qp = dsub(p, q);
    k->qe = ddot(e, qp);
    k->qf = ddot(f, qp);
    if (k->qe >= 0 && k->qf <= k->qe) {
        *feat = feat_q;
        *out = q;
        return true;
    }
    k->v = ep * k->qf - k->qe * fp;
    if (k->v <= 0 && ep >= 0 && k->qe <= 0) {
        *feat = feat_e;
        *out = dadd(a, dscale(e, ep / (ep - k->qe)));
        return true;
    }
    return false;
}

/* Closest point on triangle abc to p; *feat: 0 face, 1..3 edge ab / bc / ca, 4..6 vertex a b c. */
static dv_t closest_on_tri(dv_t p, dv_t a, dv_t b, dv_t c, int *feat)
{
    const dv_t ab = dsub(b, a), ac = dsub(c, a), ap = dsub(p, a);
    const double d1 = ddot(ab, ap), d2 = ddot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        *feat = 4;
        return a;
    }
    tri_corner_t kb, kc;
    dv_t q;
    if (tri_corner(p, a, b, ab, ac, d1, d2, 5, 1, &kb, &q, feat) ||
        tri_corner(p, a, c, ac, ab, d2, d1, 6, 3, &kc, &q, feat))
        return q;
    const double d3 = kb.qe, d4 = kb.qf, d5 = kc.qf, d6 = kc.qe, vc = kb.v, vb = kc.v;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        *feat = 2;
        return dadd(b, dscale(dsub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    const double den = 1.0 / (va + vb + vc);
    *feat = 0;
    return dadd(a, dadd(dscale(ab, vb * den), dscale(ac, vc * den)));
}

typedef struct {
    uint32_t lo, hi, tri;
    uint8_t edge;
} sdf_edge_t;

/* -1, 0 or 1 as a is below, equal to or above b. */
static int u32_cmp(uint32_t a, uint32_t b)
{
    return a < b ? -1 : (a > b);
}

/* qsort order of edges: by lo, then hi, then triangle. */
static int edge_cmp(const void *x, const void *y)
{
    const sdf_edge_t *a = x, *b = y;
    int c = u32_cmp(a->lo, b->lo);
    if (c == 0)
        c = u32_cmp(a->hi, b->hi);
    return c != 0 ? c : u32_cmp(a->tri, b->tri);
}

typedef struct {
    uint32_t row;
    float x;
} sdf_cross_t;

/* qsort order of crossings: by row, then x. */
static int cross_cmp(const void *x, const void *y)
{
    const sdf_cross_t *a = x, *b = y;
    const int c = u32_cmp(a->row, b->row);
    return c != 0 ? c : (a->x < b->x ? -1 : (a->x > b->x));
}

/* Face normals fn, angle-weighted vertex pseudo-normals vn (zero on entry) and the neighbour
 * face nb across each edge of the watertight mesh m (ed: room for 3 n_tri edges); returns the
 * number of zero-area faces. */
static size_t sdf_normals(const mesh_t *m, dv_t *fn, dv_t *vn, uint32_t *nb, sdf_edge_t *ed)
{
    const size_t nt = m->n_tri;
    size_t degenerate = 0;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = m->tri + 3 * t;
        const dv_t p[3] = {vtx(m, v[0]), vtx(m, v[1]), vtx(m, v[2])};
        const dv_t nrm = dcross(dsub(p[1], p[0]), dsub(p[2], p[0]));
        fn[t] = dnorm(nrm);
        if (!(ddot(nrm, nrm) > 0.0))
            degenerate++;
        for (int k = 0; k < 3; k++) {
            const dv_t u = dnorm(dsub(p[(k + 1) % 3], p[k])), w = dnorm(dsub(p[(k + 2) % 3], p[k]));
            const double cosang = fmax(-1.0, fmin(1.0, ddot(u, w)));
            vn[v[k]] = dadd(vn[v[k]], dscale(fn[t], acos(cosang)));
            const uint32_t a = v[k], b = v[(k + 1) % 3];
            ed[3 * t + (size_t)k] = (sdf_edge_t){a < b ? a : b, a < b ? b : a, (uint32_t)t, (uint8_t)k};
        }
    }
    qsort(ed, 3 * nt, sizeof(sdf_edge_t), edge_cmp);
    for (size_t i = 0; i + 1 < 3 * nt; i += 2) { /* watertight: edges come in pairs */
        nb[3 * (size_t)ed[i].tri + ed[i].edge] = ed[i + 1].tri;
        nb[3 * (size_t)ed[i + 1].tri + ed[i + 1].edge] = ed[i].tri;
    }
    return degenerate;
}

/* Appends the crossing (row, x) to *cr, doubling its room *cap when full; false when out of
 * memory (*cr is then unchanged). */
static bool sdf_cross_push(sdf_cross_t **cr, size_t *n, size_t *cap, uint32_t row, float x)
{
    if (*n == *cap) {
        sdf_cross_t *ncr = realloc(*cr, 2 * *cap * sizeof(sdf_cross_t));
        if (ncr == NULL)
            return false;
        *cr = ncr;
        *cap *= 2;
    }
    (*cr)[(*n)++] = (sdf_cross_t){row, x};
    return true;
}

argil_err_t mesh_sdf(const mesh_t *m, const int32_t dims[3], float spacing_m, vec3_t origin_m,
                     float band_m, float *sd, mesh_sdf_report_t *rep)
{
    mesh_sdf_report_t r = {0, 0, 0};
    if (rep != NULL)
        *rep = r;
    if (m == NULL || sd == NULL || m->n_tri == 0 || !(spacing_m > 0) || !isfinite(spacing_m) ||
        !(band_m > 0) || !isfinite(band_m) || !vec3_isfinite(origin_m) || m->n_tri > UINT32_MAX / 3)
        return ARGIL_ERR_ARG;
    uint64_t total;
    if (!mc_grid_samples(dims, &total))
        return ARGIL_ERR_ARG;
    for (size_t i = 0; i < 3 * m->n_vert; i++)
        if (!isfinite(m->pos[i]))
            return ARGIL_ERR_ARG;
    if (!mesh_watertight(m, &r.boundary_edges, &r.nonmanifold_edges)) {
        if (rep != NULL)
            *rep = r;
        return r.boundary_edges == SIZE_MAX ? ARGIL_ERR_NOMEM : ARGIL_ERR_STATE;
    }
    const size_t nt = m->n_tri, nv = m->n_vert, n = (size_t)total;
    dv_t *fn = malloc(nt * sizeof(dv_t)), *vn = calloc(nv, sizeof(dv_t));
    uint32_t *nb = malloc(3 * nt * sizeof(uint32_t)); /* neighbour face across each edge */
    sdf_edge_t *ed = malloc(3 * nt * sizeof(sdf_edge_t));
    uint32_t *near = malloc(n * sizeof(uint32_t));
    uint8_t *feat = malloc(n);
    float *d2 = malloc(n * sizeof(float));
    size_t n_cross = 0, cap_cross = 1024;
    sdf_cross_t *cr = malloc(cap_cross * sizeof(sdf_cross_t));
    argil_err_t e = ARGIL_OK;
    if (fn == NULL || vn == NULL || nb == NULL || ed == NULL || near == NULL || feat == NULL ||
        d2 == NULL || cr == NULL) {
        e = ARGIL_ERR_NOMEM;
        goto out;
    }
    r.degenerate += sdf_normals(m, fn, vn, nb, ed);
    for (size_t i = 0; i < n; i++) {
        d2[i] = band_m * band_m;
        near[i] = UINT32_MAX;
    }
    const double h = spacing_m, org[3] = {origin_m.x, origin_m.y, origin_m.z};
    /* rows are offset by a small irrational fraction of a spacing so no ray meets an edge */
    const double oy = 1e-4 * M_SQRT2 * h, oz = 1e-4 * M_PI * h;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = m->tri + 3 * t;
        const dv_t a = vtx(m, v[0]), b = vtx(m, v[1]), c = vtx(m, v[2]);
        const double lo[3] = {fmin(a.x, fmin(b.x, c.x)), fmin(a.y, fmin(b.y, c.y)), fmin(a.z, fmin(b.z, c.z))};
        const double hi[3] = {fmax(a.x, fmax(b.x, c.x)), fmax(a.y, fmax(b.y, c.y)), fmax(a.z, fmax(b.z, c.z))};
        int32_t i0[3], i1[3];
        for (int q = 0; q < 3; q++) {
            i0[q] = (int32_t)fmax(0.0, ceil((lo[q] - band_m - org[q]) / h));
            i1[q] = (int32_t)fmin((double)dims[q] - 1, floor((hi[q] + band_m - org[q]) / h));
        }
        for (int32_t z = i0[2]; z <= i1[2]; z++)
            for (int32_t y = i0[1]; y <= i1[1]; y++)
                for (int32_t x = i0[0]; x <= i1[0]; x++) {
                    const dv_t p = dv(org[0] + h * x, org[1] + h * y, org[2] + h * z);
                    int f;
                    const dv_t q = dsub(p, closest_on_tri(p, a, b, c, &f));
                    const double dd = ddot(q, q);
                    const size_t i = (size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                    if (dd < d2[i]) {
                        d2[i] = (float)dd;
                        near[i] = (uint32_t)t;
                        feat[i] = (uint8_t)f;
                    }
                }
        /* +x ray crossings of the rows whose (y, z) the triangle's projection covers */
        if (fn[t].x == 0.0)
            continue;
        const int32_t y0 = (int32_t)fmax(0.0, ceil((lo[1] - oy - org[1]) / h));
        const int32_t y1 = (int32_t)fmin((double)dims[1] - 1, floor((hi[1] - oy - org[1]) / h));
        const int32_t z0 = (int32_t)fmax(0.0, ceil((lo[2] - oz - org[2]) / h));
        const int32_t z1 = (int32_t)fmin((double)dims[2] - 1, floor((hi[2] - oz - org[2]) / h));
        for (int32_t z = z0; z <= z1; z++)
            for (int32_t y = y0; y <= y1; y++) {
                const double py = org[1] + h * y + oy, pz = org[2] + h * z + oz;
                /* 2-D edge functions in the yz plane: inside when all share one sign */
                const double e0 = (b.y - a.y) * (pz - a.z) - (b.z - a.z) * (py - a.y);
                const double e1 = (c.y - b.y) * (pz - b.z) - (c.z - b.z) * (py - b.y);
                const double e2 = (a.y - c.y) * (pz - c.z) - (a.z - c.z) * (py - c.y);
                if (!((e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0)))
                    continue;
                const dv_t nrm = fn[t];
                const double x = a.x - (nrm.y * (py - a.y) + nrm.z * (pz - a.z)) / nrm.x;
                const uint32_t row = (uint32_t)(y + dims[1] * z);
                if (!sdf_cross_push(&cr, &n_cross, &cap_cross, row, (float)x)) {
                    e = ARGIL_ERR_NOMEM;
                    goto out;
                }
            }
    }
    qsort(cr, n_cross, sizeof(sdf_cross_t), cross_cmp);
    size_t c0 = 0;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++) {
            const uint32_t row = (uint32_t)(y + dims[1] * z);
            while (c0 < n_cross && cr[c0].row < row)
                c0++;
            size_t c = c0;
            for (int32_t x = 0; x < dims[0]; x++) {
                const double px = org[0] + h * x;
                while (c < n_cross && cr[c].row == row && cr[c].x < px)
                    c++;
                const bool inside = ((c - c0) & 1) != 0;
                const size_t i = (size_t)x + (size_t)dims[0] * ((size_t)y + (size_t)dims[1] * (size_t)z);
                if (near[i] == UINT32_MAX) {
                    sd[i] = inside ? band_m : -band_m;
                    continue;
                }
                /* the closest feature's angle-weighted pseudo-normal decides the sign */
                const uint32_t t = near[i], *v = m->tri + 3 * (size_t)t;
                const int f = feat[i];
                dv_t pn;
                if (f == 0)
                    pn = fn[t];
                else if (f <= 3)
                    pn = dadd(fn[t], fn[nb[3 * (size_t)t + (size_t)(f - 1)]]);
                else
                    pn = vn[v[f - 4]];
                const dv_t p = dv(px, org[1] + h * y, org[2] + h * z);
                int f2;
                const dv_t q = dsub(p, closest_on_tri(p, vtx(m, v[0]), vtx(m, v[1]), vtx(m, v[2]), &f2));
                const float dist = sqrtf(d2[i]);
                sd[i] = ddot(q, pn) < 0.0 ? dist : -dist;
            }
        }
out:
    if (rep != NULL)
        *rep = r;
    free(fn);
    free(vn);
    free(nb);
    free(ed);
    free(near);
    free(feat);
    free(d2);
    free(cr);
    return e;
}
