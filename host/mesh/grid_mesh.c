/* Meshes the host grid over the box its samples occupy: a dense copy of that box, or the live
 * block mesher reading the grid in place. */
#include "host/mesh/grid_mesh.h"

#include <stdlib.h>

#include "host/mesh/mc.h"

void grid_mesh_read(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out)
{
    const grid_mesh_view_t *v = ctx;
    grid_read_box(v->g, GRID_DENSITY, lo, n, out);
}

void grid_mesh_read_rgb(const void *ctx, const int32_t lo[3], const int32_t n[3], uint8_t *out)
{
    const grid_mesh_view_t *v = ctx;
    grid_rgb_read_box(v->g, lo, n, out);
}

/* An mc_outside_fn over a view: the grid's blocks answer without reading samples. */
static bool grid_mesh_outside(const void *ctx, const int32_t lo[3], const int32_t n[3], float iso)
{
    const grid_mesh_view_t *v = ctx;
    const int32_t hi[3] = {lo[0] + n[0], lo[1] + n[1], lo[2] + n[2]};
    return grid_box_density_at_most(v->g, lo, hi, iso);
}

argil_err_t grid_mesh_blocks_init(mc_blocks_t *b, grid_mesh_view_t *v, const grid_t *g,
                                  float iso)
{
    const int32_t zero[3] = {0, 0, 0};
    v->g = g;
    grid_bounds(g, v->lo, v->hi);
    const argil_err_t e =
        mc_blocks_init_box(b, v->lo, v->hi, g->spacing_m, grid_box_origin(g, zero), iso);
    if (e == ARGIL_OK)
        b->outside = grid_mesh_outside; /* blocks of empty space are skipped unread */
    return e;
}

bool grid_mesh_view_stale(const grid_mesh_view_t *v, const grid_t *g)
{
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        if (lo[a] < v->lo[a] || hi[a] > v->hi[a])
            return true;
    return false;
}

argil_err_t grid_mesh_grow(mc_blocks_t *b, grid_mesh_view_t *v, const grid_t *g)
{
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    const argil_err_t e = mc_blocks_grow(b, lo, hi);
    if (e == ARGIL_OK)
        for (int a = 0; a < 3; a++) {
            v->lo[a] = b->lo[a];
            v->hi[a] = b->hi[a];
        }
    return e;
}

void grid_mesh_mark(mc_blocks_t *b, const grid_mesh_view_t *v, const int32_t lo[3],
                    const int32_t hi[3])
{
    (void)v; /* the mesher's indices are the grid's */
    mc_blocks_mark(b, lo, hi);
}

argil_err_t grid_mesh_extract(const grid_t *g, float iso, mesh_t *out)
{
    int32_t lo[3], n[3];
    float *d = grid_dense_copy(g, GRID_DENSITY, lo, n);
    if (d == NULL) {
        mesh_clear(out);
        return ARGIL_ERR_NOMEM;
    }
    const argil_err_t e = mc_extract(d, n, g->spacing_m, grid_box_origin(g, lo), iso, out);
    free(d);
    return e;
}

argil_err_t grid_mesh_region(const grid_t *g, const uint8_t *rgb, float iso, mesh_t *out)
{
    int32_t lo[3], n[3];
    float *d = grid_dense_copy(g, GRID_DENSITY, lo, n);
    if (d == NULL) {
        mesh_clear(out);
        return ARGIL_ERR_NOMEM;
    }
    const argil_err_t e = mc_extract_region(d, rgb, n, g->spacing_m, grid_box_origin(g, lo), iso,
                                            NULL, NULL, out);
    free(d);
    return e;
}
