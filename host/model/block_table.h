/* The block-key hash of every sparse block store on the host: linear probing bounded by the
 * capacity, doubling at half load, deletion by backward shift (no tombstones). */
#ifndef ARGIL_BLOCK_TABLE_H
#define ARGIL_BLOCK_TABLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shared/argil_err.h"

/* Largest capacity a table grows to unless cap_max says less. */
#define BLOCK_TABLE_CAP_MAX ((size_t)1 << 40)

/* Each entry starts with its key, int32_t key[3]; the rest of entry_bytes is the caller's. */
typedef struct {
    unsigned char *entries;  /* cap entries of entry_bytes; a free slot is all zero */
    uint8_t *used;           /* 1 per taken slot */
    size_t entry_bytes;
    size_t cap, count;       /* slots (a power of two), slots taken */
    size_t cap_max;          /* the table does not grow past this (a power of two) */
} block_table_t;

/* An empty table of cap0 slots (a power of two >= 2) of entry_bytes each (at least the key).
 * ARGIL_ERR_ARG, ARGIL_ERR_NOMEM (t is then empty: block_table_free is safe). */
argil_err_t block_table_init(block_table_t *t, size_t entry_bytes, size_t cap0);

/* Releases the table's arrays (not what entries point to); t may be initialised again. */
void block_table_free(block_table_t *t);

/* The home slot of key in a table of cap slots (a power of two). */
static inline size_t block_table_home(const int32_t key[3], size_t cap)
{
    const uint64_t h = (uint64_t)(uint32_t)key[0] * 0x9E3779B97F4A7C15ull ^
                       (uint64_t)(uint32_t)key[1] * 0xC2B2AE3D27D4EB4Full ^
                       (uint64_t)(uint32_t)key[2] * 0x165667B19E3779F9ull;
    return (size_t)(h ^ (h >> 29)) & (cap - 1);
}

/* The entry of key, or NULL; looks at no more than cap slots (inline: every sample read of a
 * sparse store looks its block up). */
static inline void *block_table_find(const block_table_t *t, const int32_t key[3])
{
    const size_t mask = t->cap - 1;
    size_t i = block_table_home(key, t->cap);
    for (size_t n = 0; n < t->cap; n++, i = (i + 1) & mask) {
        if (!t->used[i])
            return NULL;
        unsigned char *e = t->entries + i * t->entry_bytes;
        int32_t k[3];
        memcpy(k, e, sizeof(k));
        if (k[0] == key[0] && k[1] == key[1] && k[2] == key[2])
            return e;
    }
    return NULL;
}

/* Doubles the capacity (entries move: pointers to them go stale). ARGIL_ERR_FULL at cap_max,
 * ARGIL_ERR_NOMEM (the table unchanged). */
argil_err_t block_table_grow(block_table_t *t);

/* The entry of key into *entry: the one held, or a new one (zero past the key), growing first
 * when that would pass half load (entries may then move). ARGIL_ERR_FULL when every slot is
 * taken and the table cannot grow, ARGIL_ERR_NOMEM; *entry NULL on error. */
argil_err_t block_table_insert(block_table_t *t, const int32_t key[3], void **entry);

/* Gives up entry's slot (one this table returned); later keys of its probe run move back, so
 * every other key stays findable (pointers to moved entries go stale). */
void block_table_remove(block_table_t *t, void *entry);

/* The first taken entry at slot *slot or after it, *slot moved past it; NULL when none is left.
 * Start with *slot = 0; the order is the slots'. */
void *block_table_next(const block_table_t *t, size_t *slot);

/* Bytes the table's arrays hold. */
size_t block_table_bytes(const block_table_t *t);

#endif
