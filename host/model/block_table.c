/* The block-key hash every sparse block store uses (grid, B-spline blocks, the journal's shadow,
 * the block mesher). */
#include "host/model/block_table.h"

#include <stdlib.h>
#include <string.h>

static unsigned char *bt_at(const block_table_t *t, size_t slot)
{
    return t->entries + slot * t->entry_bytes;
}

static bool bt_is(const unsigned char *entry, const int32_t key[3])
{
    int32_t k[3];
    memcpy(k, entry, sizeof(k));
    return k[0] == key[0] && k[1] == key[1] && k[2] == key[2];
}

argil_err_t block_table_init(block_table_t *t, size_t entry_bytes, size_t cap0)
{
    memset(t, 0, sizeof(*t));
    if (entry_bytes < 3 * sizeof(int32_t) || cap0 < 2 || (cap0 & (cap0 - 1)) != 0 ||
        cap0 > BLOCK_TABLE_CAP_MAX)
        return ARGIL_ERR_ARG;
    t->entries = calloc(cap0, entry_bytes);
    t->used = calloc(cap0, 1);
    if (t->entries == NULL || t->used == NULL) {
        block_table_free(t);
        return ARGIL_ERR_NOMEM;
    }
    t->entry_bytes = entry_bytes;
    t->cap = cap0;
    t->cap_max = BLOCK_TABLE_CAP_MAX;
    return ARGIL_OK;
}

void block_table_free(block_table_t *t)
{
    free(t->entries);
    free(t->used);
    memset(t, 0, sizeof(*t));
}

/* The slot holding key, or the free slot ending its probe run (cap when neither: full). */
static size_t bt_probe(const block_table_t *t, const int32_t key[3])
{
    const size_t mask = t->cap - 1;
    size_t i = block_table_home(key, t->cap);
    for (size_t n = 0; n < t->cap; n++, i = (i + 1) & mask)
        if (!t->used[i] || bt_is(bt_at(t, i), key))
            return i;
    return t->cap;
}

argil_err_t block_table_grow(block_table_t *t)
{
    if (t->cap == 0 || t->cap >= t->cap_max)
        return ARGIL_ERR_FULL;
    const size_t cap = t->cap * 2, mask = cap - 1;
    unsigned char *entries = calloc(cap, t->entry_bytes);
    uint8_t *used = calloc(cap, 1);
    if (entries == NULL || used == NULL) {
        free(entries);
        free(used);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < t->cap; i++) {
        if (!t->used[i])
            continue;
        int32_t k[3];
        memcpy(k, bt_at(t, i), sizeof(k));
        size_t j = block_table_home(k, cap);
        while (used[j]) /* at most count < cap taken slots */
            j = (j + 1) & mask;
        memcpy(entries + j * t->entry_bytes, bt_at(t, i), t->entry_bytes);
        used[j] = 1;
    }
    free(t->entries);
    free(t->used);
    t->entries = entries;
    t->used = used;
    t->cap = cap;
    return ARGIL_OK;
}

argil_err_t block_table_insert(block_table_t *t, const int32_t key[3], void **entry)
{
    *entry = NULL;
    if (t->cap == 0)
        return ARGIL_ERR_STATE;
    size_t i = bt_probe(t, key);
    if (i < t->cap && t->used[i]) {
        *entry = bt_at(t, i);
        return ARGIL_OK;
    }
    if ((t->count + 1) * 2 > t->cap) {
        const argil_err_t e = block_table_grow(t);
        if (e == ARGIL_ERR_NOMEM)
            return e;
        if (e == ARGIL_OK)
            i = bt_probe(t, key);
    }
    if (i >= t->cap)
        return ARGIL_ERR_FULL;
    unsigned char *b = bt_at(t, i);
    memset(b, 0, t->entry_bytes);
    memcpy(b, key, 3 * sizeof(int32_t));
    t->used[i] = 1;
    t->count++;
    *entry = b;
    return ARGIL_OK;
}

void block_table_remove(block_table_t *t, void *entry)
{
    const size_t mask = t->cap - 1;
    size_t i = (size_t)((unsigned char *)entry - t->entries) / t->entry_bytes;
    for (size_t j = (i + 1) & mask, n = 1; n < t->cap && t->used[j]; j = (j + 1) & mask, n++) {
        int32_t k[3];
        memcpy(k, bt_at(t, j), sizeof(k));
        const size_t h = block_table_home(k, t->cap);
        /* slot j stays when its home lies cyclically in (i, j] */
        const bool stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
        if (!stays) {
            memcpy(bt_at(t, i), bt_at(t, j), t->entry_bytes);
            i = j;
        }
    }
    memset(bt_at(t, i), 0, t->entry_bytes);
    t->used[i] = 0;
    t->count--;
}

void *block_table_next(const block_table_t *t, size_t *slot)
{
    for (; *slot < t->cap; (*slot)++)
        if (t->used[*slot])
            return bt_at(t, (*slot)++);
    return NULL;
}

size_t block_table_bytes(const block_table_t *t)
{
    return t->cap * (t->entry_bytes + 1);
}
