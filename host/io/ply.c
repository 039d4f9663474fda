/* Binary little-endian PLY: atomic export of meshes and a strict reader of the same layout.
 * Fields are encoded byte by byte, never by copying structs. */
#include "host/io/ply.h"

#include "host/io/io_util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define PLY_VERT_BYTES 24u  /* 6 floats */
#define PLY_FACE_BYTES 13u  /* uchar count + 3 int32 */
#define PLY_CHUNK_BYTES 65520u /* multiple of 24 and 13 */
#define PLY_VERT_MAX ((uint64_t)INT32_MAX) /* indices are signed int in the file */

static const char *const ply_prop_names[6] = {"x", "y", "z", "nx", "ny", "nz"};

/* Writes a formatted message into err (when there is room). */
static void ply_err(char *err, size_t err_len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void ply_err(char *err, size_t err_len, const char *fmt, ...)
{
    if (err == NULL || err_len == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_len, fmt, ap);
    va_end(ap);
}

static void put_u32_le(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32_le(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_f32_le(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof(v));
    put_u32_le(p, v);
}

static float get_f32_le(const uint8_t *p)
{
    const uint32_t v = get_u32_le(p);
    float f;
    memcpy(&f, &v, sizeof(f));
    return f;
}

/* ---------------------------------------------------------------- writer */

/* Checks that m can be written; fills err otherwise. */
static argil_err_t ply_check_mesh(const char *path, const mesh_t *m, char *err, size_t err_len)
{
    if ((uint64_t)m->n_vert > PLY_VERT_MAX) {
        ply_err(err, err_len, "ply_write: %s: %zu vertices exceed the format's int indices",
                path, m->n_vert);
        return ARGIL_ERR_ARG;
    }
    if ((m->n_vert > 0 && m->pos == NULL) || (m->n_tri > 0 && m->tri == NULL)) {
        ply_err(err, err_len, "ply_write: %s: mesh arrays missing", path);
        return ARGIL_ERR_ARG;
    }
    for (size_t i = 0; i < 3 * m->n_vert; i++) {
        if (!isfinite(m->pos[i]) || (m->normal != NULL && !isfinite(m->normal[i]))) {
            ply_err(err, err_len, "ply_write: %s: vertex %zu is not finite", path, i / 3);
            return ARGIL_ERR_NONFINITE;
        }
    }
    for (size_t i = 0; i < 3 * m->n_tri; i++) {
        if (m->tri[i] >= m->n_vert) {
            ply_err(err, err_len, "ply_write: %s: triangle %zu names vertex %u of %zu", path,
                    i / 3, (unsigned)m->tri[i], m->n_vert);
            return ARGIL_ERR_ARG;
        }
    }
    return ARGIL_OK;
}

/* Writes header and body to f; returns the name of the failing call or NULL. */
static const char *ply_write_stream(FILE *f, const mesh_t *m, uint8_t *buf)
{
    if (fprintf(f,
                "ply\nformat binary_little_endian 1.0\ncomment argil mesh, model space, metres\n"
                "element vertex %zu\n",
                m->n_vert) < 0)
        return "fprintf";
    for (int k = 0; k < 6; k++) {
        if (fprintf(f, "property float %s\n", ply_prop_names[k]) < 0)
            return "fprintf";
    }
    if (fprintf(f, "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
                m->n_tri) < 0)
        return "fprintf";
    size_t used = 0;
    for (size_t v = 0; v < m->n_vert; v++) {
        if (used + PLY_VERT_BYTES > PLY_CHUNK_BYTES) {
            if (fwrite(buf, 1, used, f) != used)
                return "fwrite";
            used = 0;
        }
        for (int k = 0; k < 3; k++) {
            put_f32_le(buf + used + 4 * (size_t)k, m->pos[3 * v + (size_t)k]);
            put_f32_le(buf + used + 12 + 4 * (size_t)k,
                       m->normal != NULL ? m->normal[3 * v + (size_t)k] : 0.0f);
        }
        used += PLY_VERT_BYTES;
    }
    for (size_t t = 0; t < m->n_tri; t++) {
        if (used + PLY_FACE_BYTES > PLY_CHUNK_BYTES) {
            if (fwrite(buf, 1, used, f) != used)
                return "fwrite";
            used = 0;
        }
        buf[used] = 3;
        for (int k = 0; k < 3; k++)
            put_u32_le(buf + used + 1 + 4 * (size_t)k, m->tri[3 * t + (size_t)k]);
        used += PLY_FACE_BYTES;
    }
    if (used > 0 && fwrite(buf, 1, used, f) != used)
        return "fwrite";
    return NULL;
}

typedef struct {
    const mesh_t *mesh;
    uint8_t *buf;
} ply_write_ctx_t;

/* io_write_atomic's callback: the whole file into f. */
static const char *ply_write_cb(FILE *f, const void *ctx)
{
    const ply_write_ctx_t *c = ctx;
    return ply_write_stream(f, c->mesh, c->buf);
}

argil_err_t ply_write(const char *path, const mesh_t *m, char *err, size_t err_len)
{
    if (path == NULL || m == NULL) {
        ply_err(err, err_len, "ply_write: no path or no mesh");
        return ARGIL_ERR_ARG;
    }
    argil_err_t e = ply_check_mesh(path, m, err, err_len);
    if (e != ARGIL_OK)
        return e;
    uint8_t *buf = malloc(PLY_CHUNK_BYTES);
    if (buf == NULL) {
        ply_err(err, err_len, "ply_write: %s: out of memory", path);
        return ARGIL_ERR_NOMEM;
    }
    /* Temp file, fsync, rename, directory sync: a crash never leaves a half file. */
    const ply_write_ctx_t ctx = {m, buf};
    e = io_write_atomic(path, ply_write_cb, &ctx, "ply_write", err, err_len);
    free(buf);
    return e;
}

/* ---------------------------------------------------------------- reader */

typedef struct {
    const char *path;
    char *err;
    size_t err_len;
} ply_ctx_t;

/* Splits line (NUL-terminated, modified) at spaces and tabs into at most max tokens; returns
 * the count, or max + 1 when there are more. */
static int ply_tokens(char *line, char **tok, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0')
            return n;
        if (n == max)
            return max + 1;
        tok[n++] = p;
        while (*p != '\0' && *p != ' ' && *p != '\t')
            p++;
        if (*p != '\0')
            *p++ = '\0';
    }
}

/* Parses a decimal count (digits only, no sign); false when not a number or above limit. */
static bool ply_parse_count(const char *s, uint64_t limit, uint64_t *out)
{
    uint64_t v = 0;
    if (*s == '\0')
        return false;
    for (; *s != '\0'; s++) {
        if (*s < '0' || *s > '9')
            return false;
        const uint64_t digit = (uint64_t)(*s - '0');
        if (v > (limit - digit) / 10)
            return false;
        v = v * 10 + digit;
    }
    *out = v;
    return true;
}

static bool ply_is(const char *s, const char *a, const char *b)
{
    return strcmp(s, a) == 0 || (b != NULL && strcmp(s, b) == 0);
}

/* The header states in the order the lines must come. */
enum {
    PLY_H_MAGIC,
    PLY_H_FORMAT,
    PLY_H_VERTEX,
    PLY_H_PROP0, /* .. PLY_H_PROP0 + 5 */
    PLY_H_FACE = PLY_H_PROP0 + 6,
    PLY_H_LIST,
    PLY_H_END,
    PLY_H_DONE
};

static const char *ply_expected(int state)
{
    static const char *const props[6] = {"property float x",  "property float y",
                                         "property float z",  "property float nx",
                                         "property float ny", "property float nz"};
    switch (state) {
    case PLY_H_MAGIC: return "ply";
    case PLY_H_FORMAT: return "format binary_little_endian 1.0";
    case PLY_H_VERTEX: return "element vertex <count>";
    case PLY_H_FACE: return "element face <count>";
    case PLY_H_LIST: return "property list uchar int vertex_indices";
    case PLY_H_END: return "end_header";
    default: return props[state - PLY_H_PROP0];
    }
}

/* Checks one header line against the expected state; advances it and stores counts. */
static argil_err_t ply_header_line(ply_ctx_t *c, char *line, int line_no, int *state,
                                   uint64_t *n_vert, uint64_t *n_face)
{
    char *tok[6];
    const int n = ply_tokens(line, tok, 5);
    if (*state != PLY_H_MAGIC && n >= 1 && (ply_is(tok[0], "comment", "obj_info")))
        return ARGIL_OK;
    bool ok = false;
    switch (*state) {
    case PLY_H_MAGIC:
        ok = n == 1 && strcmp(tok[0], "ply") == 0;
        break;
    case PLY_H_FORMAT:
        ok = n == 3 && strcmp(tok[0], "format") == 0 &&
             strcmp(tok[1], "binary_little_endian") == 0 && strcmp(tok[2], "1.0") == 0;
        break;
    case PLY_H_VERTEX:
    case PLY_H_FACE: {
        const bool vert = *state == PLY_H_VERTEX;
        ok = n == 3 && strcmp(tok[0], "element") == 0 &&
             strcmp(tok[1], vert ? "vertex" : "face") == 0;
        if (ok) {
            const uint64_t limit = vert ? PLY_VERT_MAX : UINT64_MAX / PLY_FACE_BYTES;
            if (!ply_parse_count(tok[2], limit, vert ? n_vert : n_face)) {
                ply_err(c->err, c->err_len,
                        "ply_read_mesh: %s: header line %d: %s count '%.32s' is not a number "
                        "from 0 to %llu",
                        c->path, line_no, vert ? "vertex" : "face", tok[2],
                        (unsigned long long)limit);
                return ARGIL_ERR_PARSE;
            }
        }
        break;
    }
    case PLY_H_LIST:
        ok = n == 5 && strcmp(tok[0], "property") == 0 && strcmp(tok[1], "list") == 0 &&
             ply_is(tok[2], "uchar", "uint8") && ply_is(tok[3], "int", "int32") &&
             strcmp(tok[4], "vertex_indices") == 0;
        break;
    case PLY_H_END:
        ok = n == 1 && strcmp(tok[0], "end_header") == 0;
        break;
    default:
        ok = n == 3 && strcmp(tok[0], "property") == 0 && ply_is(tok[1], "float", "float32") &&
             strcmp(tok[2], ply_prop_names[*state - PLY_H_PROP0]) == 0;
        break;
    }
    if (!ok) {
        ply_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: expected '%s'", c->path,
                line_no, ply_expected(*state));
        return ARGIL_ERR_PARSE;
    }
    (*state)++;
    return ARGIL_OK;
}

/* Parses the header at the start of buf (len bytes); sets its byte length and the counts. */
static argil_err_t ply_parse_header(ply_ctx_t *c, const char *buf, size_t len, size_t *header_len,
                                    uint64_t *n_vert, uint64_t *n_face)
{
    int state = PLY_H_MAGIC;
    int line_no = 0;
    size_t pos = 0;
    char line[PLY_LINE_MAX];
    while (state != PLY_H_DONE) {
        line_no++;
        const char *nl = memchr(buf + pos, '\n', len - pos);
        if (nl == NULL) {
            ply_err(c->err, c->err_len,
                    "ply_read_mesh: %s: header line %d: no end of line (file truncated or "
                    "header over %d bytes)",
                    c->path, line_no, PLY_HEADER_MAX_BYTES);
            return ARGIL_ERR_PARSE;
        }
        size_t n = (size_t)(nl - (buf + pos));
        if (n >= sizeof(line)) {
            ply_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: longer than %d bytes",
                    c->path, line_no, PLY_LINE_MAX - 1);
            return ARGIL_ERR_PARSE;
        }
        memcpy(line, buf + pos, n);
        if (n > 0 && line[n - 1] == '\r')
            n--;
        line[n] = '\0';
        if (strlen(line) != n) {
            ply_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: contains a NUL byte",
                    c->path, line_no);
            return ARGIL_ERR_PARSE;
        }
        argil_err_t e = ply_header_line(c, line, line_no, &state, n_vert, n_face);
        if (e != ARGIL_OK)
            return e;
        pos = (size_t)(nl - buf) + 1;
    }
    *header_len = pos;
    return ARGIL_OK;
}

/* Reads exactly n bytes at the current position (offset is for the message). */
static argil_err_t ply_read_exact(ply_ctx_t *c, FILE *f, uint8_t *dst, size_t n, uint64_t offset)
{
    if (fread(dst, 1, n, f) == n)
        return ARGIL_OK;
    if (ferror(f)) {
        ply_err(c->err, c->err_len, "ply_read_mesh: %s: fread at byte %llu failed: %s", c->path,
                (unsigned long long)offset, strerror(errno));
        return ARGIL_ERR_IO;
    }
    ply_err(c->err, c->err_len, "ply_read_mesh: %s: byte %llu: file ended early", c->path,
            (unsigned long long)offset);
    return ARGIL_ERR_PARSE;
}

/* Reads and checks the vertex and face records that follow the header. */
static argil_err_t ply_read_body(ply_ctx_t *c, FILE *f, uint64_t offset, uint64_t n_vert,
                                 uint64_t n_face, mesh_t *out, uint8_t *buf)
{
    argil_err_t e;
    uint64_t done = 0;
    while (done < n_vert) {
        uint64_t batch = n_vert - done;
        if (batch > PLY_CHUNK_BYTES / PLY_VERT_BYTES)
            batch = PLY_CHUNK_BYTES / PLY_VERT_BYTES;
        e = ply_read_exact(c, f, buf, (size_t)batch * PLY_VERT_BYTES, offset);
        if (e != ARGIL_OK)
            return e;
        for (uint64_t i = 0; i < batch; i++, done++, offset += PLY_VERT_BYTES) {
            float v[6];
            for (int k = 0; k < 6; k++) {
                v[k] = get_f32_le(buf + i * PLY_VERT_BYTES + 4 * (size_t)k);
                if (!isfinite(v[k])) {
                    ply_err(c->err, c->err_len,
                            "ply_read_mesh: %s: byte %llu: vertex %llu has a non-finite %s",
                            c->path, (unsigned long long)(offset + 4 * (uint64_t)k),
                            (unsigned long long)done, ply_prop_names[k]);
                    return ARGIL_ERR_PARSE;
                }
            }
            e = mesh_add_vertex(out, vec3(v[0], v[1], v[2]), vec3(v[3], v[4], v[5]), NULL);
            if (e != ARGIL_OK)
                return e;
        }
    }
    done = 0;
    while (done < n_face) {
        uint64_t batch = n_face - done;
        if (batch > PLY_CHUNK_BYTES / PLY_FACE_BYTES)
            batch = PLY_CHUNK_BYTES / PLY_FACE_BYTES;
        e = ply_read_exact(c, f, buf, (size_t)batch * PLY_FACE_BYTES, offset);
        if (e != ARGIL_OK)
            return e;
        for (uint64_t i = 0; i < batch; i++, done++, offset += PLY_FACE_BYTES) {
            const uint8_t *r = buf + i * PLY_FACE_BYTES;
            if (r[0] != 3) {
                ply_err(c->err, c->err_len,
                        "ply_read_mesh: %s: byte %llu: face %llu has %u vertices (only "
                        "triangles are read)",
                        c->path, (unsigned long long)offset, (unsigned long long)done,
                        (unsigned)r[0]);
                return ARGIL_ERR_PARSE;
            }
            uint32_t idx[3];
            for (int k = 0; k < 3; k++) {
                const int32_t s = (int32_t)get_u32_le(r + 1 + 4 * k);
                if (s < 0 || (uint64_t)s >= n_vert) {
                    ply_err(c->err, c->err_len,
                            "ply_read_mesh: %s: byte %llu: face %llu names vertex %ld of %llu",
                            c->path, (unsigned long long)(offset + 1 + 4 * (uint64_t)k),
                            (unsigned long long)done, (long)s, (unsigned long long)n_vert);
                    return ARGIL_ERR_PARSE;
                }
                idx[k] = (uint32_t)s;
            }
            e = mesh_add_triangle(out, idx[0], idx[1], idx[2]);
            if (e != ARGIL_OK)
                return e;
        }
    }
    return ARGIL_OK;
}

/* Everything after opening: size, header, count checks, body. */
static argil_err_t ply_read_file(ply_ctx_t *c, FILE *f, mesh_t *out, uint8_t *buf)
{
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        ply_err(c->err, c->err_len, "ply_read_mesh: fstat(\"%s\") failed: %s", c->path,
                strerror(errno));
        return ARGIL_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        ply_err(c->err, c->err_len, "ply_read_mesh: %s: not a regular file", c->path);
        return ARGIL_ERR_IO;
    }
    const uint64_t file_size = (uint64_t)st.st_size;
    size_t head = file_size < PLY_HEADER_MAX_BYTES ? (size_t)file_size : PLY_HEADER_MAX_BYTES;
    const size_t got = fread(buf, 1, head, f);
    if (got != head && ferror(f)) {
        ply_err(c->err, c->err_len, "ply_read_mesh: fread(\"%s\") failed: %s", c->path,
                strerror(errno));
        return ARGIL_ERR_IO;
    }
    size_t header_len = 0;
    uint64_t n_vert = 0, n_face = 0;
    argil_err_t e = ply_parse_header(c, (const char *)buf, got, &header_len, &n_vert, &n_face);
    if (e != ARGIL_OK)
        return e;
    /* The declared records must fill the rest of the file exactly: no count drives an
     * allocation beyond what the file holds. */
    const uint64_t avail = file_size - header_len;
    const uint64_t vbytes = n_vert * PLY_VERT_BYTES;
    const bool fits = vbytes <= avail && n_face <= (avail - vbytes) / PLY_FACE_BYTES;
    const uint64_t need = fits ? vbytes + n_face * PLY_FACE_BYTES : 0;
    if (!fits || need != avail) {
        ply_err(c->err, c->err_len,
                "ply_read_mesh: %s: byte %zu: header declares %llu vertices and %llu faces but "
                "%llu bytes follow the header (%s)",
                c->path, header_len, (unsigned long long)n_vert, (unsigned long long)n_face,
                (unsigned long long)avail, fits ? "trailing bytes" : "file too short");
        return ARGIL_ERR_PARSE;
    }
    e = mesh_reserve(out, (size_t)n_vert, (size_t)n_face);
    if (e != ARGIL_OK) {
        ply_err(c->err, c->err_len, "ply_read_mesh: %s: out of memory for %llu vertices",
                c->path, (unsigned long long)n_vert);
        return e;
    }
    if (fseek(f, (long)header_len, SEEK_SET) != 0) {
        ply_err(c->err, c->err_len, "ply_read_mesh: fseek(\"%s\") failed: %s", c->path,
                strerror(errno));
        return ARGIL_ERR_IO;
    }
    return ply_read_body(c, f, header_len, n_vert, n_face, out, buf);
}

argil_err_t ply_read_mesh(const char *path, mesh_t *out, char *err, size_t err_len)
{
    if (path == NULL || out == NULL) {
        ply_err(err, err_len, "ply_read_mesh: no path or no mesh");
        return ARGIL_ERR_ARG;
    }
    mesh_clear(out);
    ply_ctx_t c = {path, err, err_len};
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        ply_err(err, err_len, "ply_read_mesh: fopen(\"%s\") failed: %s", path, strerror(errno));
        return ARGIL_ERR_IO;
    }
    uint8_t *buf = malloc(PLY_CHUNK_BYTES);
    argil_err_t e = ARGIL_ERR_NOMEM;
    if (buf == NULL)
        ply_err(err, err_len, "ply_read_mesh: %s: out of memory", path);
    else
        e = ply_read_file(&c, f, out, buf);
    free(buf);
    (void)fclose(f);
    if (e != ARGIL_OK)
        mesh_clear(out);
    return e;
}
