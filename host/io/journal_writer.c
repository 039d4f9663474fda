/* The journal writer: opens a journal on a base snapshot, assembles each edit step's record from
 * the diff, makes buffered records durable at a bounded interval, rotates onto new bases at
 * checkpoints and rebases, and removes the journal's files at a clean end. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/io/journal_internal.h"
#include "shared/crc32c.h"

#define JOURNAL_RECORD_MAX_BYTES ((uint64_t)1 << 32) /* the length field is 32 bits */

/* Autosave every 1 s, checkpoint every 60 s or 64 MiB. */
void journal_cfg_default(journal_cfg_t *cfg)
{
    cfg->autosave_s = 1.0f;
    cfg->checkpoint_s = 60.0f;
    cfg->checkpoint_bytes = (uint64_t)64 << 20;
}

/* dir + "/" + name, malloc'ed; NULL when out of memory. */
char *journal_path(const char *dir, const char *name)
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

/* fsyncs dir so a rename or unlink in it is durable (best effort). */
static void sync_dir(const char *dir)
{
    const int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        (void)fsync(fd);
        (void)close(fd);
    }
}

/* The file name of base snapshot number checkpoint. */
static void base_name(uint32_t checkpoint, char out[JOURNAL_BASE_NAME_MAX + 1])
{
    snprintf(out, JOURNAL_BASE_NAME_MAX + 1, JOURNAL_BASE_PREFIX "%u.argil", checkpoint);
}

/* Writes all len bytes (retrying short writes and EINTR); false on an error. */
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

/* Shadow, record buffer and views scratch, in bytes. */
size_t journal_bytes(const journal_t *j)
{
    return block_table_bytes(&j->shadow.blocks) + j->shadow.arrays_bytes + j->buf_cap +
           j->views_cap * sizeof(grid_block_view_t);
}

/* Room for more bytes after buf_len (doubling from 64 KiB); false when out of memory. */
bool journal_buf_reserve(journal_t *j, size_t more)
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
    if (e == ARGIL_OK && !journal_doc_set_rgb(&doc, rgb, j->n))
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

/* The grid or, with g NULL, the shadow, written densely as .argil. */
argil_err_t journal_write_model(const journal_t *j, const grid_t *g, uint32_t edits,
                                const char *path, char *err, size_t err_len)
{
    if ((g == NULL && !j->ready) || (g != NULL && !journal_fits(j, g))) {
        io_err(err, err_len, "%s: the journal holds no model (or not this grid's)", path);
        return ARGIL_ERR_STATE;
    }
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = g != NULL ? journal_grid_dense(g, j->lo, j->dims, &dens, mat, &rgb)
                              : journal_shadow_dense(j, &dens, mat, &rgb);
    if (e != ARGIL_OK)
        io_err(err, err_len, "%s: out of memory for the model", path);
    else
        e = write_dense_model(j, edits, dens, mat, rgb, path, err, err_len);
    journal_dense_free(&dens, mat, &rgb);
    return e;
}

/* The 160-byte header of a journal on base file base (docs/files.md). */
static void encode_header(const journal_t *j, const char *base, uint64_t base_len,
                          uint32_t base_crc, uint32_t base_edits, uint8_t h[JOURNAL_HEADER_BYTES])
{
    memset(h, 0, JOURNAL_HEADER_BYTES);
    memcpy(h, JOURNAL_MAGIC, 8);
    le_put_u32(h + 8, JOURNAL_VERSION);
    le_put_u32(h + 12, JOURNAL_HEADER_BYTES);
    for (int a = 0; a < 3; a++)
        le_put_u32(h + 16 + 4 * a, (uint32_t)j->dims[a]);
    le_put_f32(h + 28, j->spacing_m);
    le_put_f32(h + 32, j->origin_m.x);
    le_put_f32(h + 36, j->origin_m.y);
    le_put_f32(h + 40, j->origin_m.z);
    le_put_f32(h + 44, j->iso);
    le_put_f32(h + 48, j->band_m);
    journal_put_material(h + 52, &j->material);
    le_put_u32(h + 72, j->checkpoint);
    le_put_u32(h + 76, j->seq + 1u);
    le_put_u64(h + 80, base_len);
    le_put_u32(h + 88, base_crc);
    le_put_u32(h + 92, base_edits);
    memcpy(h + 96, base, strlen(base));
    le_put_u32(h + JOURNAL_HEADER_BYTES - 4, crc32c(0, h, JOURNAL_HEADER_BYTES - 4));
}

/* Writes base snapshot number j->checkpoint from the shadow, then a new journal.log (via
 * journal.log.tmp + rename) that starts on it; leaves the new file open in j->fd. The model is
 * made dense over the journal's box for the while (the .argil and the base CRC need it). */
static argil_err_t start_file(journal_t *j, uint32_t edits, char *err, size_t err_len)
{
    char base[JOURNAL_BASE_NAME_MAX + 1];
    base_name(j->checkpoint, base);
    char *base_path = journal_path(j->dir, base);
    char *log_path = journal_path(j->dir, JOURNAL_FILE);
    char *tmp_path = journal_path(j->dir, JOURNAL_FILE ".tmp");
    float *dens = NULL, *mat[GRID_MAT_N] = {NULL};
    uint8_t *rgb = NULL;
    argil_err_t e = ARGIL_ERR_NOMEM;
    int fd = -1;
    if (base_path == NULL || log_path == NULL || tmp_path == NULL ||
        journal_shadow_dense(j, &dens, mat, &rgb) != ARGIL_OK) {
        io_err(err, err_len, "%s: out of memory for the journal", j->dir);
        goto out;
    }
    e = write_dense_model(j, edits, dens, mat, rgb, base_path, err, err_len);
    if (e != ARGIL_OK)
        goto out;
    const uint32_t crc = journal_model_crc(dens, mat, rgb, j->n);
    journal_dense_free(&dens, mat, &rgb);
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
    journal_dense_free(&dens, mat, &rgb);
    if (fd >= 0) {
        (void)close(fd);
        (void)unlink(tmp_path);
    }
    free(base_path);
    free(log_path);
    free(tmp_path);
    return e;
}

/* Shadow of the grid's bounds, then base 0 and journal.log (journal.h). */
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
    if (j->dir == NULL || !journal_fits(j, g) || !journal_shadow_take(&j->shadow, g, glo, ghi)) {
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
    if (!journal_shadow_take(&sh, g, glo, ghi)) {
        journal_shadow_free(&sh);
        io_err(err, err_len, "%s: out of memory for the journal of the grown clay", j->dir);
        return ARGIL_ERR_NOMEM;
    }
    journal_shadow_free(&j->shadow);
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

/* One record of what changed since the last one, or a rebase (journal.h). */
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
    const bool material_changed =
        !journal_same_bits(&g->material, &j->material, sizeof(j->material));
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
    if (!journal_diff_blocks(j, g, JOURNAL_KIND_DENS, gl, gh, &nviews) ||
        !journal_buf_reserve(j, 4 + JOURNAL_RECORD_HEAD_BYTES)) {
        io_err(err, err_len, "%s: out of memory for journal records", j->dir);
        return ARGIL_ERR_NOMEM; /* nothing written yet: the journal goes on */
    }
    j->buf_len += 4 + JOURNAL_RECORD_HEAD_BYTES;
    uint32_t runs = 0;
    if (!journal_diff_put_runs(j, g, JOURNAL_KIND_DENS, gl, gh, nviews, &runs))
        goto nomem;
    /* Painted channels: over the whole box, when they may have changed (record type 2); then
     * the painted colour likewise (type 3: the material block count, maybe 0, always precedes
     * it). */
    uint32_t blocks = 0, rgb_runs = 0;
    const bool look_mat = box == NULL || g->mat_writes != j->mat_writes;
    const bool look_rgb = box == NULL || g->rgb_writes != j->rgb_writes;
    const size_t blocks_at = j->buf_len;
    if (look_mat || look_rgb) {
        if (!journal_buf_reserve(j, 4))
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
        if (!journal_buf_reserve(j, 8) ||
            !journal_diff_blocks(j, g, JOURNAL_KIND_MAT0 + ch, jl, jh, &nviews))
            goto nomem;
        j->buf_len += 8;
        if (!journal_diff_put_runs(j, g, JOURNAL_KIND_MAT0 + ch, jl, jh, nviews, &mruns))
            goto nomem;
        if (mruns == 0) {
            j->buf_len = at;
            continue;
        }
        le_put_u32(j->buf + at, (uint32_t)ch);
        le_put_u32(j->buf + at + 4, mruns);
        blocks++;
    }
    if (look_mat)
        j->mat_writes = g->mat_writes;
    if (look_rgb) {
        if (grid_rgb_any(g))
            j->rgb_seen = true;
        const size_t rgb_at = j->buf_len;
        if (!journal_buf_reserve(j, 4) ||
            !journal_diff_blocks(j, g, JOURNAL_KIND_RGB, jl, jh, &nviews))
            goto nomem;
        j->buf_len += 4;
        if (!journal_diff_put_runs(j, g, JOURNAL_KIND_RGB, jl, jh, nviews, &rgb_runs))
            goto nomem;
        if (rgb_runs == 0)
            j->buf_len = rgb_at;
        else
            le_put_u32(j->buf + rgb_at, rgb_runs);
        j->rgb_writes = g->rgb_writes;
    }
    if (blocks == 0 && rgb_runs == 0)
        j->buf_len = blocks_at;
    else
        le_put_u32(j->buf + blocks_at, blocks);
    if (runs == 0 && !material_changed && blocks == 0 && rgb_runs == 0) {
        j->buf_len = rec_at;
        return ARGIL_OK;
    }
    const size_t payload = j->buf_len - rec_at - 4;
    if ((uint64_t)payload + 8 >= JOURNAL_RECORD_MAX_BYTES || !journal_buf_reserve(j, 4))
        goto nomem;
    j->material = g->material;
    j->edits = edits;
    j->seq++;
    uint8_t *p = j->buf + rec_at;
    le_put_u32(p, (uint32_t)payload);
    uint8_t *h = p + 4;
    /* record type: edit step (2: with painted material, 3: with painted colour) */
    le_put_u32(h, rgb_runs > 0 ? 3u : (blocks > 0 ? 2u : 1u));
    le_put_u32(h + 4, j->seq);
    const double sim_us = sim_s > 0.0 ? sim_s * 1e6 + 0.5 : 0.0;
    le_put_u64(h + 8, (uint64_t)sim_us);
    le_put_u64(h + 16, wall_ms);
    le_put_u32(h + 24, edits);
    journal_put_material(h + 28, &j->material);
    le_put_u32(h + 48, runs);
    le_put_u32(j->buf + j->buf_len, crc32c(0, p, 4 + payload));
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
    journal_shadow_free(&j->shadow);
    j->ready = false;
    return ARGIL_ERR_NOMEM;
}

/* Writes and fdatasyncs the buffer; it empties only on success. */
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

/* Base N+1 and a new journal.log, then base N removed. */
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
    char *p = journal_path(j->dir, name);
    if (p != NULL)
        (void)unlink(p);
    free(p);
    j->checkpoint_sim_s = sim_s;
    j->stats.checkpoints++;
    return ARGIL_OK;
}

/* True once the oldest buffered record is autosave_s old in either clock. */
bool journal_sync_due(const journal_t *j, double sim_s, double real_s)
{
    return j->buf_len > 0 && (sim_s - j->oldest_pending_sim_s >= (double)j->cfg.autosave_s ||
                              real_s - j->oldest_pending_real_s >= (double)j->cfg.autosave_s);
}

/* A sync when due, then a checkpoint when due. */
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

/* Frees everything the journal holds; its files stay. */
void journal_close(journal_t *j)
{
    if (j->fd >= 0)
        (void)close(j->fd);
    j->fd = -1;
    free(j->dir);
    j->dir = NULL;
    journal_shadow_free(&j->shadow);
    j->ready = false;
    free(j->views);
    j->views = NULL;
    j->views_cap = 0;
    free(j->buf);
    j->buf = NULL;
    j->buf_len = j->buf_cap = 0;
}

/* Closes, then discards the journal's files. */
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

/* True when dir/journal.log is a regular file. */
bool journal_exists(const char *dir)
{
    char *p = journal_path(dir, JOURNAL_FILE);
    struct stat st;
    const bool yes = p != NULL && stat(p, &st) == 0 && S_ISREG(st.st_mode);
    free(p);
    return yes;
}

/* journal.log first, then the bases and temporaries (journal.h). */
argil_err_t journal_discard(const char *dir, char *err, size_t err_len)
{
    /* The journal first: once it is gone no base is needed. */
    char *p = journal_path(dir, JOURNAL_FILE);
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
        char *q = journal_path(dir, name);
        if (q != NULL)
            (void)unlink(q);
        free(q);
    }
    closedir(d);
    sync_dir(dir);
    return ARGIL_OK;
}
