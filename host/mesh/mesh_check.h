/* Checks a person would notice on a mesh: enclosed volume, holes and folds, sliver triangles. */
#ifndef ARGIL_MESH_CHECK_H
#define ARGIL_MESH_CHECK_H

#include <stdbool.h>
#include <stddef.h>

#include "host/mesh/mesh.h"

/* Signed enclosed volume (m³) by the divergence theorem: positive for a closed mesh whose
 * triangles are CCW seen from outside. */
double mesh_volume_m3(const mesh_t *m);

/* True when every undirected edge is used by exactly two triangles, once in each direction.
 * boundary_edges (may be NULL) counts edges used once; nonmanifold_edges (may be NULL) counts
 * edges used more than twice, twice in the same direction, joining a vertex to itself or naming
 * a vertex that does not exist. Both are SIZE_MAX (and the result false) when the check cannot
 * run: an allocation failed or the mesh has more than 2^31 vertices. */
bool mesh_watertight(const mesh_t *m, size_t *boundary_edges, size_t *nonmanifold_edges);

/* Number of distinct undirected edges (SIZE_MAX when the count cannot be made, as above). */
size_t mesh_edge_count(const mesh_t *m);

/* Number of triangles with area below min_area_m2 (or not finite, or naming a missing vertex). */
size_t mesh_degenerate_triangles(const mesh_t *m, float min_area_m2);

#endif
