/* Meshes the host grid over the box its samples occupy (a dense copy of that box). */
#include "host/mesh/grid_mesh.h"

#include <stdlib.h>

#include "host/mesh/mc.h"
#include "host/mesh/mc_blocks.h"

void grid_mesh_read(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out)
{
    grid_read_box(ctx, GRID_DENSITY, lo, n, out);
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
