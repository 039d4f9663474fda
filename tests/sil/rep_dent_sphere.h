/* A second representation behind the seam (host/model/rep.h), small enough to read at once: an
 * analytic sphere's signed distance plus a per-node offset that the board's impulses move (a
 * push lowers it: the sphere dents where it is pushed) and the host's carve lowers. No B-spline:
 * what the peer, the board and the mesher get from it they get through the seam. Its densities
 * are mirrored in a sample grid (host/model/grid.h) that the journal and .argil writers save. */
#ifndef ARGIL_REP_DENT_SPHERE_H
#define ARGIL_REP_DENT_SPHERE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/model/rep.h"

typedef struct {
    int32_t dims[3];                  /* lattice nodes per axis, sample 0 at origin_m */
    rep_lattice_t lat;
    vec3_t centre_m;
    float radius_m;
    float *offset_m;                  /* added to the signed distance (positive inside) */
    float *force;                     /* per node, taken by the next step */
    rep_box_t force_box;              /* nodes holding force (hi[0] <= lo[0]: none) */
    grid_t grid;                      /* every node's density (and rest = density), as
                                       * ds_density gives it: what is saved */
} dent_sphere_t;

/* True when n is a lattice node; its array index then goes to i. */
static inline bool ds_node(const dent_sphere_t *s, const int32_t n[3], size_t *i)
{
    for (int a = 0; a < 3; a++)
        if (n[a] < 0 || n[a] >= s->dims[a])
            return false;
    *i = ((size_t)n[2] * (size_t)s->dims[1] + (size_t)n[1]) * (size_t)s->dims[0] + (size_t)n[0];
    return true;
}

/* Model-space position of node n. */
static inline vec3_t ds_pos_m(const dent_sphere_t *s, const int32_t n[3])
{
    return vec3(s->lat.origin_m.x + (float)n[0] * s->lat.spacing_m,
                s->lat.origin_m.y + (float)n[1] * s->lat.spacing_m,
                s->lat.origin_m.z + (float)n[2] * s->lat.spacing_m);
}

/* Signed distance (positive inside) of node n: the sphere's, plus the node's offset. */
static inline float ds_sd_m(const dent_sphere_t *s, const int32_t n[3])
{
    size_t i;
    const float sd = s->radius_m - vec3_norm(vec3_sub(ds_pos_m(s, n), s->centre_m));
    return ds_node(s, n, &i) ? sd + s->offset_m[i] : sd;
}

/* The density profile of node n's signed distance; 0 beyond the lattice. */
static inline float ds_density(const dent_sphere_t *s, const int32_t n[3])
{
    size_t i;
    return ds_node(s, n, &i) ? grid_profile(ds_sd_m(s, n), s->lat.band_m) : 0.0f;
}

/* Copies the density of every node in box into the sample grid (rest = density, as the files
 * read it back); grid_set's error (ARGIL_ERR_NOMEM) when the grid cannot store it. */
static argil_err_t ds_mirror(dent_sphere_t *s, const rep_box_t *box)
{
    int32_t n[3];
    argil_err_t e = ARGIL_OK;
    for (n[2] = box->lo[2]; n[2] < box->hi[2]; n[2]++)
        for (n[1] = box->lo[1]; n[1] < box->hi[1]; n[1]++)
            for (n[0] = box->lo[0]; n[0] < box->hi[0] && e == ARGIL_OK; n[0]++) {
                const float d = ds_density(s, n);
                e = grid_set(&s->grid, GRID_DENSITY, n[0], n[1], n[2], d);
                if (e == ARGIL_OK)
                    e = grid_set(&s->grid, GRID_REST, n[0], n[1], n[2], d);
            }
    return e;
}

/* The sphere's lattice and material. */
static void ds_lattice(const void *st, rep_lattice_t *out)
{
    *out = ((const dent_sphere_t *)st)->lat;
}

/* The corner of the dims window centred nearest centre_m. */
static void ds_window_corner(const void *st, vec3_t centre_m, const int32_t dims[3],
                             int32_t corner[3])
{
    const dent_sphere_t *s = st;
    const float c[3] = {centre_m.x - s->lat.origin_m.x, centre_m.y - s->lat.origin_m.y,
                        centre_m.z - s->lat.origin_m.z};
    for (int a = 0; a < 3; a++)
        corner[a] = isfinite(c[a]) ? (int32_t)lroundf(c[a] / s->lat.spacing_m -
                                                       0.5f * (float)(dims[a] - 1))
                                   : 0;
}

/* Every node's density; the material is uniform, so no stiffness channel. */
static bool ds_window_samples(const void *st, const int32_t corner[3], const int32_t dims[3],
                              float *density, float *stiffness_n_per_m)
{
    (void)stiffness_n_per_m;
    size_t k = 0;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++)
            for (int32_t x = 0; x < dims[0]; x++) {
                const int32_t n[3] = {corner[0] + x, corner[1] + y, corner[2] + z};
                density[k++] = ds_density(st, n);
            }
    return false;
}

/* b grows to hold node n (b with hi[0] <= lo[0] counts as none). */
static void ds_grow(rep_box_t *b, const int32_t n[3])
{
    const bool none = b->hi[0] <= b->lo[0];
    for (int a = 0; a < 3; a++) {
        if (none || n[a] < b->lo[a]) b->lo[a] = n[a];
        if (none || n[a] + 1 > b->hi[a]) b->hi[a] = n[a] + 1;
    }
}

/* Adds the force to the node, for the next step. */
static argil_err_t ds_add_node_force(void *st, const int32_t node[3], float force_per_s)
{
    dent_sphere_t *s = st;
    size_t i;
    if (!isfinite(force_per_s))
        return ARGIL_ERR_NONFINITE;
    if (!ds_node(s, node, &i))
        return ARGIL_ERR_ARG;
    s->force[i] += force_per_s;
    ds_grow(&s->force_box, node);
    return ARGIL_OK;
}

/* The density change a free node would make under the force over dt (d'' = f / m), as metres
 * of its signed distance (2 band per unit of density across the ramp). Forces outside region
 * are dropped. */
static argil_err_t ds_step(void *st, const rep_box_t *region, float dt_s, rep_change_t *changed)
{
    dent_sphere_t *s = st;
    memset(changed, 0, sizeof(*changed));
    const float m_per_force = 2.0f * s->lat.band_m * dt_s * dt_s / s->lat.material.node_mass;
    const rep_box_t f = s->force_box;
    memset(&s->force_box, 0, sizeof(s->force_box));
    int32_t n[3];
    for (n[2] = f.lo[2]; n[2] < f.hi[2]; n[2]++)
        for (n[1] = f.lo[1]; n[1] < f.hi[1]; n[1]++)
            for (n[0] = f.lo[0]; n[0] < f.hi[0]; n[0]++) {
                size_t i;
                (void)ds_node(s, n, &i);
                if (s->force[i] == 0.0f)
                    continue;
                bool inside = region != NULL;
                for (int a = 0; a < 3 && inside; a++)
                    inside = n[a] >= region->lo[a] && n[a] < region->hi[a];
                if (inside) {
                    s->offset_m[i] += m_per_force * s->force[i];
                    ds_grow(&changed->box, n);
                    changed->felt = true;
                }
                s->force[i] = 0.0f;
            }
    return ds_mirror(s, &changed->box);
}

/* Only the default carve. */
static bool ds_tool_supported(const void *st, const host_tool_t *tool)
{
    (void)st;
    return host_tool_is_default(tool);
}

/* The default host tool, Ferley's eraser: the signed distance becomes at most the distance to
 * the carving sphere at the stylus. */
static argil_err_t ds_apply_tool(void *st, const host_tool_t *tool, float radius_m, vec3_t axis,
                                 const vec3_t *pts_m, size_t n_pts, float dt_s,
                                 rep_change_t *changed)
{
    dent_sphere_t *s = st;
    (void)axis;
    (void)dt_s;
    memset(changed, 0, sizeof(*changed));
    if (n_pts == 0 || !host_tool_is_default(tool))
        return ARGIL_ERR_ARG;
    const vec3_t at = pts_m[n_pts - 1];
    int32_t n[3];
    for (n[2] = 0; n[2] < s->dims[2]; n[2]++)
        for (n[1] = 0; n[1] < s->dims[1]; n[1]++)
            for (n[0] = 0; n[0] < s->dims[0]; n[0]++) {
                size_t i;
                (void)ds_node(s, n, &i);
                const float cut = vec3_norm(vec3_sub(ds_pos_m(s, n), at)) - radius_m;
                const float sd = ds_sd_m(s, n);
                if (cut < sd && cut < s->lat.band_m) {
                    s->offset_m[i] += cut - sd;
                    ds_grow(&changed->box, n);
                    changed->felt = true;
                }
            }
    return ds_mirror(s, &changed->box);
}

/* Its material is uniform. */
static argil_err_t ds_paint(void *st, rep_material_t ch, vec3_t centre_m, float radius_m,
                            float scale, rep_change_t *changed)
{
    (void)st, (void)ch, (void)centre_m, (void)radius_m, (void)scale;
    memset(changed, 0, sizeof(*changed));
    return ARGIL_ERR_STATE;
}

/* Uniform: 1 everywhere. */
static float ds_material_at(const void *st, rep_material_t ch, vec3_t x_m)
{
    (void)st, (void)ch, (void)x_m;
    return 1.0f;
}

/* Its nodes are its state: nothing finer to make. */
static argil_err_t ds_refine(void *st, float *max_change, rep_change_t *changed)
{
    (void)st;
    if (max_change)
        *max_change = 0.0f;
    memset(changed, 0, sizeof(*changed));
    return ARGIL_ERR_STATE;
}

/* Its nodes are its state. */
static int32_t ds_samples_per_dof(const void *st)
{
    (void)st;
    return 0;
}

/* It keeps no history. */
static argil_err_t ds_restored(void *st, const rep_box_t *box, rep_change_t *changed)
{
    (void)st, (void)box;
    memset(changed, 0, sizeof(*changed));
    return ARGIL_ERR_STATE;
}

/* Marching cubes of the lattice's densities. */
static argil_err_t ds_surface(const void *st, mesh_t *out)
{
    const dent_sphere_t *s = st;
    const size_t n_all = (size_t)s->dims[0] * (size_t)s->dims[1] * (size_t)s->dims[2];
    float *d = malloc(n_all * sizeof(float));
    if (!d)
        return ARGIL_ERR_NOMEM;
    const int32_t zero[3] = {0, 0, 0};
    (void)ds_window_samples(st, zero, s->dims, d, NULL);
    const argil_err_t e =
        mc_extract(d, s->dims, s->lat.spacing_m, s->lat.origin_m, s->lat.iso, out);
    free(d);
    return e;
}

/* The grid that mirrors its densities. */
static grid_t *ds_samples(void *st)
{
    return &((dent_sphere_t *)st)->grid;
}

/* Frees the offset and force arrays and the sample grid. */
static void ds_free(void *st)
{
    dent_sphere_t *s = st;
    free(s->offset_m);
    free(s->force);
    s->offset_m = s->force = NULL;
    grid_free(&s->grid);
}

static const rep_ops_t dent_sphere_ops = {
    .lattice = ds_lattice,
    .window_corner = ds_window_corner,
    .window_samples = ds_window_samples,
    .add_node_force = ds_add_node_force,
    .step = ds_step,
    .tool_supported = ds_tool_supported,
    .apply_tool = ds_apply_tool,
    .paint = ds_paint,
    .material_at = ds_material_at,
    .refine = ds_refine,
    .samples_per_dof = ds_samples_per_dof,
    .restored = ds_restored,
    .surface = ds_surface,
    .samples = ds_samples,
    .free = ds_free,
};

/* A sphere of radius_m at the lattice's centre: edge³ nodes spacing_m apart, the grid's default
 * band (4 spacings) and material, its densities in the sample grid. False when out of memory
 * (ds_free releases what was made). */
static inline bool dent_sphere_init(dent_sphere_t *s, int32_t edge, float spacing_m,
                                    float radius_m, rep_t *rep)
{
    memset(s, 0, sizeof(*s));
    for (int a = 0; a < 3; a++)
        s->dims[a] = edge;
    const float half = 0.5f * (float)(edge - 1) * spacing_m;
    s->lat.origin_m = vec3(-half, -half, -half);
    s->lat.spacing_m = spacing_m;
    s->lat.iso = 0.5f;
    s->lat.band_m = 4.0f * spacing_m;
    spring_material_default(&s->lat.material);
    s->centre_m = vec3(0, 0, 0);
    s->radius_m = radius_m;
    const size_t n = (size_t)edge * (size_t)edge * (size_t)edge;
    s->offset_m = calloc(n, sizeof(float));
    s->force = calloc(n, sizeof(float));
    *rep = (rep_t){.ops = &dent_sphere_ops, .st = s};
    if (!s->offset_m || !s->force ||
        grid_init(&s->grid, s->dims, spacing_m, s->lat.origin_m) != ARGIL_OK)
        return false;
    s->grid.iso = s->lat.iso;
    s->grid.band_m = s->lat.band_m;
    s->grid.material = s->lat.material;
    const rep_box_t all = {{0, 0, 0}, {edge, edge, edge}};
    return ds_mirror(s, &all) == ARGIL_OK;
}

#endif
