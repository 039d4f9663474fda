/* Recovery from a session directory: probes its journal for the offer to recover, and rebuilds
 * the model from the base snapshot the journal names (checked against the header) and the
 * journal's records. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>
#include <sys/stat.h>

#include "host/io/journal_internal.h"

/* dir's journal.log into *data, its path into *path (both malloc'ed). */
static journal_err_t read_journal(const char *dir, uint8_t **data, size_t *len, char **path,
                                  char *err, size_t err_len)
{
    *data = NULL;
    *path = journal_path(dir, JOURNAL_FILE);
    if (*path == NULL) {
        io_err(err, err_len, "out of memory");
        return JOURNAL_ERR_NOMEM;
    }
    return journal_outside_err(io_slurp(*path, IO_FILE_MAX_BYTES, data, len, err, err_len));
}

/* Scans dir's journal without applying it (journal.h). */
journal_err_t journal_probe(const char *dir, journal_info_t *info, char *err, size_t err_len)
{
    uint8_t *data;
    size_t len = 0;
    char *path;
    journal_err_t e = read_journal(dir, &data, &len, &path, err, err_len);
    if (e == JOURNAL_OK)
        e = journal_replay(data, len, path, NULL, 0, info, err, err_len);
    free(data);
    free(path);
    return e;
}

/* The journal_err_t of argil_file_read's result for the base snapshot. */
static journal_err_t base_file_err(argil_file_err_t e)
{
    const argil_err_t a = argil_file_err_argil(e);
    return a == ARGIL_ERR_PARSE ? JOURNAL_ERR_BASE_FILE : journal_outside_err(a);
}

/* True when e is a rule the journal or its base broke (not a failure outside the files). */
static bool journal_rule(journal_err_t e)
{
    return journal_err_argil(e) == ARGIL_ERR_PARSE;
}

/* True when a and b are the same binary32, bit for bit. */
static bool same_f32(float a, float b)
{
    return journal_same_bits(&a, &b, sizeof(a));
}

/* Base snapshot checked against the header, then the records replayed onto it (journal.h). */
journal_err_t journal_recover(const char *dir, argil_doc_t *doc, journal_info_t *info, char *err,
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
    journal_err_t e = read_journal(dir, &data, &len, &path, err, err_len);
    if (e != JOURNAL_OK)
        goto out;
    e = journal_header_decode(data, len, path, info, err, err_len);
    if (e != JOURNAL_OK)
        goto out;
    base_path = journal_path(dir, info->base_name);
    if (base_path == NULL) {
        e = JOURNAL_ERR_NOMEM;
        io_err(err, err_len, "out of memory");
        goto out;
    }
    e = base_file_err(argil_file_read(base_path, &b, err, err_len));
    if (e != JOURNAL_OK)
        goto out;
    const grid_t *g = &b.grid;
    int32_t glo[3], ghi[3], gdims[3];
    grid_bounds(g, glo, ghi);
    for (int a = 0; a < 3; a++)
        gdims[a] = ghi[a] - glo[a];
    const size_t bn = grid_count(g);
    struct stat st;
    const uint64_t blen = stat(base_path, &st) == 0 ? (uint64_t)st.st_size : 0;
    e = journal_outside_err(journal_grid_dense(g, glo, gdims, &dens, mat, &rgb));
    if (e != JOURNAL_OK) {
        io_err(err, err_len, "%s: out of memory for the model", base_path);
        goto out;
    }
    /* The base's colour (its COLR, dense over the same box) is what the records paint on. */
    free(rgb);
    rgb = b.rgb;
    b.rgb = NULL;
    const uint32_t crc = journal_model_crc(dens, mat, rgb, bn);
    if (blen != info->base_len || crc != info->base_crc ||
        !journal_same_bits(&g->material, &info->material, sizeof(g->material)) ||
        b.state.edits != info->edits) {
        io_err(err, err_len,
               "%s: the base snapshot %s is not the one this journal continues (%llu bytes, "
               "model CRC %08x; the journal expects %llu bytes, CRC %08x, and its material "
               "and edit count): refusing to replay onto it",
               path, base_path, (unsigned long long)blen, crc, (unsigned long long)info->base_len,
               info->base_crc);
        e = JOURNAL_ERR_BASE_MISMATCH;
        goto out;
    }
    if (glo[0] != 0 || glo[1] != 0 || glo[2] != 0 || gdims[0] != info->dims[0] ||
        gdims[1] != info->dims[1] || gdims[2] != info->dims[2] ||
        !same_f32(g->spacing_m, info->spacing_m) ||
        !same_f32(g->origin_m.x, info->origin_m.x) || !same_f32(g->origin_m.y, info->origin_m.y) ||
        !same_f32(g->origin_m.z, info->origin_m.z) || !same_f32(g->iso, info->iso) ||
        !same_f32(g->band_m, info->band_m)) {
        io_err(err, err_len, "%s: the base snapshot's grid differs from the journal's", base_path);
        e = JOURNAL_ERR_BASE_GRID;
        goto out;
    }
    e = journal_replay_channels(data, len, path, dens, bn, mat, &rgb, info, err, err_len);
    if (e != JOURNAL_OK && !journal_rule(e))
        goto out;
    /* After a bad record the arrays hold the model as of the record before it. */
    argil_err_t me = journal_model_doc(info, dens, mat, doc);
    if (me == ARGIL_OK && !journal_doc_set_rgb(doc, rgb, bn))
        me = ARGIL_ERR_NOMEM;
    if (me != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the recovered model", path);
        e = journal_outside_err(me);
    }
out:
    if (e != JOURNAL_OK && !journal_rule(e))
        argil_doc_free(doc);
    else if (journal_rule(e) && grid_count(&doc->grid) == 0)
        argil_doc_free(doc);
    journal_dense_free(&dens, mat, &rgb);
    argil_doc_free(&b);
    free(data);
    free(path);
    free(base_path);
    return e;
}
