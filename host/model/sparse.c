/* Blocks of channels in the block-key hash (host/model/block_table.h). */
#include "host/model/sparse.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static int32_t sparse_local(int32_t i)
{
    return floor_mod_i32(i, SPARSE_B);
}

_Static_assert(offsetof(sparse_block_t, key) == 0, "a block_table entry starts with its key");

argil_err_t sparse_init(sparse_t *s, int nch, const float *defaults)
{
    memset(s, 0, sizeof(*s));
    if (nch < 1 || nch > SPARSE_CH_MAX || defaults == NULL)
        return ARGIL_ERR_ARG;
    for (int c = 0; c < nch; c++)
        if (!isfinite(defaults[c]))
            return ARGIL_ERR_NONFINITE;
    s->nch = nch;
    memcpy(s->defaults, defaults, sizeof(float) * (size_t)nch);
    return block_table_init(&s->blocks, sizeof(sparse_block_t), 64);
}

void sparse_free(sparse_t *s)
{
    size_t slot = 0;
    for (sparse_block_t *b; (b = sparse_next(s, &slot)) != NULL;)
        free(b->data);
    block_table_free(&s->blocks);
}

sparse_block_t *sparse_find(const sparse_t *s, const int32_t key[3])
{
    return block_table_find(&s->blocks, key);
}

sparse_block_t *sparse_next(const sparse_t *s, size_t *slot)
{
    return block_table_next(&s->blocks, slot);
}

argil_err_t sparse_touch(sparse_t *s, const int32_t key[3], sparse_block_t **out)
{
    sparse_block_t *b = sparse_find(s, key);
    if (b == NULL) {
        float *data = malloc(sizeof(float) * (size_t)s->nch * SPARSE_BN);
        if (data == NULL)
            return ARGIL_ERR_NOMEM;
        for (int c = 0; c < s->nch; c++)
            for (int i = 0; i < SPARSE_BN; i++)
                data[c * SPARSE_BN + i] = s->defaults[c];
        void *e;
        const argil_err_t err = block_table_insert(&s->blocks, key, &e);
        if (err != ARGIL_OK) {
            free(data);
            return err;
        }
        b = e;
        b->data = data;
        b->dirty = true;
    }
    *out = b;
    return ARGIL_OK;
}

float sparse_get(const sparse_t *s, int ch, int32_t i, int32_t j, int32_t k)
{
    const int32_t key[3] = {sparse_block_of(i), sparse_block_of(j), sparse_block_of(k)};
    const sparse_block_t *b = sparse_find(s, key);
    if (b == NULL)
        return s->defaults[ch];
    return b->data[ch * SPARSE_BN + sparse_local(i) +
                   SPARSE_B * (sparse_local(j) + SPARSE_B * sparse_local(k))];
}

argil_err_t sparse_set(sparse_t *s, int ch, int32_t i, int32_t j, int32_t k, float v)
{
    if (ch < 0 || ch >= s->nch)
        return ARGIL_ERR_ARG;
    const int32_t key[3] = {sparse_block_of(i), sparse_block_of(j), sparse_block_of(k)};
    sparse_block_t *b;
    argil_err_t e = sparse_touch(s, key, &b);
    if (e != ARGIL_OK)
        return e;
    b->data[ch * SPARSE_BN + sparse_local(i) + SPARSE_B * (sparse_local(j) + SPARSE_B * sparse_local(k))] = v;
    b->dirty = true;
    return ARGIL_OK;
}

static bool sparse_box_ok(const sparse_t *s, int ch, const int32_t lo[3], const int32_t dims[3])
{
    if (ch < 0 || ch >= s->nch)
        return false;
    for (int a = 0; a < 3; a++)
        if (dims[a] < 0 || lo[a] < -SPARSE_INDEX_MAX || lo[a] > SPARSE_INDEX_MAX ||
            dims[a] > SPARSE_INDEX_MAX)
            return false;
    return true;
}

/* The part [a0, a1) of block key that lies inside the box [lo, hi), per axis. */
static void sparse_block_span(const int32_t key[3], const int32_t lo[3], const int32_t hi[3],
                              int32_t a0[3], int32_t a1[3])
{
    for (int a = 0; a < 3; a++) {
        a0[a] = key[a] * SPARSE_B > lo[a] ? key[a] * SPARSE_B : lo[a];
        a1[a] = (key[a] + 1) * SPARSE_B < hi[a] ? (key[a] + 1) * SPARSE_B : hi[a];
    }
}

/* Index of point (x, y, z) in a box of dims from lo, x fastest. */
static size_t sparse_box_at(const int32_t lo[3], const int32_t dims[3], int32_t x, int32_t y,
                            int32_t z)
{
    return (size_t)(x - lo[0]) +
           (size_t)dims[0] * ((size_t)(y - lo[1]) + (size_t)dims[1] * (size_t)(z - lo[2]));
}

/* Index of point (x, y, z) of block key in its data, channel ch. */
static size_t sparse_block_at(const int32_t key[3], int ch, int32_t x, int32_t y, int32_t z)
{
    return (size_t)(ch * SPARSE_BN + (x - key[0] * SPARSE_B) +
                    SPARSE_B * ((y - key[1] * SPARSE_B) + SPARSE_B * (z - key[2] * SPARSE_B)));
}

void sparse_read_box(const sparse_t *s, int ch, const int32_t lo[3], const int32_t dims[3],
                     float *out)
{
    if (!sparse_box_ok(s, ch, lo, dims))
        return;
    const int32_t hi[3] = {lo[0] + dims[0], lo[1] + dims[1], lo[2] + dims[2]};
    for (int32_t bz = sparse_block_of(lo[2]); bz <= sparse_block_of(hi[2] - 1); bz++)
        for (int32_t by = sparse_block_of(lo[1]); by <= sparse_block_of(hi[1] - 1); by++)
            for (int32_t bx = sparse_block_of(lo[0]); bx <= sparse_block_of(hi[0] - 1); bx++) {
                const int32_t key[3] = {bx, by, bz};
                const sparse_block_t *b = sparse_find(s, key);
                int32_t a0[3], a1[3];
                sparse_block_span(key, lo, hi, a0, a1);
                const size_t run = (size_t)(a1[0] - a0[0]);
                for (int32_t z = a0[2]; z < a1[2]; z++)
                    for (int32_t y = a0[1]; y < a1[1]; y++) {
                        float *dst = out + sparse_box_at(lo, dims, a0[0], y, z);
                        if (b == NULL) {
                            for (size_t x = 0; x < run; x++)
                                *dst++ = s->defaults[ch];
                        } else {
                            memcpy(dst, b->data + sparse_block_at(key, ch, a0[0], y, z),
                                   sizeof(float) * run);
                        }
                    }
            }
}

/* True when the part [a0, a1) of block b (absent: all defaults) differs bitwise from in. */
static bool sparse_block_differs(const sparse_t *s, const sparse_block_t *b, int ch,
                                 const int32_t key[3], const int32_t a0[3], const int32_t a1[3],
                                 const int32_t lo[3], const int32_t dims[3], const float *in)
{
    const size_t run = (size_t)(a1[0] - a0[0]);
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const float *src = in + sparse_box_at(lo, dims, a0[0], y, z);
            if (b == NULL) {
                for (size_t x = 0; x < run; x++)
                    if (memcmp(&src[x], &s->defaults[ch], sizeof(float)) != 0)
                        return true;
            } else if (memcmp(b->data + sparse_block_at(key, ch, a0[0], y, z), src,
                              sizeof(float) * run) != 0) {
                return true;
            }
        }
    return false;
}

argil_err_t sparse_write_box(sparse_t *s, int ch, const int32_t lo[3], const int32_t dims[3],
                             const float *in)
{
    if (!sparse_box_ok(s, ch, lo, dims))
        return ARGIL_ERR_ARG;
    const int32_t hi[3] = {lo[0] + dims[0], lo[1] + dims[1], lo[2] + dims[2]};
    for (int32_t bz = sparse_block_of(lo[2]); bz <= sparse_block_of(hi[2] - 1); bz++)
        for (int32_t by = sparse_block_of(lo[1]); by <= sparse_block_of(hi[1] - 1); by++)
            for (int32_t bx = sparse_block_of(lo[0]); bx <= sparse_block_of(hi[0] - 1); bx++) {
                const int32_t key[3] = {bx, by, bz};
                sparse_block_t *b = sparse_find(s, key);
                int32_t a0[3], a1[3];
                sparse_block_span(key, lo, hi, a0, a1);
                if (!sparse_block_differs(s, b, ch, key, a0, a1, lo, dims, in))
                    continue;
                if (b == NULL) {
                    argil_err_t e = sparse_touch(s, key, &b);
                    if (e != ARGIL_OK)
                        return e;
                }
                b->dirty = true;
                for (int32_t z = a0[2]; z < a1[2]; z++)
                    for (int32_t y = a0[1]; y < a1[1]; y++)
                        memcpy(b->data + sparse_block_at(key, ch, a0[0], y, z),
                               in + sparse_box_at(lo, dims, a0[0], y, z),
                               sizeof(float) * (size_t)(a1[0] - a0[0]));
            }
    return ARGIL_OK;
}

size_t sparse_take_dirty(sparse_t *s, int32_t (*keys)[3], size_t max)
{
    size_t n = 0, slot = 0;
    for (sparse_block_t *b; (b = sparse_next(s, &slot)) != NULL;) {
        if (!b->dirty)
            continue;
        if (keys != NULL) {
            if (n < max)
                memcpy(keys[n], b->key, sizeof(b->key));
            b->dirty = false;
        }
        n++;
    }
    return n;
}

size_t sparse_bytes(const sparse_t *s)
{
    return s->blocks.count * sizeof(float) * (size_t)s->nch * SPARSE_BN +
           block_table_bytes(&s->blocks);
}
