/* The journal reader: decodes and checks the header, then walks the records (CRC, head, runs,
 * painted material and colour, each rule checked before anything is applied) and replays them
 * onto dense arrays or a grid. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/journal_internal.h"
#include "shared/crc32c.h"

/* code, with err "name: byte N: why". */
static journal_err_t fail(char *err, size_t err_len, const char *name, journal_err_t code,
                          size_t byte, const char *why)
{
    io_err(err, err_len, "%s: byte %zu: %s", name, byte, why);
    return code;
}

argil_err_t journal_err_argil(journal_err_t e)
{
    switch (e) {
    case JOURNAL_OK: return ARGIL_OK;
    case JOURNAL_ERR_ARG: return ARGIL_ERR_ARG;
    case JOURNAL_ERR_IO: return ARGIL_ERR_IO;
    case JOURNAL_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

journal_err_t journal_outside_err(argil_err_t e)
{
    switch (e) {
    case ARGIL_OK: return JOURNAL_OK;
    case ARGIL_ERR_ARG: return JOURNAL_ERR_ARG;
    case ARGIL_ERR_NOMEM: return JOURNAL_ERR_NOMEM;
    case ARGIL_ERR_PARSE: return JOURNAL_ERR_FILE_SIZE;
    default: return JOURNAL_ERR_IO;
    }
}

/* The uint32 count at payload offset o into *count, or code with "record rec: what runs past the
 * record" when it does not fit. */
static journal_err_t get_count(const uint8_t *p, size_t payload, size_t o, size_t at,
                               const char *name, uint32_t rec, const char *what, journal_err_t code,
                               uint32_t *count, char *err, size_t err_len)
{
    if (payload - o < 4) {
        char why[200];
        snprintf(why, sizeof(why), "record %u: %s runs past the record", rec, what);
        return fail(err, err_len, name, code, at + 4 + o, why);
    }
    *count = le_get_u32(p + o);
    return JOURNAL_OK;
}

/* What a kind of run is called in messages, its bytes per sample, whether its runs must come in
 * sample order without overlapping, and the rules its head and extent break. */
typedef struct {
    const char *label;
    size_t sample_bytes;
    bool ordered;
    journal_err_t head_err, range_err;
} run_kind_t;

static const run_kind_t RUN_DENS = {"run", 4, false, JOURNAL_ERR_RUN_HEAD, JOURNAL_ERR_RUN_RANGE};
static const run_kind_t RUN_MAT = {"material run", 4, false, JOURNAL_ERR_MAT_RUN_HEAD,
                                   JOURNAL_ERR_MAT_RUN_RANGE};
static const run_kind_t RUN_RGB = {"colour run", 3, true, JOURNAL_ERR_RGB_RUN_HEAD,
                                   JOURNAL_ERR_RGB_RUN_RANGE};

/* Run r's first sample and count from its head at payload offset o into *start and *count, or the
 * rule it broke: head past the record, or a run empty, before next (ordered kinds), beyond the n
 * samples or past the record. */
static journal_err_t check_run_head(const uint8_t *p, size_t payload, size_t o, size_t at,
                                    const char *name, size_t n, uint32_t rec, uint32_t r,
                                    const run_kind_t *k, uint64_t next, uint64_t *start,
                                    uint64_t *count, char *err, size_t err_len)
{
    char why[200];
    if (payload - o < 8) {
        snprintf(why, sizeof(why), "record %u: %s %u head runs past the record", rec, k->label, r);
        return fail(err, err_len, name, k->head_err, at + 4 + o, why);
    }
    *start = le_get_u32(p + o);
    *count = le_get_u32(p + o + 4);
    if (*count == 0 || (k->ordered && *start < next) || *start + *count > (uint64_t)n ||
        *count > (payload - o - 8) / k->sample_bytes) {
        snprintf(why, sizeof(why),
                 "record %u: %s %u (%llu samples from %llu) empty, %sbeyond the grid or past the "
                 "record",
                 rec, k->label, r, (unsigned long long)*count, (unsigned long long)*start,
                 k->ordered ? "out of order, " : "");
        return fail(err, err_len, name, k->range_err, at + 4 + o, why);
    }
    return JOURNAL_OK;
}

/* Checks the 160-byte header field by field into info (journal.h). */
journal_err_t journal_header_decode(const uint8_t *data, size_t len, const char *name,
                                    journal_info_t *info, char *err, size_t err_len)
{
    memset(info, 0, sizeof(*info));
    if (len < JOURNAL_HEADER_BYTES)
        return fail(err, err_len, name, JOURNAL_ERR_SHORT, len,
                    "file shorter than the journal header");
    if (memcmp(data, JOURNAL_MAGIC, 8) != 0)
        return fail(err, err_len, name, JOURNAL_ERR_MAGIC, 0, "not an argil journal");
    if (le_get_u32(data + JOURNAL_HEADER_BYTES - 4) !=
        crc32c(0, data, JOURNAL_HEADER_BYTES - 4))
        return fail(err, err_len, name, JOURNAL_ERR_HEADER_CRC, JOURNAL_HEADER_BYTES - 4,
                    "header checksum mismatch");
    info->version = le_get_u32(data + 8);
    if (info->version < 1 || info->version > JOURNAL_VERSION)
        return fail(err, err_len, name, JOURNAL_ERR_VERSION, 8,
                    "journal version (this argil reads 1..2)");
    if (le_get_u32(data + 12) != JOURNAL_HEADER_BYTES)
        return fail(err, err_len, name, JOURNAL_ERR_HEADER_SIZE, 12, "header size");
    int64_t n = 1;
    for (int a = 0; a < 3; a++) {
        const int32_t d = (int32_t)le_get_u32(data + 16 + 4 * a);
        if (d < 1 || (n *= d) > GRID_SAMPLES_MAX)
            return fail(err, err_len, name, JOURNAL_ERR_DIMS, 16 + 4 * (size_t)a,
                        "grid dimension below 1 or "
                        "more than 2^30 samples");
        info->dims[a] = d;
    }
    info->spacing_m = le_get_f32(data + 28);
    info->origin_m = vec3(le_get_f32(data + 32), le_get_f32(data + 36),
                          le_get_f32(data + 40));
    info->iso = le_get_f32(data + 44);
    info->band_m = le_get_f32(data + 48);
    if (!isfinite(info->spacing_m) || !(info->spacing_m > 0.0f) || !vec3_isfinite(info->origin_m) ||
        !isfinite(info->iso) || !isfinite(info->band_m))
        return fail(err, err_len, name, JOURNAL_ERR_GEOMETRY, 28,
                    "grid spacing, origin, iso or band not finite");
    journal_get_material(data + 52, &info->material);
    if (!spring_material_valid(&info->material))
        return fail(err, err_len, name, JOURNAL_ERR_MATERIAL, 52, "material out of range");
    info->checkpoint = le_get_u32(data + 72);
    info->first_seq = le_get_u32(data + 76);
    if (info->first_seq == 0)
        return fail(err, err_len, name, JOURNAL_ERR_FIRST_SEQ, 76, "first record number 0");
    info->last_seq = info->first_seq - 1u;
    info->base_len = le_get_u64(data + 80);
    info->base_crc = le_get_u32(data + 88);
    info->edits = le_get_u32(data + 92);
    const uint8_t *bn = data + 96;
    size_t bl = 0;
    while (bl < JOURNAL_BASE_NAME_MAX && bn[bl] != 0)
        bl++;
    for (size_t i = bl; i < JOURNAL_BASE_NAME_MAX; i++)
        if (bn[i] != 0)
            return fail(err, err_len, name, JOURNAL_ERR_BASE_PADDING, 96 + i,
                        "base name not NUL-padded");
    if (bl == 0 || memchr(bn, '/', bl) != NULL || (bl <= 2 && bn[0] == '.'))
        return fail(err, err_len, name, JOURNAL_ERR_BASE_NAME, 96,
                    "base name empty or not a plain file name");
    for (size_t i = 0; i < bl; i++)
        if (bn[i] < 0x20 || bn[i] > 0x7e)
            return fail(err, err_len, name, JOURNAL_ERR_BASE_ASCII, 96 + i,
                        "base name not printable ASCII");
    memcpy(info->base_name, bn, bl);
    info->base_name[bl] = '\0';
    info->good_bytes = JOURNAL_HEADER_BYTES;
    return JOURNAL_OK;
}

/* Checks the painted-material blocks of a type-2 record (type 3: min_blocks 0) from payload
 * offset *off against n samples; advances *off past them and adds their values to *samples. */
static journal_err_t check_mat_blocks(const uint8_t *p, size_t payload, size_t *off, size_t at,
                                      const char *name, size_t n, uint32_t rec, uint32_t min_blocks,
                                      uint64_t *samples, char *err, size_t err_len)
{
    char why[200];
    size_t o = *off;
    uint32_t blocks;
    const journal_err_t ce = get_count(p, payload, o, at, name, rec, "material block count",
                                       JOURNAL_ERR_MAT_COUNT_HEAD, &blocks, err, err_len);
    if (ce != JOURNAL_OK)
        return ce;
    if (blocks < min_blocks || blocks > GRID_MAT_N) {
        snprintf(why, sizeof(why), "record %u: material block count %u not in %u..4", rec, blocks,
                 min_blocks);
        return fail(err, err_len, name, JOURNAL_ERR_MAT_COUNT, at + 4 + o, why);
    }
    o += 4;
    int64_t prev = -1;
    for (uint32_t k = 0; k < blocks; k++) {
        if (payload - o < 8) {
            snprintf(why, sizeof(why), "record %u: material block %u head runs past the record",
                     rec, k);
            return fail(err, err_len, name, JOURNAL_ERR_MAT_BLOCK_HEAD, at + 4 + o, why);
        }
        const uint32_t ch = le_get_u32(p + o), runs = le_get_u32(p + o + 4);
        if (ch >= GRID_MAT_N || (int64_t)ch <= prev || runs < 1) {
            snprintf(why, sizeof(why), "record %u: material block %u: channel %u not 0..3 in "
                     "increasing order, or no runs", rec, k, ch);
            return fail(err, err_len, name, JOURNAL_ERR_MAT_CHANNEL, at + 4 + o, why);
        }
        prev = (int64_t)ch;
        o += 8;
        for (uint32_t r = 0; r < runs; r++) {
            uint64_t start, count;
            const journal_err_t re = check_run_head(p, payload, o, at, name, n, rec, r, &RUN_MAT,
                                                    0, &start, &count, err, err_len);
            if (re != JOURNAL_OK)
                return re;
            for (uint64_t i = 0; i < count; i++)
                if (!grid_mat_valid((grid_mat_t)ch, le_get_f32(p + o + 8 + 4 * i))) {
                    snprintf(why, sizeof(why), "record %u: painted material value out of range "
                             "(finite; mass scale > 0, stiffness and damping scales >= 0)", rec);
                    return fail(err, err_len, name, JOURNAL_ERR_MAT_VALUE,
                                at + 4 + o + 8 + 4 * (size_t)i, why);
                }
            o += 8 + 4 * (size_t)count;
            *samples += count;
        }
    }
    *off = o;
    return JOURNAL_OK;
}

/* Checks the painted colour of a type-3 record (from payload offset *off: uint32 run count >= 1,
 * runs of uint32 first sample, uint32 count >= 1, 3 count bytes) against n samples; advances *off
 * past it and adds its samples to *samples. */
static journal_err_t check_rgb_runs(const uint8_t *p, size_t payload, size_t *off, size_t at,
                                    const char *name, size_t n, uint32_t rec, uint64_t *samples,
                                    char *err, size_t err_len)
{
    uint32_t runs;
    const journal_err_t ce = get_count(p, payload, *off, at, name, rec, "colour run count",
                                       JOURNAL_ERR_RGB_COUNT_HEAD, &runs, err, err_len);
    if (ce != JOURNAL_OK)
        return ce;
    char why[200];
    if (runs < 1) {
        snprintf(why, sizeof(why), "record %u: colour run count 0", rec);
        return fail(err, err_len, name, JOURNAL_ERR_RGB_COUNT, at + 4 + *off, why);
    }
    size_t o = *off + 4;
    uint64_t next = 0; /* runs are in sample order and do not overlap */
    for (uint32_t r = 0; r < runs; r++) {
        uint64_t start, count;
        const journal_err_t re = check_run_head(p, payload, o, at, name, n, rec, r, &RUN_RGB, next,
                                                &start, &count, err, err_len);
        if (re != JOURNAL_OK)
            return re;
        next = start + count;
        o += 8 + 3 * (size_t)count;
        *samples += count;
    }
    *off = o;
    return JOURNAL_OK;
}

/* Applies the checked colour runs at payload offset off to the n-sample colour *rgb (made, every
 * sample GRID_RGB_DEFAULT, when absent). */
static journal_err_t apply_rgb_runs(const uint8_t *p, size_t off, uint8_t **rgb, size_t n,
                                    const char *name, char *err, size_t err_len)
{
    if (*rgb == NULL) {
        *rgb = malloc(3 * n);
        if (*rgb == NULL) {
            io_err(err, err_len, "%s: out of memory for the painted colour", name);
            return JOURNAL_ERR_NOMEM;
        }
        memset(*rgb, (int)GRID_RGB_DEFAULT, 3 * n);
    }
    const uint32_t runs = le_get_u32(p + off);
    size_t o = off + 4;
    for (uint32_t r = 0; r < runs; r++) {
        const size_t start = le_get_u32(p + o), count = le_get_u32(p + o + 4);
        memcpy(*rgb + 3 * start, p + o + 8, 3 * count);
        o += 8 + 3 * count;
    }
    return JOURNAL_OK;
}

/* Applies the checked material blocks at payload offset off to the n-sample channels mat (an
 * absent one is made, every sample the default, before it is written). */
static journal_err_t apply_mat_blocks(const uint8_t *p, size_t off, float *mat[GRID_MAT_N],
                                      size_t n, const char *name, char *err, size_t err_len)
{
    const uint32_t blocks = le_get_u32(p + off);
    size_t o = off + 4;
    /* Every channel the record touches exists before anything is written. */
    for (uint32_t k = 0; k < blocks; k++) {
        const uint32_t ch = le_get_u32(p + o), runs = le_get_u32(p + o + 4);
        if (mat[ch] == NULL) {
            mat[ch] = malloc(n * sizeof(float));
            if (mat[ch] == NULL) {
                io_err(err, err_len, "%s: out of memory for a painted material channel", name);
                return JOURNAL_ERR_NOMEM;
            }
            const float def = grid_mat_default((grid_mat_t)ch);
            for (size_t i = 0; i < n; i++)
                mat[ch][i] = def;
        }
        o += 8;
        for (uint32_t r = 0; r < runs; r++)
            o += 8 + 4 * (size_t)le_get_u32(p + o + 4);
    }
    o = off + 4;
    for (uint32_t k = 0; k < blocks; k++) {
        const uint32_t ch = le_get_u32(p + o), runs = le_get_u32(p + o + 4);
        float *m = mat[ch];
        o += 8;
        for (uint32_t r = 0; r < runs; r++) {
            const size_t start = le_get_u32(p + o), count = le_get_u32(p + o + 4);
            for (size_t i = 0; i < count; i++)
                m[start + i] = le_get_f32(p + o + 8 + 4 * i);
            o += 8 + 4 * count;
        }
    }
    return JOURNAL_OK;
}

/* Checks one record's payload (CRC already good) and, with density (and g), applies it. */
static journal_err_t apply_record(const uint8_t *p, size_t payload, size_t at, const char *name,
                                  float *density, float **mat, uint8_t **rgb, size_t n,
                                  journal_info_t *info, char *err, size_t err_len)
{
    char why[160];
    const uint32_t rec = info->records + 1u;
    if (payload < JOURNAL_RECORD_HEAD_BYTES) {
        snprintf(why, sizeof(why), "record %u: shorter than a record head", rec);
        return fail(err, err_len, name, JOURNAL_ERR_RECORD_HEAD, at, why);
    }
    const uint32_t type = le_get_u32(p);
    if (type != 1u && ((type != 2u && type != 3u) || info->version < 2u)) {
        snprintf(why, sizeof(why), "record %u: unknown record type %u", rec, type);
        return fail(err, err_len, name, JOURNAL_ERR_RECORD_TYPE, at + 4, why);
    }
    const uint32_t seq = le_get_u32(p + 4);
    if (seq != info->last_seq + 1u) {
        snprintf(why, sizeof(why), "record %u: number %u, expected %u", rec, seq,
                 info->last_seq + 1u);
        return fail(err, err_len, name, JOURNAL_ERR_RECORD_SEQ, at + 8, why);
    }
    spring_material_t m;
    journal_get_material(p + 28, &m);
    if (!spring_material_valid(&m)) {
        snprintf(why, sizeof(why), "record %u: material out of range", rec);
        return fail(err, err_len, name, JOURNAL_ERR_RECORD_MATERIAL, at + 32, why);
    }
    const uint32_t runs = le_get_u32(p + 48);
    /* Check every run before changing anything. */
    size_t off = JOURNAL_RECORD_HEAD_BYTES;
    uint64_t samples = 0, mat_samples = 0;
    for (uint32_t r = 0; r < runs; r++) {
        uint64_t start, count;
        const journal_err_t re = check_run_head(p, payload, off, at, name, n, rec, r, &RUN_DENS, 0,
                                                &start, &count, err, err_len);
        if (re != JOURNAL_OK)
            return re;
        for (uint64_t i = 0; i < count; i++) {
            const float v = le_get_f32(p + off + 8 + 4 * i);
            if (!isfinite(v) || v < 0.0f || v > 1.0f) {
                snprintf(why, sizeof(why), "record %u: density not a finite number in [0, 1]",
                         rec);
                return fail(err, err_len, name, JOURNAL_ERR_DENSITY,
                            at + 4 + off + 8 + 4 * (size_t)i, why);
            }
        }
        off += 8 + 4 * (size_t)count;
        samples += count;
    }
    const size_t mat_off = off;
    uint64_t rgb_samples = 0;
    size_t rgb_off = 0;
    if (type >= 2u) {
        journal_err_t e = check_mat_blocks(p, payload, &off, at, name, n, rec, type == 3u ? 0u : 1u,
                                           &mat_samples, err, err_len);
        rgb_off = off;
        if (e == JOURNAL_OK && type == 3u)
            e = check_rgb_runs(p, payload, &off, at, name, n, rec, &rgb_samples, err, err_len);
        if (e != JOURNAL_OK)
            return e;
    }
    if (off != payload) {
        snprintf(why, sizeof(why), "record %u: %zu bytes after the last run", rec, payload - off);
        return fail(err, err_len, name, JOURNAL_ERR_TRAILING, at + 4 + off, why);
    }
    if (type >= 2u && mat != NULL && le_get_u32(p + mat_off) > 0) {
        const journal_err_t e = apply_mat_blocks(p, mat_off, mat, n, name, err, err_len);
        if (e != JOURNAL_OK)
            return e;
    }
    if (type == 3u && rgb != NULL) {
        const journal_err_t e = apply_rgb_runs(p, rgb_off, rgb, n, name, err, err_len);
        if (e != JOURNAL_OK)
            return e;
    }
    if (density != NULL) {
        off = JOURNAL_RECORD_HEAD_BYTES;
        for (uint32_t r = 0; r < runs; r++) {
            const size_t start = le_get_u32(p + off), count = le_get_u32(p + off + 4);
            for (size_t i = 0; i < count; i++)
                density[start + i] = le_get_f32(p + off + 8 + 4 * i);
            off += 8 + 4 * count;
        }
    }
    info->records++;
    info->last_seq = seq;
    info->last_sim_s = (double)le_get_u64(p + 8) * 1e-6;
    info->last_wall_ms = le_get_u64(p + 16);
    info->edits = le_get_u32(p + 24);
    info->material = m;
    info->samples += samples;
    info->mat_samples += mat_samples;
    info->rgb_samples += rgb_samples;
    return JOURNAL_OK;
}

/* journal_replay with optional painted channels (mat[GRID_MAT_N], n samples each) and colour
 * (*rgb, 3 n bytes, made when a record paints and it is NULL). */
journal_err_t journal_replay_channels(const uint8_t *data, size_t len, const char *name,
                                      float *density, size_t n, float **mat, uint8_t **rgb,
                                      journal_info_t *info, char *err, size_t err_len)
{
    journal_err_t e = journal_header_decode(data, len, name, info, err, err_len);
    if (e != JOURNAL_OK)
        return e;
    const size_t want = (size_t)info->dims[0] * (size_t)info->dims[1] * (size_t)info->dims[2];
    if (density != NULL && n != want) {
        io_err(err, err_len, "%s: the journal's grid (%zu samples) is not the model's (%zu)", name,
               want, n);
        return JOURNAL_ERR_ARG;
    }
    size_t at = JOURNAL_HEADER_BYTES;
    while (at < len) {
        const size_t left = len - at;
        if (left < 8) {
            info->torn_bytes = left;
            break;
        }
        const uint64_t payload = le_get_u32(data + at);
        if (payload + 8 > left) {
            info->torn_bytes = left; /* declared length runs past the end: a cut-short write */
            break;
        }
        const uint32_t crc = le_get_u32(data + at + 4 + payload);
        if (crc != crc32c(0, data + at, 4 + (size_t)payload)) {
            if (payload + 8 == left) {
                info->torn_bytes = left; /* the very last record, partly written */
                break;
            }
            char why[96];
            snprintf(why, sizeof(why), "record %u: checksum mismatch (recovery stops before it)",
                     info->records + 1u);
            return fail(err, err_len, name, JOURNAL_ERR_RECORD_CRC, at, why);
        }
        e = apply_record(data + at + 4, (size_t)payload, at, name, density, mat, rgb, want, info,
                         err, err_len);
        if (e != JOURNAL_OK)
            return e;
        at += 8 + (size_t)payload;
        info->good_bytes = at;
    }
    return JOURNAL_OK;
}

/* Replays densities only (journal.h). */
journal_err_t journal_replay(const uint8_t *data, size_t len, const char *name, float *density,
                             size_t n, journal_info_t *info, char *err, size_t err_len)
{
    return journal_replay_channels(data, len, name, density, n, NULL, NULL, info, err, err_len);
}

/* Replays onto g through dense copies of its bounds, written back even after a bad record. */
journal_err_t journal_replay_grid(const uint8_t *data, size_t len, const char *name, grid_t *g,
                                  journal_info_t *info, char *err, size_t err_len)
{
    int32_t lo[3], hi[3], dims[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        dims[a] = hi[a] - lo[a];
    const size_t n = grid_count(g);
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    const argil_err_t de = journal_grid_dense(g, lo, dims, &dens, mat, &rgb);
    if (de != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", name);
        return journal_outside_err(de);
    }
    const journal_err_t e =
        journal_replay_channels(data, len, name, dens, n, mat, &rgb, info, err, err_len);
    /* Even after a bad record the grid takes the model as of the record before it. */
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
    journal_dense_free(&dens, mat, &rgb);
    if (we != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", name);
        return journal_outside_err(we);
    }
    return e;
}
