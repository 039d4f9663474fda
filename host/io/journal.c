/* Autosave journal: base .argil snapshot + CRC'd records of changed density, painted material
 * and painted colour samples; the writer
 * buffers records and makes them durable at a bounded interval, the reader replays them. */
#define _POSIX_C_SOURCE 200809L
#include "journal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/io/io_util.h"
#include "shared/crc32c.h"

static const uint8_t JOURNAL_MAGIC[8] = {'A', 'R', 'G', 'J', 'R', 'N', 'L', 0x1a};
#define JOURNAL_RECORD_MAX_BYTES ((uint64_t)1 << 32) /* the length field is 32 bits */

void journal_cfg_default(journal_cfg_t *cfg)
{
    cfg->autosave_s = 1.0f;
    cfg->checkpoint_s = 60.0f;
    cfg->checkpoint_bytes = (uint64_t)64 << 20;
}

/* ---- little helpers ---- */

static void put_u64(uint8_t *p, uint64_t v)
{
    io_put_u32le(p, (uint32_t)v);
    io_put_u32le(p + 4, (uint32_t)(v >> 32));
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)io_get_u32le(p) | (uint64_t)io_get_u32le(p + 4) << 32;
}

static void put_material(uint8_t *p, const spring_material_t *m)
{
    io_put_f32le(p, m->node_mass);
    io_put_f32le(p + 4, m->stiffness);
    io_put_f32le(p + 8, m->coupling);
    io_put_f32le(p + 12, m->damping);
    io_put_f32le(p + 16, m->plastic_rate_hz);
}

static void get_material(const uint8_t *p, spring_material_t *m)
{
    m->node_mass = io_get_f32le(p);
    m->stiffness = io_get_f32le(p + 4);
    m->coupling = io_get_f32le(p + 8);
    m->damping = io_get_f32le(p + 12);
    m->plastic_rate_hz = io_get_f32le(p + 16);
}

static bool same_bits(const void *a, const void *b, size_t n)
{
    return memcmp(a, b, n) == 0;
}

static char *path_join(const char *dir, const char *name)
{
    const size_t a = strlen(dir), b = strlen(name);
    char *p = malloc(a + b + 2);
    if (p == NULL)
        return NULL;
    memcpy(p, dir, a);
    p[a] = '/';
    memcpy(p + a + 1, name, b + 1);
    return p;
}

static void sync_dir(const char *dir)
{
    const int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        (void)fsync(fd);
        (void)close(fd);
    }
}

static void base_name(uint32_t checkpoint, char out[JOURNAL_BASE_NAME_MAX + 1])
{
    snprintf(out, JOURNAL_BASE_NAME_MAX + 1, JOURNAL_BASE_PREFIX "%u.argil", checkpoint);
}

static bool write_all(int fd, const uint8_t *p, size_t len)
{
    while (len > 0) {
        const ssize_t w = write(fd, p, len);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        p += w;
        len -= (size_t)w;
    }
    return true;
}

static uint32_t f32s_crc(uint32_t crc, const float *v, size_t n)
{
    uint8_t chunk[1024];
    size_t i = 0;
    while (i < n) {
        size_t k = 0;
        for (; k < sizeof(chunk) / 4 && i < n; k++, i++)
            io_put_f32le(chunk + 4 * k, v[i]);
        crc = crc32c(crc, chunk, 4 * k);
    }
    return crc;
}

/* True when channel m (n samples) holds any value other than ch's default, bit for bit. */
static bool mat_painted(const float *m, size_t n, grid_mat_t ch)
{
    if (m == NULL)
        return false;
    const float def = grid_mat_default(ch);
    for (size_t i = 0; i < n; i++)
        if (!same_bits(&m[i], &def, sizeof(float)))
            return true;
    return false;
}

/* True when rgb (n samples, NULL = unpainted) holds any byte other than GRID_RGB_DEFAULT. */
static bool rgb_painted(const uint8_t *rgb, size_t n)
{
    for (size_t i = 0; rgb != NULL && i < 3 * n; i++)
        if (rgb[i] != GRID_RGB_DEFAULT)
            return true;
    return false;
}

/* The base's identity: CRC-32C of its densities as little-endian binary32, continued over each
 * painted channel (its id as uint32, then its values); a channel holding only the default counts
 * as absent, so an unpainted model's CRC is its densities' alone (as in version 1). (Not a CRC
 * over the file: a CRC over data followed by its own CRC is a constant, so over an .argil, whose
 * sections each end in their CRC, it would not depend on the sections' contents at all.) */
static uint32_t model_crc(const float *density, float *const mat[GRID_MAT_N], const uint8_t *rgb,
                          size_t n)
{
    uint32_t crc = f32s_crc(0, density, n);
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        if (!mat_painted(mat[ch], n, (grid_mat_t)ch))
            continue;
        uint8_t id[4];
        io_put_u32le(id, (uint32_t)ch);
        crc = crc32c(crc, id, 4);
        crc = f32s_crc(crc, mat[ch], n);
    }
    if (rgb_painted(rgb, n)) { /* then the colour as id 4 and 3 bytes per sample */
        uint8_t id[4];
        io_put_u32le(id, JOURNAL_RGB_CRC_ID);
        crc = crc32c(crc, id, 4);
        crc = crc32c(crc, rgb, 3 * n);
    }
    return crc;
}

/* A copy of rgb (3 n bytes) as doc's colour; false when out of memory. */
static bool doc_set_rgb(argil_doc_t *doc, const uint8_t *rgb, size_t n)
{
    if (rgb == NULL || !rgb_painted(rgb, n))
        return true;
    doc->rgb = malloc(3 * n);
    if (doc->rgb == NULL)
        return false;
    memcpy(doc->rgb, rgb, 3 * n);
    return true;
}

/* ---- the model as a journal holds it ---- */

/* True when g can be journalled by j: its bounds lie within the journal's box [lo, lo + dims). */
static bool journal_fits(const journal_t *j, const grid_t *g)
{
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        if (lo[a] < j->lo[a] || hi[a] > j->lo[a] + j->dims[a])
            return false;
    return true;
}

static void dense_all_free(float **dens, float *mat[GRID_MAT_N], uint8_t **rgb)
{
    free(*dens);
    *dens = NULL;
    free(*rgb);
    *rgb = NULL;
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        free(mat[ch]);
        mat[ch] = NULL;
    }
}

/* Dense copies over [zero, zero + dims) of g's densities, of each painted channel (NULL =
 * unpainted) and of its colour (3 bytes per sample; NULL = never painted). */
static argil_err_t grid_dense_all(const grid_t *g, const int32_t zero[3], const int32_t dims[3],
                                  float **dens, float *mat[GRID_MAT_N], uint8_t **rgb)
{
    const size_t n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    *rgb = NULL;
    *dens = malloc(n * sizeof(float));
    if (*dens == NULL)
        return ARGIL_ERR_NOMEM;
    grid_read_box(g, GRID_DENSITY, zero, dims, *dens);
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        mat[ch] = NULL;
        if (!grid_mat_painted(g, (grid_mat_t)ch))
            continue;
        mat[ch] = malloc(n * sizeof(float));
        if (mat[ch] == NULL) {
            dense_all_free(dens, mat, rgb);
            return ARGIL_ERR_NOMEM;
        }
        grid_mat_read_box(g, (grid_mat_t)ch, zero, dims, mat[ch]);
    }
    if (grid_rgb_any(g)) {
        *rgb = malloc(3 * n);
        if (*rgb == NULL) {
            dense_all_free(dens, mat, rgb);
            return ARGIL_ERR_NOMEM;
        }
        grid_rgb_read_box(g, zero, dims, *rgb);
    }
    return ARGIL_OK;
}

argil_err_t journal_model_doc(const journal_info_t *info, const float *density,
                              float *const mat[GRID_MAT_N], argil_doc_t *doc)
{
    argil_doc_init(doc);
    argil_err_t e = grid_init(&doc->grid, info->dims, info->spacing_m, info->origin_m);
    if (e != ARGIL_OK)
        return e;
    const int32_t zero[3] = {0, 0, 0};
    e = grid_write_box(&doc->grid, GRID_DENSITY, zero, info->dims, density);
    if (e != ARGIL_OK)
        return e;
    for (int ch = 0; mat != NULL && ch < GRID_MAT_N; ch++) {
        if (mat[ch] == NULL)
            continue;
        e = grid_mat_write_box(&doc->grid, (grid_mat_t)ch, zero, info->dims, mat[ch]);
        if (e != ARGIL_OK)
            return e;
    }
    e = grid_write_box(&doc->grid, GRID_REST, zero, info->dims, density);
    if (e != ARGIL_OK)
        return e;
    doc->grid.iso = info->iso;
    doc->grid.band_m = info->band_m;
    doc->grid.material = info->material;
    doc->state.edits = info->edits;
    return ARGIL_OK;
}

/* The header fields a writer knows, as an info. */
static void writer_info(const journal_t *j, uint32_t edits, journal_info_t *info)
{
    memset(info, 0, sizeof(*info));
    for (int a = 0; a < 3; a++)
        info->dims[a] = j->dims[a];
    info->spacing_m = j->spacing_m;
    info->origin_m = j->origin_m;
    info->iso = j->iso;
    info->band_m = j->band_m;
    info->material = j->material;
    info->edits = edits;
}

/* ---- the writer's copy of the model: grid blocks in a hash (journal_shadow_t) ---- */

#define SHADOW_CAP0 64u /* hash slots of a new shadow */

/* What a record compares: densities, painted channel KIND_MAT0 + ch, or the colour. */
enum { KIND_DENS = 0, KIND_MAT0 = 1, KIND_RGB = KIND_MAT0 + GRID_MAT_N };

/* Bytes per sample of kind. */
static size_t kind_bytes(int kind)
{
    return kind == KIND_RGB ? 3u : 4u;
}

_Static_assert(offsetof(journal_block_t, key) == 0, "a block_table entry starts with its key");

static journal_block_t *sh_find(const journal_shadow_t *s, const int32_t k[3])
{
    return block_table_find(&s->blocks, k);
}

/* Block k, added (density 0, no arrays) when absent; NULL when out of memory. Adding may move
 * every other block (pointers to them go stale). */
static journal_block_t *sh_touch(journal_shadow_t *s, const int32_t k[3])
{
    void *b;
    return block_table_insert(&s->blocks, k, &b) == ARGIL_OK ? b : NULL;
}

static void sh_free(journal_shadow_t *s)
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
static uint8_t *sh_arr(const journal_block_t *b, int kind, uint8_t cst[4])
{
    if (kind == KIND_DENS) {
        const float u = b != NULL ? b->uniform : 0.0f;
        memcpy(cst, &u, 4);
        return b != NULL ? (uint8_t *)b->dens : NULL;
    }
    if (kind == KIND_RGB) {
        memset(cst, (int)GRID_RGB_DEFAULT, 3);
        return b != NULL ? b->rgb : NULL;
    }
    const float def = grid_mat_default((grid_mat_t)(kind - KIND_MAT0));
    memcpy(cst, &def, 4);
    return b != NULL ? (uint8_t *)b->mat[kind - KIND_MAT0] : NULL;
}

/* The same for the grid's block v (a channel never painted reads its default everywhere). */
static const uint8_t *live_arr(const grid_t *g, const grid_block_view_t *v, int kind,
                               uint8_t cst[4])
{
    if (kind == KIND_DENS) {
        memcpy(cst, &v->uniform, 4);
        return (const uint8_t *)v->density;
    }
    if (kind == KIND_RGB) {
        memset(cst, (int)GRID_RGB_DEFAULT, 3);
        return v->rgb;
    }
    const grid_mat_t ch = (grid_mat_t)(kind - KIND_MAT0);
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
static bool sh_arr_make(journal_shadow_t *s, journal_block_t *b, int kind)
{
    uint8_t cst[4];
    if (sh_arr(b, kind, cst) != NULL)
        return true;
    const size_t es = kind_bytes(kind);
    uint8_t *a = malloc(es * GRID_BN);
    if (a == NULL)
        return false;
    for (size_t i = 0; i < GRID_BN; i++)
        memcpy(a + es * i, cst, es);
    if (kind == KIND_DENS)
        b->dens = (float *)(void *)a;
    else if (kind == KIND_RGB)
        b->rgb = a;
    else
        b->mat[kind - KIND_MAT0] = (float *)(void *)a;
    s->arrays_bytes += es * GRID_BN;
    return true;
}

/* Drops b's array for kind when it says nothing more than no array would: densities all one
 * value (which becomes b's uniform), a channel or the colour all its default. */
static void sh_arr_compact(journal_shadow_t *s, journal_block_t *b, int kind)
{
    uint8_t cst[4];
    uint8_t *a = sh_arr(b, kind, cst);
    const size_t es = kind_bytes(kind);
    if (a == NULL || !arr_all(a, es, kind == KIND_DENS ? a : cst))
        return;
    if (kind == KIND_DENS) {
        memcpy(&b->uniform, a, 4);
        b->dens = NULL;
    } else if (kind == KIND_RGB) {
        b->rgb = NULL;
    } else {
        b->mat[kind - KIND_MAT0] = NULL;
    }
    free(a);
    s->arrays_bytes -= es * GRID_BN;
}

/* The block box of v clipped to the sample box [gl, gh) into [a0, a1); false when empty. */
static bool block_clip(const int32_t key[3], const int32_t gl[3], const int32_t gh[3],
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
static size_t block_local(const int32_t key[3], int32_t x, int32_t y, int32_t z)
{
    return (size_t)(x - key[0] * GRID_B) +
           GRID_B * ((size_t)(y - key[1] * GRID_B) + GRID_B * (size_t)(z - key[2] * GRID_B));
}

/* Copies the grid's block v into s: its densities, each painted channel and the colour, arrays
 * only where they hold more than one value (a default). false when out of memory. */
static bool sh_copy_block(journal_shadow_t *s, const grid_t *g, const grid_block_view_t *v)
{
    const uint8_t *arr[KIND_RGB + 1];
    bool need = false;
    float uniform = v->uniform;
    for (int kind = 0; kind <= KIND_RGB; kind++) {
        uint8_t cst[4];
        const size_t es = kind_bytes(kind);
        arr[kind] = live_arr(g, v, kind, cst);
        if (arr[kind] != NULL && arr_all(arr[kind], es, kind == KIND_DENS ? arr[kind] : cst)) {
            if (kind == KIND_DENS)
                memcpy(&uniform, arr[kind], 4);
            arr[kind] = NULL;
        }
        need = need || arr[kind] != NULL;
    }
    const float zero = 0.0f;
    if (!need && same_bits(&uniform, &zero, sizeof(float)))
        return true; /* reads as an absent block */
    journal_block_t *b = sh_touch(s, v->key);
    if (b == NULL)
        return false;
    b->uniform = uniform;
    for (int kind = 0; kind <= KIND_RGB; kind++) {
        if (arr[kind] == NULL)
            continue;
        if (!sh_arr_make(s, b, kind))
            return false;
        uint8_t cst[4];
        memcpy(sh_arr(b, kind, cst), arr[kind], kind_bytes(kind) * GRID_BN);
    }
    return true;
}

/* s (empty) becomes a copy of the grid's blocks that meet the sample box [gl, gh); false when
 * out of memory (s then holds part: sh_free it). */
static bool shadow_take(journal_shadow_t *s, const grid_t *g, const int32_t gl[3],
                        const int32_t gh[3])
{
    if (block_table_init(&s->blocks, sizeof(journal_block_t), SHADOW_CAP0) != ARGIL_OK)
        return false;
    size_t slot = 0;
    grid_block_view_t v;
    while (grid_block_next(g, &slot, &v)) {
        int32_t a0[3], a1[3];
        if (block_clip(v.key, gl, gh, a0, a1) && !sh_copy_block(s, g, &v))
            return false;
    }
    return true;
}

/* Dense copies over the journal's box of its shadow: densities, each channel the journal has
 * seen painted (the others NULL) and the colour once seen (else NULL). */
static argil_err_t shadow_dense(const journal_t *j, float **dens, float *mat[GRID_MAT_N],
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
        dense_all_free(dens, mat, rgb);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        (*dens)[i] = 0.0f;
    const int32_t gh[3] = {j->lo[0] + j->dims[0], j->lo[1] + j->dims[1], j->lo[2] + j->dims[2]};
    const size_t nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    size_t slot = 0;
    for (const journal_block_t *b; (b = block_table_next(&j->shadow.blocks, &slot)) != NULL;) {
        int32_t a0[3], a1[3];
        if (!block_clip(b->key, j->lo, gh, a0, a1))
            continue;
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++)
                for (int32_t x = a0[0]; x < a1[0]; x++) {
                    const size_t li = block_local(b->key, x, y, z);
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

size_t journal_bytes(const journal_t *j)
{
    return block_table_bytes(&j->shadow.blocks) + j->shadow.arrays_bytes + j->buf_cap +
           j->views_cap * sizeof(grid_block_view_t);
}

/* Writes the model given densely over the journal's box (densities, painted channels, colour),
 * with the journal's grid, material and edits, to path as .argil. */
static argil_err_t write_dense_model(const journal_t *j, uint32_t edits, const float *dens,
                                     float *const mat[GRID_MAT_N], const uint8_t *rgb,
                                     const char *path, char *err, size_t err_len)
{
    journal_info_t info;
    writer_info(j, edits, &info);
    argil_doc_t doc;
    argil_doc_init(&doc);
    argil_err_t e = journal_model_doc(&info, dens, mat, &doc);
    if (e == ARGIL_OK && !doc_set_rgb(&doc, rgb, j->n))
        e = ARGIL_ERR_NOMEM;
    if (e != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", path);
        argil_doc_free(&doc);
        return e;
    }
    e = argil_file_write(path, &doc, err, err_len);
    argil_doc_free(&doc);
    return e;
}

argil_err_t journal_write_model(const journal_t *j, const grid_t *g, uint32_t edits,
                                const char *path, char *err, size_t err_len)
{
    if ((g == NULL && !j->ready) || (g != NULL && !journal_fits(j, g))) {
        io_err(err, err_len, "%s: the journal holds no model (or not this grid's)", path);
        return ARGIL_ERR_STATE;
    }
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = g != NULL ? grid_dense_all(g, j->lo, j->dims, &dens, mat, &rgb)
                              : shadow_dense(j, &dens, mat, &rgb);
    if (e != ARGIL_OK)
        io_err(err, err_len, "%s: out of memory for the model", path);
    else
        e = write_dense_model(j, edits, dens, mat, rgb, path, err, err_len);
    dense_all_free(&dens, mat, &rgb);
    return e;
}

/* ---- writer ---- */

static void encode_header(const journal_t *j, const char *base, uint64_t base_len,
                          uint32_t base_crc, uint32_t base_edits, uint8_t h[JOURNAL_HEADER_BYTES])
{
    memset(h, 0, JOURNAL_HEADER_BYTES);
    memcpy(h, JOURNAL_MAGIC, 8);
    io_put_u32le(h + 8, JOURNAL_VERSION);
    io_put_u32le(h + 12, JOURNAL_HEADER_BYTES);
    for (int a = 0; a < 3; a++)
        io_put_u32le(h + 16 + 4 * a, (uint32_t)j->dims[a]);
    io_put_f32le(h + 28, j->spacing_m);
    io_put_f32le(h + 32, j->origin_m.x);
    io_put_f32le(h + 36, j->origin_m.y);
    io_put_f32le(h + 40, j->origin_m.z);
    io_put_f32le(h + 44, j->iso);
    io_put_f32le(h + 48, j->band_m);
    put_material(h + 52, &j->material);
    io_put_u32le(h + 72, j->checkpoint);
    io_put_u32le(h + 76, j->seq + 1u);
    put_u64(h + 80, base_len);
    io_put_u32le(h + 88, base_crc);
    io_put_u32le(h + 92, base_edits);
    memcpy(h + 96, base, strlen(base));
    io_put_u32le(h + JOURNAL_HEADER_BYTES - 4, crc32c(0, h, JOURNAL_HEADER_BYTES - 4));
}

/* Writes base snapshot number j->checkpoint from the shadow, then a new journal.log (via
 * journal.log.tmp + rename) that starts on it; leaves the new file open in j->fd. The model is
 * made dense over the journal's box for the while (the .argil and the base CRC need it). */
static argil_err_t start_file(journal_t *j, uint32_t edits, char *err, size_t err_len)
{
    char base[JOURNAL_BASE_NAME_MAX + 1];
    base_name(j->checkpoint, base);
    char *base_path = path_join(j->dir, base);
    char *log_path = path_join(j->dir, JOURNAL_FILE);
    char *tmp_path = path_join(j->dir, JOURNAL_FILE ".tmp");
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = ARGIL_ERR_NOMEM;
    int fd = -1;
    if (base_path == NULL || log_path == NULL || tmp_path == NULL ||
        shadow_dense(j, &dens, mat, &rgb) != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the journal", j->dir);
        goto out;
    }
    e = write_dense_model(j, edits, dens, mat, rgb, base_path, err, err_len);
    if (e != ARGIL_OK)
        goto out;
    const uint32_t crc = model_crc(dens, mat, rgb, j->n);
    dense_all_free(&dens, mat, &rgb);
    struct stat st;
    if (stat(base_path, &st) != 0) {
        io_err(err, err_len, "%s: cannot stat: %s", base_path, strerror(errno));
        e = ARGIL_ERR_IO;
        goto out;
    }
    uint8_t h[JOURNAL_HEADER_BYTES];
    encode_header(j, base, (uint64_t)st.st_size, crc, edits, h);
    fd = open(tmp_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    e = ARGIL_ERR_IO;
    if (fd < 0) {
        io_err(err, err_len, "%s: cannot create: %s", tmp_path, strerror(errno));
        goto out;
    }
    if (!write_all(fd, h, sizeof(h)) || fsync(fd) != 0) {
        io_err(err, err_len, "%s: cannot write: %s", tmp_path, strerror(errno));
        goto out;
    }
    if (rename(tmp_path, log_path) != 0) {
        io_err(err, err_len, "%s: cannot rename to %s: %s", tmp_path, log_path, strerror(errno));
        goto out;
    }
    sync_dir(j->dir);
    if (j->fd >= 0)
        (void)close(j->fd);
    j->fd = fd;
    fd = -1;
    j->file_bytes = JOURNAL_HEADER_BYTES;
    e = ARGIL_OK;
out:
    dense_all_free(&dens, mat, &rgb);
    if (fd >= 0) {
        (void)close(fd);
        (void)unlink(tmp_path);
    }
    free(base_path);
    free(log_path);
    free(tmp_path);
    return e;
}

argil_err_t journal_open(journal_t *j, const char *dir, const grid_t *g, const journal_cfg_t *cfg,
                         double sim_s, double real_s, char *err, size_t err_len)
{
    memset(j, 0, sizeof(*j));
    j->fd = -1;
    if (!(cfg->autosave_s > 0.0f) || !(cfg->checkpoint_s > 0.0f) || cfg->checkpoint_bytes == 0 ||
        grid_count(g) == 0) {
        io_err(err, err_len, "journal: autosave and checkpoint intervals must be > 0");
        return ARGIL_ERR_ARG;
    }
    j->cfg = *cfg;
    int32_t glo[3], ghi[3];
    grid_bounds(g, glo, ghi);
    for (int a = 0; a < 3; a++) {
        j->lo[a] = glo[a];
        j->dims[a] = ghi[a] - glo[a];
    }
    j->spacing_m = g->spacing_m;
    j->origin_m = grid_box_origin(g, glo);
    j->iso = g->iso;
    j->band_m = g->band_m;
    j->material = g->material;
    j->n = (size_t)j->dims[0] * (size_t)j->dims[1] * (size_t)j->dims[2];
    j->dir = strdup(dir);
    if (j->dir == NULL || !journal_fits(j, g) || !shadow_take(&j->shadow, g, glo, ghi)) {
        io_err(err, err_len, "%s: out of memory for the journal", dir);
        journal_close(j);
        return ARGIL_ERR_NOMEM;
    }
    j->ready = true;
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        j->mat_seen[ch] = grid_mat_painted(g, (grid_mat_t)ch);
    j->mat_writes = g->mat_writes;
    j->rgb_seen = grid_rgb_any(g);
    j->rgb_writes = g->rgb_writes;
    if (journal_exists(dir)) {
        io_err(err, err_len, "%s holds an unfinished session's journal: run 'argil recover %s' "
                             "or start with --discard-journal", dir, dir);
        journal_close(j);
        return ARGIL_ERR_STATE;
    }
    (void)journal_discard(dir, NULL, 0); /* bases a crash left without a journal */
    const argil_err_t e = start_file(j, 0, err, err_len);
    if (e != ARGIL_OK) {
        journal_close(j);
        return e;
    }
    j->checkpoint_sim_s = sim_s;
    (void)real_s;
    return ARGIL_OK;
}

static bool reserve(journal_t *j, size_t more)
{
    if (j->buf_cap - j->buf_len >= more)
        return true;
    size_t cap = j->buf_cap ? j->buf_cap : 65536;
    while (cap - j->buf_len < more)
        cap *= 2;
    uint8_t *p = realloc(j->buf, cap);
    if (p == NULL)
        return false;
    j->buf = p;
    j->buf_cap = cap;
    return true;
}

/* Room in j->views for n blocks; false when out of memory. */
static bool views_reserve(journal_t *j, size_t n)
{
    if (n <= j->views_cap)
        return true;
    size_t cap = j->views_cap > 0 ? j->views_cap : 64;
    while (cap < n)
        cap *= 2;
    grid_block_view_t *v = realloc(j->views, cap * sizeof(*v));
    if (v == NULL)
        return false;
    j->views = v;
    j->views_cap = cap;
    return true;
}

/* True when the grid's block v and the shadow's block b (NULL: absent) differ in kind inside
 * the sample box [gl, gh); two blocks without arrays compare in one step. */
static bool block_differs(const grid_t *g, const grid_block_view_t *v, const journal_block_t *b,
                          int kind, const int32_t gl[3], const int32_t gh[3])
{
    int32_t a0[3], a1[3];
    if (!block_clip(v->key, gl, gh, a0, a1))
        return false;
    uint8_t lc[4], sc[4];
    const uint8_t *la = live_arr(g, v, kind, lc), *sa = sh_arr(b, kind, sc);
    const size_t es = kind_bytes(kind), w = (size_t)(a1[0] - a0[0]);
    if (la == NULL && sa == NULL)
        return memcmp(lc, sc, es) != 0;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const size_t li = block_local(v->key, a0[0], y, z);
            if (la != NULL && sa != NULL) {
                if (memcmp(la + es * li, sa + es * li, es * w) != 0)
                    return true;
                continue;
            }
            const uint8_t *arr = (la != NULL ? la : sa) + es * li, *c = la != NULL ? sc : lc;
            for (size_t x = 0; x < w; x++)
                if (memcmp(arr + es * x, c, es) != 0)
                    return true;
        }
    return false;
}

/* Orders blocks as their samples come in the journal's sample order: z, then y, then x. */
static int view_order(const void *pa, const void *pb)
{
    const grid_block_view_t *a = pa, *b = pb;
    for (int q = 2; q >= 0; q--)
        if (a->key[q] != b->key[q])
            return a->key[q] < b->key[q] ? -1 : 1;
    return 0;
}

/* The blocks meeting the sample box [gl, gh) whose kind differs between the grid and the
 * shadow, in sample order, into j->views[0, *count). Looks only at blocks one of them holds
 * (a block neither holds reads the same in both). false when out of memory. */
static bool changed_blocks(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                           const int32_t gh[3], size_t *count)
{
    *count = 0;
    int32_t k0[3], k1[3];
    uint64_t nk = 1;
    for (int a = 0; a < 3; a++) {
        if (gh[a] <= gl[a])
            return true;
        k0[a] = grid_block_index(gl[a]);
        k1[a] = grid_block_index(gh[a] - 1);
        nk *= (uint64_t)(k1[a] - k0[a] + 1);
    }
    const size_t held = g->blocks.count + j->shadow.blocks.count;
    if (!views_reserve(j, nk < (uint64_t)held ? (size_t)nk : held))
        return false;
    size_t n = 0;
    grid_block_view_t v;
    if (nk <= (uint64_t)held) { /* every block index of the box, already in order */
        int32_t k[3];
        for (k[2] = k0[2]; k[2] <= k1[2]; k[2]++)
            for (k[1] = k0[1]; k[1] <= k1[1]; k[1]++)
                for (k[0] = k0[0]; k[0] <= k1[0]; k[0]++) {
                    (void)grid_block_view(g, k, &v);
                    if (block_differs(g, &v, sh_find(&j->shadow, k), kind, gl, gh))
                        j->views[n++] = v;
                }
        *count = n;
        return true;
    }
    /* The blocks either side holds for kind, sorted, each once. */
    int32_t a0[3], a1[3];
    uint8_t cst[4];
    for (size_t slot = 0; grid_block_next(g, &slot, &v);)
        if (block_clip(v.key, gl, gh, a0, a1) &&
            (kind == KIND_DENS || live_arr(g, &v, kind, cst) != NULL))
            j->views[n++] = v;
    size_t sslot = 0;
    for (const journal_block_t *b; (b = block_table_next(&j->shadow.blocks, &sslot)) != NULL;) {
        if (block_clip(b->key, gl, gh, a0, a1) &&
            (kind == KIND_DENS || sh_arr(b, kind, cst) != NULL)) {
            (void)grid_block_view(g, b->key, &v);
            j->views[n++] = v;
        }
    }
    if (n > 1)
        qsort(j->views, n, sizeof(*j->views), view_order);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && view_order(&j->views[i], &j->views[i - 1]) == 0)
            continue;
        if (block_differs(g, &j->views[i], sh_find(&j->shadow, j->views[i].key), kind, gl, gh))
            j->views[m++] = j->views[i];
    }
    *count = m;
    return true;
}

/* A record's runs of one kind being made. */
typedef struct {
    journal_t *j;
    const grid_t *g;
    int kind;
    bool open;                /* a run [start, end) is open */
    size_t start, end;        /* journal sample indices */
    uint32_t runs;            /* written */
    grid_block_view_t lv;     /* the grid block last read */
    bool lv_ok;
    journal_block_t *sb;      /* the shadow block last written (NULL: absent) */
    int32_t sb_key[3];
    bool sb_ok;
} emit_t;

/* Appends the run [start, end) of the grid's current values to the open record and to the
 * shadow; false when out of memory. */
static bool put_run(emit_t *e, size_t start, size_t end)
{
    journal_t *j = e->j;
    const size_t count = end - start, es = kind_bytes(e->kind);
    if (!reserve(j, 8 + es * count))
        return false;
    uint8_t *p = j->buf + j->buf_len;
    io_put_u32le(p, (uint32_t)start);
    io_put_u32le(p + 4, (uint32_t)count);
    const size_t nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    for (size_t i = start; i < end; i++) {
        const int32_t x = j->lo[0] + (int32_t)(i % nx), y = j->lo[1] + (int32_t)(i / nx % ny),
                      z = j->lo[2] + (int32_t)(i / (nx * ny));
        const int32_t k[3] = {grid_block_index(x), grid_block_index(y), grid_block_index(z)};
        const size_t li = block_local(k, x, y, z);
        if (!e->lv_ok || memcmp(e->lv.key, k, sizeof(k)) != 0) {
            (void)grid_block_view(e->g, k, &e->lv);
            e->lv_ok = true;
        }
        uint8_t lc[4], sc[4];
        const uint8_t *la = live_arr(e->g, &e->lv, e->kind, lc);
        const uint8_t *val = la != NULL ? la + es * li : lc;
        uint8_t *out = p + 8 + es * (i - start);
        if (es == 4) {
            float f;
            memcpy(&f, val, 4);
            io_put_f32le(out, f);
        } else {
            memcpy(out, val, es);
        }
        if (!e->sb_ok || memcmp(e->sb_key, k, sizeof(k)) != 0) {
            e->sb = sh_find(&j->shadow, k);
            memcpy(e->sb_key, k, sizeof(k));
            e->sb_ok = true;
        }
        uint8_t *sa = sh_arr(e->sb, e->kind, sc);
        if (sa == NULL) {
            if (memcmp(val, sc, es) == 0)
                continue;
            if (e->sb == NULL && (e->sb = sh_touch(&j->shadow, k)) == NULL)
                return false;
            if (!sh_arr_make(&j->shadow, e->sb, e->kind))
                return false;
            sa = sh_arr(e->sb, e->kind, sc);
        }
        memcpy(sa + es * li, val, es);
    }
    j->buf_len += 8 + es * count;
    if (e->kind == KIND_DENS)
        j->stats.samples += count;
    else if (e->kind == KIND_RGB)
        j->stats.rgb_samples += count;
    else
        j->stats.mat_samples += count;
    return true;
}

/* Sample i (journal index, increasing) differs: it joins the open run when at most
 * JOURNAL_RUN_GAP unchanged samples lie between (they are written too), else the open run is
 * written and a new one starts. false when out of memory. */
static bool emit_sample(emit_t *e, size_t i)
{
    if (e->open && i - e->end <= JOURNAL_RUN_GAP) {
        e->end = i + 1;
        return true;
    }
    if (e->open) {
        if (!put_run(e, e->start, e->end))
            return false;
        e->runs++;
    }
    e->open = true;
    e->start = i;
    e->end = i + 1;
    return true;
}

/* Appends as runs, in sample order, the samples of kind inside [gl, gh) that differ between the
 * grid and the shadow, over the changed blocks j->views[0, nviews), and brings the shadow up to
 * date; then drops the shadow arrays that became uniform. *runs counts the runs. false when out
 * of memory. */
static bool put_changes(journal_t *j, const grid_t *g, int kind, const int32_t gl[3],
                        const int32_t gh[3], size_t nviews, uint32_t *runs)
{
    emit_t e;
    memset(&e, 0, sizeof(e));
    e.j = j;
    e.g = g;
    e.kind = kind;
    const size_t es = kind_bytes(kind), nx = (size_t)j->dims[0], ny = (size_t)j->dims[1];
    const grid_block_view_t *vs = j->views;
    for (size_t a = 0; a < nviews;) {
        size_t b = a; /* [a, b): one slab of blocks (same z index) */
        while (b < nviews && vs[b].key[2] == vs[a].key[2])
            b++;
        const int32_t bz = vs[a].key[2] * GRID_B;
        const int32_t z0 = bz > gl[2] ? bz : gl[2], z1 = bz + GRID_B < gh[2] ? bz + GRID_B : gh[2];
        for (int32_t z = z0; z < z1; z++)
            for (size_t c = a; c < b;) {
                size_t d = c; /* [c, d): one row of blocks (same y index) */
                while (d < b && vs[d].key[1] == vs[c].key[1])
                    d++;
                const int32_t by = vs[c].key[1] * GRID_B;
                const int32_t y0 = by > gl[1] ? by : gl[1];
                const int32_t y1 = by + GRID_B < gh[1] ? by + GRID_B : gh[1];
                for (int32_t y = y0; y < y1; y++)
                    for (size_t q = c; q < d; q++) {
                        const int32_t bx = vs[q].key[0] * GRID_B;
                        const int32_t x0 = bx > gl[0] ? bx : gl[0];
                        const int32_t x1 = bx + GRID_B < gh[0] ? bx + GRID_B : gh[0];
                        /* This row's samples of both, copied before a run may write the
                         * shadow (only samples before the current one). */
                        uint8_t lc[4], sc[4], lrow[4 * GRID_B], srow[4 * GRID_B];
                        const uint8_t *la = live_arr(g, &vs[q], kind, lc);
                        const uint8_t *sa = sh_arr(sh_find(&j->shadow, vs[q].key), kind, sc);
                        const size_t li = block_local(vs[q].key, x0, y, z);
                        const size_t w = (size_t)(x1 - x0);
                        for (size_t x = 0; x < w; x++) {
                            memcpy(lrow + es * x, la != NULL ? la + es * (li + x) : lc, es);
                            memcpy(srow + es * x, sa != NULL ? sa + es * (li + x) : sc, es);
                        }
                        if (memcmp(lrow, srow, es * w) == 0)
                            continue;
                        const size_t i0 = (size_t)(x0 - j->lo[0]) +
                                          nx * ((size_t)(y - j->lo[1]) + ny * (size_t)(z - j->lo[2]));
                        for (size_t x = 0; x < w; x++)
                            if (memcmp(lrow + es * x, srow + es * x, es) != 0 &&
                                !emit_sample(&e, i0 + x))
                                return false;
                    }
                c = d;
            }
        a = b;
    }
    if (e.open) {
        if (!put_run(&e, e.start, e.end))
            return false;
        e.runs++;
    }
    for (size_t q = 0; q < nviews; q++) {
        journal_block_t *sb = sh_find(&j->shadow, vs[q].key);
        if (sb != NULL)
            sh_arr_compact(&j->shadow, sb, kind);
    }
    *runs = e.runs;
    return true;
}

/* The clay grew past the journal's box: everything buffered is written, the shadow takes the
 * whole grid over its new bounds and a checkpoint makes that the new base (header and base file
 * with the new box). */
static argil_err_t journal_rebase(journal_t *j, const grid_t *g, uint32_t edits, double sim_s,
                                  char *err, size_t err_len)
{
    argil_err_t e = journal_sync(j, err, err_len);
    if (e != ARGIL_OK)
        return e;
    /* The new box: the old one and the bounds, with room to grow on every side that grew (so a
     * growing stroke rebases every JOURNAL_GROW_SAMPLES, not every sample). */
    int32_t glo[3], ghi[3], dims[3];
    grid_bounds(g, glo, ghi);
    for (int a = 0; a < 3; a++) {
        const int32_t olo = j->lo[a], ohi = j->lo[a] + j->dims[a];
        glo[a] = glo[a] < olo ? glo[a] - JOURNAL_GROW_SAMPLES : olo;
        ghi[a] = ghi[a] > ohi ? ghi[a] + JOURNAL_GROW_SAMPLES : ohi;
        dims[a] = ghi[a] - glo[a];
    }
    journal_shadow_t sh;
    memset(&sh, 0, sizeof(sh));
    if (!shadow_take(&sh, g, glo, ghi)) {
        sh_free(&sh);
        io_err(err, err_len, "%s: out of memory for the journal of the grown clay", j->dir);
        return ARGIL_ERR_NOMEM;
    }
    sh_free(&j->shadow);
    j->shadow = sh;
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        j->mat_seen[ch] = grid_mat_painted(g, (grid_mat_t)ch);
    j->rgb_seen = grid_rgb_any(g);
    j->rgb_writes = g->rgb_writes;
    for (int a = 0; a < 3; a++) {
        j->lo[a] = glo[a];
        j->dims[a] = dims[a];
    }
    j->n = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    j->origin_m = grid_box_origin(g, glo);
    j->material = g->material;
    j->mat_writes = g->mat_writes;
    j->edits = edits;
    j->stats.rebases++;
    return journal_checkpoint(j, sim_s, err, err_len);
}

argil_err_t journal_record(journal_t *j, const grid_t *g, const journal_box_t *box,
                           uint32_t edits, double sim_s, double real_s, uint64_t wall_ms,
                           bool *appended, char *err, size_t err_len)
{
    *appended = false;
    if (!j->ready) {
        io_err(err, err_len, "journal: not open (or stopped by an earlier failure)");
        return ARGIL_ERR_STATE;
    }
    if (!journal_fits(j, g)) {
        if (g->spacing_m != j->spacing_m) {
            io_err(err, err_len, "journal: the grid is not the one the journal was opened on");
            return ARGIL_ERR_ARG;
        }
        const argil_err_t re = journal_rebase(j, g, edits, sim_s, err, err_len);
        *appended = re == ARGIL_OK;
        return re;
    }
    const bool material_changed = !same_bits(&g->material, &j->material, sizeof(j->material));
    /* The box to compare (grid sample indices), clipped to the journal's. */
    const int32_t jl[3] = {j->lo[0], j->lo[1], j->lo[2]};
    const int32_t jh[3] = {j->lo[0] + j->dims[0], j->lo[1] + j->dims[1], j->lo[2] + j->dims[2]};
    int32_t gl[3] = {jl[0], jl[1], jl[2]}, gh[3] = {jh[0], jh[1], jh[2]};
    if (box != NULL) {
        for (int a = 0; a < 3; a++) {
            gl[a] = box->lo[a] < jl[a] ? jl[a] : (box->lo[a] > jh[a] ? jh[a] : box->lo[a]);
            gh[a] = box->hi[a] < gl[a] ? gl[a] : (box->hi[a] > jh[a] ? jh[a] : box->hi[a]);
        }
    }
    const size_t rec_at = j->buf_len;
    size_t nviews = 0;
    if (!changed_blocks(j, g, KIND_DENS, gl, gh, &nviews) ||
        !reserve(j, 4 + JOURNAL_RECORD_HEAD_BYTES)) {
        io_err(err, err_len, "%s: out of memory for journal records", j->dir);
        return ARGIL_ERR_NOMEM; /* nothing written yet: the journal goes on */
    }
    j->buf_len += 4 + JOURNAL_RECORD_HEAD_BYTES;
    uint32_t runs = 0;
    if (!put_changes(j, g, KIND_DENS, gl, gh, nviews, &runs))
        goto nomem;
    /* Painted channels: over the whole box, when they may have changed (record type 2); then
     * the painted colour likewise (type 3: the material block count, maybe 0, always precedes
     * it). */
    uint32_t blocks = 0, rgb_runs = 0;
    const bool look_mat = box == NULL || g->mat_writes != j->mat_writes;
    const bool look_rgb = box == NULL || g->rgb_writes != j->rgb_writes;
    const size_t blocks_at = j->buf_len;
    if (look_mat || look_rgb) {
        if (!reserve(j, 4))
            goto nomem;
        j->buf_len += 4;
    }
    for (int ch = 0; look_mat && ch < GRID_MAT_N; ch++) {
        if (grid_mat_painted(g, (grid_mat_t)ch))
            j->mat_seen[ch] = true;
        if (!j->mat_seen[ch])
            continue;
        const size_t at = j->buf_len;
        uint32_t mruns = 0;
        if (!reserve(j, 8) || !changed_blocks(j, g, KIND_MAT0 + ch, jl, jh, &nviews))
            goto nomem;
        j->buf_len += 8;
        if (!put_changes(j, g, KIND_MAT0 + ch, jl, jh, nviews, &mruns))
            goto nomem;
        if (mruns == 0) {
            j->buf_len = at;
            continue;
        }
        io_put_u32le(j->buf + at, (uint32_t)ch);
        io_put_u32le(j->buf + at + 4, mruns);
        blocks++;
    }
    if (look_mat)
        j->mat_writes = g->mat_writes;
    if (look_rgb) {
        if (grid_rgb_any(g))
            j->rgb_seen = true;
        const size_t rgb_at = j->buf_len;
        if (!reserve(j, 4) || !changed_blocks(j, g, KIND_RGB, jl, jh, &nviews))
            goto nomem;
        j->buf_len += 4;
        if (!put_changes(j, g, KIND_RGB, jl, jh, nviews, &rgb_runs))
            goto nomem;
        if (rgb_runs == 0)
            j->buf_len = rgb_at;
        else
            io_put_u32le(j->buf + rgb_at, rgb_runs);
        j->rgb_writes = g->rgb_writes;
    }
    if (blocks == 0 && rgb_runs == 0)
        j->buf_len = blocks_at;
    else
        io_put_u32le(j->buf + blocks_at, blocks);
    if (runs == 0 && !material_changed && blocks == 0 && rgb_runs == 0) {
        j->buf_len = rec_at;
        return ARGIL_OK;
    }
    const size_t payload = j->buf_len - rec_at - 4;
    if ((uint64_t)payload + 8 >= JOURNAL_RECORD_MAX_BYTES || !reserve(j, 4))
        goto nomem;
    j->material = g->material;
    j->edits = edits;
    j->seq++;
    uint8_t *p = j->buf + rec_at;
    io_put_u32le(p, (uint32_t)payload);
    uint8_t *h = p + 4;
    /* record type: edit step (2: with painted material, 3: with painted colour) */
    io_put_u32le(h, rgb_runs > 0 ? 3u : (blocks > 0 ? 2u : 1u));
    io_put_u32le(h + 4, j->seq);
    const double sim_us = sim_s > 0.0 ? sim_s * 1e6 + 0.5 : 0.0;
    put_u64(h + 8, (uint64_t)sim_us);
    put_u64(h + 16, wall_ms);
    io_put_u32le(h + 24, edits);
    put_material(h + 28, &j->material);
    io_put_u32le(h + 48, runs);
    io_put_u32le(j->buf + j->buf_len, crc32c(0, p, 4 + payload));
    j->buf_len += 4;
    const size_t rec_bytes = j->buf_len - rec_at;
    if (rec_at == 0) {
        j->oldest_pending_sim_s = sim_s;
        j->oldest_pending_real_s = real_s;
    }
    j->file_bytes += rec_bytes;
    j->stats.records++;
    j->stats.bytes += rec_bytes;
    *appended = true;
    return ARGIL_OK;
nomem:
    /* The shadow may already hold part of this step: the journal cannot go on consistently.
     * The whole records before this one stay buffered and can still be synced. */
    j->buf_len = rec_at;
    io_err(err, err_len, "%s: out of memory for journal records", j->dir);
    sh_free(&j->shadow);
    j->ready = false;
    return ARGIL_ERR_NOMEM;
}

argil_err_t journal_sync(journal_t *j, char *err, size_t err_len)
{
    if (j->buf_len == 0)
        return ARGIL_OK;
    if (j->fd < 0) {
        io_err(err, err_len, "%s/" JOURNAL_FILE ": the journal is not open", j->dir);
        return ARGIL_ERR_STATE;
    }
    if (!write_all(j->fd, j->buf, j->buf_len) || fdatasync(j->fd) != 0) {
        io_err(err, err_len, "%s/" JOURNAL_FILE ": cannot write: %s", j->dir, strerror(errno));
        return ARGIL_ERR_IO;
    }
    j->buf_len = 0;
    j->stats.syncs++;
    return ARGIL_OK;
}

argil_err_t journal_checkpoint(journal_t *j, double sim_s, char *err, size_t err_len)
{
    argil_err_t e = journal_sync(j, err, err_len);
    if (e != ARGIL_OK)
        return e;
    /* The base holds the model as of the last record; the new journal starts after it. */
    const uint32_t old = j->checkpoint;
    j->checkpoint = old + 1u;
    e = start_file(j, j->edits, err, err_len);
    if (e != ARGIL_OK) {
        j->checkpoint = old;
        return e;
    }
    char name[JOURNAL_BASE_NAME_MAX + 1];
    base_name(old, name);
    char *p = path_join(j->dir, name);
    if (p != NULL)
        (void)unlink(p);
    free(p);
    j->checkpoint_sim_s = sim_s;
    j->stats.checkpoints++;
    return ARGIL_OK;
}

bool journal_sync_due(const journal_t *j, double sim_s, double real_s)
{
    return j->buf_len > 0 && (sim_s - j->oldest_pending_sim_s >= (double)j->cfg.autosave_s ||
                              real_s - j->oldest_pending_real_s >= (double)j->cfg.autosave_s);
}

argil_err_t journal_tick(journal_t *j, double sim_s, double real_s, char *err, size_t err_len)
{
    if (journal_sync_due(j, sim_s, real_s)) {
        const argil_err_t e = journal_sync(j, err, err_len);
        if (e != ARGIL_OK)
            return e;
    }
    if (sim_s - j->checkpoint_sim_s >= (double)j->cfg.checkpoint_s ||
        j->file_bytes >= j->cfg.checkpoint_bytes)
        return journal_checkpoint(j, sim_s, err, err_len);
    return ARGIL_OK;
}

void journal_close(journal_t *j)
{
    if (j->fd >= 0)
        (void)close(j->fd);
    j->fd = -1;
    free(j->dir);
    j->dir = NULL;
    sh_free(&j->shadow);
    j->ready = false;
    free(j->views);
    j->views = NULL;
    j->views_cap = 0;
    free(j->buf);
    j->buf = NULL;
    j->buf_len = j->buf_cap = 0;
}

argil_err_t journal_finish(journal_t *j, char *err, size_t err_len)
{
    if (j->dir == NULL) {
        journal_close(j);
        return ARGIL_OK;
    }
    char *dir = strdup(j->dir);
    journal_close(j);
    if (dir == NULL) {
        io_err(err, err_len, "out of memory");
        return ARGIL_ERR_NOMEM;
    }
    const argil_err_t e = journal_discard(dir, err, err_len);
    free(dir);
    return e;
}

bool journal_exists(const char *dir)
{
    char *p = path_join(dir, JOURNAL_FILE);
    struct stat st;
    const bool yes = p != NULL && stat(p, &st) == 0 && S_ISREG(st.st_mode);
    free(p);
    return yes;
}

argil_err_t journal_discard(const char *dir, char *err, size_t err_len)
{
    /* The journal first: once it is gone no base is needed. */
    char *p = path_join(dir, JOURNAL_FILE);
    if (p == NULL) {
        io_err(err, err_len, "out of memory");
        return ARGIL_ERR_NOMEM;
    }
    if (unlink(p) != 0 && errno != ENOENT) {
        io_err(err, err_len, "%s: cannot remove: %s", p, strerror(errno));
        free(p);
        return ARGIL_ERR_IO;
    }
    free(p);
    DIR *d = opendir(dir);
    if (d == NULL)
        return ARGIL_OK;
    const size_t plen = strlen(JOURNAL_BASE_PREFIX);
    struct dirent *ent;
    while ((ent = readdir(d)) != NULL) {
        const char *name = ent->d_name;
        const size_t len = strlen(name);
        const bool base = strncmp(name, JOURNAL_BASE_PREFIX, plen) == 0 &&
                          (len > 6 && (strcmp(name + len - 6, ".argil") == 0 ||
                                       (len > 10 && strcmp(name + len - 10, ".argil.tmp") == 0)));
        if (!base && strcmp(name, JOURNAL_FILE ".tmp") != 0)
            continue;
        char *q = path_join(dir, name);
        if (q != NULL)
            (void)unlink(q);
        free(q);
    }
    closedir(d);
    sync_dir(dir);
    return ARGIL_OK;
}

/* ---- reader ---- */

static argil_err_t fail(char *err, size_t err_len, const char *name, size_t byte, const char *why)
{
    io_err(err, err_len, "%s: byte %zu: %s", name, byte, why);
    return ARGIL_ERR_PARSE;
}

argil_err_t journal_header_decode(const uint8_t *data, size_t len, const char *name,
                                  journal_info_t *info, char *err, size_t err_len)
{
    memset(info, 0, sizeof(*info));
    if (len < JOURNAL_HEADER_BYTES)
        return fail(err, err_len, name, len, "file shorter than the journal header");
    if (memcmp(data, JOURNAL_MAGIC, 8) != 0)
        return fail(err, err_len, name, 0, "not an argil journal");
    if (io_get_u32le(data + JOURNAL_HEADER_BYTES - 4) !=
        crc32c(0, data, JOURNAL_HEADER_BYTES - 4))
        return fail(err, err_len, name, JOURNAL_HEADER_BYTES - 4, "header checksum mismatch");
    info->version = io_get_u32le(data + 8);
    if (info->version < 1 || info->version > JOURNAL_VERSION)
        return fail(err, err_len, name, 8, "journal version (this argil reads 1..2)");
    if (io_get_u32le(data + 12) != JOURNAL_HEADER_BYTES)
        return fail(err, err_len, name, 12, "header size");
    int64_t n = 1;
    for (int a = 0; a < 3; a++) {
        const int32_t d = (int32_t)io_get_u32le(data + 16 + 4 * a);
        if (d < 1 || (n *= d) > GRID_SAMPLES_MAX)
            return fail(err, err_len, name, 16 + 4 * (size_t)a, "grid dimension below 1 or "
                                                               "more than 2^30 samples");
        info->dims[a] = d;
    }
    info->spacing_m = io_get_f32le(data + 28);
    info->origin_m = vec3(io_get_f32le(data + 32), io_get_f32le(data + 36),
                          io_get_f32le(data + 40));
    info->iso = io_get_f32le(data + 44);
    info->band_m = io_get_f32le(data + 48);
    if (!isfinite(info->spacing_m) || !(info->spacing_m > 0.0f) || !vec3_isfinite(info->origin_m) ||
        !isfinite(info->iso) || !isfinite(info->band_m))
        return fail(err, err_len, name, 28, "grid spacing, origin, iso or band not finite");
    get_material(data + 52, &info->material);
    if (!spring_material_valid(&info->material))
        return fail(err, err_len, name, 52, "material out of range");
    info->checkpoint = io_get_u32le(data + 72);
    info->first_seq = io_get_u32le(data + 76);
    if (info->first_seq == 0)
        return fail(err, err_len, name, 76, "first record number 0");
    info->last_seq = info->first_seq - 1u;
    info->base_len = get_u64(data + 80);
    info->base_crc = io_get_u32le(data + 88);
    info->edits = io_get_u32le(data + 92);
    const uint8_t *bn = data + 96;
    size_t bl = 0;
    while (bl < JOURNAL_BASE_NAME_MAX && bn[bl] != 0)
        bl++;
    for (size_t i = bl; i < JOURNAL_BASE_NAME_MAX; i++)
        if (bn[i] != 0)
            return fail(err, err_len, name, 96 + i, "base name not NUL-padded");
    if (bl == 0 || memchr(bn, '/', bl) != NULL || (bl <= 2 && bn[0] == '.'))
        return fail(err, err_len, name, 96, "base name empty or not a plain file name");
    for (size_t i = 0; i < bl; i++)
        if (bn[i] < 0x20 || bn[i] > 0x7e)
            return fail(err, err_len, name, 96 + i, "base name not printable ASCII");
    memcpy(info->base_name, bn, bl);
    info->base_name[bl] = '\0';
    info->good_bytes = JOURNAL_HEADER_BYTES;
    return ARGIL_OK;
}

/* Checks the painted-material blocks of a type-2 record (type 3: min_blocks 0) from payload
 * offset *off against n samples; advances *off past them and adds their values to *samples. */
static argil_err_t check_mat_blocks(const uint8_t *p, size_t payload, size_t *off, size_t at,
                                    const char *name, size_t n, uint32_t rec, uint32_t min_blocks,
                                    uint64_t *samples, char *err, size_t err_len)
{
    char why[200];
    size_t o = *off;
    if (payload - o < 4) {
        snprintf(why, sizeof(why), "record %u: material block count runs past the record", rec);
        return fail(err, err_len, name, at + 4 + o, why);
    }
    const uint32_t blocks = io_get_u32le(p + o);
    if (blocks < min_blocks || blocks > GRID_MAT_N) {
        snprintf(why, sizeof(why), "record %u: material block count %u not in %u..4", rec, blocks,
                 min_blocks);
        return fail(err, err_len, name, at + 4 + o, why);
    }
    o += 4;
    int64_t prev = -1;
    for (uint32_t k = 0; k < blocks; k++) {
        if (payload - o < 8) {
            snprintf(why, sizeof(why), "record %u: material block %u head runs past the record",
                     rec, k);
            return fail(err, err_len, name, at + 4 + o, why);
        }
        const uint32_t ch = io_get_u32le(p + o), runs = io_get_u32le(p + o + 4);
        if (ch >= GRID_MAT_N || (int64_t)ch <= prev || runs < 1) {
            snprintf(why, sizeof(why), "record %u: material block %u: channel %u not 0..3 in "
                     "increasing order, or no runs", rec, k, ch);
            return fail(err, err_len, name, at + 4 + o, why);
        }
        prev = (int64_t)ch;
        o += 8;
        for (uint32_t r = 0; r < runs; r++) {
            if (payload - o < 8) {
                snprintf(why, sizeof(why), "record %u: material run %u head runs past the record",
                         rec, r);
                return fail(err, err_len, name, at + 4 + o, why);
            }
            const uint64_t start = io_get_u32le(p + o), count = io_get_u32le(p + o + 4);
            if (count == 0 || start + count > (uint64_t)n || count > (payload - o - 8) / 4) {
                snprintf(why, sizeof(why), "record %u: material run %u (%llu samples from %llu) "
                         "empty, beyond the grid or past the record", rec, r,
                         (unsigned long long)count, (unsigned long long)start);
                return fail(err, err_len, name, at + 4 + o, why);
            }
            for (uint64_t i = 0; i < count; i++)
                if (!grid_mat_valid((grid_mat_t)ch, io_get_f32le(p + o + 8 + 4 * i))) {
                    snprintf(why, sizeof(why), "record %u: painted material value out of range "
                             "(finite; mass scale > 0, stiffness and damping scales >= 0)", rec);
                    return fail(err, err_len, name, at + 4 + o + 8 + 4 * (size_t)i, why);
                }
            o += 8 + 4 * (size_t)count;
            *samples += count;
        }
    }
    *off = o;
    return ARGIL_OK;
}

/* Checks the painted colour of a type-3 record (from payload offset *off: uint32 run count >= 1,
 * runs of uint32 first sample, uint32 count >= 1, 3 count bytes) against n samples; advances *off
 * past it and adds its samples to *samples. */
static argil_err_t check_rgb_runs(const uint8_t *p, size_t payload, size_t *off, size_t at,
                                  const char *name, size_t n, uint32_t rec, uint64_t *samples,
                                  char *err, size_t err_len)
{
    char why[200];
    size_t o = *off;
    if (payload - o < 4) {
        snprintf(why, sizeof(why), "record %u: colour run count runs past the record", rec);
        return fail(err, err_len, name, at + 4 + o, why);
    }
    const uint32_t runs = io_get_u32le(p + o);
    if (runs < 1) {
        snprintf(why, sizeof(why), "record %u: colour run count 0", rec);
        return fail(err, err_len, name, at + 4 + o, why);
    }
    o += 4;
    uint64_t next = 0; /* runs are in sample order and do not overlap */
    for (uint32_t r = 0; r < runs; r++) {
        if (payload - o < 8) {
            snprintf(why, sizeof(why), "record %u: colour run %u head runs past the record", rec,
                     r);
            return fail(err, err_len, name, at + 4 + o, why);
        }
        const uint64_t start = io_get_u32le(p + o), count = io_get_u32le(p + o + 4);
        if (count == 0 || start < next || start + count > (uint64_t)n ||
            count > (payload - o - 8) / 3) {
            snprintf(why, sizeof(why), "record %u: colour run %u (%llu samples from %llu) empty, "
                     "out of order, beyond the grid or past the record", rec, r,
                     (unsigned long long)count, (unsigned long long)start);
            return fail(err, err_len, name, at + 4 + o, why);
        }
        next = start + count;
        o += 8 + 3 * (size_t)count;
        *samples += count;
    }
    *off = o;
    return ARGIL_OK;
}

/* Applies the checked colour runs at payload offset off to the n-sample colour *rgb (made, every
 * sample GRID_RGB_DEFAULT, when absent). */
static argil_err_t apply_rgb_runs(const uint8_t *p, size_t off, uint8_t **rgb, size_t n,
                                  const char *name, char *err, size_t err_len)
{
    if (*rgb == NULL) {
        *rgb = malloc(3 * n);
        if (*rgb == NULL) {
            io_err(err, err_len, "%s: out of memory for the painted colour", name);
            return ARGIL_ERR_NOMEM;
        }
        memset(*rgb, (int)GRID_RGB_DEFAULT, 3 * n);
    }
    const uint32_t runs = io_get_u32le(p + off);
    size_t o = off + 4;
    for (uint32_t r = 0; r < runs; r++) {
        const size_t start = io_get_u32le(p + o), count = io_get_u32le(p + o + 4);
        memcpy(*rgb + 3 * start, p + o + 8, 3 * count);
        o += 8 + 3 * count;
    }
    return ARGIL_OK;
}

/* Applies the checked material blocks at payload offset off to the n-sample channels mat (an
 * absent one is made, every sample the default, before it is written). */
static argil_err_t apply_mat_blocks(const uint8_t *p, size_t off, float *mat[GRID_MAT_N],
                                    size_t n, const char *name, char *err, size_t err_len)
{
    const uint32_t blocks = io_get_u32le(p + off);
    size_t o = off + 4;
    /* Every channel the record touches exists before anything is written. */
    for (uint32_t k = 0; k < blocks; k++) {
        const uint32_t ch = io_get_u32le(p + o), runs = io_get_u32le(p + o + 4);
        if (mat[ch] == NULL) {
            mat[ch] = malloc(n * sizeof(float));
            if (mat[ch] == NULL) {
                io_err(err, err_len, "%s: out of memory for a painted material channel", name);
                return ARGIL_ERR_NOMEM;
            }
            const float def = grid_mat_default((grid_mat_t)ch);
            for (size_t i = 0; i < n; i++)
                mat[ch][i] = def;
        }
        o += 8;
        for (uint32_t r = 0; r < runs; r++)
            o += 8 + 4 * (size_t)io_get_u32le(p + o + 4);
    }
    o = off + 4;
    for (uint32_t k = 0; k < blocks; k++) {
        const uint32_t ch = io_get_u32le(p + o), runs = io_get_u32le(p + o + 4);
        float *m = mat[ch];
        o += 8;
        for (uint32_t r = 0; r < runs; r++) {
            const size_t start = io_get_u32le(p + o), count = io_get_u32le(p + o + 4);
            for (size_t i = 0; i < count; i++)
                m[start + i] = io_get_f32le(p + o + 8 + 4 * i);
            o += 8 + 4 * count;
        }
    }
    return ARGIL_OK;
}

/* Checks one record's payload (CRC already good) and, with density (and g), applies it. */
static argil_err_t apply_record(const uint8_t *p, size_t payload, size_t at, const char *name,
                                float *density, float **mat, uint8_t **rgb, size_t n,
                                journal_info_t *info, char *err, size_t err_len)
{
    char why[160];
    const uint32_t rec = info->records + 1u;
    if (payload < JOURNAL_RECORD_HEAD_BYTES) {
        snprintf(why, sizeof(why), "record %u: shorter than a record head", rec);
        return fail(err, err_len, name, at, why);
    }
    const uint32_t type = io_get_u32le(p);
    if (type != 1u && ((type != 2u && type != 3u) || info->version < 2u)) {
        snprintf(why, sizeof(why), "record %u: unknown record type %u", rec, type);
        return fail(err, err_len, name, at + 4, why);
    }
    const uint32_t seq = io_get_u32le(p + 4);
    if (seq != info->last_seq + 1u) {
        snprintf(why, sizeof(why), "record %u: number %u, expected %u", rec, seq,
                 info->last_seq + 1u);
        return fail(err, err_len, name, at + 8, why);
    }
    spring_material_t m;
    get_material(p + 28, &m);
    if (!spring_material_valid(&m)) {
        snprintf(why, sizeof(why), "record %u: material out of range", rec);
        return fail(err, err_len, name, at + 32, why);
    }
    const uint32_t runs = io_get_u32le(p + 48);
    /* Check every run before changing anything. */
    size_t off = JOURNAL_RECORD_HEAD_BYTES;
    uint64_t samples = 0, mat_samples = 0;
    for (uint32_t r = 0; r < runs; r++) {
        if (payload - off < 8) {
            snprintf(why, sizeof(why), "record %u: run %u head runs past the record", rec, r);
            return fail(err, err_len, name, at + 4 + off, why);
        }
        const uint64_t start = io_get_u32le(p + off), count = io_get_u32le(p + off + 4);
        if (count == 0 || start + count > (uint64_t)n || count > (payload - off - 8) / 4) {
            snprintf(why, sizeof(why),
                     "record %u: run %u (%llu samples from %llu) empty, beyond the grid or "
                     "past the record",
                     rec, r, (unsigned long long)count, (unsigned long long)start);
            return fail(err, err_len, name, at + 4 + off, why);
        }
        for (uint64_t i = 0; i < count; i++) {
            const float v = io_get_f32le(p + off + 8 + 4 * i);
            if (!isfinite(v) || v < 0.0f || v > 1.0f) {
                snprintf(why, sizeof(why), "record %u: density not a finite number in [0, 1]",
                         rec);
                return fail(err, err_len, name, at + 4 + off + 8 + 4 * (size_t)i, why);
            }
        }
        off += 8 + 4 * (size_t)count;
        samples += count;
    }
    const size_t mat_off = off;
    uint64_t rgb_samples = 0;
    size_t rgb_off = 0;
    if (type >= 2u) {
        argil_err_t e = check_mat_blocks(p, payload, &off, at, name, n, rec, type == 3u ? 0u : 1u,
                                         &mat_samples, err, err_len);
        rgb_off = off;
        if (e == ARGIL_OK && type == 3u)
            e = check_rgb_runs(p, payload, &off, at, name, n, rec, &rgb_samples, err, err_len);
        if (e != ARGIL_OK)
            return e;
    }
    if (off != payload) {
        snprintf(why, sizeof(why), "record %u: %zu bytes after the last run", rec, payload - off);
        return fail(err, err_len, name, at + 4 + off, why);
    }
    if (type >= 2u && mat != NULL && io_get_u32le(p + mat_off) > 0) {
        const argil_err_t e = apply_mat_blocks(p, mat_off, mat, n, name, err, err_len);
        if (e != ARGIL_OK)
            return e;
    }
    if (type == 3u && rgb != NULL) {
        const argil_err_t e = apply_rgb_runs(p, rgb_off, rgb, n, name, err, err_len);
        if (e != ARGIL_OK)
            return e;
    }
    if (density != NULL) {
        off = JOURNAL_RECORD_HEAD_BYTES;
        for (uint32_t r = 0; r < runs; r++) {
            const size_t start = io_get_u32le(p + off), count = io_get_u32le(p + off + 4);
            for (size_t i = 0; i < count; i++)
                density[start + i] = io_get_f32le(p + off + 8 + 4 * i);
            off += 8 + 4 * count;
        }
    }
    info->records++;
    info->last_seq = seq;
    info->last_sim_s = (double)get_u64(p + 8) * 1e-6;
    info->last_wall_ms = get_u64(p + 16);
    info->edits = io_get_u32le(p + 24);
    info->material = m;
    info->samples += samples;
    info->mat_samples += mat_samples;
    info->rgb_samples += rgb_samples;
    return ARGIL_OK;
}

/* journal_replay with optional painted channels (mat[GRID_MAT_N], n samples each) and colour
 * (*rgb, 3 n bytes, made when a record paints and it is NULL). */
static argil_err_t replay(const uint8_t *data, size_t len, const char *name, float *density,
                          size_t n, float **mat, uint8_t **rgb, journal_info_t *info, char *err,
                          size_t err_len)
{
    argil_err_t e = journal_header_decode(data, len, name, info, err, err_len);
    if (e != ARGIL_OK)
        return e;
    const size_t want = (size_t)info->dims[0] * (size_t)info->dims[1] * (size_t)info->dims[2];
    if (density != NULL && n != want) {
        io_err(err, err_len, "%s: the journal's grid (%zu samples) is not the model's (%zu)", name,
               want, n);
        return ARGIL_ERR_ARG;
    }
    size_t at = JOURNAL_HEADER_BYTES;
    while (at < len) {
        const size_t left = len - at;
        if (left < 8) {
            info->torn_bytes = left;
            break;
        }
        const uint64_t payload = io_get_u32le(data + at);
        if (payload + 8 > left) {
            info->torn_bytes = left; /* declared length runs past the end: a cut-short write */
            break;
        }
        const uint32_t crc = io_get_u32le(data + at + 4 + payload);
        if (crc != crc32c(0, data + at, 4 + (size_t)payload)) {
            if (payload + 8 == left) {
                info->torn_bytes = left; /* the very last record, partly written */
                break;
            }
            char why[96];
            snprintf(why, sizeof(why), "record %u: checksum mismatch (recovery stops before it)",
                     info->records + 1u);
            return fail(err, err_len, name, at, why);
        }
        e = apply_record(data + at + 4, (size_t)payload, at, name, density, mat, rgb, want, info,
                         err, err_len);
        if (e != ARGIL_OK)
            return e;
        at += 8 + (size_t)payload;
        info->good_bytes = at;
    }
    return ARGIL_OK;
}

argil_err_t journal_replay(const uint8_t *data, size_t len, const char *name, float *density,
                           size_t n, journal_info_t *info, char *err, size_t err_len)
{
    return replay(data, len, name, density, n, NULL, NULL, info, err, err_len);
}

argil_err_t journal_replay_grid(const uint8_t *data, size_t len, const char *name, grid_t *g,
                                journal_info_t *info, char *err, size_t err_len)
{
    int32_t lo[3], hi[3], dims[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        dims[a] = hi[a] - lo[a];
    const size_t n = grid_count(g);
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = grid_dense_all(g, lo, dims, &dens, mat, &rgb);
    if (e != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", name);
        return e;
    }
    e = replay(data, len, name, dens, n, mat, &rgb, info, err, err_len);
    /* Even after a bad record (PARSE) the grid takes the model as of the record before it. */
    argil_err_t we = grid_write_box(g, GRID_DENSITY, lo, dims, dens);
    bool painted = false;
    for (int ch = 0; ch < GRID_MAT_N && we == ARGIL_OK; ch++)
        if (mat[ch] != NULL) {
            we = grid_mat_write_box(g, (grid_mat_t)ch, lo, dims, mat[ch]);
            painted = true;
        }
    if (painted)
        g->mat_writes++;
    if (we == ARGIL_OK && rgb != NULL) {
        we = grid_rgb_write_box(g, lo, dims, rgb);
        if (info->rgb_samples > 0)
            g->rgb_writes++;
    }
    dense_all_free(&dens, mat, &rgb);
    if (we != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", name);
        return we;
    }
    return e;
}

static argil_err_t read_journal(const char *dir, uint8_t **data, size_t *len, char **path,
                                char *err, size_t err_len)
{
    *data = NULL;
    *path = path_join(dir, JOURNAL_FILE);
    if (*path == NULL) {
        io_err(err, err_len, "out of memory");
        return ARGIL_ERR_NOMEM;
    }
    return io_slurp(*path, IO_FILE_MAX_BYTES, data, len, err, err_len);
}

argil_err_t journal_probe(const char *dir, journal_info_t *info, char *err, size_t err_len)
{
    uint8_t *data;
    size_t len = 0;
    char *path;
    argil_err_t e = read_journal(dir, &data, &len, &path, err, err_len);
    if (e == ARGIL_OK)
        e = journal_replay(data, len, path, NULL, 0, info, err, err_len);
    free(data);
    free(path);
    return e;
}

static bool same_f32(float a, float b)
{
    return same_bits(&a, &b, sizeof(a));
}

argil_err_t journal_recover(const char *dir, argil_doc_t *doc, journal_info_t *info, char *err,
                            size_t err_len)
{
    argil_doc_init(doc);
    uint8_t *data = NULL;
    size_t len = 0;
    char *path = NULL, *base_path = NULL;
    argil_doc_t b;
    argil_doc_init(&b);
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = read_journal(dir, &data, &len, &path, err, err_len);
    if (e != ARGIL_OK)
        goto out;
    e = journal_header_decode(data, len, path, info, err, err_len);
    if (e != ARGIL_OK)
        goto out;
    base_path = path_join(dir, info->base_name);
    if (base_path == NULL) {
        e = ARGIL_ERR_NOMEM;
        io_err(err, err_len, "out of memory");
        goto out;
    }
    e = argil_file_read(base_path, &b, err, err_len);
    if (e != ARGIL_OK)
        goto out;
    const grid_t *g = &b.grid;
    int32_t glo[3], ghi[3], gdims[3];
    grid_bounds(g, glo, ghi);
    for (int a = 0; a < 3; a++)
        gdims[a] = ghi[a] - glo[a];
    const size_t bn = grid_count(g);
    struct stat st;
    const uint64_t blen = stat(base_path, &st) == 0 ? (uint64_t)st.st_size : 0;
    e = grid_dense_all(g, glo, gdims, &dens, mat, &rgb);
    if (e != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", base_path);
        goto out;
    }
    /* The base's colour (its COLR, dense over the same box) is what the records paint on. */
    free(rgb);
    rgb = b.rgb;
    b.rgb = NULL;
    const uint32_t crc = model_crc(dens, mat, rgb, bn);
    if (blen != info->base_len || crc != info->base_crc ||
        !same_bits(&g->material, &info->material, sizeof(g->material)) ||
        b.state.edits != info->edits) {
        io_err(err, err_len,
               "%s: the base snapshot %s is not the one this journal continues (%llu bytes, "
               "model CRC %08x; the journal expects %llu bytes, CRC %08x, and its material "
               "and edit count): refusing to replay onto it",
               path, base_path, (unsigned long long)blen, crc, (unsigned long long)info->base_len,
               info->base_crc);
        e = ARGIL_ERR_PARSE;
        goto out;
    }
    if (glo[0] != 0 || glo[1] != 0 || glo[2] != 0 || gdims[0] != info->dims[0] ||
        gdims[1] != info->dims[1] || gdims[2] != info->dims[2] ||
        !same_f32(g->spacing_m, info->spacing_m) ||
        !same_f32(g->origin_m.x, info->origin_m.x) || !same_f32(g->origin_m.y, info->origin_m.y) ||
        !same_f32(g->origin_m.z, info->origin_m.z) || !same_f32(g->iso, info->iso) ||
        !same_f32(g->band_m, info->band_m)) {
        io_err(err, err_len, "%s: the base snapshot's grid differs from the journal's", base_path);
        e = ARGIL_ERR_PARSE;
        goto out;
    }
    e = replay(data, len, path, dens, bn, mat, &rgb, info, err, err_len);
    if (e != ARGIL_OK && e != ARGIL_ERR_PARSE)
        goto out;
    /* After a bad record (PARSE) the arrays hold the model as of the record before it. */
    argil_err_t me = journal_model_doc(info, dens, mat, doc);
    if (me == ARGIL_OK && !doc_set_rgb(doc, rgb, bn))
        me = ARGIL_ERR_NOMEM;
    if (me != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the recovered model", path);
        e = me;
    }
out:
    if (e != ARGIL_OK && e != ARGIL_ERR_PARSE)
        argil_doc_free(doc);
    else if (e == ARGIL_ERR_PARSE && grid_count(&doc->grid) == 0)
        argil_doc_free(doc);
    dense_all_free(&dens, mat, &rgb);
    argil_doc_free(&b);
    free(data);
    free(path);
    free(base_path);
    return e;
}
