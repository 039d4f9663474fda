/* A uniform grid over a point set for nearest-neighbour queries: the normal estimator's k
 * nearest neighbours and the octree fit's signed-distance prior both ask it. */
#ifndef ARGIL_KNN_H
#define ARGIL_KNN_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"
#include "shared/vec3.h"

#define KNN_K_MAX 64u            /* most neighbours one query returns */
#define KNN_CELLS_MAX (1u << 23) /* grid cells at most (32 MiB of cell starts) */

typedef struct {
    const float *pos;   /* 3 per point, borrowed: must outlive the grid */
    uint32_t n;
    float lo[3];        /* corner of cell (0,0,0) */
    float cell_m;       /* cell edge */
    int32_t dims[3];
    uint32_t *start;    /* cells + 1 offsets into idx (cell-sorted point indices) */
    uint32_t *idx;
} knn_grid_t;

/* Bins n points (finite, n >= 1, n < 2^32) so that a surface sample cloud holds a few points per
 * occupied cell. ARGIL_ERR_ARG (n = 0, NaN / Inf), NOMEM. */
argil_err_t knn_grid_build(knn_grid_t *g, const float *pos, size_t n);

void knn_grid_free(knn_grid_t *g);

/* The min(k, n) points nearest p (k <= KNN_K_MAX), nearest first: indices into idx, squared
 * distances into d2 (may be NULL). Returns how many were written. */
uint32_t knn_grid_query(const knn_grid_t *g, vec3_t p, uint32_t k, uint32_t *idx, float *d2);

#endif
