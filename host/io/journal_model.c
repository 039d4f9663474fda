/* The model as a journal file holds it: dense arrays over the journal's box (densities, painted
 * channels, colour), the base snapshot's identity CRC over them, and the .argil document they
 * make. Shared by the writer (base snapshots) and recovery. */
#include <stdlib.h>
#include <string.h>

#include "host/io/journal_internal.h"
#include "shared/crc32c.h"

/* crc continued over v[0, n) as little-endian binary32. */
static uint32_t f32s_crc(uint32_t crc, const float *v, size_t n)
{
    uint8_t chunk[1024];
    size_t i = 0;
    while (i < n) {
        size_t k = 0;
        for (; k < sizeof(chunk) / 4 && i < n; k++, i++)
            le_put_f32(chunk + 4 * k, v[i]);
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
        if (!journal_same_bits(&m[i], &def, sizeof(float)))
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
uint32_t journal_model_crc(const float *density, float *const mat[GRID_MAT_N], const uint8_t *rgb,
                           size_t n)
{
    uint32_t crc = f32s_crc(0, density, n);
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        if (!mat_painted(mat[ch], n, (grid_mat_t)ch))
            continue;
        uint8_t id[4];
        le_put_u32(id, (uint32_t)ch);
        crc = crc32c(crc, id, 4);
        crc = f32s_crc(crc, mat[ch], n);
    }
    if (rgb_painted(rgb, n)) { /* then the colour as id 4 and 3 bytes per sample */
        uint8_t id[4];
        le_put_u32(id, JOURNAL_RGB_CRC_ID);
        crc = crc32c(crc, id, 4);
        crc = crc32c(crc, rgb, 3 * n);
    }
    return crc;
}

/* A copy of rgb (3 n bytes) as doc's colour; false when out of memory. */
bool journal_doc_set_rgb(argil_doc_t *doc, const uint8_t *rgb, size_t n)
{
    if (rgb == NULL || !rgb_painted(rgb, n))
        return true;
    doc->rgb = malloc(3 * n);
    if (doc->rgb == NULL)
        return false;
    memcpy(doc->rgb, rgb, 3 * n);
    return true;
}

/* Frees the dense arrays grid_dense or shadow_dense made, leaving them NULL. */
void journal_dense_free(float **dens, float *mat[GRID_MAT_N], uint8_t **rgb)
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
argil_err_t journal_grid_dense(const grid_t *g, const int32_t zero[3], const int32_t dims[3],
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
            journal_dense_free(dens, mat, rgb);
            return ARGIL_ERR_NOMEM;
        }
        grid_mat_read_box(g, (grid_mat_t)ch, zero, dims, mat[ch]);
    }
    if (grid_rgb_any(g)) {
        *rgb = malloc(3 * n);
        if (*rgb == NULL) {
            journal_dense_free(dens, mat, rgb);
            return ARGIL_ERR_NOMEM;
        }
        grid_rgb_read_box(g, zero, dims, *rgb);
    }
    return ARGIL_OK;
}

/* doc from the dense model and info (journal.h). */
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
