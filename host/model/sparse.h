/* Sparse working space (Ferley et al. §3.1): fixed-size blocks of per-sample channels, allocated
 * only where material or edits are, addressed by integer lattice indices of any sign, so the
 * sculpture can grow in any direction and memory follows the surface, not the bounding box. */
#ifndef ARGIL_SPARSE_H
#define ARGIL_SPARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/model/block_table.h"
#include "host/model/floor_div.h"
#include "shared/argil_err.h"

#define SPARSE_B 8                               /* lattice points per block edge */
#define SPARSE_BN (SPARSE_B * SPARSE_B * SPARSE_B)
#define SPARSE_CH_MAX 16
#define SPARSE_INDEX_MAX (1 << 28)               /* |index| bound per axis */

typedef struct {
    int32_t key[3];      /* block coordinates floor(index / SPARSE_B); the table's key */
    bool dirty;          /* changed since the mesher last took it */
    float *data;         /* nch * SPARSE_BN floats, channel-major, x fastest */
} sparse_block_t;

typedef struct {
    int nch;
    float defaults[SPARSE_CH_MAX];  /* value of every point of an absent block */
    block_table_t blocks;           /* sparse_block_t by key */
} sparse_t;

/* An empty store of nch channels with the given default values. ARGIL_ERR_ARG, ARGIL_ERR_NOMEM. */
argil_err_t sparse_init(sparse_t *s, int nch, const float *defaults);
void sparse_free(sparse_t *s);

/* The block key of lattice index i: floor(i / SPARSE_B) (inline: the tools call it per
 * coefficient). */
static inline int32_t sparse_block_of(int32_t i)
{
    return floor_div_i32(i, SPARSE_B);
}

/* The block holding key, or NULL. */
sparse_block_t *sparse_find(const sparse_t *s, const int32_t key[3]);

/* The next block held at slot *slot or after it, *slot moved past it; NULL when none is left.
 * Start with *slot = 0; the order is the hash's. */
sparse_block_t *sparse_next(const sparse_t *s, size_t *slot);

/* The block holding key, allocated (filled with defaults) when absent. */
argil_err_t sparse_touch(sparse_t *s, const int32_t key[3], sparse_block_t **out);

/* Channel ch at lattice point (i, j, k): the stored value or the channel default. */
float sparse_get(const sparse_t *s, int ch, int32_t i, int32_t j, int32_t k);

/* Stores v (allocating the block), marks the block dirty. */
argil_err_t sparse_set(sparse_t *s, int ch, int32_t i, int32_t j, int32_t k, float v);

/* Copies the box [lo, lo+dims) of channel ch into out (x fastest); absent points read the default. */
void sparse_read_box(const sparse_t *s, int ch, const int32_t lo[3], const int32_t dims[3],
                     float *out);

/* Writes the box; blocks are allocated only where a written value differs from what is stored
 * (so writing defaults into empty space allocates nothing). Blocks that change are marked dirty.
 * ARGIL_ERR_ARG for a bad channel or box, ARGIL_ERR_NOMEM. */
argil_err_t sparse_write_box(sparse_t *s, int ch, const int32_t lo[3], const int32_t dims[3],
                             const float *in);

/* Number of dirty blocks; when keys is not NULL up to max keys are written and all dirty flags
 * are cleared (the mesher took them). */
size_t sparse_take_dirty(sparse_t *s, int32_t (*keys)[3], size_t max);

/* Bytes held by block data and the table. */
size_t sparse_bytes(const sparse_t *s);

#endif
