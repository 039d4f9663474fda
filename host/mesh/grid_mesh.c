/* Meshes the host grid over the box its samples occupy (a dense copy of that box). */
#include "host/mesh/grid_mesh.h"

#include <stdlib.h>

#include "host/mesh/mc.h"

void grid_mesh_read(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out)
{
    const grid_mesh_view_t *v = ctx;
    const int32_t at[3] = {v->lo[0] + lo[0], v->lo[1] + lo[1], v->lo[2] + lo[2]};
    grid_read_box(v->g, GRID_DENSITY, at, n, out);
}

void grid_mesh_read_rgb(const void *ctx, const int32_t lo[3], const int32_t n[3], uint8_t *out)
{
    const grid_mesh_view_t *v = ctx;
    const int32_t at[3] = {v->lo[0] + lo[0], v->lo[1] + lo[1], v->lo[2] + lo[2]};
    grid_rgb_read_box(v->g, at, n, out);
}

argil_err_t grid_mesh_blocks_init(mc_blocks_t *b, grid_mesh_view_t *v, const grid_t *g,
                                  float iso)
{
    int32_t n[3];
    v->g = g;
    grid_bounds(g, v->lo, v->hi);
    for (int a = 0; a < 3; a++)
        n[a] = v->hi[a] - v->lo[a];
    return mc_blocks_init(b, n, g->spacing_m, grid_box_origin(g, v->lo), iso);
}

bool grid_mesh_view_stale(const grid_mesh_view_t *v, const grid_t *g)
{
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        if (lo[a] != v->lo[a] || hi[a] != v->hi[a])
            return true;
    return false;
}

void grid_mesh_mark(mc_blocks_t *b, const grid_mesh_view_t *v, const int32_t lo[3],
                    const int32_t hi[3])
{
    int32_t l[3], h[3];
    for (int a = 0; a < 3; a++) {
        l[a] = lo[a] - v->lo[a];
        h[a] = hi[a] - v->lo[a];
    }
    mc_blocks_mark(b, l, h);
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
