/* STL, OBJ and XYZ importers and the extension dispatch (PLY lives in ply_load.c). */
#include "host/io/mesh_import.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "host/io/io_util.h"
#include "shared/wire.h"

argil_err_t import_err_argil(import_err_t e)
{
    switch (e) {
    case IMPORT_OK: return ARGIL_OK;
    case IMPORT_ERR_ARG: return ARGIL_ERR_ARG;
    case IMPORT_ERR_IO: return ARGIL_ERR_IO;
    case IMPORT_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

import_err_t import_slurp(const char *who, const char *path, mesh_t *out, uint8_t **data,
                          size_t *len, char *err, size_t err_len)
{
    if (path == NULL || out == NULL) {
        io_err(err, err_len, "%s: no path or no mesh", who);
        return IMPORT_ERR_ARG;
    }
    mesh_clear(out);
    switch (io_slurp(path, IO_FILE_MAX_BYTES, data, len, err, err_len)) {
    case ARGIL_OK: return IMPORT_OK;
    case ARGIL_ERR_IO: return IMPORT_ERR_IO;
    case ARGIL_ERR_NOMEM: return IMPORT_ERR_NOMEM;
    case ARGIL_ERR_PARSE: return IMPORT_ERR_FILE_SIZE;
    default: return IMPORT_ERR_ARG;
    }
}

/* The rule of a line io_next_line refused (n = -2 too long, -3 NUL), with err naming the line. */
static import_err_t import_line_err(const char *path, size_t line_no, long n, char *err,
                                    size_t err_len)
{
    io_err(err, err_len, "%s: line %zu: %s", path, line_no,
           n == -2 ? "longer than 1023 bytes" : "contains a NUL byte");
    return n == -2 ? IMPORT_ERR_LINE_LONG : IMPORT_ERR_LINE_NUL;
}

/* A whole text file read one line at a time (OBJ, XYZ). */
typedef struct {
    uint8_t *buf;
    io_lines_t it;
    char line[IMPORT_LINE_MAX];
} import_text_t;

/* Clears *has_normals (when given) and reads path whole into t, as import_slurp. */
static import_err_t import_text_open(import_text_t *t, const char *who, const char *path,
                                     mesh_t *out, bool *has_normals, char *err, size_t err_len)
{
    if (has_normals != NULL)
        *has_normals = false;
    size_t len = 0;
    t->buf = NULL;
    const import_err_t e = import_slurp(who, path, out, &t->buf, &len, err, err_len);
    t->it = (io_lines_t){(const char *)t->buf, len, 0, 0, 0};
    return e;
}

/* The next line into t->line and its length; -1 at the end, or on a line too long or holding a
 * NUL, which sets *e to its rule with err naming the line. */
static long import_text_next(import_text_t *t, const char *path, import_err_t *e, char *err,
                             size_t err_len)
{
    const long n = io_next_line(&t->it, t->line, sizeof(t->line));
    if (n < -1)
        *e = import_line_err(path, t->it.line_no, n, err, err_len);
    return n < 0 ? -1 : n;
}

/* Returns e, leaving out empty unless e is IMPORT_OK. */
static import_err_t import_done(mesh_t *out, import_err_t e)
{
    if (e != IMPORT_OK)
        mesh_clear(out);
    return e;
}

/* ------------------------------------------------------------------ STL */

/* Joins bit-identical corner positions into shared vertices. */
typedef struct {
    uint32_t *slot; /* vertex index + 1, 0 = empty */
    size_t mask;
} weld_t;

static size_t weld_hash(const float p[3])
{
    uint32_t w[3];
    memcpy(w, p, sizeof(w));
    uint64_t h = w[0] * 0x9E3779B97F4A7C15ull ^ (w[1] + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
    h ^= (w[2] + 0x165667B19E3779F9ull) * 0xFF51AFD7ED558CCDull;
    return (size_t)(h ^ (h >> 29));
}

static argil_err_t weld_vertex(weld_t *wd, mesh_t *m, const float p[3], uint32_t *id)
{
    size_t h = weld_hash(p) & wd->mask;
    while (wd->slot[h] != 0) {
        const uint32_t v = wd->slot[h] - 1;
        if (memcmp(m->pos + 3 * (size_t)v, p, 3 * sizeof(float)) == 0) {
            *id = v;
            return ARGIL_OK;
        }
        h = (h + 1) & wd->mask;
    }
    argil_err_t e = mesh_add_vertex(m, vec3(p[0], p[1], p[2]), vec3(0, 0, 0), id);
    if (e == ARGIL_OK)
        wd->slot[h] = *id + 1;
    return e;
}

/* Adds one facet: welds its corners and accumulates its normal on them. */
static argil_err_t stl_facet(weld_t *wd, mesh_t *m, const float c[9])
{
    uint32_t id[3];
    for (int k = 0; k < 3; k++) {
        argil_err_t e = weld_vertex(wd, m, c + 3 * k, &id[k]);
        if (e != ARGIL_OK)
            return e;
    }
    const vec3_t a = vec3(c[0], c[1], c[2]), b = vec3(c[3], c[4], c[5]), d = vec3(c[6], c[7], c[8]);
    const vec3_t n = vec3_cross(vec3_sub(b, a), vec3_sub(d, a));
    for (int k = 0; k < 3; k++) {
        float *nn = m->normal + 3 * (size_t)id[k];
        nn[0] += n.x;
        nn[1] += n.y;
        nn[2] += n.z;
    }
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2])
        return ARGIL_OK; /* a degenerate facet adds nothing to the surface */
    return mesh_add_triangle(m, id[0], id[1], id[2]);
}

static void normalise_normals(mesh_t *m)
{
    for (size_t v = 0; v < m->n_vert; v++) {
        float *n = m->normal + 3 * v;
        const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0.0f && isfinite(len)) {
            n[0] /= len;
            n[1] /= len;
            n[2] /= len;
        } else {
            n[0] = n[1] = n[2] = 0.0f;
        }
    }
}

static import_err_t stl_binary(const char *path, const uint8_t *b, size_t len, uint32_t n_tri,
                               weld_t *wd, mesh_t *out, char *err, size_t err_len)
{
    for (uint32_t t = 0; t < n_tri; t++) {
        const size_t off = 84 + 50 * (size_t)t;
        float c[9];
        for (int k = 0; k < 9; k++) {
            c[k] = le_get_f32(b + off + 12 + 4 * (size_t)k);
            if (!isfinite(c[k])) {
                io_err(err, err_len, "%s: byte %zu: facet %u has a non-finite coordinate", path,
                       off + 12 + 4 * (size_t)k, t);
                return IMPORT_ERR_NUMBER;
            }
        }
        if (stl_facet(wd, out, c) != ARGIL_OK) {
            io_err(err, err_len, "%s: out of memory at facet %u", path, t);
            return IMPORT_ERR_NOMEM;
        }
    }
    (void)len;
    return IMPORT_OK;
}

/* ASCII STL: solid / facet normal / outer loop / 3 vertex / endloop / endfacet ... endsolid. */
static import_err_t stl_ascii(const char *path, const uint8_t *b, size_t len, weld_t *wd,
                              mesh_t *out, char *err, size_t err_len)
{
    io_lines_t it = {(const char *)b, len, 0, 0, 0};
    char line[IMPORT_LINE_MAX];
    char *tok[6];
    enum { S_SOLID, S_FACET, S_LOOP, S_VERTEX, S_ENDLOOP, S_ENDFACET, S_END } st = S_SOLID;
    static const char *const expect[] = {"solid <name>", "facet normal nx ny nz' or 'endsolid",
                                         "outer loop", "vertex x y z", "endloop", "endfacet",
                                         "nothing after endsolid"};
    float c[9];
    int nv = 0;
    for (;;) {
        const long n = io_next_line(&it, line, sizeof(line));
        if (n == -1)
            break;
        if (n < 0)
            return import_line_err(path, it.line_no, n, err, err_len);
        const int nt = io_tokens(line, tok, 5);
        if (nt == 0)
            continue;
        bool ok = false;
        const int prev = (int)st;
        switch (st) {
        case S_SOLID:
            ok = strcmp(tok[0], "solid") == 0;
            st = S_FACET;
            break;
        case S_FACET:
            if (strcmp(tok[0], "endsolid") == 0) {
                ok = true;
                st = S_END;
            } else if (nt == 5 && strcmp(tok[0], "facet") == 0 && strcmp(tok[1], "normal") == 0) {
                double d;
                ok = io_parse_double(tok[2], &d) && io_parse_double(tok[3], &d) &&
                     io_parse_double(tok[4], &d);
                st = S_LOOP;
            }
            break;
        case S_LOOP:
            ok = nt == 2 && strcmp(tok[0], "outer") == 0 && strcmp(tok[1], "loop") == 0;
            st = S_VERTEX;
            nv = 0;
            break;
        case S_VERTEX:
            if (nt == 4 && strcmp(tok[0], "vertex") == 0) {
                ok = true;
                for (int k = 0; k < 3 && ok; k++) {
                    double d;
                    ok = io_parse_double(tok[1 + k], &d) && fabs(d) < 3e38;
                    c[3 * nv + k] = (float)d;
                }
                if (++nv == 3)
                    st = S_ENDLOOP;
            }
            break;
        case S_ENDLOOP:
            ok = nt == 1 && strcmp(tok[0], "endloop") == 0;
            st = S_ENDFACET;
            break;
        case S_ENDFACET:
            ok = nt == 1 && strcmp(tok[0], "endfacet") == 0;
            if (ok && stl_facet(wd, out, c) != ARGIL_OK) {
                io_err(err, err_len, "%s: line %zu: out of memory", path, it.line_no);
                return IMPORT_ERR_NOMEM;
            }
            st = S_FACET;
            break;
        case S_END:
            ok = false;
            break;
        }
        if (!ok) {
            io_err(err, err_len, "%s: line %zu: unexpected '%.40s' (ASCII STL expects '%s' here, "
                   "with finite numbers)", path, it.line_no, tok[0], expect[prev]);
            return IMPORT_ERR_STL_SYNTAX;
        }
    }
    if (st != S_END) {
        io_err(err, err_len, "%s: line %zu: file ends before 'endsolid'", path, it.line_no);
        return IMPORT_ERR_TRUNCATED;
    }
    return IMPORT_OK;
}

/* A weld table for up to n_corners corners. */
static import_err_t weld_init(weld_t *wd, size_t n_corners)
{
    size_t slots = 16;
    while (slots < 2 * n_corners + 16)
        slots *= 2;
    wd->slot = calloc(slots, sizeof(uint32_t));
    wd->mask = slots - 1;
    return wd->slot != NULL ? IMPORT_OK : IMPORT_ERR_NOMEM;
}

import_err_t stl_read(const char *path, mesh_t *out, char *err, size_t err_len)
{
    uint8_t *b;
    size_t len;
    import_err_t e = import_slurp("stl_read", path, out, &b, &len, err, err_len);
    if (e != IMPORT_OK)
        return e;
    weld_t wd = {NULL, 0};
    const uint32_t n_bin = len >= 84 ? le_get_u32(b + 80) : 0;
    const bool binary = len >= 84 && (uint64_t)len == 84 + 50 * (uint64_t)n_bin;
    const bool ascii = !binary && len >= 5 && memcmp(b, "solid", 5) == 0;
    if (binary) {
        e = weld_init(&wd, 3 * (size_t)n_bin);
        if (e == IMPORT_OK)
            e = stl_binary(path, b, len, n_bin, &wd, out, err, err_len);
    } else if (ascii) {
        e = weld_init(&wd, len / 16); /* a corner line takes more than 16 bytes */
        if (e == IMPORT_OK)
            e = stl_ascii(path, b, len, &wd, out, err, err_len);
    } else if (len < 84) {
        io_err(err, err_len, "%s: byte %zu: too short for binary STL (84-byte header) and not "
               "ASCII STL ('solid')", path, len);
        e = IMPORT_ERR_STL_SIZE;
    } else {
        io_err(err, err_len, "%s: byte 80: binary STL declares %u facets (%llu bytes) but the "
               "file has %zu bytes", path, n_bin, (unsigned long long)(84 + 50 * (uint64_t)n_bin),
               len);
        e = IMPORT_ERR_STL_SIZE;
    }
    if (e == IMPORT_ERR_NOMEM && wd.slot == NULL)
        io_err(err, err_len, "%s: out of memory", path);
    free(wd.slot);
    free(b);
    if (e == IMPORT_OK)
        normalise_normals(out);
    return import_done(out, e);
}

/* ------------------------------------------------------------------ OBJ */

/* Resolves an OBJ index (1-based, negative = from the end) against count; false when invalid. */
static bool obj_index(const char *s, size_t count, uint32_t *out)
{
    const bool neg = *s == '-';
    uint64_t v;
    if (!io_parse_u64(neg ? s + 1 : s, UINT32_MAX, &v) || v == 0)
        return false;
    if (neg) {
        if (v > count)
            return false;
        *out = (uint32_t)(count - v);
    } else {
        if (v > count)
            return false;
        *out = (uint32_t)(v - 1);
    }
    return true;
}

/* Adds the face statement tok[0, nt) ("f", then corners v, v/t, v//n or v/t/n) on line line_no
 * to out as a fan of triangles, skipping degenerate ones; a corner's normal vn[n] is copied to
 * its vertex, marked in *got_n (grown to out's vertex room *cap_got). IMPORT_ERR_FACE_SIZE or
 * INDEX with err naming the line, or IMPORT_ERR_NOMEM. */
static import_err_t obj_face(const char *path, size_t line_no, char **tok, int nt, mesh_t *out,
                             const float *vn, size_t n_vn, uint8_t **got_n, size_t *cap_got,
                             char *err, size_t err_len)
{
    if (nt < 4 || nt > 65) {
        io_err(err, err_len, "%s: line %zu: 'f' needs 3 to 64 vertices", path, line_no);
        return IMPORT_ERR_FACE_SIZE;
    }
    if (*cap_got < out->n_vert) {
        uint8_t *g = realloc(*got_n, out->cap_vert);
        if (g == NULL)
            return IMPORT_ERR_NOMEM;
        memset(g + *cap_got, 0, out->cap_vert - *cap_got);
        *got_n = g;
        *cap_got = out->cap_vert;
    }
    uint32_t idx[64];
    for (int q = 1; q < nt; q++) {
        char *s = tok[q];
        char *sl1 = strchr(s, '/');
        char *sl2 = sl1 != NULL ? strchr(sl1 + 1, '/') : NULL;
        if (sl1 != NULL)
            *sl1 = '\0';
        if (sl2 != NULL)
            *sl2 = '\0';
        uint32_t ni = 0;
        if (!obj_index(s, out->n_vert, &idx[q - 1]) ||
            (sl2 != NULL && sl2[1] != '\0' && !obj_index(sl2 + 1, n_vn, &ni))) {
            io_err(err, err_len, "%s: line %zu: face corner %d names a vertex or normal "
                   "that does not exist (%zu vertices, %zu normals so far)",
                   path, line_no, q, out->n_vert, n_vn);
            return IMPORT_ERR_INDEX;
        }
        if (sl2 != NULL && sl2[1] != '\0') {
            memcpy(out->normal + 3 * (size_t)idx[q - 1], vn + 3 * (size_t)ni, 3 * sizeof(float));
            (*got_n)[idx[q - 1]] = 1;
        }
    }
    for (int q = 2; q + 1 < nt; q++)
        if (idx[0] != idx[q - 1] && idx[q - 1] != idx[q] && idx[0] != idx[q] &&
            mesh_add_triangle(out, idx[0], idx[q - 1], idx[q]) != ARGIL_OK)
            return IMPORT_ERR_NOMEM;
    return IMPORT_OK;
}

import_err_t obj_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len)
{
    import_text_t t;
    import_err_t e = import_text_open(&t, "obj_read", path, out, has_normals, err, err_len);
    if (e != IMPORT_OK)
        return e;
    float *vn = NULL;
    uint8_t *got_n = NULL;
    size_t n_vn = 0, cap_vn = 0, cap_got = 0;
    bool any_rgb = false;
    char *line = t.line;
    char *tok[66];
    while (e == IMPORT_OK && import_text_next(&t, path, &e, err, err_len) >= 0) {
        char *hash = strchr(line, '#');
        if (hash != NULL)
            *hash = '\0';
        const int nt = io_tokens(line, tok, 65);
        if (nt == 0)
            continue;
        const char *k = tok[0];
        if (strcmp(k, "v") == 0 || strcmp(k, "vn") == 0) {
            const bool is_v = k[1] == '\0';
            double d[6] = {0};
            const bool count_ok = is_v ? (nt == 4 || nt == 5 || nt == 7) : nt == 4;
            bool ok = count_ok;
            for (int q = 1; q < nt && q <= 6 && ok; q++)
                ok = io_parse_double(tok[q], &d[q - 1]) && fabs(d[q - 1]) < 3e38;
            if (!ok) {
                io_err(err, err_len, "%s: line %zu: '%s' needs %s finite numbers", path,
                       t.it.line_no, k, is_v ? "3 (x y z), 4 (x y z w) or 6 (x y z r g b)" : "3");
                e = IMPORT_ERR_OBJ_VERTEX;
                break;
            }
            if (is_v) {
                if (nt == 7 && !any_rgb) {
                    if (mesh_enable_rgb(out) != ARGIL_OK) {
                        e = IMPORT_ERR_NOMEM;
                        break;
                    }
                    any_rgb = true;
                }
                uint32_t id;
                if (mesh_add_vertex(out, vec3_from_d(d),
                                    vec3(0, 0, 0), &id) != ARGIL_OK) {
                    e = IMPORT_ERR_NOMEM;
                    break;
                }
                if (nt == 7)
                    for (int c = 0; c < 3; c++) {
                        const double cv = d[3 + c] < 0 ? 0 : (d[3 + c] > 1 ? 1 : d[3 + c]);
                        out->rgb[3 * (size_t)id + (size_t)c] = (uint8_t)lround(cv * 255.0);
                    }
            } else {
                if (n_vn == cap_vn) {
                    cap_vn = cap_vn ? 2 * cap_vn : 256;
                    float *nv = realloc(vn, 3 * sizeof(float) * cap_vn);
                    if (nv == NULL) {
                        e = IMPORT_ERR_NOMEM;
                        break;
                    }
                    vn = nv;
                }
                for (int c = 0; c < 3; c++)
                    vn[3 * n_vn + (size_t)c] = (float)d[c];
                n_vn++;
            }
        } else if (strcmp(k, "f") == 0) {
            e = obj_face(path, t.it.line_no, tok, nt, out, vn, n_vn, &got_n, &cap_got, err,
                         err_len);
        } else if (strcmp(k, "vt") == 0 || strcmp(k, "vp") == 0 || strcmp(k, "o") == 0 ||
                   strcmp(k, "g") == 0 || strcmp(k, "s") == 0 || strcmp(k, "usemtl") == 0 ||
                   strcmp(k, "mtllib") == 0 || strcmp(k, "l") == 0) {
            continue;
        } else {
            io_err(err, err_len, "%s: line %zu: unknown OBJ statement '%.32s'", path,
                   t.it.line_no, k);
            e = IMPORT_ERR_OBJ_STATEMENT;
        }
    }
    if (e == IMPORT_ERR_NOMEM)
        io_err(err, err_len, "%s: line %zu: out of memory", path, t.it.line_no);
    if (e == IMPORT_OK && has_normals != NULL && out->n_vert > 0) {
        bool all = got_n != NULL && cap_got >= out->n_vert;
        for (size_t v = 0; all && v < out->n_vert; v++)
            all = got_n[v] != 0;
        *has_normals = all;
    }
    free(vn);
    free(got_n);
    free(t.buf);
    return import_done(out, e);
}

/* ------------------------------------------------------------------ XYZ */

import_err_t xyz_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len)
{
    import_text_t t;
    import_err_t e = import_text_open(&t, "xyz_read", path, out, has_normals, err, err_len);
    if (e != IMPORT_OK)
        return e;
    char *line = t.line;
    char *tok[8];
    int cols = 0;
    size_t first_line = 0;
    while (e == IMPORT_OK && import_text_next(&t, path, &e, err, err_len) >= 0) {
        const int nt = io_tokens(line, tok, 7);
        if (nt == 0 || tok[0][0] == '#')
            continue;
        if (nt != 3 && nt != 6) {
            io_err(err, err_len, "%s: line %zu: %d values; each point needs 3 (x y z) or 6 "
                   "(x y z nx ny nz)", path, t.it.line_no, nt > 7 ? 7 : nt);
            e = IMPORT_ERR_XYZ_COLUMNS;
            break;
        }
        if (cols == 0) {
            cols = nt;
            first_line = t.it.line_no;
        } else if (nt != cols) {
            io_err(err, err_len, "%s: line %zu: %d values but line %zu had %d (every line must "
                   "have the same count)", path, t.it.line_no, nt, first_line, cols);
            e = IMPORT_ERR_XYZ_COLUMNS;
            break;
        }
        float v[6] = {0};
        for (int q = 0; q < nt; q++) {
            double d;
            if (!io_parse_double(tok[q], &d) || fabs(d) >= 3e38) {
                io_err(err, err_len, "%s: line %zu: value %d '%.32s' is not a finite number",
                       path, t.it.line_no, q + 1, tok[q]);
                e = IMPORT_ERR_NUMBER;
                break;
            }
            v[q] = (float)d;
        }
        if (e == IMPORT_OK &&
            mesh_add_vertex(out, vec3(v[0], v[1], v[2]), vec3(v[3], v[4], v[5]), NULL) != ARGIL_OK) {
            io_err(err, err_len, "%s: line %zu: out of memory", path, t.it.line_no);
            e = IMPORT_ERR_NOMEM;
        }
    }
    if (e == IMPORT_OK && out->n_vert == 0) {
        io_err(err, err_len, "%s: line %zu: no points in the file", path, t.it.line_no);
        e = IMPORT_ERR_XYZ_EMPTY;
    }
    if (e == IMPORT_OK && has_normals != NULL)
        *has_normals = cols == 6;
    free(t.buf);
    return import_done(out, e);
}

import_err_t mesh_import(const char *path, mesh_t *out, bool *has_normals, char *err,
                         size_t err_len)
{
    const char *dot = path != NULL ? strrchr(path, '.') : NULL;
    if (has_normals != NULL)
        *has_normals = false;
    if (dot != NULL && strcasecmp(dot, ".ply") == 0)
        return ply_load(path, out, has_normals, err, err_len);
    if (dot != NULL && strcasecmp(dot, ".stl") == 0) {
        const import_err_t e = stl_read(path, out, err, err_len);
        if (has_normals != NULL)
            *has_normals = e == IMPORT_OK && out->n_tri > 0;
        return e;
    }
    if (dot != NULL && strcasecmp(dot, ".obj") == 0)
        return obj_read(path, out, has_normals, err, err_len);
    if (dot != NULL && (strcasecmp(dot, ".xyz") == 0 || strcasecmp(dot, ".txt") == 0 ||
                        strcasecmp(dot, ".pts") == 0))
        return xyz_read(path, out, has_normals, err, err_len);
    io_err(err, err_len, "%s: unknown extension (expected .ply, .stl, .obj, .xyz, .txt or .pts)",
           path != NULL ? path : "(null)");
    return IMPORT_ERR_ARG;
}
