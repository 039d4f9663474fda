/* Normals for point clouds that come without them: a tangent plane per point from the k nearest
 * neighbours (PCA, Hoppe et al. 1992), then one consistent outward orientation propagated over
 * a minimum spanning tree of the neighbour graph (weight 1 - |n_i . n_j|), starting in every
 * connected part from its largest-x point, whose normal must point towards +x. */
#ifndef ARGIL_NORMALS_H
#define ARGIL_NORMALS_H

#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

#define NORMALS_K_DEFAULT 12u
#define NORMALS_NOISE_K_DEFAULT 16u  /* neighbours per plane fit of the noise estimate */
#define NORMALS_NOISE_SAMPLES 4096u  /* points (spread evenly) whose plane fits it takes */
#define NORMALS_NOISE_RADII 6.0      /* automatic k: neighbourhood radius / noise wanted */

typedef struct {
    uint32_t k;                 /* neighbours per point incl. itself, 4..KNN_K_MAX (0: 12, more
                                 * on a noisy cloud, up to KNN_K_MAX, so that the neighbourhood's
                                 * radius is NORMALS_NOISE_RADII x the noise of normals_noise) */
    const volatile int *stop;   /* set non-zero to abandon (ARGIL_ERR_STATE) */
    void (*progress)(void *ctx, double fraction); /* may be NULL */
    void *progress_ctx;
} normals_opts_t;

/* Gives m (a cloud of >= 4 finite points; triangles ignored) unit normals, replacing any it had.
 * *parts (may be NULL) receives the number of connected parts of the neighbour graph
 * (each oriented from its own extreme point). ARGIL_ERR_ARG (fewer than 4 points, NaN / Inf),
 * NOMEM, STATE (stopped). o may be NULL for the defaults. */
argil_err_t normals_estimate(mesh_t *m, const normals_opts_t *o, uint32_t *parts);

/* The cloud's noise level sigma (m, per coordinate): the median over up to NORMALS_NOISE_SAMPLES
 * evenly spread points of the RMS residual of a quadric height field fitted to their k nearest
 * neighbours (0 = 16) over their least-squares plane, unbiased for its 6 degrees of freedom, so
 * curvature is not taken for noise. The median ignores the few neighbourhoods that straddle an
 * edge. ARGIL_ERR_ARG (fewer than 4 points, NaN / Inf,
 * k not 4..KNN_K_MAX), NOMEM. */
argil_err_t normals_noise(const mesh_t *m, uint32_t k, float *sigma_m);

/* The RMS distance of all of m's points to their least-squares plane (0 for a plane or a line). */
float normals_thickness(const mesh_t *m);

#endif
