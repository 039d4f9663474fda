/* The journal writer's copy of the model as of the last record (journal_shadow_t): grid blocks in
 * a hash, an array per kind only where a block holds more than one value. */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/journal_internal.h"

#define SHADOW_CAP0 64u /* hash slots of a new shadow */

_Static_assert(offsetof(journal_block_t, key) == 0, "a block_table entry starts with its key");

/* Block k, or NULL when the shadow holds none. */
journal_block_t *journal_shadow_find(const journal_shadow_t *s, const int32_t k[3])
{
    return block_table_find(&s->blocks, k);
}

/* Block k, added (density 0, no arrays) when absent; NULL when out of memory. Adding may move
 * every other block (pointers to them go stale). */
journal_block_t *journal_shadow_touch(journal_shadow_t *s, const int32_t k[3])
{
    void *b;
    return block_table_insert(&s->blocks, k, &b) == ARGIL_OK ? b : NULL;
}

/* Frees every block's arrays and the hash; s is left empty. */
void journal_shadow_free(journal_shadow_t *s)
{
    size_t slot = 0;
    for (journal_block_t *b; (b = block_table_next(&s->blocks, &slot)) != NULL;) {
        free(b->dens);
        free(b->rgb);
        for (int ch = 0; ch < GRID_MAT_N; ch++)
            free(b->mat[ch]);
    }
    block_table_free(&s->blocks);
    memset(s, 0, sizeof(*s));
}

/* Block b's samples of kind (b NULL: an absent block): its array, or NULL when every sample
 * holds the value written to cst. */
uint8_t *journal_shadow_arr(const journal_block_t *b, int kind, uint8_t cst[4])
{
    if (kind == JOURNAL_KIND_DENS) {
        const float u = b != NULL ? b->uniform : 0.0f;
        memcpy(cst, &u, 4);
        return b != NULL ? (uint8_t *)b->dens : NULL;
    }
    if (kind == JOURNAL_KIND_RGB) {
        memset(cst, (int)GRID_RGB_DEFAULT, 3);
        return b != NULL ? b->rgb : NULL;
    }
    const float def = grid_mat_default((grid_mat_t)(kind - JOURNAL_KIND_MAT0));
    memcpy(cst, &def, 4);
    return b != NULL ? (uint8_t *)b->mat[kind - JOURNAL_KIND_MAT0] : NULL;
}

/* The same for the grid's block v (a channel never painted reads its default everywhere). */
const uint8_t *journal_grid_arr(const grid_t *g, const grid_block_view_t *v, int kind,
                                uint8_t cst[4])
{
    if (kind == JOURNAL_KIND_DENS) {
        memcpy(cst, &v->uniform, 4);
        return (const uint8_t *)v->density;
    }
    if (kind == JOURNAL_KIND_RGB) {
        memset(cst, (int)GRID_RGB_DEFAULT, 3);
        return v->rgb;
    }
    const grid_mat_t ch = (grid_mat_t)(kind - JOURNAL_KIND_MAT0);
    const float def = grid_mat_default(ch);
    memcpy(cst, &def, 4);
    return grid_mat_painted(g, ch) && v->mat != NULL ? (const uint8_t *)(v->mat + ch * GRID_BN)
                                                      : NULL;
}

/* True when every one of the GRID_BN samples of arr (es bytes each) holds the bytes of v. */
static bool arr_all(const uint8_t *arr, size_t es, const uint8_t *v)
{
    for (size_t i = 0; i < GRID_BN; i++)
        if (memcmp(arr + es * i, v, es) != 0)
            return false;
    return true;
}

/* Gives b an array for kind holding what b reads now; false when out of memory. */
bool journal_shadow_arr_make(journal_shadow_t *s, journal_block_t *b, int kind)
{
    uint8_t cst[4];
    if (journal_shadow_arr(b, kind, cst) != NULL)
        return true;
    const size_t es = journal_kind_bytes(kind);
    uint8_t *a = malloc(es * GRID_BN);
    if (a == NULL)
        return false;
    for (size_t i = 0; i < GRID_BN; i++)
        memcpy(a + es * i, cst, es);
    if (kind == JOURNAL_KIND_DENS)
        b->dens = (float *)(void *)a;
    else if (kind == JOURNAL_KIND_RGB)
        b->rgb = a;
    else
        b->mat[kind - JOURNAL_KIND_MAT0] = (float *)(void *)a;
    s->arrays_bytes += es * GRID_BN;
    return true;
}

/* Drops b's array for kind when it says nothing more than no array would: densities all one
 * value (which becomes b's uniform), a channel or the colour all its default. */
void journal_shadow_arr_compact(journal_shadow_t *s, journal_block_t *b, int kind)
{
    uint8_t cst[4];
    uint8_t *a = journal_shadow_arr(b, kind, cst);
    const size_t es = journal_kind_bytes(kind);
    if (a == NULL || !arr_all(a, es, kind == JOURNAL_KIND_DENS ? a : cst))
        return;
    if (kind == JOURNAL_KIND_DENS) {
        memcpy(&b->uniform, a, 4);
        b->dens = NULL;
    } else if (kind == JOURNAL_KIND_RGB) {
        b->rgb = NULL;
    } else {
        b->mat[kind - JOURNAL_KIND_MAT0] = NULL;
    }
    free(a);
    s->arrays_bytes -= es * GRID_BN;
}

/* The block box of v clipped to the sample box [gl, gh) into [a0, a1); false when empty. */
bool journal_block_clip(const int32_t key[3], const int32_t gl[3], const int32_t gh[3],
                        int32_t a0[3], int32_t a1[3])
{
    for (int a = 0; a < 3; a++) {
        const int64_t b0 = (int64_t)key[a] * GRID_B, b1 = b0 + GRID_B;
        a0[a] = (int32_t)(b0 > gl[a] ? b0 : gl[a]);
        a1[a] = (int32_t)(b1 < gh[a] ? b1 : gh[a]);
        if (a1[a] <= a0[a])
            return false;
    }
    return true;
}

/* Index within a block of global sample (x, y, z) of block key. */
size_t journal_block_local(const int32_t key[3], int32_t x, int32_t y, int32_t z)
{
    return (size_t)(x - key[0] * GRID_B) +
           GRID_B * ((size_t)(y - key[1] * GRID_B) + GRID_B * (size_t)(z - key[2] * GRID_B));
}

/* Copies the grid's block v into s: its densities, each painted channel and the colour, arrays
 * only where they hold more than one value (a default). false when out of memory. */
static bool sh_copy_block(journal_shadow_t *s, const grid_t *g, const grid_block_view_t *v)
{
    const uint8_t *arr[JOURNAL_KIND_RGB + 1];
    bool need = false;
    float uniform = v->uniform;
    for (int kind = 0; kind <= JOURNAL_KIND_RGB; kind++) {
        uint8_t cst[4];
        const size_t es = journal_kind_bytes(kind);
        arr[kind] = journal_grid_arr(g, v, kind, cst);
        if (arr[kind] != NULL &&
            arr_all(arr[kind], es, kind == JOURNAL_KIND_DENS ? arr[kind] : cst)) {
            if (kind == JOURNAL_KIND_DENS)
                memcpy(&uniform, arr[kind], 4);
            arr[kind] = NULL;
        }
        need = need || arr[kind] != NULL;
    }
    const float zero = 0.0f;
    if (!need && journal_same_bits(&uniform, &zero, sizeof(float)))
        return true; /* reads as an absent block */
    journal_block_t *b = journal_shadow_touch(s, v->key);
    if (b == NULL)
        return false;
    b->uniform = uniform;
    for (int kind = 0; kind <= JOURNAL_KIND_RGB; kind++) {
        if (arr[kind] == NULL)
            continue;
        if (!journal_shadow_arr_make(s, b, kind))
            return false;
        uint8_t cst[4];
        memcpy(journal_shadow_arr(b, kind, cst), arr[kind], journal_kind_bytes(kind) * GRID_BN);
    }
    return true;
}

/* s (empty) becomes a copy of the grid's blocks that meet the sample box [gl, gh); false when
 * out of memory (s then holds part: journal_shadow_free it). */
bool journal_shadow_take(journal_shadow_t *s, const grid_t *g, const int32_t gl[3],
                         const int32_t gh[3])
{
    if (block_table_init(&s->blocks, sizeof(journal_block_t), SHADOW_CAP0) != ARGIL_OK)
        return false;
    size_t slot = 0;
    grid_block_view_t v;
    while (grid_block_next(g, &slot, &v)) {
        int32_t a0[3], a1[3];
        if (journal_block_clip(v.key, gl, gh, a0, a1) && !sh_copy_block(s, g, &v))
            return false;
    }
    return true;
}

/* Dense copies over the journal's box of its shadow: densities, each channel the journal has
 * seen painted (the others NULL) and the colour once seen (else NULL). */
argil_err_t journal_shadow_dense(const journal_t *j, float **dens, float *mat[GRID_MAT_N],
                                 uint8_t **rgb)
{
    const size_t n = j->n;
    *rgb = NULL;
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        mat[ch] = NULL;
    *dens = malloc(n * sizeof(float));
    bool ok = *dens != NULL;
    for (int ch = 0; ok && ch < GRID_MAT_N; ch++) {
        if (!j->mat_seen[ch])
            continue;
        mat[ch] = malloc(n * sizeof(float));
        ok = mat[ch] != NULL;
        const float def = grid_mat_default((grid_mat_t)ch);
        for (size_t i = 0; ok && i < n; i++)
            mat[ch][i] = def;
    }
    if (ok && j->rgb_seen) {
        *rgb = malloc(3 * n);
        ok = *rgb != NULL;
        if (ok)
            memset(*rgb, (int)GRID_RGB_DEFAULT, 3 * n);
    }
    if (!ok) {
        journal_dense_free(dens, mat, rgb);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        (*dens)[i] = 0.0f;
    const int32_t gh[3] = {j->lo[0] + j->dims[0], j->lo[1] + j->dims[1], j->lo[2] + j->dims[2]};
    const size_t nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    size_t slot = 0;
    for (const journal_block_t *b; (b = block_table_next(&j->shadow.blocks, &slot)) != NULL;) {
        int32_t a0[3], a1[3];
        if (!journal_block_clip(b->key, j->lo, gh, a0, a1))
            continue;
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++)
                for (int32_t x = a0[0]; x < a1[0]; x++) {
                    const size_t li = journal_block_local(b->key, x, y, z);
                    const size_t i = (size_t)(x - j->lo[0]) +
                                     nx * ((size_t)(y - j->lo[1]) + ny * (size_t)(z - j->lo[2]));
                    (*dens)[i] = b->dens != NULL ? b->dens[li] : b->uniform;
                    for (int ch = 0; ch < GRID_MAT_N; ch++)
                        if (mat[ch] != NULL && b->mat[ch] != NULL)
                            mat[ch][i] = b->mat[ch][li];
                    if (*rgb != NULL && b->rgb != NULL)
                        memcpy(*rgb + 3 * i, b->rgb + 3 * li, 3);
                }
    }
    return ARGIL_OK;
}
