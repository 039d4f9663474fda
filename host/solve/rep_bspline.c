/* The B-spline density representation: the grid and, when implicit, its B-spline model. */
#include "host/solve/rep_bspline.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/grid_mesh.h"

static const rep_box_t box_none = {{1, 1, 1}, {0, 0, 0}};

/* True when b holds a sample (the boxes the grid and the solve give: hi > lo on x). */
static bool box_some(const rep_box_t *b)
{
    return b->hi[0] > b->lo[0];
}

/* acc becomes the bounding box of acc and b (acc with lo > hi on an axis counts as none). */
static void box_grow(rep_box_t *acc, const int32_t lo[3], const int32_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        if (acc->lo[a] > acc->hi[a]) {
            memcpy(acc->lo, lo, sizeof(acc->lo));
            memcpy(acc->hi, hi, sizeof(acc->hi));
            return;
        }
    }
    for (int a = 0; a < 3; a++) {
        if (lo[a] < acc->lo[a]) acc->lo[a] = lo[a];
        if (hi[a] > acc->hi[a]) acc->hi[a] = hi[a];
    }
}

/* c says nothing changed. */
static void change_none(rep_change_t *c)
{
    c->box = box_none;
    c->felt = false;
}

/* c is box [lo, hi), felt by the board when felt and not empty. */
static void change_set(rep_change_t *c, const int32_t lo[3], const int32_t hi[3], bool felt)
{
    memcpy(c->box.lo, lo, sizeof(c->box.lo));
    memcpy(c->box.hi, hi, sizeof(c->box.hi));
    c->felt = felt && box_some(&c->box);
}

argil_err_t rep_bspline_init(rep_bspline_t *b, grid_t *g, bool implicit, int32_t knot_ratio)
{
    if (knot_ratio != 1 && knot_ratio != 2 && knot_ratio != 4)
        return ARGIL_ERR_ARG;
    memset(b, 0, sizeof(*b));
    b->grid = g;
    b->force = box_none;
    if (!implicit)
        return ARGIL_OK;
    b->gs = calloc(1, sizeof(*b->gs));
    if (!b->gs)
        return ARGIL_ERR_NOMEM;
    argil_err_t e = gsolve_init_ratio(b->gs, g, knot_ratio);
    /* A loaded model's painted material (.argil MTLS, journal recovery) and colour (COLR). */
    if (e == ARGIL_OK) {
        e = gsolve_material_from_grid(b->gs, g);
        if (e == ARGIL_OK)
            e = gsolve_colour_from_grid(b->gs, g);
        if (e != ARGIL_OK)
            gsolve_free(b->gs);
    }
    if (e != ARGIL_OK) {
        free(b->gs);
        b->gs = NULL;
        return e;
    }
    b->gs_mat = g->material;
    return ARGIL_OK;
}

/* Releases the B-spline model (the grid stays the caller's). */
static void bs_free(void *st)
{
    rep_bspline_t *b = st;
    if (b->gs) {
        gsolve_free(b->gs);
        free(b->gs);
        b->gs = NULL;
    }
}

/* The grid's lattice and material. */
static void bs_lattice(const void *st, rep_lattice_t *out)
{
    const grid_t *g = ((const rep_bspline_t *)st)->grid;
    out->origin_m = g->origin_m;
    out->spacing_m = g->spacing_m;
    out->iso = g->iso;
    out->band_m = g->band_m;
    out->material = g->material;
}

/* grid_window_corner on the grid. */
static void bs_window_corner(const void *st, vec3_t centre_m, const int32_t dims[3],
                             int32_t corner[3])
{
    grid_window_corner(((const rep_bspline_t *)st)->grid, centre_m, dims, corner);
}

/* Painted stiffness is felt: a window any node of which has a painted scale carries each node's
 * spring stiffness (base × scale); painted mass acts in the global solve only (the wire has one
 * node_mass per window: docs/model.md "In the session"). */
static bool bs_window_samples(const void *st, const int32_t corner[3], const int32_t dims[3],
                              float *density, float *stiffness_n_per_m)
{
    const rep_bspline_t *b = st;
    grid_extract(b->grid, corner, dims, density);
    if (!b->gs ||
        !gsolve_material_box(b->gs, GSOLVE_MAT_STIFFNESS, corner, dims, stiffness_n_per_m))
        return false;
    const int32_t n = dims[0] * dims[1] * dims[2];
    for (int32_t i = 0; i < n; i++)
        stiffness_n_per_m[i] *= b->grid->material.stiffness;
    return true;
}

/* grid_add_force, remembering the box that holds force. */
static argil_err_t bs_add_node_force(void *st, const int32_t node[3], float force_per_s)
{
    rep_bspline_t *b = st;
    if (!isfinite(force_per_s))
        return ARGIL_ERR_NONFINITE;
    if (!grid_add_force(b->grid, node[0], node[1], node[2], force_per_s))
        return ARGIL_ERR_ARG;
    const int32_t hi[3] = {node[0] + 1, node[1] + 1, node[2] + 1};
    box_grow(&b->force, node, hi);
    return ARGIL_OK;
}

/* Drops the external forces the implicit step did not take (outside its window). */
static void drop_forces(rep_bspline_t *b)
{
    if (!box_some(&b->force))
        return;
    const rep_box_t f = b->force;
    for (int32_t z = f.lo[2]; z < f.hi[2]; z++)
        for (int32_t y = f.lo[1]; y < f.hi[1]; y++)
            for (int32_t x = f.lo[0]; x < f.hi[0]; x++)
                if (grid_get(b->grid, GRID_FORCE, x, y, z) != 0.0f)
                    (void)grid_set(b->grid, GRID_FORCE, x, y, z, 0.0f);
    b->force = box_none;
}

/* The model takes the grid's material when the session changed it. */
static void sync_material(rep_bspline_t *b)
{
    if (memcmp(&b->gs_mat, &b->grid->material, sizeof(b->gs_mat)) != 0) {
        gsolve_set_material(b->gs, &b->grid->material);
        b->gs_mat = b->grid->material;
    }
}

/* Keeps box simulated until it comes to rest; with no room, merges the two oldest boxes. */
static void remember_settling(rep_bspline_t *b, const rep_box_t *box)
{
    if (b->settling_count == REP_SPRINGS_SETTLING_MAX) {
        rep_box_t *a = &b->settling[0];
        box_grow(a, b->settling[1].lo, b->settling[1].hi);
        b->settling[1] = b->settling[--b->settling_count];
    }
    b->settling[b->settling_count++] = *box;
}

/* The springs' step: the region, then the regions earlier windows left while they still move
 * (elastic clay springing back), each until it rests. */
static void step_springs(rep_bspline_t *b, const rep_box_t *region, float dt_s,
                         rep_change_t *changed)
{
    if (b->have_region && memcmp(region, &b->region, sizeof(*region)) != 0)
        remember_settling(b, &b->region);
    b->region = *region;
    b->have_region = true;
    if (grid_springs_step(b->grid, region->lo, region->hi, dt_s) > 0.0f) {
        box_grow(&changed->box, region->lo, region->hi);
        changed->felt = true;
    }
    for (uint32_t k = 0; k < b->settling_count;) {
        const rep_box_t *s = &b->settling[k];
        const float acc = grid_springs_step(b->grid, s->lo, s->hi, dt_s);
        if (acc > 0.0f)
            box_grow(&changed->box, s->lo, s->hi);
        if (acc < REP_SPRINGS_REST_ACCEL)
            b->settling[k] = b->settling[--b->settling_count];
        else
            k++;
    }
}

/* The springs' step or the implicit step (forces outside its window dropped). */
static argil_err_t bs_step(void *st, const rep_box_t *region, float dt_s, rep_change_t *changed)
{
    rep_bspline_t *b = st;
    change_none(changed);
    if (!b->gs) {
        if (region)
            step_springs(b, region, dt_s, changed);
        return ARGIL_OK;
    }
    sync_material(b);
    argil_err_t e = ARGIL_OK;
    if (region) {
        int32_t lo[3], hi[3];
        float change = 0.0f;
        e = gsolve_step(b->gs, b->grid, region->lo, region->hi, dt_s, lo, hi, &change);
        if (e == ARGIL_OK)
            change_set(changed, lo, hi, true);
    }
    drop_forces(b);
    return e;
}

/* Any valid setting on the B-spline model; the default carve only on the springs. */
static bool bs_tool_supported(const void *st, const host_tool_t *tool)
{
    return host_tool_valid(tool) &&
           (((const rep_bspline_t *)st)->gs != NULL || host_tool_is_default(tool));
}

/* The springs carve a sphere at the stylus; the model applies the whole setting. */
static argil_err_t bs_apply_tool(void *st, const host_tool_t *tool, float radius_m, vec3_t axis,
                                 const vec3_t *pts_m, size_t n_pts, float dt_s,
                                 rep_change_t *changed)
{
    rep_bspline_t *b = st;
    change_none(changed);
    if (n_pts == 0 || !bs_tool_supported(st, tool))
        return ARGIL_ERR_ARG;
    int32_t lo[3], hi[3];
    if (!b->gs) {
        grid_carve_sphere(b->grid, pts_m[n_pts - 1], radius_m, lo, hi);
        change_set(changed, lo, hi, true);
        return ARGIL_OK;
    }
    sync_material(b);
    const argil_err_t e =
        gsolve_apply_tool(b->gs, b->grid, tool, radius_m, axis, pts_m, n_pts, dt_s, lo, hi);
    if (e == ARGIL_OK)
        /* A colour paint leaves the board's densities be. */
        change_set(changed, lo, hi, !host_action_paints(tool->action));
    return e;
}

/* The model's channel for the seam's. */
static gsolve_material_t gs_channel(rep_material_t ch)
{
    return ch == REP_MAT_MASS ? GSOLVE_MAT_MASS : GSOLVE_MAT_STIFFNESS;
}

/* The densities did not change, but the surface there is re-meshed to show the new material
 * (colour maps) and the grid's painted channels follow (what .argil files and the journal
 * keep): the painted ball's sample box, clipped to the grid, is the change. */
static argil_err_t bs_paint(void *st, rep_material_t ch, vec3_t centre_m, float radius_m,
                            float scale, rep_change_t *changed)
{
    rep_bspline_t *b = st;
    change_none(changed);
    if (!b->gs)
        return ARGIL_ERR_STATE;
    const argil_err_t e = gsolve_paint(b->gs, gs_channel(ch), centre_m, radius_m, scale);
    if (e != ARGIL_OK)
        return e;
    const grid_t *g = b->grid;
    int32_t lo[3], hi[3], b0[3], b1[3];
    grid_bounds(g, b0, b1);
    const float c[3] = {centre_m.x - g->origin_m.x, centre_m.y - g->origin_m.y,
                        centre_m.z - g->origin_m.z};
    for (int a = 0; a < 3; a++) {
        const float l = floorf((c[a] - radius_m) / g->spacing_m);
        const float h = ceilf((c[a] + radius_m) / g->spacing_m) + 1.0f;
        const float fl = (float)b0[a], fh = (float)b1[a];
        lo[a] = l < fl ? b0[a] : l > fh ? b1[a] : (int32_t)l;
        hi[a] = h < fl ? b0[a] : h > fh ? b1[a] : (int32_t)h;
    }
    if (!(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2]))
        return ARGIL_OK;
    const argil_err_t me = gsolve_material_to_grid(b->gs, b->grid, lo, hi);
    if (me != ARGIL_OK)
        return me;
    change_set(changed, lo, hi, true);
    return ARGIL_OK;
}

/* The model's painted scale; 1 on the springs. */
static float bs_material_at(const void *st, rep_material_t ch, vec3_t x_m)
{
    const rep_bspline_t *b = st;
    return b->gs ? gsolve_material_at(b->gs, gs_channel(ch), x_m) : 1.0f;
}

/* Knot insertion on the model (gsolve_refine); ARGIL_ERR_STATE on the springs. */
static argil_err_t bs_refine(void *st, float *max_change, rep_change_t *changed)
{
    rep_bspline_t *b = st;
    change_none(changed);
    float dd = 0.0f;
    argil_err_t e = ARGIL_ERR_STATE;
    if (b->gs) {
        int32_t lo[3], hi[3];
        e = gsolve_refine(b->gs, b->grid, &dd, lo, hi);
        if (e == ARGIL_OK)
            change_set(changed, lo, hi, true);
    }
    if (max_change)
        *max_change = dd;
    return e;
}

/* R, samples per knot span; 0 on the springs. */
static int32_t bs_samples_per_dof(const void *st)
{
    const rep_bspline_t *b = st;
    return b->gs ? gsolve_ratio(b->gs) : 0;
}

/* gsolve_restored; ARGIL_ERR_STATE on the springs (they keep no history). */
static argil_err_t bs_restored(void *st, const rep_box_t *box, rep_change_t *changed)
{
    rep_bspline_t *b = st;
    change_none(changed);
    if (!b->gs)
        return ARGIL_ERR_STATE;
    int32_t lo[3], hi[3];
    const argil_err_t e = gsolve_restored(b->gs, b->grid, box->lo, box->hi, lo, hi);
    if (e == ARGIL_OK)
        change_set(changed, lo, hi, true);
    return e;
}

/* Marching cubes of the whole grid at its iso level. */
static argil_err_t bs_surface(const void *st, mesh_t *out)
{
    const grid_t *g = ((const rep_bspline_t *)st)->grid;
    return grid_mesh_extract(g, g->iso, out);
}

/* The grid itself: it is what files, the journal and undo record. */
static grid_t *bs_samples(void *st)
{
    return ((rep_bspline_t *)st)->grid;
}

static const rep_ops_t bspline_ops = {
    .lattice = bs_lattice,
    .window_corner = bs_window_corner,
    .window_samples = bs_window_samples,
    .add_node_force = bs_add_node_force,
    .step = bs_step,
    .tool_supported = bs_tool_supported,
    .apply_tool = bs_apply_tool,
    .paint = bs_paint,
    .material_at = bs_material_at,
    .refine = bs_refine,
    .samples_per_dof = bs_samples_per_dof,
    .restored = bs_restored,
    .surface = bs_surface,
    .samples = bs_samples,
    .free = bs_free,
};

rep_t rep_bspline(rep_bspline_t *b)
{
    return (rep_t){.ops = &bspline_ops, .st = b};
}
