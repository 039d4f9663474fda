/* .argil reader and writer. Every field is encoded little-endian byte by byte; the reader checks
 * the header CRC, the declared length against the real file size, the whole-file CRC and every
 * section's CRC and size before it allocates or decodes anything. */
#include "host/io/argil_file.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/io_util.h"
#include "shared/crc32c.h"
#include "shared/wire.h"

static const uint8_t AF_MAGIC[8] = {'A', 'R', 'G', 'I', 'L', '\r', '\n', 0x1a};
#define AF_SEC_OVERHEAD 16u /* tag 4 + length 8 + crc 4 */

void argil_doc_init(argil_doc_t *d)
{
    memset(d, 0, sizeof(*d));
    d->tool.radius_m = 0.005f;
    d->tool.strength = 0.5f;
    d->tool.paint_rgb[0] = 200;
    d->tool.paint_rgb[1] = 80;
    d->tool.paint_rgb[2] = 40;
    d->state.device_scale = 1.0f;
}

void argil_doc_free(argil_doc_t *d)
{
    grid_free(&d->grid);
    free(d->rgb);
    rbf_free(&d->rbf);
    octfit_free(&d->octree);
    argil_doc_init(d);
}

/* ------------------------------------------------------------------ writer */

typedef struct {
    const argil_doc_t *d;
    size_t n; /* samples */
    int32_t dims[3], lo[3];           /* the dense box written: the grid's bounds */
    const float *dens;                /* its densities */
    const float *mat[GRID_MAT_N];     /* its painted channels (NULL: unpainted) */
    uint32_t mat_runs[GRID_MAT_N];    /* MTLS runs per painted channel (0: not written) */
    uint64_t mat_samples[GRID_MAT_N]; /* samples inside those runs */
} af_wctx_t;

static bool af_same(float a, float b)
{
    return memcmp(&a, &b, sizeof(float)) == 0;
}

/* The next MTLS run of channel m at or after *pos: [start, end) from a painted sample to a
 * painted sample, bridging at most ARGIL_FILE_RUN_GAP unpainted ones; false when none is left. */
static bool af_next_run(const float *m, size_t n, float def, size_t *pos, size_t *start,
                        size_t *end)
{
    size_t i = *pos;
    while (i < n && af_same(m[i], def))
        i++;
    if (i >= n) {
        *pos = n;
        return false;
    }
    *start = i;
    size_t last = i;
    for (i = last + 1; i < n && i - last - 1 <= ARGIL_FILE_RUN_GAP; i++)
        if (!af_same(m[i], def))
            last = i;
    *end = last + 1;
    *pos = last + 1;
    return true;
}

uint32_t argil_file_mat_runs(const float *m, size_t n, float def, uint64_t *samples)
{
    uint32_t runs = 0;
    *samples = 0;
    if (m == NULL)
        return 0;
    size_t pos = 0, a, b;
    while (af_next_run(m, n, def, &pos, &a, &b)) {
        runs++;
        *samples += b - a;
    }
    return runs;
}

/* MTLS: channel count, then per painted channel its id, run count and runs (start, count,
 * count values). */
static uint64_t af_mtls_bytes(const af_wctx_t *c)
{
    uint64_t bytes = 4;
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        if (c->mat_runs[ch] > 0)
            bytes += 8u + 8u * (uint64_t)c->mat_runs[ch] + 4u * c->mat_samples[ch];
    return bytes;
}

static uint32_t af_mtls_channels(const af_wctx_t *c)
{
    uint32_t k = 0;
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        k += c->mat_runs[ch] > 0;
    return k;
}

typedef struct {
    FILE *f;
    uint32_t file_crc, sec_crc;
    bool bad;
} af_out_t;

static void af_put(af_out_t *o, const void *p, size_t n)
{
    if (o->bad || n == 0)
        return;
    o->file_crc = crc32c(o->file_crc, p, n);
    o->sec_crc = crc32c(o->sec_crc, p, n);
    if (fwrite(p, 1, n, o->f) != n)
        o->bad = true;
}

static void af_begin(af_out_t *o, const char tag[4], uint64_t len)
{
    uint8_t h[12];
    memcpy(h, tag, 4);
    le_put_u64(h + 4, len);
    o->sec_crc = 0;
    af_put(o, h, 12);
}

static void af_end(af_out_t *o)
{
    uint8_t c[4];
    le_put_u32(c, o->sec_crc);
    af_put(o, c, 4);
}

static void af_put_f32s(af_out_t *o, const float *v, size_t n)
{
    uint8_t buf[4096];
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        le_put_f32(buf + used, v[i]);
        used += 4;
        if (used == sizeof(buf)) {
            af_put(o, buf, used);
            used = 0;
        }
    }
    af_put(o, buf, used);
}

static uint64_t af_grid_bytes(size_t n)
{
    return 36u + 4u * (uint64_t)n;
}

/* OCTB: 40-byte head, a uint32 child link per node, OCTFIT_NCOEF floats per leaf. */
static uint64_t af_octb_bytes(const octfit_model_t *m)
{
    return 40u + 4u * (uint64_t)m->n_nodes + 4u * OCTFIT_NCOEF * (uint64_t)m->n_leaves;
}

static void af_wctx_free(af_wctx_t *c)
{
    free((void *)c->dens);
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        free((void *)c->mat[ch]);
}

static const char *af_write_body(FILE *f, const void *vctx)
{
    const af_wctx_t *c = vctx;
    const argil_doc_t *d = c->d;
    const grid_t *g = &d->grid;
    af_out_t o = {f, 0, 0, false};
    const bool mtls = af_mtls_channels(c) > 0;
    const bool pnts = d->tool.paint_chosen;
    uint32_t n_sec =
        4 + (d->rgb != NULL) + (d->has_rbf != 0) + (d->has_octree != 0) + mtls + pnts;
    uint64_t total = ARGIL_FILE_HEADER_BYTES + 4;
    total += AF_SEC_OVERHEAD + af_grid_bytes(c->n);
    total += AF_SEC_OVERHEAD + 20 + AF_SEC_OVERHEAD + 16 + AF_SEC_OVERHEAD + 20;
    if (d->rgb != NULL)
        total += AF_SEC_OVERHEAD + 3u * (uint64_t)c->n;
    if (pnts)
        total += AF_SEC_OVERHEAD + 4;
    if (d->has_rbf)
        total += AF_SEC_OVERHEAD + 28u + 16u * (uint64_t)d->rbf.n;
    if (d->has_octree)
        total += AF_SEC_OVERHEAD + af_octb_bytes(&d->octree);
    if (mtls)
        total += AF_SEC_OVERHEAD + af_mtls_bytes(c);
    uint8_t h[ARGIL_FILE_HEADER_BYTES] = {0};
    memcpy(h, AF_MAGIC, 8);
    le_put_u32(h + 8, mtls ? ARGIL_FILE_VERSION_MTLS : 1u);
    le_put_u32(h + 12, n_sec);
    le_put_u64(h + 16, total);
    le_put_u32(h + 28, crc32c(0, h, 28));
    af_put(&o, h, sizeof(h));

    uint8_t b[64];
    af_begin(&o, "GRID", af_grid_bytes(c->n));
    for (int a = 0; a < 3; a++)
        le_put_u32(b + 4 * a, (uint32_t)c->dims[a]);
    const vec3_t org = grid_box_origin(g, c->lo);
    const float gf[6] = {g->spacing_m, org.x, org.y, org.z, g->iso, g->band_m};
    for (int k = 0; k < 6; k++)
        le_put_f32(b + 12 + 4 * k, gf[k]);
    af_put(&o, b, 36);
    af_put_f32s(&o, c->dens, c->n);
    af_end(&o);

    af_begin(&o, "MATL", 20);
    const spring_material_t *m = &g->material;
    const float mf[5] = {m->node_mass, m->stiffness, m->coupling, m->damping, m->plastic_rate_hz};
    af_put_f32s(&o, mf, 5);
    af_end(&o);

    af_begin(&o, "TOOL", 16);
    le_put_u32(b, d->tool.tool_kind);
    le_put_f32(b + 4, d->tool.radius_m);
    le_put_f32(b + 8, d->tool.strength);
    memcpy(b + 12, d->tool.paint_rgb, 3);
    b[15] = 0;
    af_put(&o, b, 16);
    af_end(&o);

    af_begin(&o, "STAT", 20);
    const float sf[4] = {d->state.device_offset_m.x, d->state.device_offset_m.y,
                         d->state.device_offset_m.z, d->state.device_scale};
    for (int k = 0; k < 4; k++)
        le_put_f32(b + 4 * k, sf[k]);
    le_put_u32(b + 16, d->state.edits);
    af_put(&o, b, 20);
    af_end(&o);

    if (pnts) { /* the paint settings a session chose (its colour is TOOL's paint rgb) */
        af_begin(&o, "PNTS", 4);
        le_put_f32(b, d->tool.soft_paint_per_s);
        af_put(&o, b, 4);
        af_end(&o);
    }

    if (d->rgb != NULL) {
        af_begin(&o, "COLR", 3u * (uint64_t)c->n);
        af_put(&o, d->rgb, 3 * c->n);
        af_end(&o);
    }
    if (mtls) {
        af_begin(&o, "MTLS", af_mtls_bytes(c));
        le_put_u32(b, af_mtls_channels(c));
        af_put(&o, b, 4);
        for (int ch = 0; ch < GRID_MAT_N; ch++) {
            if (c->mat_runs[ch] == 0)
                continue;
            le_put_u32(b, (uint32_t)ch);
            le_put_u32(b + 4, c->mat_runs[ch]);
            af_put(&o, b, 8);
            const float *mv = c->mat[ch], def = grid_mat_default((grid_mat_t)ch);
            size_t pos = 0, r0, r1;
            while (af_next_run(mv, c->n, def, &pos, &r0, &r1)) {
                le_put_u32(b, (uint32_t)r0);
                le_put_u32(b + 4, (uint32_t)(r1 - r0));
                af_put(&o, b, 8);
                af_put_f32s(&o, mv + r0, r1 - r0);
            }
        }
        af_end(&o);
    }
    if (d->has_rbf) {
        const rbf_model_t *r = &d->rbf;
        af_begin(&o, "RBF3", 28u + 16u * (uint64_t)r->n);
        le_put_u32(b, r->n);
        const float rf[6] = {r->poly[0], r->poly[1], r->poly[2], r->poly[3], r->rms_err_m,
                             r->max_err_m};
        for (int k = 0; k < 6; k++)
            le_put_f32(b + 4 + 4 * k, rf[k]);
        af_put(&o, b, 28);
        for (uint32_t i = 0; i < r->n; i++) {
            const float cf[4] = {r->centre_m[3 * i], r->centre_m[3 * i + 1], r->centre_m[3 * i + 2],
                                 r->weight[i]};
            af_put_f32s(&o, cf, 4);
        }
        af_end(&o);
    }
    if (d->has_octree) {
        const octfit_model_t *om = &d->octree;
        af_begin(&o, "OCTB", af_octb_bytes(om));
        le_put_u32(b, om->n_nodes);
        le_put_u32(b + 4, OCTFIT_N);
        le_put_u32(b + 8, om->kind);
        const float of[7] = {om->origin_m[0], om->origin_m[1], om->origin_m[2], om->size_m,
                             om->rms_err, om->max_err, OCTFIT_OVERLAP};
        for (int k = 0; k < 7; k++)
            le_put_f32(b + 12 + 4 * k, of[k]);
        af_put(&o, b, 40);
        for (uint32_t i = 0; i < om->n_nodes; i++) {
            le_put_u32(b, om->child[i]);
            af_put(&o, b, 4);
        }
        for (uint32_t i = 0; i < om->n_leaves; i++)
            af_put_f32s(&o, om->leaf[i].coef, OCTFIT_NCOEF);
        af_end(&o);
    }
    uint8_t t[4];
    le_put_u32(t, o.file_crc);
    if (!o.bad && fwrite(t, 1, 4, f) != 4)
        o.bad = true;
    return o.bad ? "fwrite" : NULL;
}

static bool af_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return false;
    return true;
}

static argil_err_t af_write_ctx(const char *path, af_wctx_t *cp, char *err, size_t err_len);

argil_err_t argil_file_write(const char *path, const argil_doc_t *d, char *err, size_t err_len)
{
    if (path == NULL || d == NULL || grid_count(&d->grid) == 0) {
        io_err(err, err_len, "argil_file_write: no path or no model grid");
        return ARGIL_ERR_ARG;
    }
    const grid_t *g = &d->grid;
    af_wctx_t c = {d, grid_count(g), {0}, {0}, NULL, {NULL}, {0}, {0}};
    float *dens = grid_dense_copy(g, GRID_DENSITY, c.lo, c.dims);
    if (dens == NULL) {
        io_err(err, err_len, "argil_file_write: %s: out of memory", path);
        return ARGIL_ERR_NOMEM;
    }
    c.dens = dens;
    const argil_err_t e = af_write_ctx(path, &c, err, err_len);
    af_wctx_free(&c);
    return e;
}

/* Takes a dense copy of painted channel ch into c (its runs and painted samples counted);
 * ARGIL_ERR_NOMEM, or ARGIL_ERR_NONFINITE for a value out of grid_mat_valid's range. */
static argil_err_t af_take_mat(af_wctx_t *c, int ch, const char *path, char *err, size_t err_len)
{
    const grid_mat_t mc = (grid_mat_t)ch;
    int32_t mlo[3], mn[3];
    c->mat[ch] = grid_dense_copy_mat(&c->d->grid, mc, mlo, mn);
    const float *m = c->mat[ch];
    if (m == NULL) {
        io_err(err, err_len, "argil_file_write: %s: out of memory", path);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < c->n; i++)
        if (!grid_mat_valid(mc, m[i])) {
            io_err(err, err_len, "argil_file_write: %s: painted material channel %d holds "
                   "%g at sample %zu (out of range)", path, ch, (double)m[i], i);
            return ARGIL_ERR_NONFINITE;
        }
    c->mat_runs[ch] = argil_file_mat_runs(m, c->n, grid_mat_default(mc), &c->mat_samples[ch]);
    return ARGIL_OK;
}

static argil_err_t af_write_ctx(const char *path, af_wctx_t *cp, char *err, size_t err_len)
{
    const argil_doc_t *d = cp->d;
    const grid_t *g = &d->grid;
    const size_t n = cp->n;
    const float gf[6] = {g->spacing_m, g->origin_m.x, g->origin_m.y, g->origin_m.z, g->iso,
                         g->band_m};
    if (!af_finite(gf, 6) || !af_finite(cp->dens, n) ||
        (d->has_rbf && (!af_finite(d->rbf.centre_m, 3 * (size_t)d->rbf.n) ||
                        !af_finite(d->rbf.weight, d->rbf.n) || !af_finite(d->rbf.poly, 4)))) {
        io_err(err, err_len, "argil_file_write: %s: the model holds NaN or Inf", path);
        return ARGIL_ERR_NONFINITE;
    }
    if (d->has_octree) {
        const octfit_model_t *m = &d->octree;
        bool ok = m->n_nodes >= 1 && m->n_nodes <= OCTFIT_NODES_MAX && m->kind <= 1;
        const float of[6] = {m->origin_m[0], m->origin_m[1], m->origin_m[2], m->size_m,
                             m->rms_err, m->max_err};
        ok = ok && af_finite(of, 6);
        for (uint32_t i = 0; ok && i < m->n_leaves; i++)
            ok = af_finite(m->leaf[i].coef, OCTFIT_NCOEF);
        if (!ok) {
            io_err(err, err_len, "argil_file_write: %s: octree fit holds NaN, Inf or no nodes", path);
            return ARGIL_ERR_NONFINITE;
        }
    }
    const float rate = d->tool.soft_paint_per_s;
    if (d->tool.paint_chosen && !(isfinite(rate) && rate >= 0 && rate <= ARGIL_FILE_PAINT_RATE_MAX)) {
        io_err(err, err_len, "argil_file_write: %s: soft-paint rate %g not in 0..%g per second",
               path, (double)rate, (double)ARGIL_FILE_PAINT_RATE_MAX);
        return ARGIL_ERR_NONFINITE;
    }
    if (d->has_rbf && d->rbf.n > RBF_CENTRES_MAX) {
        io_err(err, err_len, "argil_file_write: %s: RBF has too many centres", path);
        return ARGIL_ERR_ARG;
    }
    for (int ch = 0; ch < GRID_MAT_N; ch++) {
        const argil_err_t e = grid_mat_painted(g, (grid_mat_t)ch)
                                  ? af_take_mat(cp, ch, path, err, err_len)
                                  : ARGIL_OK;
        if (e != ARGIL_OK)
            return e;
    }
    return io_write_atomic(path, af_write_body, cp, "argil_file_write", err, err_len);
}

/* ------------------------------------------------------------------ reader */

typedef struct {
    const char *path;
    char *err;
    size_t err_len;
} af_rctx_t;

/* Writes "path: byte off: rule" into the context's err and returns code. */
static argil_file_err_t af_fail(const af_rctx_t *c, size_t off, argil_file_err_t code,
                                const char *rule)
{
    io_err(c->err, c->err_len, "%s: byte %zu: %s", c->path, off, rule);
    return code;
}

argil_err_t argil_file_err_argil(argil_file_err_t e)
{
    switch (e) {
    case ARGIL_FILE_OK: return ARGIL_OK;
    case ARGIL_FILE_ERR_ARG: return ARGIL_ERR_ARG;
    case ARGIL_FILE_ERR_IO: return ARGIL_ERR_IO;
    case ARGIL_FILE_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

/* The argil_file_err_t of a failure outside the file: io_slurp's (PARSE: the file is too
 * large) or an allocation's. */
static argil_file_err_t af_outside_err(argil_err_t e)
{
    switch (e) {
    case ARGIL_OK: return ARGIL_FILE_OK;
    case ARGIL_ERR_ARG: return ARGIL_FILE_ERR_ARG;
    case ARGIL_ERR_NOMEM: return ARGIL_FILE_ERR_NOMEM;
    case ARGIL_ERR_PARSE: return ARGIL_FILE_ERR_FILE_SIZE;
    default: return ARGIL_FILE_ERR_IO;
    }
}

static void af_get_f32s(const uint8_t *p, float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        v[i] = le_get_f32(p + 4 * i);
}

/* Decodes the GRID section payload (len bytes at p, file offset off). */
static argil_file_err_t af_grid(const af_rctx_t *c, const uint8_t *p, uint64_t len, size_t off,
                                argil_doc_t *d)
{
    if (len < 36)
        return af_fail(c, off, ARGIL_FILE_ERR_GRID_HEAD,
                       "GRID section shorter than its 36-byte head");
    int32_t dims[3];
    uint64_t n = 1;
    for (int a = 0; a < 3; a++) {
        dims[a] = (int32_t)le_get_u32(p + 4 * a);
        if (dims[a] < 1)
            return af_fail(c, off + 4 * (size_t)a, ARGIL_FILE_ERR_GRID_DIM,
                           "GRID dimension below 1");
        n *= (uint64_t)dims[a];
        if (n > (uint64_t)GRID_SAMPLES_MAX)
            return af_fail(c, off + 4 * (size_t)a, ARGIL_FILE_ERR_GRID_SAMPLES_MAX,
                           "GRID holds more than 2^30 samples");
    }
    if (len != af_grid_bytes((size_t)n))
        return af_fail(c, off, ARGIL_FILE_ERR_GRID_LENGTH,
                       "GRID section length does not match its dimensions");
    float gf[6];
    af_get_f32s(p + 12, gf, 6);
    if (!af_finite(gf, 6) || !(gf[0] > 0) || !(gf[5] > 0))
        return af_fail(c, off + 12, ARGIL_FILE_ERR_GRID_GEOMETRY,
                       "GRID spacing, origin, iso or band not finite (or not > 0)");
    if (grid_init(&d->grid, dims, gf[0], vec3(gf[1], gf[2], gf[3])) != ARGIL_OK) {
        io_err(c->err, c->err_len, "%s: out of memory for %llu samples", c->path,
               (unsigned long long)n);
        return ARGIL_FILE_ERR_NOMEM;
    }
    d->grid.iso = gf[4];
    d->grid.band_m = gf[5];
    float *v = malloc((size_t)n * sizeof(float));
    if (v == NULL) {
        io_err(c->err, c->err_len, "%s: out of memory for %llu samples", c->path,
               (unsigned long long)n);
        return ARGIL_FILE_ERR_NOMEM;
    }
    for (size_t i = 0; i < (size_t)n; i++) {
        v[i] = le_get_f32(p + 36 + 4 * i);
        if (!isfinite(v[i]) || v[i] < 0.0f || v[i] > 1.0f) {
            free(v);
            return af_fail(c, off + 36 + 4 * i, ARGIL_FILE_ERR_GRID_DENSITY,
                           "GRID density not a finite number in [0, 1]");
        }
    }
    const int32_t zero[3] = {0, 0, 0};
    argil_err_t e = grid_write_box(&d->grid, GRID_DENSITY, zero, dims, v);
    if (e == ARGIL_OK)
        e = grid_write_box(&d->grid, GRID_REST, zero, dims, v);
    free(v);
    if (e != ARGIL_OK) {
        io_err(c->err, c->err_len, "%s: out of memory for %llu samples", c->path,
               (unsigned long long)n);
        return af_outside_err(e);
    }
    return ARGIL_FILE_OK;
}

/* Decodes the OCTB section (len >= 40 bytes at p, file offset off). */
static argil_file_err_t af_octb(const af_rctx_t *c, const uint8_t *p, uint64_t len, size_t off,
                                argil_doc_t *d)
{
    const uint32_t n = le_get_u32(p), per_axis = le_get_u32(p + 4), kind = le_get_u32(p + 8);
    if (n < 1 || n > OCTFIT_NODES_MAX || (uint64_t)len < 40u + 4u * (uint64_t)n)
        return af_fail(c, off, ARGIL_FILE_ERR_OCTB_NODES,
                       "OCTB node count not in 1..65537 or past the section's end");
    if (per_axis != OCTFIT_N)
        return af_fail(c, off + 4, ARGIL_FILE_ERR_OCTB_PER_AXIS,
                       "OCTB coefficients per axis not 6");
    if (kind > 1)
        return af_fail(c, off + 8, ARGIL_FILE_ERR_OCTB_KIND,
                       "OCTB kind not 0 (signed distance) or 1 (intensity)");
    float of[7];
    af_get_f32s(p + 12, of, 7);
    if (!af_finite(of, 7) || !(of[3] > 0) || of[6] != OCTFIT_OVERLAP)
        return af_fail(c, off + 12, ARGIL_FILE_ERR_OCTB_GEOMETRY,
                       "OCTB origin, size, errors or overlap not finite (size > 0, "
                       "overlap 0.25)");
    uint32_t *child = malloc((size_t)n * sizeof(uint32_t));
    if (child == NULL) {
        io_err(c->err, c->err_len, "%s: out of memory", c->path);
        return ARGIL_FILE_ERR_NOMEM;
    }
    uint64_t leaves = 0;
    for (uint32_t i = 0; i < n; i++) {
        child[i] = le_get_u32(p + 40 + 4 * (size_t)i);
        leaves += child[i] == 0;
    }
    /* The leaves' coefficients must all be in the section before anything is allocated for
     * them: a declared count never drives an allocation the file cannot back. */
    if (len != 40u + 4u * (uint64_t)n + 4u * OCTFIT_NCOEF * leaves) {
        free(child);
        return af_fail(c, off, ARGIL_FILE_ERR_OCTB_LENGTH,
                       "OCTB section length does not match its nodes and leaves");
    }
    const argil_err_t e = octfit_alloc(&d->octree, n, child, of, of[3]);
    free(child);
    if (e == ARGIL_ERR_NOMEM) {
        io_err(c->err, c->err_len, "%s: out of memory", c->path);
        return ARGIL_FILE_ERR_NOMEM;
    }
    if (e != ARGIL_OK)
        return af_fail(c, off + 40, ARGIL_FILE_ERR_OCTB_LINKS,
                       "OCTB child links do not form an octree (each node the child "
                       "of one earlier node, 8 consecutive children, depth <= 10)");
    d->has_octree = true;
    octfit_model_t *m = &d->octree;
    if (len != af_octb_bytes(m))
        return af_fail(c, off, ARGIL_FILE_ERR_OCTB_LENGTH,
                       "OCTB section length does not match its nodes and leaves");
    m->kind = kind;
    m->rms_err = of[4];
    m->max_err = of[5];
    const uint8_t *q = p + 40 + 4 * (size_t)n;
    for (uint32_t i = 0; i < m->n_leaves; i++) {
        af_get_f32s(q + 4 * OCTFIT_NCOEF * (size_t)i, m->leaf[i].coef, OCTFIT_NCOEF);
        if (!af_finite(m->leaf[i].coef, OCTFIT_NCOEF))
            return af_fail(c, off + (size_t)(q - p) + 4 * OCTFIT_NCOEF * (size_t)i,
                           ARGIL_FILE_ERR_OCTB_COEF, "OCTB coefficient NaN or Inf");
    }
    return ARGIL_FILE_OK;
}

/* Decodes the MTLS section (len bytes at p, file offset off) into the grid's painted channels
 * (n samples). Every value is checked before the channel it belongs to is allocated. */
static argil_file_err_t af_mtls(const af_rctx_t *c, const uint8_t *p, uint64_t len, size_t off,
                                size_t n, argil_doc_t *d)
{
    if (len < 4)
        return af_fail(c, off, ARGIL_FILE_ERR_MTLS_COUNT,
                       "MTLS section shorter than its 4-byte channel count");
    const uint32_t k = le_get_u32(p);
    if (k < 1 || k > GRID_MAT_N)
        return af_fail(c, off, ARGIL_FILE_ERR_MTLS_COUNT, "MTLS channel count not in 1..4");
    uint64_t at = 4;
    int64_t prev_ch = -1;
    for (uint32_t i = 0; i < k; i++) {
        if (len - at < 8)
            return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_CHANNEL,
                           "MTLS channel head runs past the section");
        const uint32_t ch = le_get_u32(p + at), runs = le_get_u32(p + at + 4);
        if (ch >= GRID_MAT_N || (int64_t)ch <= prev_ch)
            return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_CHANNEL,
                           "MTLS channel id not 0..3 (stiffness, mass, "
                           "damping, rest length) in increasing order");
        if (runs < 1)
            return af_fail(c, off + (size_t)at + 4, ARGIL_FILE_ERR_MTLS_CHANNEL,
                           "MTLS channel with no runs");
        prev_ch = (int64_t)ch;
        at += 8;
        const uint64_t first = at;
        uint64_t next_start = 0;
        /* Check the runs... */
        for (uint32_t r = 0; r < runs; r++) {
            if (len - at < 8)
                return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_RUN,
                               "MTLS run head runs past the section");
            const uint64_t start = le_get_u32(p + at), count = le_get_u32(p + at + 4);
            if (count < 1 || start < next_start || start + count > (uint64_t)n)
                return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_RUN,
                               "MTLS run empty, overlapping or out of order, "
                               "or beyond the grid's samples");
            if ((len - at - 8) / 4 < count)
                return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_RUN,
                               "MTLS run values run past the section");
            for (uint64_t v = 0; v < count; v++) {
                const size_t vo = (size_t)(at + 8 + 4 * v);
                if (!grid_mat_valid((grid_mat_t)ch, le_get_f32(p + vo)))
                    return af_fail(c, off + vo, ARGIL_FILE_ERR_MTLS_VALUE,
                                   "MTLS value out of range (finite; mass scale > 0, "
                                   "stiffness and damping scales >= 0)");
            }
            next_start = start + count;
            at += 8 + 4 * count;
        }
        /* ... then store them. */
        int32_t mlo[3], mn[3];
        float *m = grid_dense_copy_mat(&d->grid, (grid_mat_t)ch, mlo, mn);
        if (m == NULL) {
            io_err(c->err, c->err_len, "%s: out of memory", c->path);
            return ARGIL_FILE_ERR_NOMEM;
        }
        for (uint64_t q = first, r = 0; r < runs; r++) {
            const size_t start = le_get_u32(p + q), count = le_get_u32(p + q + 4);
            af_get_f32s(p + q + 8, m + start, count);
            q += 8 + 4 * (uint64_t)count;
        }
        const argil_err_t we = grid_mat_write_box(&d->grid, (grid_mat_t)ch, mlo, mn, m);
        free(m);
        if (we != ARGIL_OK) {
            io_err(c->err, c->err_len, "%s: out of memory", c->path);
            return af_outside_err(we);
        }
    }
    if (at != len)
        return af_fail(c, off + (size_t)at, ARGIL_FILE_ERR_MTLS_TRAILING,
                       "bytes after the last MTLS channel");
    return ARGIL_FILE_OK;
}

/* The 16-byte TOOL section at p (payload offset off in the file) into d->tool. */
static argil_file_err_t af_tool(const af_rctx_t *c, const uint8_t *p, size_t off, argil_doc_t *d)
{
    d->tool.tool_kind = le_get_u32(p);
    d->tool.radius_m = le_get_f32(p + 4);
    d->tool.strength = le_get_f32(p + 8);
    memcpy(d->tool.paint_rgb, p + 12, 3);
    if (!isfinite(d->tool.radius_m) || d->tool.radius_m < 0 || !isfinite(d->tool.strength) ||
        d->tool.strength < 0 || d->tool.strength > 1)
        return af_fail(c, off + 4, ARGIL_FILE_ERR_TOOL_VALUE,
                       "TOOL radius or strength out of range");
    return ARGIL_FILE_OK;
}

/* The RBF3 section (sl >= 28 bytes at p, file offset off) into d->rbf. */
static argil_file_err_t af_rbf3(const af_rctx_t *c, const uint8_t *p, uint64_t sl, size_t off,
                                argil_doc_t *d)
{
    const uint32_t n = le_get_u32(p);
    if (n > RBF_CENTRES_MAX || sl != 28u + 16u * (uint64_t)n)
        return af_fail(c, off, ARGIL_FILE_ERR_RBF3_COUNT,
                       "RBF3 centre count out of range or not matching the "
                       "section length");
    if (rbf_alloc(&d->rbf, n) != ARGIL_OK) {
        io_err(c->err, c->err_len, "%s: out of memory", c->path);
        return ARGIL_FILE_ERR_NOMEM;
    }
    d->has_rbf = true;
    float rf[6];
    af_get_f32s(p + 4, rf, 6);
    memcpy(d->rbf.poly, rf, sizeof(d->rbf.poly));
    d->rbf.rms_err_m = rf[4];
    d->rbf.max_err_m = rf[5];
    for (uint32_t i = 0; i < n; i++) {
        float cf[4];
        af_get_f32s(p + 28 + 16 * (size_t)i, cf, 4);
        memcpy(d->rbf.centre_m + 3 * (size_t)i, cf, 3 * sizeof(float));
        d->rbf.weight[i] = cf[3];
    }
    if (!af_finite(rf, 6) || !af_finite(d->rbf.centre_m, 3 * (size_t)n) ||
        !af_finite(d->rbf.weight, n))
        return af_fail(c, off, ARGIL_FILE_ERR_RBF3_VALUE, "RBF3 holds NaN or Inf");
    return ARGIL_FILE_OK;
}

/* The sections a file holds at most once, each of a fixed length or at least a head's. */
enum { AF_MATL, AF_TOOL, AF_STAT, AF_PNTS, AF_RBF3, AF_OCTB, AF_ONCE_N };

static const struct {
    char tag[5];
    uint64_t bytes; /* the length, or the head's when not exact */
    bool exact;
    argil_file_err_t size_err;
    const char *size_rule;
} AF_ONCE[AF_ONCE_N] = {
    {"MATL", 20, true, ARGIL_FILE_ERR_MATL_SIZE, "MATL section repeated or not 20 bytes"},
    {"TOOL", 16, true, ARGIL_FILE_ERR_TOOL_SIZE, "TOOL section repeated or not 16 bytes"},
    {"STAT", 20, true, ARGIL_FILE_ERR_STAT_SIZE, "STAT section repeated or not 20 bytes"},
    {"PNTS", 4, true, ARGIL_FILE_ERR_PNTS_SIZE, "PNTS section repeated or not 4 bytes"},
    {"RBF3", 28, false, ARGIL_FILE_ERR_RBF3_HEAD,
     "RBF3 section repeated or shorter than 28 bytes"},
    {"OCTB", 40, false, ARGIL_FILE_ERR_OCTB_HEAD,
     "OCTB section repeated or shorter than its 40-byte head"},
};

/* The AF_ONCE index of tag, or -1 when it is not one of them. */
static int af_once_find(const char *tag)
{
    for (int i = 0; i < AF_ONCE_N; i++)
        if (strcmp(tag, AF_ONCE[i].tag) == 0)
            return i;
    return -1;
}

/* True when section fx may be sl bytes long. */
static bool af_once_length_ok(int fx, uint64_t sl)
{
    return AF_ONCE[fx].exact ? sl == AF_ONCE[fx].bytes : sl >= AF_ONCE[fx].bytes;
}

/* Decodes section fx (its length checked; sl bytes at p, file offset off) into d, or the
 * material into *matl (applied once the grid exists: sections come in any order). */
static argil_file_err_t af_once(const af_rctx_t *c, int fx, const uint8_t *p, uint64_t sl,
                                size_t off, spring_material_t *matl, argil_doc_t *d)
{
    float v[5];
    af_get_f32s(p, v, fx <= AF_PNTS ? (size_t)AF_ONCE[fx].bytes / 4 : 0);
    switch (fx) {
    case AF_MATL: {
        const spring_material_t m = {v[0], v[1], v[2], v[3], v[4]};
        if (!spring_material_valid(&m))
            return af_fail(c, off, ARGIL_FILE_ERR_MATL_VALUE,
                           "MATL values out of range (mass > 0, others >= 0, finite)");
        *matl = m;
        return ARGIL_FILE_OK;
    }
    case AF_TOOL: return af_tool(c, p, off, d);
    case AF_STAT:
        if (!af_finite(v, 4) || !(v[3] > 0))
            return af_fail(c, off, ARGIL_FILE_ERR_STAT_VALUE,
                           "STAT transform not finite (or scale not > 0)");
        d->state.device_offset_m = vec3(v[0], v[1], v[2]);
        d->state.device_scale = v[3];
        d->state.edits = le_get_u32(p + 16);
        return ARGIL_FILE_OK;
    case AF_RBF3: return af_rbf3(c, p, sl, off, d);
    case AF_OCTB: return af_octb(c, p, sl, off, d);
    default:
        if (!isfinite(v[0]) || v[0] < 0 || v[0] > ARGIL_FILE_PAINT_RATE_MAX)
            return af_fail(c, off, ARGIL_FILE_ERR_PNTS_RATE,
                           "PNTS soft-paint rate not in 0..100 per second");
        d->tool.paint_chosen = true;
        d->tool.soft_paint_per_s = v[0];
        return ARGIL_FILE_OK;
    }
}

static argil_file_err_t af_parse(const af_rctx_t *c, const uint8_t *b, size_t len, argil_doc_t *d)
{
    if (len < ARGIL_FILE_HEADER_BYTES + 4)
        return af_fail(c, len, ARGIL_FILE_ERR_SHORT,
                       "file shorter than the 32-byte header and 4-byte checksum");
    if (memcmp(b, AF_MAGIC, 8) != 0)
        return af_fail(c, 0, ARGIL_FILE_ERR_MAGIC,
                       "not an .argil file (magic \"ARGIL\\r\\n\\x1a\")");
    if (le_get_u32(b + 28) != crc32c(0, b, 28))
        return af_fail(c, 28, ARGIL_FILE_ERR_HEADER_CRC,
                       "header checksum mismatch (file corrupted)");
    const uint32_t version = le_get_u32(b + 8);
    if (version == 0 || version > ARGIL_FILE_VERSION) {
        io_err(c->err, c->err_len, "%s: byte 8: format version %u; this argil reads 1..%u", c->path,
               version, ARGIL_FILE_VERSION);
        return ARGIL_FILE_ERR_VERSION;
    }
    const uint32_t n_sec = le_get_u32(b + 12);
    if (n_sec < 1 || n_sec > ARGIL_FILE_SECTIONS_MAX)
        return af_fail(c, 12, ARGIL_FILE_ERR_SECTION_COUNT, "section count not in 1..64");
    if (le_get_u64(b + 16) != (uint64_t)len)
        return af_fail(c, 16, ARGIL_FILE_ERR_FILE_LENGTH,
                       "declared file length differs from the real size (truncated or "
                       "extended)");
    if (le_get_u32(b + len - 4) != crc32c(0, b, len - 4))
        return af_fail(c, len - 4, ARGIL_FILE_ERR_FILE_CRC,
                       "file checksum mismatch (file corrupted)");
    size_t pos = ARGIL_FILE_HEADER_BYTES;
    bool seen_grid = false, seen[AF_ONCE_N] = {false};
    int fx;
    spring_material_t matl;
    spring_material_default(&matl);
    const uint8_t *colr = NULL, *mtls = NULL;
    uint64_t colr_len = 0, mtls_len = 0;
    size_t colr_off = 0, mtls_off = 0;
    for (uint32_t s = 0; s < n_sec; s++) {
        const size_t end = len - 4;
        if (end - pos < AF_SEC_OVERHEAD)
            return af_fail(c, pos, ARGIL_FILE_ERR_SECTION_HEAD,
                           "section head runs past the end of the file");
        const uint64_t sl = le_get_u64(b + pos + 4);
        if (sl > (uint64_t)(end - pos - AF_SEC_OVERHEAD))
            return af_fail(c, pos + 4, ARGIL_FILE_ERR_SECTION_LENGTH,
                           "section length runs past the end of the file");
        const uint8_t *p = b + pos + 12;
        const size_t crc_off = pos + 12 + (size_t)sl;
        if (le_get_u32(b + crc_off) != crc32c(0, b + pos, 12 + (size_t)sl))
            return af_fail(c, crc_off, ARGIL_FILE_ERR_SECTION_CRC,
                           "section checksum mismatch (file corrupted)");
        const size_t off = pos + 12;
        char tag[5] = {0};
        memcpy(tag, b + pos, 4);
        argil_file_err_t e = ARGIL_FILE_OK;
        if (strcmp(tag, "GRID") == 0) {
            if (seen_grid)
                return af_fail(c, pos, ARGIL_FILE_ERR_GRID_REPEATED, "second GRID section");
            seen_grid = true;
            e = af_grid(c, p, sl, off, d);
        } else if ((fx = af_once_find(tag)) >= 0) {
            if (seen[fx] || !af_once_length_ok(fx, sl))
                return af_fail(c, pos, AF_ONCE[fx].size_err, AF_ONCE[fx].size_rule);
            seen[fx] = true;
            e = af_once(c, fx, p, sl, off, &matl, d);
        } else if (strcmp(tag, "COLR") == 0) {
            if (colr != NULL)
                return af_fail(c, pos, ARGIL_FILE_ERR_COLR_REPEATED, "second COLR section");
            colr = p;
            colr_len = sl;
            colr_off = off;
        } else if (strcmp(tag, "MTLS") == 0) {
            if (mtls != NULL)
                return af_fail(c, pos, ARGIL_FILE_ERR_MTLS_REPEATED, "second MTLS section");
            if (version < ARGIL_FILE_VERSION_MTLS)
                return af_fail(c, pos, ARGIL_FILE_ERR_MTLS_VERSION,
                               "MTLS section (painted material) in a version-1 file");
            mtls = p;
            mtls_len = sl;
            mtls_off = off;
        }
        /* other tags: a later minor revision's optional data, checked and skipped */
        if (e != ARGIL_FILE_OK)
            return e;
        pos = crc_off + 4;
    }
    if (pos != len - 4)
        return af_fail(c, pos, ARGIL_FILE_ERR_TRAILING,
                       "bytes between the last section and the file checksum");
    if (!seen_grid)
        return af_fail(c, ARGIL_FILE_HEADER_BYTES, ARGIL_FILE_ERR_GRID_MISSING,
                       "no GRID section (the model)");
    d->grid.material = matl;
    const size_t n = grid_count(&d->grid);
    if (colr != NULL) {
        if (colr_len != 3u * (uint64_t)n)
            return af_fail(c, colr_off, ARGIL_FILE_ERR_COLR_LENGTH,
                           "COLR section is not 3 bytes per GRID sample");
        d->rgb = malloc(3 * n);
        if (d->rgb == NULL) {
            io_err(c->err, c->err_len, "%s: out of memory", c->path);
            return ARGIL_FILE_ERR_NOMEM;
        }
        memcpy(d->rgb, colr, 3 * n);
    }
    if (mtls != NULL) {
        const argil_file_err_t e = af_mtls(c, mtls, mtls_len, mtls_off, n, d);
        if (e != ARGIL_FILE_OK)
            return e;
    }
    d->file_version = version;
    return ARGIL_FILE_OK;
}

/* Reads the file c names and parses it into d (initialised). */
static argil_file_err_t af_read(const af_rctx_t *c, argil_doc_t *d)
{
    uint8_t *b;
    size_t len;
    argil_file_err_t e = af_outside_err(io_slurp(c->path, IO_FILE_MAX_BYTES, &b, &len, c->err,
                                                 c->err_len));
    if (e == ARGIL_FILE_OK) {
        e = af_parse(c, b, len, d);
        free(b);
    }
    return e;
}

argil_file_err_t argil_file_read(const char *path, argil_doc_t *d, char *err, size_t err_len)
{
    const af_rctx_t c = {path, err, err_len};
    if (path == NULL || d == NULL) {
        io_err(err, err_len, "argil_file_read: no path or no document");
        return ARGIL_FILE_ERR_ARG;
    }
    argil_doc_init(d);
    const argil_file_err_t e = af_read(&c, d);
    if (e != ARGIL_FILE_OK)
        argil_doc_free(d);
    return e;
}
