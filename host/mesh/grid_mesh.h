/* Meshing the host's density grid: the box holding its samples (grid_bounds) is copied out and
 * meshed whole, or meshed a block at a time by a live block mesher that grows with the bounds,
 * so the surface follows the clay wherever it has grown. */
#ifndef ARGIL_GRID_MESH_H
#define ARGIL_GRID_MESH_H

#include <stdbool.h>
#include <stdint.h>

#include "host/mesh/mc_blocks.h"

#include "host/mesh/mesh.h"
#include "host/model/grid.h"
#include "shared/argil_err.h"

/* mc_extract of g's densities over grid_bounds at level iso into out (replaced). As mc_extract,
 * and ARGIL_ERR_NOMEM when the copy cannot be made. */
argil_err_t grid_mesh_extract(const grid_t *g, float iso, mesh_t *out);

/* mc_extract_region of g's densities over grid_bounds (rgb: 3 bytes per sample of that box, or
 * NULL) at level iso into out. As mc_extract_region, and ARGIL_ERR_NOMEM. */
argil_err_t grid_mesh_region(const grid_t *g, const uint8_t *rgb, float iso, mesh_t *out);

/* A block mesher's view of a grid: the mesher's sample indices are the grid's (its sample
 * (0,0,0) is the grid's origin_m), and [lo, hi) is the grid box it meshes (the bounds it has
 * seen, grown only). */
typedef struct {
    const grid_t *g;
    int32_t lo[3], hi[3];
} grid_mesh_view_t;

/* An mc_read_fn over a view (ctx: const grid_mesh_view_t *). */
void grid_mesh_read(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out);

/* An mc_read_rgb_fn over a view (ctx: const grid_mesh_view_t *): the grid's painted colour. */
void grid_mesh_read_rgb(const void *ctx, const int32_t lo[3], const int32_t n[3], uint8_t *out);

/* Sets up b (all dirty) over g's bounds at level iso and v onto them; blocks the grid says lie
 * wholly at or below iso are not read. As mc_blocks_init_box. */
argil_err_t grid_mesh_blocks_init(mc_blocks_t *b, grid_mesh_view_t *v, const grid_t *g,
                                  float iso);

/* True when g's bounds reach beyond v's box (the clay grew: grid_mesh_grow). */
bool grid_mesh_view_stale(const grid_mesh_view_t *v, const grid_t *g);

/* Widens b and v to g's bounds without re-meshing (mc_blocks_grow; the caller marks what was
 * written). As mc_blocks_grow: on ARGIL_ERR_FULL the mesher must be set up again. */
argil_err_t grid_mesh_grow(mc_blocks_t *b, grid_mesh_view_t *v, const grid_t *g);

/* Marks the blocks that depend on the grid's samples [lo, hi) (grid indices). */
void grid_mesh_mark(mc_blocks_t *b, const grid_mesh_view_t *v, const int32_t lo[3],
                    const int32_t hi[3]);

#endif
