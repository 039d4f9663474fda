/* Incremental marching cubes (Ferley et al. §3.2): the cell lattice is cut into blocks of
 * MC_BLOCK_CELLS³ cells, each block keeps its own triangles, and after an edit only the blocks
 * whose cells or vertex normals depend on a changed sample are meshed again. Assembling the
 * blocks gives one indexed mesh with every vertex shared across cells and blocks; it is identical,
 * array for array, whether the blocks were meshed incrementally or all from scratch. */
#ifndef ARGIL_MC_BLOCKS_H
#define ARGIL_MC_BLOCKS_H

#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mc_table.h"
#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

#define MC_BLOCK_CELLS 16 /* cells per block edge */

/* One block's surface: vertices keyed by the global grid edge they lie on. */
typedef struct {
    float *pos, *normal; /* 3 per vertex */
    uint8_t *rgb;        /* 3 per vertex when the field has colours */
    uint64_t *key;       /* global edge id: ((z*P1 + y)*P0 + x)*3 + axis over padded samples */
    uint32_t *tri;       /* 3 block-local vertex indices per triangle, CCW seen from outside */
    uint32_t n_vert, n_tri, cap_vert, cap_tri;
} mc_block_mesh_t;

typedef struct {
    int32_t dims[3];     /* samples per axis (x fastest); beyond them density reads 0 */
    float spacing_m;
    vec3_t origin_m;     /* position of sample (0,0,0) */
    float iso;
    int32_t nblk[3];     /* blocks per axis over the dims+1 padded cells per axis */
    size_t n_blocks;
    mc_block_mesh_t *blocks; /* x fastest */
    uint8_t *dirty;      /* 1 = must be meshed at the next update */
    int has_rgb;         /* the last update had colours */
    mc_table_t *tab;
    float *val;          /* scratch: block samples with a one-sample halo */
    float *rd;           /* scratch: what a reader returns for one block */
    uint8_t *rdc;        /* scratch: what a colour reader returns for one block */
    uint8_t *ins, *col;
    uint32_t *cache;     /* scratch: vertex of each block-local edge */
    size_t blocks_meshed;  /* by the last update */
    uint64_t cells_meshed; /* by the last update (cells of non-empty blocks) */
} mc_blocks_t;

/* Prepares an all-dirty block mesher for a dims field. ARGIL_ERR_ARG for dims < 1 or above
 * 2^31 samples, a spacing that is not finite and > 0, a non-finite iso or origin; NOMEM. */
argil_err_t mc_blocks_init(mc_blocks_t *b, const int32_t dims[3], float spacing_m,
                           vec3_t origin_m, float iso);

/* Releases everything; b may be initialised again. */
void mc_blocks_free(mc_blocks_t *b);

/* Marks every block dirty (a full re-mesh at the next update). */
void mc_blocks_mark_all(mc_blocks_t *b);

/* Marks the blocks that depend on samples in the box [lo, hi) (clipped to the field). */
void mc_blocks_mark(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3]);

/* Meshes every dirty block from density (and rgb, 3 bytes per sample, may be NULL: a vertex takes
 * the colour of its edge's inside sample). Toggling rgb between updates re-meshes everything.
 * ARGIL_ERR_NONFINITE when a sample read is NaN or Inf (that block stays dirty), NOMEM, FULL. */
argil_err_t mc_blocks_update(mc_blocks_t *b, const float *density, const uint8_t *rgb);

/* Fills out (x fastest) with the densities of the sample box [lo, lo+n), which lies inside the
 * mesher's dims. */
typedef void (*mc_read_fn)(const void *ctx, const int32_t lo[3], const int32_t n[3], float *out);

/* mc_blocks_update with the densities read through read(ctx, ...) a block at a time (no
 * colours), so the field need not be one array. As mc_blocks_update. */
argil_err_t mc_blocks_update_read(mc_blocks_t *b, mc_read_fn read, const void *ctx);

/* Fills out (3 bytes per sample, x fastest) with the colours of the sample box [lo, lo+n). */
typedef void (*mc_read_rgb_fn)(const void *ctx, const int32_t lo[3], const int32_t n[3],
                               uint8_t *out);

/* mc_blocks_update_read with colours read through read_rgb(ctx, ...) (NULL: no colours, as
 * mc_blocks_update_read). As mc_blocks_update. */
argil_err_t mc_blocks_update_read_rgb(mc_blocks_t *b, mc_read_fn read, mc_read_rgb_fn read_rgb,
                                      const void *ctx);

/* Joins the blocks into out (replaced): closed, edge-manifold, each grid edge one vertex, in
 * block order; colours when the last update had them. NOMEM / FULL; out empty on error. */
argil_err_t mc_blocks_assemble(const mc_blocks_t *b, mesh_t *out);

/* Meshes the sample box [lo, hi) of a field on its own (samples outside the box read 0, so the
 * piece is closed) at any iso: one call of init + update + assemble. lo/hi NULL = whole field.
 * ARGIL_ERR_ARG for an empty or out-of-field box, and as mc_blocks_init / update. */
argil_err_t mc_extract_region(const float *density, const uint8_t *rgb, const int32_t dims[3],
                              float spacing_m, vec3_t origin_m, float iso, const int32_t lo[3],
                              const int32_t hi[3], mesh_t *out);

#endif
