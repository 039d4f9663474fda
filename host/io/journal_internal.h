/* What the journal's own files share (journal_model.c, journal_shadow.c, journal_diff.c,
 * journal_writer.c, journal_reader.c, journal_recover.c); everyone else includes journal.h. */
#ifndef ARGIL_JOURNAL_INTERNAL_H
#define ARGIL_JOURNAL_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "host/io/io_util.h"
#include "host/io/journal.h"
#include "shared/wire.h"

#define JOURNAL_MAGIC "ARGJRNL\x1a" /* the 8 bytes journal.log starts with */

/* What a record compares: densities, painted channel JOURNAL_KIND_MAT0 + ch, or the colour. */
enum {
    JOURNAL_KIND_DENS = 0,
    JOURNAL_KIND_MAT0 = 1,
    JOURNAL_KIND_RGB = JOURNAL_KIND_MAT0 + GRID_MAT_N
};

/* Bytes per sample of kind. */
static inline size_t journal_kind_bytes(int kind)
{
    return kind == JOURNAL_KIND_RGB ? 3u : 4u;
}

/* Stores m at p as five little-endian binary32 (20 bytes). */
static inline void journal_put_material(uint8_t *p, const spring_material_t *m)
{
    le_put_f32(p, m->node_mass);
    le_put_f32(p + 4, m->stiffness);
    le_put_f32(p + 8, m->coupling);
    le_put_f32(p + 12, m->damping);
    le_put_f32(p + 16, m->plastic_rate_hz);
}

/* Loads the 20-byte material at p into m. */
static inline void journal_get_material(const uint8_t *p, spring_material_t *m)
{
    m->node_mass = le_get_f32(p);
    m->stiffness = le_get_f32(p + 4);
    m->coupling = le_get_f32(p + 8);
    m->damping = le_get_f32(p + 12);
    m->plastic_rate_hz = le_get_f32(p + 16);
}

/* True when the n bytes at a and b are the same. */
static inline bool journal_same_bits(const void *a, const void *b, size_t n)
{
    return memcmp(a, b, n) == 0;
}

/* ---- journal_model.c: the model as dense arrays over a box ---- */

/* The base identity CRC of a dense model (densities, painted channels, colour). */
uint32_t journal_model_crc(const float *density, float *const mat[GRID_MAT_N], const uint8_t *rgb,
                           size_t n);
/* Gives doc a copy of rgb when it is painted; false when out of memory. */
bool journal_doc_set_rgb(argil_doc_t *doc, const uint8_t *rgb, size_t n);
/* Frees the dense arrays and sets them to NULL. */
void journal_dense_free(float **dens, float *mat[GRID_MAT_N], uint8_t **rgb);
/* Dense copies of g over [zero, zero + dims); ARGIL_ERR_NOMEM. */
argil_err_t journal_grid_dense(const grid_t *g, const int32_t zero[3], const int32_t dims[3],
                               float **dens, float *mat[GRID_MAT_N], uint8_t **rgb);

/* ---- journal_shadow.c: the writer's copy of the model ---- */

/* Block k of s, or NULL when absent. */
journal_block_t *journal_shadow_find(const journal_shadow_t *s, const int32_t k[3]);
/* Block k of s, added when absent; NULL when out of memory. */
journal_block_t *journal_shadow_touch(journal_shadow_t *s, const int32_t k[3]);
/* Releases s and leaves it empty. */
void journal_shadow_free(journal_shadow_t *s);
/* b's array for kind, or NULL with the one value in cst. */
uint8_t *journal_shadow_arr(const journal_block_t *b, int kind, uint8_t cst[4]);
/* The grid block v's array for kind, or NULL with the one value in cst. */
const uint8_t *journal_grid_arr(const grid_t *g, const grid_block_view_t *v, int kind,
                                uint8_t cst[4]);
/* Gives b an array for kind; false when out of memory. */
bool journal_shadow_arr_make(journal_shadow_t *s, journal_block_t *b, int kind);
/* Drops b's array for kind when it holds one value. */
void journal_shadow_arr_compact(journal_shadow_t *s, journal_block_t *b, int kind);
/* Block key's box clipped to [gl, gh) into [a0, a1); false when empty. */
bool journal_block_clip(const int32_t key[3], const int32_t gl[3], const int32_t gh[3],
                        int32_t a0[3], int32_t a1[3]);
/* Index within block key of global sample (x, y, z). */
size_t journal_block_local(const int32_t key[3], int32_t x, int32_t y, int32_t z);
/* s (empty) becomes a copy of g's blocks meeting [gl, gh); false when out of memory. */
bool journal_shadow_take(journal_shadow_t *s, const grid_t *g, const int32_t gl[3],
                         const int32_t gh[3]);
/* Dense copies of j's shadow over the journal's box; ARGIL_ERR_NOMEM. */
argil_err_t journal_shadow_dense(const journal_t *j, float **dens, float *mat[GRID_MAT_N],
                                 uint8_t **rgb);

/* ---- journal_diff.c: what changed since the last record, as runs ---- */

/* The changed blocks of kind inside [gl, gh) into j->views; false when out of memory. */
bool journal_diff_blocks(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                         const int32_t gh[3], size_t *count);
/* Appends the changed samples as runs and updates the shadow; false when out of memory. */
bool journal_diff_put_runs(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                           const int32_t gh[3], size_t nviews, uint32_t *runs);

/* ---- journal_writer.c ---- */

/* dir/name (malloc'ed), or NULL when out of memory. */
char *journal_path(const char *dir, const char *name);
/* Room for more bytes in j's record buffer; false when out of memory. */
bool journal_buf_reserve(journal_t *j, size_t more);

/* ---- journal_reader.c ---- */

/* journal_replay with optional painted channels mat and colour *rgb. */
journal_err_t journal_replay_channels(const uint8_t *data, size_t len, const char *name,
                                      float *density, size_t n, float **mat, uint8_t **rgb,
                                      journal_info_t *info, char *err, size_t err_len);
/* The journal_err_t of a failure outside the file (io_slurp's: PARSE is a file too large). */
journal_err_t journal_outside_err(argil_err_t e);

#endif
