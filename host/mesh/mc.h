/* Marching cubes over a dense density block: the closed triangle surface the renderer draws and
 * the exporters write. */
#ifndef ARGIL_MC_H
#define ARGIL_MC_H

#include <stdbool.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

/* Smallest fraction of a cell edge between a vertex and a sample, so no triangle collapses when
 * a sample sits exactly on the iso-value. */
#define MC_T_MIN 0.01f

/* The vertex both meshers put on the grid edge from padded sample p (sample p - 1) along axis
 * a, whose ends hold densities d0 and d1 and central-difference gradients g0 and g1: where the
 * iso-value crosses (at least MC_T_MIN of the edge from either end, also for NaN) and the unit
 * outward normal (the edge direction, inside to outside, where the field is flat). One function
 * so that the slab and block meshers agree bit for bit. */
void mc_edge_point(vec3_t origin_m, float spacing_m, float iso, const int32_t p[3], int a,
                   float d0, float d1, vec3_t g0, vec3_t g1, vec3_t *pos_m, vec3_t *normal);

#define MC_GRID_SAMPLES_MAX ((uint64_t)1 << 30) /* most samples a dense grid may hold */

/* The sample count of a dense grid of dims into *samples; false when a side is below 1 or the
 * count is above MC_GRID_SAMPLES_MAX. */
bool mc_grid_samples(const int32_t dims[3], uint64_t *samples);

/* Replaces out with the iso-surface of density (x fastest, dims samples, sample (0,0,0) at
 * origin_m): closed, edge-manifold, one vertex per crossed grid edge, triangles CCW seen from
 * outside (density <= iso, which includes every sample beyond the grid), unit outward normals
 * from the central-difference gradient. Deterministic. ARGIL_ERR_ARG for dims < 1 or more than
 * 2^31 samples, a spacing that is not finite and > 0, a non-finite iso or origin;
 * ARGIL_ERR_NONFINITE when a density is NaN or Inf; ARGIL_ERR_NOMEM / ARGIL_ERR_FULL (more than
 * 2^32 vertices). On error out is left empty. */
argil_err_t mc_extract(const float *density, const int32_t dims[3], float spacing_m,
                       vec3_t origin_m, float iso, mesh_t *out);

#endif
