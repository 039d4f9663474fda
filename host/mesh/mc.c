/* Marching cubes over a whole dense block, slab by slab, with the derived case table
 * (host/mesh/mc_table.c), so neighbouring cells agree and the surface is closed and
 * edge-manifold. Samples beyond the block read 0, so the surface always closes. */
#include "host/mesh/mc.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "host/mesh/mc_table.h"

#define MC_NONE UINT32_MAX

/* Working state for one extraction over the padded lattice (sample index + 1 per axis). */
/* One padded layer of samples. */
typedef struct {
    float *val;            /* densities */
    uint8_t *ins;          /* 1 where that density > iso */
    uint32_t *xe, *ye;     /* vertex of the x / y edge starting at each sample */
} mc_layer_t;

typedef struct {
    const float *density;
    int32_t dims[3];
    int32_t pad[3];        /* dims + 2 */
    size_t layer;          /* pad[0] * pad[1] */
    float spacing_m;
    vec3_t origin_m;
    float iso;
    mc_layer_t lay[2];     /* the cell slab's lower and upper layers */
    uint32_t *ze;          /* vertex of the z edge between the two layers */
    mesh_t *out;
} mc_work_t;

/* Density of original sample (x,y,z), 0 beyond the block. */
static float mc_sample(const mc_work_t *w, int64_t x, int64_t y, int64_t z)
{
    if (x < 0 || y < 0 || z < 0 || x >= w->dims[0] || y >= w->dims[1] || z >= w->dims[2])
        return 0.0f;
    return w->density[(size_t)x + (size_t)w->dims[0] * ((size_t)y + (size_t)w->dims[1] * (size_t)z)];
}

/* Central-difference gradient (unscaled) at original sample s. */
static vec3_t mc_gradient(const mc_work_t *w, const int64_t s[3])
{
    return vec3(mc_sample(w, s[0] + 1, s[1], s[2]) - mc_sample(w, s[0] - 1, s[1], s[2]),
                mc_sample(w, s[0], s[1] + 1, s[2]) - mc_sample(w, s[0], s[1] - 1, s[2]),
                mc_sample(w, s[0], s[1], s[2] + 1) - mc_sample(w, s[0], s[1], s[2] - 1));
}

/* Fills padded layer Z (0 .. pad[2]-1) into slot k; false when a density is not finite. */
static bool mc_load_layer(mc_work_t *w, int32_t pz, int k)
{
    float *val = w->lay[k].val;
    uint8_t *ins = w->lay[k].ins;
    const int32_t z = pz - 1;
    for (size_t i = 0; i < w->layer; i++) {
        val[i] = 0.0f;
        ins[i] = 0;
    }
    if (z < 0 || z >= w->dims[2])
        return true;
    for (int32_t y = 0; y < w->dims[1]; y++) {
        const float *src = w->density + (size_t)w->dims[0] * ((size_t)y + (size_t)w->dims[1] * (size_t)z);
        const size_t row = (size_t)w->pad[0] * (size_t)(y + 1) + 1;
        for (int32_t x = 0; x < w->dims[0]; x++) {
            const float d = src[x];
            if (!isfinite(d))
                return false;
            val[row + (size_t)x] = d;
            ins[row + (size_t)x] = d > w->iso;
        }
    }
    return true;
}

void mc_edge_point(vec3_t origin_m, float spacing_m, float iso, const int32_t p[3], int a,
                   float d0, float d1, vec3_t g0, vec3_t g1, vec3_t *pos_m, vec3_t *normal)
{
    float t = (iso - d0) / (d1 - d0);
    if (!(t >= MC_T_MIN))
        t = MC_T_MIN; /* also NaN */
    if (t > 1.0f - MC_T_MIN)
        t = 1.0f - MC_T_MIN;
    const int64_t s0[3] = {p[0] - 1, p[1] - 1, p[2] - 1};
    float idx[3] = {(float)s0[0], (float)s0[1], (float)s0[2]};
    idx[a] += t;
    *pos_m = vec3(origin_m.x + spacing_m * idx[0], origin_m.y + spacing_m * idx[1],
                  origin_m.z + spacing_m * idx[2]);
    const vec3_t g = vec3_add(g0, vec3_scale(vec3_sub(g1, g0), t));
    const float len = vec3_norm(g);
    if (len > 1e-12f && isfinite(len)) {
        *normal = vec3_scale(g, -1.0f / len);
    } else {
        /* Flat field: fall back to the edge direction from the inside end to the outside end. */
        const float sgn = d0 > iso ? 1.0f : -1.0f;
        *normal = vec3(a == 0 ? sgn : 0.0f, a == 1 ? sgn : 0.0f, a == 2 ? sgn : 0.0f);
    }
}

/* Creates the vertex on the edge from padded sample p along axis a (densities d0 at p, d1 at
 * the other end, exactly one of them inside). */
static argil_err_t mc_make_vertex(mc_work_t *w, const int32_t p[3], int a, float d0, float d1,
                                  uint32_t *id)
{
    int64_t s0[3] = {p[0] - 1, p[1] - 1, p[2] - 1};
    int64_t s1[3] = {s0[0], s0[1], s0[2]};
    s1[a] += 1;
    vec3_t pos, n;
    mc_edge_point(w->origin_m, w->spacing_m, w->iso, p, a, d0, d1, mc_gradient(w, s0),
                  mc_gradient(w, s1), &pos, &n);
    return mesh_add_vertex(w->out, pos, n, id);
}

/* The vertex on cube edge e of the cell whose lower padded corner is (px, py) in the current
 * slab, created on first use and shared through the layer caches afterwards. */
static argil_err_t mc_edge_vertex(mc_work_t *w, int32_t px, int32_t py, int32_t pz, int e,
                                  uint32_t *id)
{
    const int a = e / 4, bu = e & 1, bv = (e >> 1) & 1;
    int32_t p[3] = {px, py, pz};
    p[(a + 1) % 3] += bu;
    p[(a + 2) % 3] += bv;
    const int lz = p[2] - pz; /* layer slot of the lower end */
    const size_t i = (size_t)p[0] + (size_t)w->pad[0] * (size_t)p[1];
    const size_t step = a == 0 ? 1 : (a == 1 ? (size_t)w->pad[0] : 0);
    uint32_t *slot = a == 0 ? &w->lay[lz].xe[i] : (a == 1 ? &w->lay[lz].ye[i] : &w->ze[i]);
    if (*slot != MC_NONE) {
        *id = *slot;
        return ARGIL_OK;
    }
    const float d0 = w->lay[lz].val[i];
    const float d1 = a == 2 ? w->lay[1].val[i] : w->lay[lz].val[i + step];
    argil_err_t err = mc_make_vertex(w, p, a, d0, d1, slot);
    *id = *slot;
    return err;
}

static void mc_fill_none(uint32_t *a, size_t n)
{
    for (size_t i = 0; i < n; i++)
        a[i] = MC_NONE;
}

/* Triangulates every cell of the slab between padded layers pz and pz + 1. */
static argil_err_t mc_slab(mc_work_t *w, const mc_table_t *tab, int32_t pz)
{
    const size_t px_n = (size_t)w->pad[0];
    const uint8_t *i0 = w->lay[0].ins, *i1 = w->lay[1].ins;
    for (int32_t py = 0; py + 1 < w->pad[1]; py++) {
        for (int32_t px = 0; px + 1 < w->pad[0]; px++) {
            const size_t i = (size_t)px + px_n * (size_t)py;
            const unsigned mask = (unsigned)i0[i] | (unsigned)i0[i + 1] << 1 |
                                  (unsigned)i0[i + px_n] << 2 | (unsigned)i0[i + px_n + 1] << 3 |
                                  (unsigned)i1[i] << 4 | (unsigned)i1[i + 1] << 5 |
                                  (unsigned)i1[i + px_n] << 6 | (unsigned)i1[i + px_n + 1] << 7;
            if (mask == 0 || mask == 255)
                continue;
            const mc_case_t *c = &tab->cases[mask];
            for (int k = 0; k < 3 * (int)c->n_tri; k += 3) {
                uint32_t v[3];
                for (int j = 0; j < 3; j++) {
                    argil_err_t err = mc_edge_vertex(w, px, py, pz, c->edge[k + j], &v[j]);
                    if (err != ARGIL_OK)
                        return err;
                }
                argil_err_t err = mesh_add_triangle(w->out, v[0], v[1], v[2]);
                if (err != ARGIL_OK)
                    return err;
            }
        }
    }
    return ARGIL_OK;
}

/* Runs the slabs bottom to top, rolling the layer buffers and edge caches. */
static argil_err_t mc_run(mc_work_t *w, const mc_table_t *tab)
{
    if (!mc_load_layer(w, 0, 0))
        return ARGIL_ERR_NONFINITE;
    mc_fill_none(w->lay[0].xe, w->layer);
    mc_fill_none(w->lay[0].ye, w->layer);
    for (int32_t pz = 0; pz + 1 < w->pad[2]; pz++) {
        if (!mc_load_layer(w, pz + 1, 1))
            return ARGIL_ERR_NONFINITE;
        mc_fill_none(w->lay[1].xe, w->layer);
        mc_fill_none(w->lay[1].ye, w->layer);
        mc_fill_none(w->ze, w->layer);
        argil_err_t err = mc_slab(w, tab, pz);
        if (err != ARGIL_OK)
            return err;
        /* The upper layer becomes the next slab's lower layer. */
        const mc_layer_t lower = w->lay[0];
        w->lay[0] = w->lay[1];
        w->lay[1] = lower;
    }
    return ARGIL_OK;
}

/* Gives layer l arrays of n samples; false when any could not be made (mc_layer_free frees
 * the rest). */
static bool mc_layer_alloc(mc_layer_t *l, size_t n)
{
    l->val = malloc(n * sizeof(float));
    l->ins = malloc(n);
    l->xe = malloc(n * sizeof(uint32_t));
    l->ye = malloc(n * sizeof(uint32_t));
    return l->val != NULL && l->ins != NULL && l->xe != NULL && l->ye != NULL;
}

/* Frees layer l's arrays. */
static void mc_layer_free(mc_layer_t *l)
{
    free(l->val);
    free(l->ins);
    free(l->xe);
    free(l->ye);
}

argil_err_t mc_extract(const float *density, const int32_t dims[3], float spacing_m,
                       vec3_t origin_m, float iso, mesh_t *out)
{
    if (out == NULL)
        return ARGIL_ERR_ARG;
    mesh_clear(out);
    if (density == NULL || dims == NULL)
        return ARGIL_ERR_ARG;
    int64_t n = 1;
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 1 || dims[a] > INT32_MAX - 2)
            return ARGIL_ERR_ARG;
        n *= dims[a];
        if (n > ((int64_t)1 << 31))
            return ARGIL_ERR_ARG;
    }
    if (!isfinite(spacing_m) || !(spacing_m > 0.0f) || !isfinite(iso) || !vec3_isfinite(origin_m))
        return ARGIL_ERR_ARG;

    mc_table_t *tab = malloc(sizeof(*tab));
    mc_work_t w = {0};
    w.density = density;
    for (int a = 0; a < 3; a++) {
        w.dims[a] = dims[a];
        w.pad[a] = dims[a] + 2;
    }
    w.layer = (size_t)w.pad[0] * (size_t)w.pad[1];
    w.spacing_m = spacing_m;
    w.origin_m = origin_m;
    w.iso = iso;
    w.out = out;
    const bool lay0 = mc_layer_alloc(&w.lay[0], w.layer), lay1 = mc_layer_alloc(&w.lay[1], w.layer);
    w.ze = malloc(w.layer * sizeof(uint32_t));

    argil_err_t err = ARGIL_ERR_NOMEM;
    if (tab != NULL && lay0 && lay1 && w.ze != NULL) {
        mc_table_build(tab);
        err = mc_run(&w, tab);
    }
    for (int k = 0; k < 2; k++)
        mc_layer_free(&w.lay[k]);
    free(w.ze);
    free(tab);
    if (err != ARGIL_OK)
        mesh_clear(out);
    return err;
}

bool mc_grid_samples(const int32_t dims[3], uint64_t *samples)
{
    uint64_t total = 1;
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 1)
            return false;
        total *= (uint64_t)dims[a];
        if (total > MC_GRID_SAMPLES_MAX)
            return false;
    }
    *samples = total;
    return true;
}
