/* A field made of N B-spline patches, each seen through its own affine map, combined by a
 * Boolean tree (Hua & Qin eq. 3 and eq. 4): value and analytic gradient anywhere. */
#ifndef ARGIL_CSG_H
#define ARGIL_CSG_H

#include <stdint.h>

#include "host/model/bspline.h"
#include "shared/argil_err.h"

#define CSG_NODES_MAX 64

typedef enum {
    CSG_LEAF = 0,   /* one patch: s_i(T_i x) */
    CSG_SUM,        /* a + b (Hua & Qin eq. 3, hierarchical patches) */
    CSG_UNION,      /* max(a, b) */
    CSG_INTERSECT,  /* min(a, b) */
    CSG_DIFFERENCE  /* a minus b: min(a, 2 iso - b), b reflected about the iso-level */
} csg_op_t;

/* T_i: u = L x + t, from model space (m) to the patch's parameter domain. */
typedef struct {
    const bspline_t *spline;   /* borrowed */
    double lin[3][3];
    double offset[3];
} csg_patch_t;

typedef struct {
    csg_op_t op;
    int32_t a, b;              /* child node indices (< this node's index); leaf: a = patch */
} csg_node_t;

typedef struct {
    csg_patch_t patches[CSG_NODES_MAX];
    int32_t npatches;
    csg_node_t nodes[CSG_NODES_MAX];
    int32_t nnodes;            /* the last node is the root */
    double iso;                /* the level the Boolean operators reflect about */
} csg_t;

void csg_init(csg_t *c, double iso);

/* Adds a patch with the affine map (lin, offset); writes its index. ARGIL_ERR_FULL, ARGIL_ERR_ARG
 * for a NULL spline, ARGIL_ERR_NONFINITE for a non-finite map. */
argil_err_t csg_add_patch(csg_t *c, const bspline_t *s, const double lin[3][3],
                          const double offset[3], int32_t *patch);

/* Adds a node; children must already exist (leaf: a names a patch). Writes the node index. */
argil_err_t csg_add_node(csg_t *c, csg_op_t op, int32_t a, int32_t b, int32_t *node);

/* f(x) at the root node (0 for an empty tree); grad (may be NULL) is the analytic gradient in
 * model space (1/m): Lᵀ times the parametric gradient, taken from the operand the min/max picks. */
double csg_eval(const csg_t *c, const double x_m[3], double grad[3]);

#endif
