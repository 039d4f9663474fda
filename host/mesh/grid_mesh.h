/* Meshing the host's density grid: the box holding its samples (grid_bounds) is copied out and
 * meshed whole, so the surface follows the clay wherever it has grown. */
#ifndef ARGIL_GRID_MESH_H
#define ARGIL_GRID_MESH_H

#include <stdint.h>

#include "host/mesh/mesh.h"
#include "host/model/grid.h"
#include "shared/argil_err.h"

/* mc_extract of g's densities over grid_bounds at level iso into out (replaced). As mc_extract,
 * and ARGIL_ERR_NOMEM when the copy cannot be made. */
argil_err_t grid_mesh_extract(const grid_t *g, float iso, mesh_t *out);

/* mc_extract_region of g's densities over grid_bounds (rgb: 3 bytes per sample of that box, or
 * NULL) at level iso into out. As mc_extract_region, and ARGIL_ERR_NOMEM. */
argil_err_t grid_mesh_region(const grid_t *g, const uint8_t *rgb, float iso, mesh_t *out);

/* An mc_read_fn over a grid (ctx: const grid_t *) in sample indices: for a mesher set up over
 * the grid's dims and origin. */
void grid_mesh_read(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out);

#endif
