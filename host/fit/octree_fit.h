/* Hua & Qin §4: hierarchical implicit B-spline fitting. An octree over the working space; each
 * node gets a least-squares cubic B-spline (uniform knots over the node's cube widened by an
 * overlap margin) fitted to the data inside it, and is split into eight while its mean square
 * error exceeds the bound (up to a maximum depth). The function is the partition-of-unity blend
 * of the leaf splines, so it is smooth across leaf faces. Data are values d at points: for a
 * point cloud the surface samples (d = 0) plus one interior (+e) and one exterior (-e) point
 * per sample along its normal, i.e. a signed distance, positive inside; for a volume the
 * normalised intensities minus the iso-level. Either way the surface is the zero set. */
#ifndef ARGIL_OCTREE_FIT_H
#define ARGIL_OCTREE_FIT_H

#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "host/model/bspline.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

#define OCTFIT_N 6u                 /* coefficients per axis per node (3 uniform spans) */
#define OCTFIT_NCOEF (OCTFIT_N * OCTFIT_N * OCTFIT_N)
#define OCTFIT_DEPTH_MAX 10u        /* deepest level --max-depth may ask for */
#define OCTFIT_NODES_MAX 65537u     /* nodes at most (root + 8k); deeper splits stop there */
#define OCTFIT_OVERLAP 0.25f        /* each node's spline covers its cube +/- 25 % of its edge */

typedef enum {
    OCTFIT_SIGNED_DISTANCE = 0, /* f in metres, positive inside (point clouds, meshes) */
    OCTFIT_INTENSITY = 1        /* f = normalised intensity - iso (volumes) */
} octfit_kind_t;

typedef struct {
    uint32_t n_nodes;      /* node 0 is the root; children of a node are 8 consecutive nodes */
    uint32_t *child;       /* per node: index of the first child, 0 for a leaf */
    uint32_t *leaf_of;     /* per node: its index among the leaves, UINT32_MAX if internal */
    uint32_t n_leaves;
    bspline_t *leaf;       /* per leaf, in node order: OCTFIT_N^3 coefficients */
    float origin_m[3];     /* root cube corner */
    float size_m;          /* root cube edge */
    uint32_t kind;         /* octfit_kind_t */
    uint32_t depth;        /* deepest leaf level (root = 0) */
    float rms_err, max_err; /* surface samples: |f| / |grad f| (m); volumes: |f - d| */
    float noise_m;         /* the cloud's estimated noise sigma (not stored; 0 for volumes) */
} octfit_model_t;

typedef struct {
    float tolerance;            /* RMS residual bound per node (MSE bound = tolerance^2); > 0 */
    uint32_t max_depth;         /* 0..OCTFIT_DEPTH_MAX */
    float offset_m;             /* off-surface distance e (0 = 0.5 % of the bounding diagonal) */
    const volatile int *stop;   /* set non-zero to abandon the fit (ARGIL_ERR_STATE) */
    void (*progress)(void *ctx, double fraction); /* may be NULL */
    void *progress_ctx;
} octfit_opts_t;

/* Why a point cloud bounds no solid to fit (octfit_check_points). */
typedef enum {
    OCTFIT_CLOUD_OK = 0,
    OCTFIT_CLOUD_FEW,        /* fewer than 4 points */
    OCTFIT_CLOUD_MANY,       /* more than 2^32 / 3 points */
    OCTFIT_CLOUD_NONFINITE,  /* a coordinate (or a normal, when it has them) is NaN or Inf */
    OCTFIT_CLOUD_DUPLICATES, /* fewer than 4 distinct positions */
    OCTFIT_CLOUD_FLAT        /* all on one plane or line: thickness within the noise */
} octfit_cloud_t;

#define OCTFIT_FLAT_NOISE 3.0f /* a cloud thinner (RMS off its plane) than this x its noise is flat */

/* Which rule a cloud breaks (OCTFIT_CLOUD_OK if none); normals are checked when pts has them.
 * thickness_m and noise_m (either may be NULL) receive the RMS distance of the points to their
 * plane and the noise estimate (normals_noise) when they were measured, else 0. */
octfit_cloud_t octfit_check_points(const mesh_t *pts, float *thickness_m, float *noise_m);

/* No tolerance (the caller must set one > 0), max depth 5, automatic offset. */
void octfit_opts_default(octfit_opts_t *o);

/* Fits a point cloud with unit outward normals that passes octfit_check_points. The prior where
 * no data reach is the distance to the nearest sample, signed by its normal. The noise sigma is
 * estimated from the points (normals_noise) and sets a floor under the off-surface distance
 * (3 sigma), the node error bound (1.5 sigma, with a local bias test) and the smoothing, so a
 * noisy scan is averaged, not followed. ARGIL_ERR_ARG (a cloud octfit_check_points rejects, bad
 * options), NOMEM, STATE (stopped). */
argil_err_t octfit_points(const mesh_t *pts, const octfit_opts_t *o, octfit_model_t *out);

/* Fits a volume of intensities v (x fastest, dims, sample (0,0,0) at origin_m, cubic cells of
 * spacing_m) so that f = (v - lo) / (hi - lo) - iso_norm, hi > lo the value range. */
argil_err_t octfit_volume(const float *v, const int32_t dims[3], float spacing_m, vec3_t origin_m,
                          float lo, float hi, float iso_norm, const octfit_opts_t *o,
                          octfit_model_t *out);

/* f at p: the blend of the leaves whose widened cubes hold p. Outside the root cube, f at the
 * nearest point of the cube minus the distance to it (signed distances) or that value (volumes). */
float octfit_eval(const octfit_model_t *m, vec3_t p_m);

/* Allocates a model of n_nodes nodes from child links (copied), leaves zero: checks that the
 * links form an octree (every node but the root the child of exactly one earlier node, depth
 * <= OCTFIT_DEPTH_MAX). ARGIL_ERR_ARG when they do not, or size <= 0 / non-finite; NOMEM. */
argil_err_t octfit_alloc(octfit_model_t *m, uint32_t n_nodes, const uint32_t *child,
                         const float origin_m[3], float size_m);

void octfit_free(octfit_model_t *m);

#endif
