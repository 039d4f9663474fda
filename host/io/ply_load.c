/* General PLY import (meshes and point clouds): the header is parsed into element and property
 * descriptions, every element's declared count is checked against the bytes that follow before
 * anything is allocated, then records are read through one cursor (ASCII tokens with line
 * numbers, or binary values of either byte order with byte offsets). */
#include "host/io/mesh_import.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/io_util.h"
#include "shared/wire.h"

#define PLY_ELEMENTS_MAX 16
#define PLY_PROPS_MAX 32
#define PLY_HEADER_LINES_MAX 512

typedef enum { PT_I8, PT_U8, PT_I16, PT_U16, PT_I32, PT_U32, PT_F32, PT_F64, PT_BAD } ply_type_t;

typedef struct {
    char name[32];
    ply_type_t type;       /* scalar type, or the item type of a list */
    ply_type_t count_type; /* PT_BAD for a scalar */
} ply_prop_t;

typedef struct {
    char name[32];
    uint64_t count;
    int n_props;
    ply_prop_t props[PLY_PROPS_MAX];
} ply_elem_t;

typedef struct {
    const char *path;
    char *err;
    size_t err_len;
    const uint8_t *buf;
    size_t len, pos;
    int fmt; /* 0 ascii, 1 little-endian, 2 big-endian */
    size_t line_no;
} ply_in_t;

static const struct {
    const char *a, *b;
    ply_type_t t;
    int size;
} ply_types[] = {
    {"char", "int8", PT_I8, 1},    {"uchar", "uint8", PT_U8, 1}, {"short", "int16", PT_I16, 2},
    {"ushort", "uint16", PT_U16, 2}, {"int", "int32", PT_I32, 4},  {"uint", "uint32", PT_U32, 4},
    {"float", "float32", PT_F32, 4}, {"double", "float64", PT_F64, 8},
};

static ply_type_t ply_type_of(const char *s)
{
    for (size_t i = 0; i < sizeof(ply_types) / sizeof(ply_types[0]); i++)
        if (strcmp(s, ply_types[i].a) == 0 || strcmp(s, ply_types[i].b) == 0)
            return ply_types[i].t;
    return PT_BAD;
}

static int ply_size(ply_type_t t)
{
    return ply_types[t].size;
}

/* Parses the header; sets in->pos to the first body byte. */
static import_err_t ply_header(ply_in_t *in, ply_elem_t *el, int *n_el)
{
    io_lines_t it = {(const char *)in->buf, in->len, 0, 0, 0};
    char line[IMPORT_LINE_MAX];
    char *tok[8];
    *n_el = 0;
    for (int k = 0;; k++) {
        const long n = io_next_line(&it, line, sizeof(line));
        const size_t ln = it.line_no;
        if (n == -1 || k >= PLY_HEADER_LINES_MAX) {
            io_err(in->err, in->err_len, "%s: line %zu: header has no end_header line%s", in->path,
                   ln, n == -1 ? " (file ends)" : " within 512 lines");
            return IMPORT_ERR_PLY_HEADER_END;
        }
        if (n < 0) {
            io_err(in->err, in->err_len, "%s: line %zu: header line %s", in->path, ln,
                   n == -2 ? "longer than 1023 bytes" : "contains a NUL byte");
            return n == -2 ? IMPORT_ERR_LINE_LONG : IMPORT_ERR_LINE_NUL;
        }
        const int nt = io_tokens(line, tok, 7);
        if (k == 0) {
            if (nt != 1 || strcmp(tok[0], "ply") != 0) {
                io_err(in->err, in->err_len, "%s: line 1: not a PLY file (first line must be 'ply')",
                       in->path);
                return IMPORT_ERR_PLY_MAGIC;
            }
            continue;
        }
        if (k == 1) {
            if (nt != 3 || strcmp(tok[0], "format") != 0 || strcmp(tok[2], "1.0") != 0 ||
                (strcmp(tok[1], "ascii") != 0 && strcmp(tok[1], "binary_little_endian") != 0 &&
                 strcmp(tok[1], "binary_big_endian") != 0)) {
                io_err(in->err, in->err_len,
                       "%s: line 2: expected 'format ascii|binary_little_endian|"
                       "binary_big_endian 1.0'",
                       in->path);
                return IMPORT_ERR_PLY_FORMAT;
            }
            in->fmt = strcmp(tok[1], "ascii") == 0 ? 0 : (tok[1][7] == 'l' ? 1 : 2);
            continue;
        }
        if (nt == 0 || strcmp(tok[0], "comment") == 0 || strcmp(tok[0], "obj_info") == 0)
            continue;
        if (strcmp(tok[0], "end_header") == 0 && nt == 1) {
            in->pos = it.pos;
            in->line_no = it.line_no;
            return IMPORT_OK;
        }
        if (strcmp(tok[0], "element") == 0) {
            uint64_t cnt;
            if (nt != 3 || strlen(tok[1]) >= sizeof(el[0].name)) {
                io_err(in->err, in->err_len, "%s: line %zu: expected 'element <name> <count>'",
                       in->path, ln);
                return IMPORT_ERR_PLY_ELEMENT;
            }
            if (!io_parse_u64(tok[2], (uint64_t)1 << 40, &cnt)) {
                io_err(in->err, in->err_len,
                       "%s: line %zu: element count '%.32s' is not a whole number up to 2^40",
                       in->path, ln, tok[2]);
                return IMPORT_ERR_PLY_ELEMENT;
            }
            if (*n_el == PLY_ELEMENTS_MAX) {
                io_err(in->err, in->err_len, "%s: line %zu: more than %d elements", in->path, ln,
                       PLY_ELEMENTS_MAX);
                return IMPORT_ERR_PLY_LIMIT;
            }
            ply_elem_t *e = &el[(*n_el)++];
            memset(e, 0, sizeof(*e));
            strcpy(e->name, tok[1]);
            e->count = cnt;
            continue;
        }
        if (strcmp(tok[0], "property") == 0) {
            if (*n_el == 0) {
                io_err(in->err, in->err_len, "%s: line %zu: property before any element",
                       in->path, ln);
                return IMPORT_ERR_PLY_PROPERTY;
            }
            ply_elem_t *e = &el[*n_el - 1];
            if (e->n_props == PLY_PROPS_MAX) {
                io_err(in->err, in->err_len, "%s: line %zu: more than %d properties in '%s'",
                       in->path, ln, PLY_PROPS_MAX, e->name);
                return IMPORT_ERR_PLY_LIMIT;
            }
            ply_prop_t *p = &e->props[e->n_props];
            const bool list = nt >= 2 && strcmp(tok[1], "list") == 0;
            const int want = list ? 5 : 3;
            if (nt != want || strlen(tok[nt - 1]) >= sizeof(p->name)) {
                io_err(in->err, in->err_len, "%s: line %zu: expected 'property <type> <name>' or "
                       "'property list <count type> <item type> <name>'", in->path, ln);
                return IMPORT_ERR_PLY_PROPERTY;
            }
            p->count_type = list ? ply_type_of(tok[2]) : PT_BAD;
            p->type = ply_type_of(tok[list ? 3 : 1]);
            if (p->type == PT_BAD || (list && (p->count_type == PT_BAD || p->count_type == PT_F32 ||
                                               p->count_type == PT_F64))) {
                io_err(in->err, in->err_len, "%s: line %zu: unknown or unusable property type",
                       in->path, ln);
                return IMPORT_ERR_PLY_PROPERTY;
            }
            strcpy(p->name, tok[nt - 1]);
            e->n_props++;
            continue;
        }
        io_err(in->err, in->err_len, "%s: line %zu: unknown header keyword '%.32s'", in->path, ln,
               tok[0]);
        return IMPORT_ERR_PLY_KEYWORD;
    }
}

/* Where the cursor is, for messages: "line N" (ASCII) or "byte N" (binary). */
static void ply_where(const ply_in_t *in, char *s, size_t n)
{
    if (in->fmt == 0)
        snprintf(s, n, "line %zu", in->line_no + 1);
    else
        snprintf(s, n, "byte %zu", in->pos);
}

/* Reads one value of type t; err names elem/record. */
static import_err_t ply_value(ply_in_t *in, ply_type_t t, const ply_elem_t *e, uint64_t rec,
                              double *out)
{
    char where[48];
    if (in->fmt == 0) {
        /* skip blanks, counting lines */
        while (in->pos < in->len && (in->buf[in->pos] == ' ' || in->buf[in->pos] == '\t' ||
                                     in->buf[in->pos] == '\r' || in->buf[in->pos] == '\n')) {
            if (in->buf[in->pos] == '\n')
                in->line_no++;
            in->pos++;
        }
        size_t s = in->pos;
        while (in->pos < in->len && in->buf[in->pos] != ' ' && in->buf[in->pos] != '\t' &&
               in->buf[in->pos] != '\r' && in->buf[in->pos] != '\n')
            in->pos++;
        const size_t n = in->pos - s;
        char tok[64];
        if (n == 0) {
            const bool nl_end = in->len > 0 && in->buf[in->len - 1] == '\n';
            io_err(in->err, in->err_len, "%s: line %zu: file ends inside %s %llu", in->path,
                   in->line_no + (nl_end ? 0 : 1), e->name, (unsigned long long)rec);
            return IMPORT_ERR_TRUNCATED;
        }
        if (n >= sizeof(tok) || memchr(in->buf + s, 0, n) != NULL) {
            io_err(in->err, in->err_len, "%s: line %zu: %s %llu: value is not a number", in->path,
                   in->line_no + 1, e->name, (unsigned long long)rec);
            return IMPORT_ERR_NUMBER;
        }
        memcpy(tok, in->buf + s, n);
        tok[n] = '\0';
        if (!io_parse_double(tok, out)) {
            io_err(in->err, in->err_len, "%s: line %zu: %s %llu: '%s' is not a finite number",
                   in->path, in->line_no + 1, e->name, (unsigned long long)rec, tok);
            return IMPORT_ERR_NUMBER;
        }
        if (t != PT_F32 && t != PT_F64 && *out != floor(*out)) {
            io_err(in->err, in->err_len, "%s: line %zu: %s %llu: '%s' must be a whole number",
                   in->path, in->line_no + 1, e->name, (unsigned long long)rec, tok);
            return IMPORT_ERR_PLY_WHOLE;
        }
        return IMPORT_OK;
    }
    const int sz = ply_size(t);
    if (in->len - in->pos < (size_t)sz) {
        ply_where(in, where, sizeof(where));
        io_err(in->err, in->err_len, "%s: %s: file ends inside %s %llu", in->path, where, e->name,
               (unsigned long long)rec);
        return IMPORT_ERR_TRUNCATED;
    }
    uint8_t b[8];
    for (int k = 0; k < sz; k++)
        b[k] = in->buf[in->pos + (size_t)(in->fmt == 1 ? k : sz - 1 - k)];
    const uint64_t u = le_get(b, (size_t)sz);
    switch (t) {
    case PT_I8: *out = (double)(int8_t)u; break;
    case PT_U8: *out = (double)(uint8_t)u; break;
    case PT_I16: *out = (double)(int16_t)u; break;
    case PT_U16: *out = (double)(uint16_t)u; break;
    case PT_I32: *out = (double)(int32_t)(uint32_t)u; break;
    case PT_U32: *out = (double)(uint32_t)u; break;
    case PT_F32: {
        const uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        *out = f;
        break;
    }
    default: {
        double d;
        memcpy(&d, &u, 8);
        *out = d;
        break;
    }
    }
    if (!isfinite(*out)) {
        ply_where(in, where, sizeof(where));
        io_err(in->err, in->err_len, "%s: %s: %s %llu: value is not finite (NaN or Inf)",
               in->path, where, e->name, (unsigned long long)rec);
        return IMPORT_ERR_NUMBER;
    }
    in->pos += (size_t)sz;
    return IMPORT_OK;
}

static int ply_find(const ply_elem_t *e, const char *name)
{
    for (int i = 0; i < e->n_props; i++)
        if (strcmp(e->props[i].name, name) == 0)
            return i;
    return -1;
}

/* Refuses element counts the bytes after the header cannot hold: every record takes at least
 * min bytes (binary: its fixed parts; ASCII: two bytes a value), checked before any allocation. */
static import_err_t ply_check_counts(ply_in_t *in, const ply_elem_t *el, int n_el)
{
    uint64_t need = 0;
    for (int i = 0; i < n_el; i++) {
        uint64_t min = 0;
        for (int k = 0; k < el[i].n_props; k++) {
            const ply_prop_t *p = &el[i].props[k];
            min += in->fmt == 0 ? 2u
                                : (uint64_t)ply_size(p->count_type != PT_BAD ? p->count_type : p->type);
        }
        if (min > 0 && el[i].count > (uint64_t)(in->len - in->pos) / min) {
            io_err(in->err, in->err_len,
                   "%s: byte %zu: element '%s' declares %llu records but only %zu bytes follow "
                   "the header",
                   in->path, in->pos, el[i].name, (unsigned long long)el[i].count,
                   in->len - in->pos);
            return IMPORT_ERR_PLY_COUNTS;
        }
        need += el[i].count * min;
        if (need > (uint64_t)(in->len - in->pos)) {
            io_err(in->err, in->err_len, "%s: byte %zu: elements declare more data than the %zu "
                   "bytes after the header", in->path, in->pos, in->len - in->pos);
            return IMPORT_ERR_PLY_COUNTS;
        }
    }
    return IMPORT_OK;
}

/* Reads all elements into out. */
static import_err_t ply_body(ply_in_t *in, ply_elem_t *el, int n_el, mesh_t *out, bool *normals)
{
    const import_err_t ce = ply_check_counts(in, el, n_el);
    if (ce != IMPORT_OK)
        return ce;
    const ply_elem_t *ve = NULL;
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ir = -1, ig = -1, ib = -1;
    for (int i = 0; i < n_el; i++)
        if (strcmp(el[i].name, "vertex") == 0) {
            ve = &el[i];
            ix = ply_find(ve, "x");
            iy = ply_find(ve, "y");
            iz = ply_find(ve, "z");
            inx = ply_find(ve, "nx");
            iny = ply_find(ve, "ny");
            inz = ply_find(ve, "nz");
            ir = ply_find(ve, "red");
            ig = ply_find(ve, "green");
            ib = ply_find(ve, "blue");
            break;
        }
    if (ve == NULL || ix < 0 || iy < 0 || iz < 0 || ve->props[ix].count_type != PT_BAD ||
        ve->props[iy].count_type != PT_BAD || ve->props[iz].count_type != PT_BAD) {
        io_err(in->err, in->err_len, "%s: header: no 'vertex' element with scalar x, y and z",
               in->path);
        return IMPORT_ERR_PLY_NO_VERTEX;
    }
    *normals = inx >= 0 && iny >= 0 && inz >= 0;
    const bool rgb = ir >= 0 && ig >= 0 && ib >= 0;
    if (rgb && mesh_enable_rgb(out) != ARGIL_OK)
        return IMPORT_ERR_NOMEM;
    if (mesh_reserve(out, (size_t)ve->count, 0) != ARGIL_OK) {
        io_err(in->err, in->err_len, "%s: out of memory for %llu vertices", in->path,
               (unsigned long long)ve->count);
        return IMPORT_ERR_NOMEM;
    }
    uint64_t n_vert_seen = 0;
    bool faces_before_vertices = false;
    for (int i = 0; i < n_el; i++) {
        const ply_elem_t *e = &el[i];
        const bool is_v = e == ve;
        const bool is_f = strcmp(e->name, "face") == 0;
        if (is_f && n_vert_seen == 0 && ve->count > 0)
            faces_before_vertices = true;
        for (uint64_t r = 0; r < e->count; r++) {
            double v[PLY_PROPS_MAX] = {0};
            for (int k = 0; k < e->n_props; k++) {
                const ply_prop_t *p = &e->props[k];
                import_err_t er;
                if (p->count_type == PT_BAD) {
                    er = ply_value(in, p->type, e, r, &v[k]);
                    if (er != IMPORT_OK)
                        return er;
                    continue;
                }
                double cnt_d;
                er = ply_value(in, p->count_type, e, r, &cnt_d);
                if (er != IMPORT_OK)
                    return er;
                char where[48];
                ply_where(in, where, sizeof(where));
                if (cnt_d < 0 || cnt_d > 1000000) {
                    io_err(in->err, in->err_len, "%s: %s: %s %llu: list length %.0f out of 0..10^6",
                           in->path, where, e->name, (unsigned long long)r, cnt_d);
                    return IMPORT_ERR_PLY_LIST_LENGTH;
                }
                const uint32_t cnt = (uint32_t)cnt_d;
                const bool poly = is_f && (strcmp(p->name, "vertex_indices") == 0 ||
                                           strcmp(p->name, "vertex_index") == 0);
                if (poly && cnt < 3) {
                    io_err(in->err, in->err_len, "%s: %s: face %llu has %u vertices (at least 3)",
                           in->path, where, (unsigned long long)r, cnt);
                    return IMPORT_ERR_FACE_SIZE;
                }
                double first = 0, prev = 0;
                for (uint32_t q = 0; q < cnt; q++) {
                    double idx;
                    er = ply_value(in, p->type, e, r, &idx);
                    if (er != IMPORT_OK)
                        return er;
                    if (!poly)
                        continue;
                    if (idx < 0 || idx >= (double)ve->count || idx != floor(idx)) {
                        ply_where(in, where, sizeof(where));
                        io_err(in->err, in->err_len, "%s: %s: face %llu names vertex %.0f of %llu",
                               in->path, where, (unsigned long long)r, idx,
                               (unsigned long long)ve->count);
                        return IMPORT_ERR_INDEX;
                    }
                    if (q == 0)
                        first = idx;
                    else if (q >= 2) {
                        if (faces_before_vertices) {
                            io_err(in->err, in->err_len, "%s: %s: faces come before vertices",
                                   in->path, where);
                            return IMPORT_ERR_PLY_FACE_ORDER;
                        }
                        if (mesh_add_triangle(out, (uint32_t)first, (uint32_t)prev,
                                              (uint32_t)idx) != ARGIL_OK) {
                            io_err(in->err, in->err_len, "%s: out of memory for faces", in->path);
                            return IMPORT_ERR_NOMEM;
                        }
                    }
                    prev = idx;
                }
            }
            if (is_v) {
                const vec3_t pos = vec3((float)v[ix], (float)v[iy], (float)v[iz]);
                const vec3_t nrm = *normals ? vec3((float)v[inx], (float)v[iny], (float)v[inz])
                                            : vec3(0, 0, 0);
                if (!vec3_isfinite(pos) || !vec3_isfinite(nrm)) {
                    io_err(in->err, in->err_len, "%s: vertex %llu: coordinates overflow a float",
                           in->path, (unsigned long long)r);
                    return IMPORT_ERR_NUMBER;
                }
                uint32_t id;
                if (mesh_add_vertex(out, pos, nrm, &id) != ARGIL_OK)
                    return IMPORT_ERR_NOMEM;
                if (rgb) {
                    const int ci[3] = {ir, ig, ib};
                    for (int c = 0; c < 3; c++) {
                        double cv = v[ci[c]];
                        const ply_type_t ct = ve->props[ci[c]].type;
                        if (ct == PT_F32 || ct == PT_F64)
                            cv *= 255.0;
                        cv = cv < 0 ? 0 : (cv > 255 ? 255 : cv);
                        out->rgb[3 * (size_t)id + (size_t)c] = (uint8_t)lround(cv);
                    }
                }
                n_vert_seen++;
            }
        }
    }
    if (in->fmt != 0 && in->pos != in->len) {
        io_err(in->err, in->err_len, "%s: byte %zu: %zu bytes after the last element", in->path,
               in->pos, in->len - in->pos);
        return IMPORT_ERR_PLY_TRAILING;
    }
    return IMPORT_OK;
}

import_err_t ply_load(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len)
{
    uint8_t *buf;
    size_t len;
    import_err_t e = import_slurp("ply_load", path, out, &buf, &len, err, err_len);
    if (e != IMPORT_OK)
        return e;
    ply_elem_t *el = malloc(sizeof(ply_elem_t) * PLY_ELEMENTS_MAX);
    if (el == NULL) {
        free(buf);
        return IMPORT_ERR_NOMEM;
    }
    ply_in_t in = {path, err, err_len, buf, len, 0, 0, 0};
    int n_el = 0;
    bool normals = false;
    e = ply_header(&in, el, &n_el);
    if (e == IMPORT_OK)
        e = ply_body(&in, el, n_el, out, &normals);
    free(el);
    free(buf);
    if (e != IMPORT_OK)
        mesh_clear(out);
    if (has_normals != NULL)
        *has_normals = e == IMPORT_OK && normals;
    return e;
}
