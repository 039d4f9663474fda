/* Test and bench helpers: scanned-solid shapes with through-holes and sharp edges, sampled as
 * point clouds (area-uniform, optional Gaussian noise, unit outward normals) with their exact
 * unsigned distance, to measure fitted surfaces against. A box with a square through-hole
 * (genus 1, sharp convex and concave edges) and a plate with two round holes (genus 2). */
#ifndef ARGIL_TEST_FIT_SHAPES_H
#define ARGIL_TEST_FIT_SHAPES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "host/fit/octree_fit.h"
#include "host/mesh/mc.h"
#include "host/mesh/mesh.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"

typedef enum { FS_HOLED_BOX = 0, FS_PLATE_2_HOLES = 1 } fs_shape_t;

/* Half extents of each shape's bounding box (centred on the origin) and its genus. */
static const float fs_half[2][3] = {{0.03f, 0.03f, 0.01f}, {0.04f, 0.025f, 0.006f}};
static const int fs_genus[2] = {1, 2};

#define FS_HOLE_HALF 0.01  /* holed box: the square hole's half width (through z) */
#define FS_HOLE_R 0.01     /* plate: the round holes' radius, centred at x = +-FS_HOLE_X */
#define FS_HOLE_X 0.02

/* Bounding-box diagonal: the "size" errors are quoted against. */
static inline double fs_diag(fs_shape_t s)
{
    const float *h = fs_half[s];
    return 2.0 * sqrt((double)h[0] * h[0] + (double)h[1] * h[1] + (double)h[2] * h[2]);
}

typedef struct {
    double lo[3], hi[3]; /* an axis-aligned rectangle: lo[a] == hi[a] on its normal axis a */
    int a, s;            /* outward normal s * e_a */
} fs_rect_t;

/* The holed box's 16 faces: top and bottom rings as 4 rectangles each, 4 outer, 4 hole walls. */
static inline int fs_box_rects(fs_rect_t r[16])
{
    const double H = 0.03, T = 0.01, K = FS_HOLE_HALF;
    const double ring[4][4] = {{-H, H, K, H}, {-H, H, -H, -K}, {-H, -K, -K, K}, {K, H, -K, K}};
    int n = 0;
    for (int s = -1; s <= 1; s += 2)
        for (int k = 0; k < 4; k++, n++)
            r[n] = (fs_rect_t){{ring[k][0], ring[k][2], s * T}, {ring[k][1], ring[k][3], s * T}, 2, s};
    for (int a = 0; a < 2; a++)
        for (int s = -1; s <= 1; s += 2) {
            fs_rect_t o = {{-H, -H, -T}, {H, H, T}, a, s}, w = {{-K, -K, -T}, {K, K, T}, a, -s};
            o.lo[a] = o.hi[a] = s * H;
            w.lo[a] = w.hi[a] = s * K; /* the hole wall at +K faces -e_a, into the hole */
            r[n++] = o;
            r[n++] = w;
        }
    return n;
}

static inline double fs_rect_area(const fs_rect_t *r)
{
    double A = 1.0;
    for (int a = 0; a < 3; a++)
        if (a != r->a)
            A *= r->hi[a] - r->lo[a];
    return A;
}

static inline double fs_rect_dist(const fs_rect_t *r, const double p[3])
{
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double e = p[a] < r->lo[a] ? r->lo[a] - p[a] : (p[a] > r->hi[a] ? p[a] - r->hi[a] : 0.0);
        d2 += e * e;
    }
    return sqrt(d2);
}

/* Exact distance from p to the shape's surface (m). */
static inline double fs_dist(fs_shape_t s, const double p[3])
{
    double best = INFINITY;
    if (s == FS_HOLED_BOX) {
        fs_rect_t r[16];
        const int n = fs_box_rects(r);
        for (int k = 0; k < n; k++)
            best = fmin(best, fs_rect_dist(&r[k], p));
        return best;
    }
    const float *h = fs_half[s];
    for (int a = 0; a < 2; a++) /* the four side walls */
        for (int sg = -1; sg <= 1; sg += 2) {
            fs_rect_t w = {{-h[0], -h[1], -h[2]}, {h[0], h[1], h[2]}, a, sg};
            w.lo[a] = w.hi[a] = sg * h[a];
            best = fmin(best, fs_rect_dist(&w, p));
        }
    /* top and bottom: the rectangle minus the discs; in-plane distance to that region */
    const double ex = fmax(fabs(p[0]) - h[0], 0.0), ey = fmax(fabs(p[1]) - h[1], 0.0);
    double dq = sqrt(ex * ex + ey * ey);
    for (int c = -1; c <= 1; c += 2) {
        const double rho = hypot(p[0] - c * FS_HOLE_X, p[1]);
        if (rho < FS_HOLE_R)
            dq = FS_HOLE_R - rho;
        const double dz = fmax(fabs(p[2]) - h[2], 0.0); /* the hole's wall */
        best = fmin(best, hypot(rho - FS_HOLE_R, dz));
    }
    best = fmin(best, hypot(dq, fabs(p[2]) - h[2])); /* the nearer of the two */
    return best;
}

/* fs_dist for a measuring callback: ctx points to the fs_shape_t. */
static inline double fs_dist_cb(const void *ctx, const double p[3])
{
    return fs_dist(*(const fs_shape_t *)ctx, p);
}

/* A deterministic uniform deviate in (0, 1) and a normal deviate (Box-Muller). */
static inline double fs_urand(uint64_t *st)
{
    *st = *st * 6364136223846793005ull + 1442695040888963407ull;
    return ((double)(*st >> 11) + 0.5) / 9007199254740992.0;
}

static inline double fs_nrand(uint64_t *st)
{
    const double u = fs_urand(st), v = fs_urand(st);
    return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

/* Appends n surface samples of shape s (area-uniform) to m, each coordinate displaced by a
 * Gaussian of sigma noise_m; normals are the true outward ones at the undisplaced point. */
static inline argil_err_t fs_sample(fs_shape_t s, uint32_t n, double noise_m, uint64_t seed, mesh_t *m)
{
    uint64_t st = seed;
    const float *h = fs_half[s];
    fs_rect_t r[16];
    int nr;
    double cyl = 0.0; /* plate: total area of the two hole walls */
    if (s == FS_HOLED_BOX) {
        nr = fs_box_rects(r);
    } else {
        nr = 0;
        for (int a = 0; a < 2; a++)
            for (int sg = -1; sg <= 1; sg += 2) {
                fs_rect_t w = {{-h[0], -h[1], -h[2]}, {h[0], h[1], h[2]}, a, sg};
                w.lo[a] = w.hi[a] = sg * h[a];
                r[nr++] = w;
            }
        for (int sg = -1; sg <= 1; sg += 2) /* top and bottom, holes rejected below */
            r[nr++] = (fs_rect_t){{-h[0], -h[1], sg * h[2]}, {h[0], h[1], sg * h[2]}, 2, sg};
        cyl = 2.0 * (2.0 * M_PI * FS_HOLE_R) * (2.0 * h[2]);
    }
    double total = cyl;
    for (int k = 0; k < nr; k++)
        total += fs_rect_area(&r[k]);
    for (uint32_t i = 0; i < n;) {
        double p[3], nn[3] = {0, 0, 0}, u = fs_urand(&st) * total;
        int k = 0;
        while (k < nr && u >= fs_rect_area(&r[k]))
            u -= fs_rect_area(&r[k++]);
        if (k < nr) {
            for (int a = 0; a < 3; a++)
                p[a] = r[k].lo[a] + fs_urand(&st) * (r[k].hi[a] - r[k].lo[a]);
            nn[r[k].a] = r[k].s;
            if (s == FS_PLATE_2_HOLES && r[k].a == 2 &&
                (hypot(p[0] - FS_HOLE_X, p[1]) < FS_HOLE_R || hypot(p[0] + FS_HOLE_X, p[1]) < FS_HOLE_R))
                continue; /* inside a hole: no material there */
        } else {
            const double c = fs_urand(&st) < 0.5 ? -FS_HOLE_X : FS_HOLE_X, t = 2.0 * M_PI * fs_urand(&st);
            p[0] = c + FS_HOLE_R * cos(t);
            p[1] = FS_HOLE_R * sin(t);
            p[2] = -h[2] + 2.0 * h[2] * fs_urand(&st);
            nn[0] = -cos(t); /* into the hole */
            nn[1] = -sin(t);
        }
        const vec3_t q = vec3((float)(p[0] + noise_m * fs_nrand(&st)), (float)(p[1] + noise_m * fs_nrand(&st)),
                              (float)(p[2] + noise_m * fs_nrand(&st)));
        const argil_err_t e = mesh_add_vertex(m, q, vec3((float)nn[0], (float)nn[1], (float)nn[2]), NULL);
        if (e != ARGIL_OK)
            return e;
        i++;
    }
    return ARGIL_OK;
}

typedef struct {
    double mean, max;    /* vertex distances to the true surface, fraction of the size */
    size_t verts;
    uint32_t components; /* connected components of the mesh */
    long euler;          /* V - E + F (closed, edge-manifold: V - F / 2); 2 - 2 genus if connected */
} fs_measure_t;

static inline uint32_t fs_uf_find(uint32_t *up, uint32_t i)
{
    while (up[i] != i)
        i = up[i] = up[up[i]];
    return i;
}

/* Connected components of a triangle mesh (vertices shared by index). */
static inline uint32_t fs_components(const mesh_t *me)
{
    uint32_t *up = malloc((me->n_vert + 1) * sizeof(uint32_t)), n = 0;
    if (up == NULL)
        return 0;
    for (uint32_t v = 0; v < me->n_vert; v++)
        up[v] = v;
    for (size_t t = 0; t < me->n_tri; t++)
        for (int k = 1; k < 3; k++) {
            const uint32_t a = fs_uf_find(up, me->tri[3 * t]), b = fs_uf_find(up, me->tri[3 * t + (size_t)k]);
            if (a != b)
                up[a] = b;
        }
    for (uint32_t v = 0; v < me->n_vert; v++)
        n += fs_uf_find(up, v) == v;
    free(up);
    return n;
}

/* Samples m's field on a grid of spacing size/res over the box of half extents half + 15 %
 * (centred on the origin), meshes its zero set (density profile, iso 0.5, marching cubes) and
 * measures every vertex against dist (the true unsigned distance): what a person sees. */
static inline argil_err_t fs_measure(const octfit_model_t *m, double (*dist)(const void *, const double[3]),
                                     const void *ctx, const float half[3], float size, int res,
                                     fs_measure_t *r)
{
    const float h = size / (float)res;
    int32_t dims[3];
    for (int a = 0; a < 3; a++)
        dims[a] = (int32_t)(2.3f * half[a] / h) + 1;
    grid_t g;
    argil_err_t e = grid_init(&g, dims, h, vec3(-1.15f * half[0], -1.15f * half[1], -1.15f * half[2]));
    if (e != ARGIL_OK)
        return e;
    size_t i = 0;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++)
            for (int32_t x = 0; x < dims[0]; x++, i++) {
                const vec3_t p = vec3(g.origin_m.x + h * (float)x, g.origin_m.y + h * (float)y,
                                      g.origin_m.z + h * (float)z);
                gv_set(&g, GRID_DENSITY, i, grid_profile(octfit_eval(m, p), 2.0f * h));
            }
    mesh_t me;
    mesh_init(&me);
    e = mc_extract(gv_dense(&g), g.dims, h, g.origin_m, 0.5f, &me);
    *r = (fs_measure_t){0, 0, me.n_vert, fs_components(&me), (long)me.n_vert - (long)me.n_tri / 2};
    for (size_t v = 0; e == ARGIL_OK && v < me.n_vert; v++) {
        const double p[3] = {me.pos[3 * v], me.pos[3 * v + 1], me.pos[3 * v + 2]};
        const double d = fabs(dist(ctx, p));
        if (getenv("OF_DEBUG") && d > 0.01 * size)
            printf("    far vertex %g %g %g: %g\n", p[0], p[1], p[2], d);
        r->mean += d;
        r->max = fmax(r->max, d);
    }
    r->mean /= (double)(me.n_vert > 0 ? me.n_vert : 1) * size;
    r->max /= size;
    mesh_free(&me);
    grid_free(&g);
    return e;
}

#endif
