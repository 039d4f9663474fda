/* Incremental marching cubes (Ferley et al. §3.2): the cell lattice is cut into blocks of
 * MC_BLOCK_CELLS³ cells, each block keeps its own triangles, and after an edit only the blocks
 * whose cells or vertex normals depend on a changed sample are meshed again. Assembling the
 * blocks gives one indexed mesh with every vertex shared across cells and blocks; it is identical,
 * array for array, whether the blocks were meshed incrementally or all from scratch. Blocks live
 * in a hash by block key (any sign) and only while they hold triangles or wait to be meshed, so
 * memory follows the surface and the meshed box can grow in any direction without a rebuild. */
#ifndef ARGIL_MC_BLOCKS_H
#define ARGIL_MC_BLOCKS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mc_table.h"
#include "host/mesh/mesh.h"
#include "host/model/block_table.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

#define MC_BLOCK_CELLS 16 /* cells per block edge */
/* The meshed box may span at most this many samples per axis (edge ids hold 20 bits per axis). */
#define MC_BLOCKS_SPAN_MAX (((int32_t)1 << 20) - 8)
/* Sample indices of the meshed box lie in [-MC_BLOCKS_INDEX_MAX, MC_BLOCKS_INDEX_MAX]. */
#define MC_BLOCKS_INDEX_MAX ((int32_t)1 << 30)

/* One block's surface: vertices keyed by the edge they lie on. */
typedef struct {
    float *pos, *normal; /* 3 per vertex */
    uint8_t *rgb;        /* 3 per vertex when the field has colours */
    uint64_t *key;       /* edge id: lower padded sample (x, y, z mod 2^20) and axis */
    uint32_t *tri;       /* 3 block-local vertex indices per triangle, CCW seen from outside */
    uint32_t n_vert, n_tri, cap_vert, cap_tri;
} mc_block_mesh_t;

/* A slot of the block hash: block key k holds the padded cells [16 k, 16 k + 16) per axis
 * (padded cell c has its lower corner at sample c - 1), keys of any sign. */
typedef struct {
    int32_t key[3];      /* block key; first: the table's key */
    uint8_t dirty;       /* must be meshed at the next update */
    mc_block_mesh_t mesh;
} mc_block_t;

/* True when every density of the sample box [lo, lo+n) is at or below iso, so a block whose
 * corners they are holds no surface; may say false when unsure. ctx is the reader's. */
typedef bool (*mc_outside_fn)(const void *ctx, const int32_t lo[3], const int32_t n[3], float iso);

typedef struct {
    int32_t dims[3];     /* samples per axis of the array mc_blocks_update reads (the init box) */
    int32_t lo[3], hi[3]; /* the sample box meshed; beyond it density reads 0 and is outside */
    float spacing_m;
    vec3_t origin_m;     /* position of sample (0,0,0) */
    float iso;
    block_table_t blocks; /* mc_block_t of the blocks that hold triangles or are dirty */
    bool all_dirty;      /* every block of the box must be meshed at the next update */
    mc_outside_fn outside; /* optional (NULL after init): asked before a reader reads a block */
    mc_block_mesh_t spare; /* scratch: a block without a slot is meshed here */
    int32_t *keys;       /* scratch: the dirty keys of an update, 3 per block */
    size_t keys_cap;     /* blocks keys can hold */
    int has_rgb;         /* the last update had colours */
    mc_table_t *tab;
    float *val;          /* scratch: block samples with a one-sample halo */
    float *rd;           /* scratch: what a reader returns for one block */
    uint8_t *rdc;        /* scratch: what a colour reader returns for one block */
    uint8_t *ins, *col;
    uint32_t *cache;     /* scratch: vertex of each block-local edge */
    size_t blocks_meshed;  /* by the last update */
    size_t blocks_read;    /* of those, the ones whose samples were read (not skipped by outside) */
    uint64_t cells_meshed; /* by the last update (cells of non-empty blocks) */
} mc_blocks_t;

/* Prepares an all-dirty block mesher for a dims field (the box [0, dims)). ARGIL_ERR_ARG for
 * dims < 1 or above MC_BLOCKS_SPAN_MAX, a spacing that is not finite and > 0, a non-finite iso
 * or origin; NOMEM. */
argil_err_t mc_blocks_init(mc_blocks_t *b, const int32_t dims[3], float spacing_m,
                           vec3_t origin_m, float iso);

/* The same over the sample box [lo, hi) (read through a reader; origin_m is sample (0,0,0)).
 * ARGIL_ERR_ARG also for an empty box or one beyond MC_BLOCKS_INDEX_MAX. */
argil_err_t mc_blocks_init_box(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3],
                               float spacing_m, vec3_t origin_m, float iso);

/* Widens the meshed box to hold [lo, hi) as well: no block is re-meshed (samples newly inside
 * the box read what they did before, 0 and outside, unless written, which the caller marks),
 * except that with iso < 0 (0 counts as inside) every block is marked. The box is kept on error:
 * ARGIL_ERR_ARG for an empty box or beyond MC_BLOCKS_INDEX_MAX, ARGIL_ERR_FULL when the union
 * would span more than MC_BLOCKS_SPAN_MAX samples on an axis. */
argil_err_t mc_blocks_grow(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3]);

/* Bytes the mesher holds: the block hash, every block's arrays and the scratch. */
size_t mc_blocks_bytes(const mc_blocks_t *b);

/* Blocks the meshed box spans: what per-block tables over the whole box would hold. */
size_t mc_blocks_box_blocks(const mc_blocks_t *b);

/* Releases everything; b may be initialised again. */
void mc_blocks_free(mc_blocks_t *b);

/* Marks every block dirty (a full re-mesh at the next update). */
void mc_blocks_mark_all(mc_blocks_t *b);

/* Marks the blocks that depend on samples in the box [lo, hi) (clipped to the meshed box); when
 * a slot cannot be allocated, marks every block instead. */
void mc_blocks_mark(mc_blocks_t *b, const int32_t lo[3], const int32_t hi[3]);

/* Meshes every dirty block from density (and rgb, 3 bytes per sample, may be NULL: a vertex takes
 * the colour of its edge's inside sample); a block left without triangles gives up its slot.
 * Toggling rgb between updates re-meshes everything. ARGIL_ERR_NONFINITE when a sample read is
 * NaN or Inf (that block stays dirty), NOMEM, FULL; ARGIL_ERR_ARG once the box was grown past
 * [0, dims) (density is one array of dims samples). */
argil_err_t mc_blocks_update(mc_blocks_t *b, const float *density, const uint8_t *rgb);

/* Fills out (x fastest) with the densities of the sample box [lo, lo+n), which lies inside the
 * mesher's box [lo, hi) (indices may be negative). */
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
 * block key order (z, then y, then x); colours when the last update had them. NOMEM / FULL;
 * out empty on error. */
argil_err_t mc_blocks_assemble(const mc_blocks_t *b, mesh_t *out);

/* Meshes the sample box [lo, hi) of a field on its own (samples outside the box read 0, so the
 * piece is closed) at any iso: one call of init + update + assemble. lo/hi NULL = whole field.
 * ARGIL_ERR_ARG for an empty or out-of-field box, and as mc_blocks_init / update. */
argil_err_t mc_extract_region(const float *density, const uint8_t *rgb, const int32_t dims[3],
                              float spacing_m, vec3_t origin_m, float iso, const int32_t lo[3],
                              const int32_t hi[3], mesh_t *out);

#endif
