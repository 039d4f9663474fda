/* Binary little-endian PLY: atomic export of meshes (through mesh_export, the one PLY writer) and
 * a strict reader of the same layout. Fields are decoded byte by byte, never by copying structs. */
#include "host/io/ply.h"

#include "host/io/io_util.h"
#include "host/io/mesh_export.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "shared/wire.h"

#define PLY_VERT_BYTES 24u  /* 6 floats */
#define PLY_VERT_RGB_BYTES 27u /* 6 floats + uchar red green blue */
#define PLY_FACE_BYTES 13u  /* uchar count + 3 int32 */
#define PLY_CHUNK_BYTES 65520u /* read buffer: whole records of 24, 27 or 13 bytes at a time */
#define PLY_VERT_MAX ((uint64_t)INT32_MAX) /* indices are signed int in the file */

static const char *const ply_prop_names[6] = {"x", "y", "z", "nx", "ny", "nz"};
static const char *const ply_rgb_names[3] = {"red", "green", "blue"};

/* ---------------------------------------------------------------- writer */

argil_err_t ply_write(const char *path, const mesh_t *m, char *err, size_t err_len)
{
    if (path == NULL || m == NULL) {
        io_err(err, err_len, "ply_write: no path or no mesh");
        return ARGIL_ERR_ARG;
    }
    /* One PLY writer: argil mesh's (vertex colours when the mesh has them). */
    return mesh_export(path, m, EXPORT_PLY_BINARY, err, err_len);
}

/* ---------------------------------------------------------------- reader */

argil_err_t ply_err_argil(ply_err_t e)
{
    switch (e) {
    case PLY_OK: return ARGIL_OK;
    case PLY_ERR_ARG: return ARGIL_ERR_ARG;
    case PLY_ERR_IO: return ARGIL_ERR_IO;
    case PLY_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

typedef struct {
    const char *path;
    char *err;
    size_t err_len;
    bool rgb;          /* the header declared red green blue after the normal */
    size_t vert_bytes; /* PLY_VERT_BYTES, or PLY_VERT_RGB_BYTES with colour */
} ply_ctx_t;

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
    PLY_H_RGB0 = PLY_H_PROP0 + 6, /* optional: .. PLY_H_RGB0 + 2 */
    PLY_H_FACE = PLY_H_RGB0 + 3,
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
    case PLY_H_RGB0: return "property uchar red' or 'element face <count>";
    case PLY_H_RGB0 + 1: return "property uchar green";
    case PLY_H_RGB0 + 2: return "property uchar blue";
    default: return props[state - PLY_H_PROP0];
    }
}

/* Checks one header line against the expected state; advances it and stores counts. */
static ply_err_t ply_header_line(ply_ctx_t *c, char *line, int line_no, int *state,
                                 uint64_t *n_vert, uint64_t *n_face)
{
    char *tok[6];
    const int n = io_tokens(line, tok, 5);
    if (*state != PLY_H_MAGIC && n >= 1 && (ply_is(tok[0], "comment", "obj_info")))
        return PLY_OK;
    /* The colour is optional: the face element may follow the normal directly. */
    if (*state == PLY_H_RGB0 && n >= 1 && strcmp(tok[0], "element") == 0)
        *state = PLY_H_FACE;
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
            if (!io_parse_u64(tok[2], limit, vert ? n_vert : n_face)) {
                io_err(c->err, c->err_len,
                       "ply_read_mesh: %s: header line %d: %s count '%.32s' is not a number "
                       "from 0 to %llu",
                       c->path, line_no, vert ? "vertex" : "face", tok[2],
                       (unsigned long long)limit);
                return PLY_ERR_COUNT;
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
    case PLY_H_RGB0:
    case PLY_H_RGB0 + 1:
    case PLY_H_RGB0 + 2:
        ok = n == 3 && strcmp(tok[0], "property") == 0 && ply_is(tok[1], "uchar", "uint8") &&
             strcmp(tok[2], ply_rgb_names[*state - PLY_H_RGB0]) == 0;
        if (ok && *state == PLY_H_RGB0 + 2) {
            c->rgb = true;
            c->vert_bytes = PLY_VERT_RGB_BYTES;
        }
        break;
    default:
        ok = n == 3 && strcmp(tok[0], "property") == 0 && ply_is(tok[1], "float", "float32") &&
             strcmp(tok[2], ply_prop_names[*state - PLY_H_PROP0]) == 0;
        break;
    }
    if (!ok) {
        io_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: expected '%s'", c->path,
               line_no, ply_expected(*state));
        return PLY_ERR_HEADER;
    }
    (*state)++;
    return PLY_OK;
}

/* Parses the header at the start of buf (len bytes); sets its byte length and the counts. */
static ply_err_t ply_parse_header(ply_ctx_t *c, const char *buf, size_t len, size_t *header_len,
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
            io_err(c->err, c->err_len,
                   "ply_read_mesh: %s: header line %d: no end of line (file truncated or "
                   "header over %d bytes)",
                   c->path, line_no, PLY_HEADER_MAX_BYTES);
            return PLY_ERR_LINE_END;
        }
        size_t n = (size_t)(nl - (buf + pos));
        if (n >= sizeof(line)) {
            io_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: longer than %d bytes",
                   c->path, line_no, PLY_LINE_MAX - 1);
            return PLY_ERR_LINE_LONG;
        }
        memcpy(line, buf + pos, n);
        if (n > 0 && line[n - 1] == '\r')
            n--;
        line[n] = '\0';
        if (strlen(line) != n) {
            io_err(c->err, c->err_len, "ply_read_mesh: %s: header line %d: contains a NUL byte",
                   c->path, line_no);
            return PLY_ERR_LINE_NUL;
        }
        const ply_err_t e = ply_header_line(c, line, line_no, &state, n_vert, n_face);
        if (e != PLY_OK)
            return e;
        pos = (size_t)(nl - buf) + 1;
    }
    *header_len = pos;
    return PLY_OK;
}

/* Reads exactly n bytes at the current position (offset is for the message). */
static ply_err_t ply_read_exact(ply_ctx_t *c, FILE *f, uint8_t *dst, size_t n, uint64_t offset)
{
    if (fread(dst, 1, n, f) == n)
        return PLY_OK;
    if (ferror(f)) {
        io_err(c->err, c->err_len, "ply_read_mesh: %s: fread at byte %llu failed: %s", c->path,
               (unsigned long long)offset, strerror(errno));
        return PLY_ERR_IO;
    }
    io_err(c->err, c->err_len, "ply_read_mesh: %s: byte %llu: file ended early", c->path,
           (unsigned long long)offset);
    return PLY_ERR_TRUNCATED;
}

/* Reads and checks the vertex and face records that follow the header. */
static ply_err_t ply_read_body(ply_ctx_t *c, FILE *f, uint64_t offset, uint64_t n_vert,
                               uint64_t n_face, mesh_t *out, uint8_t *buf)
{
    ply_err_t e;
    uint64_t done = 0;
    while (done < n_vert) {
        uint64_t batch = n_vert - done;
        if (batch > PLY_CHUNK_BYTES / c->vert_bytes)
            batch = PLY_CHUNK_BYTES / c->vert_bytes;
        e = ply_read_exact(c, f, buf, (size_t)batch * c->vert_bytes, offset);
        if (e != PLY_OK)
            return e;
        for (uint64_t i = 0; i < batch; i++, done++, offset += c->vert_bytes) {
            const uint8_t *r = buf + i * c->vert_bytes;
            float v[6];
            for (int k = 0; k < 6; k++) {
                v[k] = le_get_f32(r + 4 * (size_t)k);
                if (!isfinite(v[k])) {
                    io_err(c->err, c->err_len,
                           "ply_read_mesh: %s: byte %llu: vertex %llu has a non-finite %s",
                           c->path, (unsigned long long)(offset + 4 * (uint64_t)k),
                           (unsigned long long)done, ply_prop_names[k]);
                    return PLY_ERR_NONFINITE;
                }
            }
            const argil_err_t me =
                c->rgb ? mesh_add_vertex_rgb(out, vec3(v[0], v[1], v[2]), vec3(v[3], v[4], v[5]),
                                             r + PLY_VERT_BYTES, NULL)
                       : mesh_add_vertex(out, vec3(v[0], v[1], v[2]), vec3(v[3], v[4], v[5]),
                                         NULL);
            if (me != ARGIL_OK)
                return PLY_ERR_NOMEM;
        }
    }
    done = 0;
    while (done < n_face) {
        uint64_t batch = n_face - done;
        if (batch > PLY_CHUNK_BYTES / PLY_FACE_BYTES)
            batch = PLY_CHUNK_BYTES / PLY_FACE_BYTES;
        e = ply_read_exact(c, f, buf, (size_t)batch * PLY_FACE_BYTES, offset);
        if (e != PLY_OK)
            return e;
        for (uint64_t i = 0; i < batch; i++, done++, offset += PLY_FACE_BYTES) {
            const uint8_t *r = buf + i * PLY_FACE_BYTES;
            if (r[0] != 3) {
                io_err(c->err, c->err_len,
                       "ply_read_mesh: %s: byte %llu: face %llu has %u vertices (only "
                       "triangles are read)",
                       c->path, (unsigned long long)offset, (unsigned long long)done,
                       (unsigned)r[0]);
                return PLY_ERR_FACE_SIZE;
            }
            uint32_t idx[3];
            for (int k = 0; k < 3; k++) {
                const int32_t s = (int32_t)le_get_u32(r + 1 + 4 * k);
                if (s < 0 || (uint64_t)s >= n_vert) {
                    io_err(c->err, c->err_len,
                           "ply_read_mesh: %s: byte %llu: face %llu names vertex %ld of %llu",
                           c->path, (unsigned long long)(offset + 1 + 4 * (uint64_t)k),
                           (unsigned long long)done, (long)s, (unsigned long long)n_vert);
                    return PLY_ERR_INDEX;
                }
                idx[k] = (uint32_t)s;
            }
            if (mesh_add_triangle(out, idx[0], idx[1], idx[2]) != ARGIL_OK)
                return PLY_ERR_NOMEM;
        }
    }
    return PLY_OK;
}

/* Everything after opening: size, header, count checks, body. */
static ply_err_t ply_read_file(ply_ctx_t *c, FILE *f, mesh_t *out, uint8_t *buf)
{
    struct stat st;
    if (fstat(fileno(f), &st) != 0) {
        io_err(c->err, c->err_len, "ply_read_mesh: fstat(\"%s\") failed: %s", c->path,
               strerror(errno));
        return PLY_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        io_err(c->err, c->err_len, "ply_read_mesh: %s: not a regular file", c->path);
        return PLY_ERR_IO;
    }
    const uint64_t file_size = (uint64_t)st.st_size;
    size_t head = file_size < PLY_HEADER_MAX_BYTES ? (size_t)file_size : PLY_HEADER_MAX_BYTES;
    const size_t got = fread(buf, 1, head, f);
    if (got != head && ferror(f)) {
        io_err(c->err, c->err_len, "ply_read_mesh: fread(\"%s\") failed: %s", c->path,
               strerror(errno));
        return PLY_ERR_IO;
    }
    size_t header_len = 0;
    uint64_t n_vert = 0, n_face = 0;
    const ply_err_t e = ply_parse_header(c, (const char *)buf, got, &header_len, &n_vert, &n_face);
    if (e != PLY_OK)
        return e;
    /* The declared records must fill the rest of the file exactly: no count drives an
     * allocation beyond what the file holds. */
    const uint64_t avail = file_size - header_len;
    const uint64_t vbytes = n_vert * c->vert_bytes;
    const bool fits = vbytes <= avail && n_face <= (avail - vbytes) / PLY_FACE_BYTES;
    const uint64_t need = fits ? vbytes + n_face * PLY_FACE_BYTES : 0;
    if (!fits || need != avail) {
        io_err(c->err, c->err_len,
               "ply_read_mesh: %s: byte %zu: header declares %llu vertices and %llu faces but "
               "%llu bytes follow the header (%s)",
               c->path, header_len, (unsigned long long)n_vert, (unsigned long long)n_face,
               (unsigned long long)avail, fits ? "trailing bytes" : "file too short");
        return PLY_ERR_SIZE;
    }
    if (out->has_rgb && !c->rgb) { /* a colour array left from an earlier use of out */
        free(out->rgb);
        out->rgb = NULL;
        out->has_rgb = 0;
    }
    argil_err_t me = mesh_reserve(out, (size_t)n_vert, (size_t)n_face);
    if (me == ARGIL_OK && c->rgb)
        me = mesh_enable_rgb(out);
    if (me != ARGIL_OK) {
        io_err(c->err, c->err_len, "ply_read_mesh: %s: out of memory for %llu vertices",
               c->path, (unsigned long long)n_vert);
        return PLY_ERR_NOMEM;
    }
    if (fseek(f, (long)header_len, SEEK_SET) != 0) {
        io_err(c->err, c->err_len, "ply_read_mesh: fseek(\"%s\") failed: %s", c->path,
               strerror(errno));
        return PLY_ERR_IO;
    }
    return ply_read_body(c, f, header_len, n_vert, n_face, out, buf);
}

ply_err_t ply_read_mesh(const char *path, mesh_t *out, char *err, size_t err_len)
{
    if (path == NULL || out == NULL) {
        io_err(err, err_len, "ply_read_mesh: no path or no mesh");
        return PLY_ERR_ARG;
    }
    mesh_clear(out);
    ply_ctx_t c = {path, err, err_len, false, PLY_VERT_BYTES};
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        io_err(err, err_len, "ply_read_mesh: fopen(\"%s\") failed: %s", path, strerror(errno));
        return PLY_ERR_IO;
    }
    uint8_t *buf = malloc(PLY_CHUNK_BYTES);
    ply_err_t e = PLY_ERR_NOMEM;
    if (buf == NULL)
        io_err(err, err_len, "ply_read_mesh: %s: out of memory", path);
    else
        e = ply_read_file(&c, f, out, buf);
    free(buf);
    (void)fclose(f);
    if (e != PLY_OK)
        mesh_clear(out);
    return e;
}
