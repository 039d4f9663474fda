/* Mesh -> signed distance on a grid: what `argil fit mesh.stl` turns a closed triangle mesh into
 * (then the density profile of the grid). Closest-triangle distance within a band around the
 * surface (triangles binned into a uniform grid), sign by the angle-weighted pseudo-normal of
 * the closest feature (Baerentzen & Aanaes 2005) near the surface and by ray parity along +x
 * away from it. Only closed (watertight) meshes have an inside: others are refused. */
#ifndef ARGIL_MESH_SDF_H
#define ARGIL_MESH_SDF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef struct {
    size_t boundary_edges;    /* edges used by one triangle */
    size_t nonmanifold_edges; /* edges used by more than two, or twice the same way */
    size_t degenerate;        /* zero-area triangles skipped */
} mesh_sdf_report_t;

/* Writes sd (dims product floats, x fastest, sample (0,0,0) at origin_m): the exact distance to
 * the mesh (positive inside) where it is below band_m, +band_m / -band_m beyond. ARGIL_ERR_ARG
 * (no triangles, bad grid, band <= 0, NaN / Inf corners), ARGIL_ERR_STATE when the mesh is not
 * closed or not edge-manifold (counts in rep; sd untouched), NOMEM. rep may be NULL. */
argil_err_t mesh_sdf(const mesh_t *m, const int32_t dims[3], float spacing_m, vec3_t origin_m,
                     float band_m, float *sd, mesh_sdf_report_t *rep);

#endif
