/* Raw and NRRD volume readers: sizes are checked against the real data length before any
 * allocation; every sample must be finite. */
#include "host/io/volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/io_util.h"

#define VOL_NAMES_PER_TYPE 8 /* the longest row's names and the NULL that ends it */

/* Every name of each sample type, one row per type. */
static const char *const vol_names[VOL_F64 + 1][VOL_NAMES_PER_TYPE] = {
    [VOL_U8] = {"u8", "uchar", "unsigned char", "uint8", "uint8_t"},
    [VOL_I8] = {"i8", "signed char", "int8", "int8_t"},
    [VOL_U16] = {"u16", "ushort", "unsigned short", "unsigned short int", "uint16", "uint16_t"},
    [VOL_I16] = {"i16", "short", "short int", "signed short", "signed short int", "int16",
                 "int16_t"},
    [VOL_U32] = {"u32", "uint", "unsigned int", "uint32", "uint32_t"},
    [VOL_I32] = {"i32", "int", "signed int", "int32", "int32_t"},
    [VOL_F32] = {"f32", "float"},
    [VOL_F64] = {"f64", "double"},
};

bool vol_type_parse(const char *name, vol_type_t *out)
{
    for (int t = VOL_U8; name != NULL && t <= VOL_F64; t++)
        for (size_t k = 0; k < VOL_NAMES_PER_TYPE && vol_names[t][k] != NULL; k++)
            if (strcmp(name, vol_names[t][k]) == 0) {
                *out = (vol_type_t)t;
                return true;
            }
    return false;
}

static size_t vol_size(vol_type_t t)
{
    static const size_t s[] = {1, 1, 2, 2, 4, 4, 4, 8};
    return s[t];
}

void volume_free(volume_t *v)
{
    free(v->value);
    memset(v, 0, sizeof(*v));
}

argil_err_t volume_err_argil(volume_err_t e)
{
    switch (e) {
    case VOLUME_OK: return ARGIL_OK;
    case VOLUME_ERR_ARG: return ARGIL_ERR_ARG;
    case VOLUME_ERR_IO: return ARGIL_ERR_IO;
    case VOLUME_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

/* The volume_err_t of io_slurp's result. */
static volume_err_t vol_slurp_err(argil_err_t e)
{
    switch (e) {
    case ARGIL_OK: return VOLUME_OK;
    case ARGIL_ERR_NOMEM: return VOLUME_ERR_NOMEM;
    case ARGIL_ERR_PARSE: return VOLUME_ERR_FILE_SIZE;
    default: return VOLUME_ERR_IO;
    }
}

/* Reads the whole file at path into *data and *len (caller frees) after checking the reader's
 * arguments (who names the reader) and emptying *out. */
static volume_err_t vol_slurp(const char *who, const char *path, bool args_ok, volume_t *out,
                              uint8_t **data, size_t *len, char *err, size_t err_len)
{
    if (path == NULL || out == NULL || !args_ok) {
        io_err(err, err_len, "%s: missing argument", who);
        return VOLUME_ERR_ARG;
    }
    memset(out, 0, sizeof(*out));
    return vol_slurp_err(io_slurp(path, IO_FILE_MAX_BYTES, data, len, err, err_len));
}

/* Converts n samples at data (len bytes exactly) into out->value. */
static volume_err_t vol_decode(const char *path, const uint8_t *data, size_t len, size_t offset,
                               const int32_t dims[3], vol_type_t t, bool big, volume_t *out,
                               char *err, size_t err_len)
{
    uint64_t n = 1;
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 1 || (uint64_t)dims[a] > VOLUME_SAMPLES_MAX) {
            io_err(err, err_len, "%s: dimension %d is %d, must be 1..2^30", path, a, dims[a]);
            return VOLUME_ERR_ARG;
        }
        n *= (uint64_t)dims[a];
        if (n > VOLUME_SAMPLES_MAX) {
            io_err(err, err_len, "%s: %d x %d x %d samples exceed the limit of 2^30", path,
                   dims[0], dims[1], dims[2]);
            return VOLUME_ERR_ARG;
        }
    }
    const size_t sz = vol_size(t);
    if ((uint64_t)len != n * sz) {
        io_err(err, err_len, "%s: byte %zu: %d x %d x %d samples of %zu bytes need %llu data "
               "bytes, the file has %zu", path, offset, dims[0], dims[1], dims[2], sz,
               (unsigned long long)(n * sz), len);
        return VOLUME_ERR_DATA_LENGTH;
    }
    float *v = malloc((size_t)n * sizeof(float));
    if (v == NULL) {
        io_err(err, err_len, "%s: out of memory for %llu samples", path, (unsigned long long)n);
        return VOLUME_ERR_NOMEM;
    }
    for (size_t i = 0; i < (size_t)n; i++) {
        uint8_t b[8];
        for (size_t k = 0; k < sz; k++)
            b[k] = data[i * sz + (big ? sz - 1 - k : k)];
        uint64_t u = 0;
        for (size_t k = sz; k-- > 0;)
            u = u << 8 | b[k];
        double d;
        switch (t) {
        case VOL_U8: d = (double)(uint8_t)u; break;
        case VOL_I8: d = (double)(int8_t)u; break;
        case VOL_U16: d = (double)(uint16_t)u; break;
        case VOL_I16: d = (double)(int16_t)u; break;
        case VOL_U32: d = (double)(uint32_t)u; break;
        case VOL_I32: d = (double)(int32_t)(uint32_t)u; break;
        case VOL_F32: {
            const uint32_t w = (uint32_t)u;
            float f;
            memcpy(&f, &w, 4);
            d = f;
            break;
        }
        default: memcpy(&d, &u, 8); break;
        }
        if (!isfinite(d) || fabs(d) > 3e38) {
            io_err(err, err_len, "%s: byte %zu: sample %zu is not a finite float", path,
                   offset + i * sz, i);
            free(v);
            return VOLUME_ERR_SAMPLE;
        }
        v[i] = (float)d;
    }
    for (int a = 0; a < 3; a++) {
        out->dims[a] = dims[a];
        if (!(out->spacing_m[a] > 0.0f))
            out->spacing_m[a] = 1.0f;
    }
    out->value = v;
    return VOLUME_OK;
}

volume_err_t volume_read_raw(const char *path, const int32_t dims[3], vol_type_t t, bool big_endian,
                             volume_t *out, char *err, size_t err_len)
{
    uint8_t *b;
    size_t len;
    volume_err_t e = vol_slurp("volume_read_raw", path, dims != NULL && (unsigned)t <= VOL_F64,
                               out, &b, &len, err, err_len);
    if (e != VOLUME_OK)
        return e;
    e = vol_decode(path, b, len, 0, dims, t, big_endian, out, err, err_len);
    free(b);
    if (e != VOLUME_OK)
        volume_free(out);
    return e;
}

/* Parses up to n numbers from s (space or comma separated, optional parentheses). */
static int nrrd_numbers(const char *s, double *v, int n)
{
    char tmp[IMPORT_NUM_LINE];
    size_t l = strlen(s);
    if (l >= sizeof(tmp))
        return -1;
    for (size_t i = 0; i <= l; i++)
        tmp[i] = (s[i] == ',' || s[i] == '(' || s[i] == ')') ? ' ' : s[i];
    char *tok[16];
    const int nt = io_tokens(tmp, tok, 15);
    if (nt > n)
        return -1;
    for (int i = 0; i < nt; i++)
        if (!io_parse_double(tok[i], &v[i]))
            return -1;
    return nt;
}

/* What a NRRD header has said so far (volume_read_nrrd). */
typedef struct {
    bool have_type, have_dim, have_sizes, have_enc, big, have_endian;
    vol_type_t t;
    int32_t dims[3];
    char data_file[IMPORT_NUM_LINE];
} nrrd_header_t;

/* Applies the header field key: val on line ln to h and out (a field that does not change the
 * samples is skipped); the rule a bad value broke, with err naming the line. */
static volume_err_t nrrd_field(const char *path, size_t ln, const char *key, const char *val,
                              nrrd_header_t *h, volume_t *out, char *err, size_t err_len)
{
    double v[9];
    if (strcmp(key, "type") == 0) {
        if (!vol_type_parse(val, &h->t)) {
            io_err(err, err_len, "%s: line %zu: unknown type '%.40s'", path, ln, val);
            return VOLUME_ERR_TYPE;
        }
        h->have_type = true;
    } else if (strcmp(key, "dimension") == 0) {
        if (strcmp(val, "3") != 0) {
            io_err(err, err_len, "%s: line %zu: dimension must be 3, got '%.20s'", path, ln,
                   val);
            return VOLUME_ERR_DIMENSION;
        }
        h->have_dim = true;
    } else if (strcmp(key, "sizes") == 0) {
        if (nrrd_numbers(val, v, 3) != 3 || v[0] < 1 || v[1] < 1 || v[2] < 1 ||
            v[0] > VOLUME_SAMPLES_MAX || v[1] > VOLUME_SAMPLES_MAX ||
            v[2] > VOLUME_SAMPLES_MAX || v[0] != floor(v[0]) || v[1] != floor(v[1]) ||
            v[2] != floor(v[2])) {
            io_err(err, err_len, "%s: line %zu: sizes must be three whole numbers 1..2^30",
                   path, ln);
            return VOLUME_ERR_SIZES;
        }
        if (v[0] * v[1] * v[2] > (double)VOLUME_SAMPLES_MAX) {
            io_err(err, err_len, "%s: line %zu: sizes give more than 2^30 samples", path, ln);
            return VOLUME_ERR_SAMPLES_MAX;
        }
        for (int a = 0; a < 3; a++)
            h->dims[a] = (int32_t)v[a];
        h->have_sizes = true;
    } else if (strcmp(key, "encoding") == 0) {
        if (strcmp(val, "raw") != 0) {
            io_err(err, err_len, "%s: line %zu: encoding '%.20s' is not supported (only raw)",
                   path, ln, val);
            return VOLUME_ERR_ENCODING;
        }
        h->have_enc = true;
    } else if (strcmp(key, "endian") == 0) {
        if (strcmp(val, "little") != 0 && strcmp(val, "big") != 0) {
            io_err(err, err_len, "%s: line %zu: endian must be little or big", path, ln);
            return VOLUME_ERR_ENDIAN;
        }
        h->big = val[0] == 'b';
        h->have_endian = true;
    } else if (strcmp(key, "spacings") == 0) {
        if (nrrd_numbers(val, v, 3) != 3 || !(v[0] > 0 && v[1] > 0 && v[2] > 0)) {
            io_err(err, err_len, "%s: line %zu: spacings must be three positive numbers", path,
                   ln);
            return VOLUME_ERR_SPACINGS;
        }
        for (int a = 0; a < 3; a++)
            out->spacing_m[a] = (float)v[a];
    } else if (strcmp(key, "space directions") == 0) {
        if (nrrd_numbers(val, v, 9) != 9) {
            io_err(err, err_len, "%s: line %zu: space directions must be three vectors (x,y,z)",
                   path, ln);
            return VOLUME_ERR_DIRECTIONS;
        }
        for (int a = 0; a < 3; a++) {
            const double s = sqrt(v[3 * a] * v[3 * a] + v[3 * a + 1] * v[3 * a + 1] +
                                  v[3 * a + 2] * v[3 * a + 2]);
            if (!(s > 0) || s > 3e38) {
                io_err(err, err_len, "%s: line %zu: a space direction has zero length", path, ln);
                return VOLUME_ERR_DIRECTIONS;
            }
            out->spacing_m[a] = (float)s;
        }
    } else if (strcmp(key, "space origin") == 0) {
        if (nrrd_numbers(val, v, 3) != 3 || fabs(v[0]) > 3e38 || fabs(v[1]) > 3e38 ||
            fabs(v[2]) > 3e38) {
            io_err(err, err_len, "%s: line %zu: space origin must be one vector (x,y,z)", path,
                   ln);
            return VOLUME_ERR_ORIGIN;
        }
        out->origin_m = vec3_from_d(v);
    } else if (strcmp(key, "data file") == 0 || strcmp(key, "datafile") == 0) {
        if (strchr(val, '/') != NULL || strchr(val, '%') != NULL || strchr(val, ' ') != NULL ||
            val[0] == '\0' || strcmp(val, "..") == 0 || strcmp(val, ".") == 0) {
            io_err(err, err_len, "%s: line %zu: data file must be one plain file name beside "
                   "the header", path, ln);
            return VOLUME_ERR_DATA_FILE;
        }
        snprintf(h->data_file, sizeof(h->data_file), "%s", val);
    }
    /* other fields (space, kinds, centers, content, ...) do not change the samples */
    return VOLUME_OK;
}

/* Reads the header (the magic line onward) into h and out, up to and including the blank line
 * that ends them; the rule the header broke, with err naming the line. */
static volume_err_t nrrd_header(const char *path, io_lines_t *it, nrrd_header_t *h, volume_t *out,
                                char *err, size_t err_len)
{
    char line[IMPORT_NUM_LINE];
    memset(h, 0, sizeof(*h));
    h->t = VOL_U8;
    for (;;) {
        const long n = io_next_line(it, line, sizeof(line));
        const size_t ln = it->line_no;
        if (n == -1) {
            io_err(err, err_len, "%s: line %zu: header does not end with a blank line", path, ln);
            return VOLUME_ERR_HEADER_END;
        }
        if (n < 0) {
            io_err(err, err_len, "%s: line %zu: header line %s", path, ln,
                   n == -2 ? "longer than 255 bytes" : "contains a NUL byte");
            return n == -2 ? VOLUME_ERR_LINE_LONG : VOLUME_ERR_LINE_NUL;
        }
        if (ln == 1) {
            if (n != 8 || memcmp(line, "NRRD000", 7) != 0 || line[7] < '1' || line[7] > '5') {
                io_err(err, err_len, "%s: line 1: not a NRRD file (magic NRRD0001..NRRD0005)",
                       path);
                return VOLUME_ERR_MAGIC;
            }
            continue;
        }
        if (n == 0)
            break; /* end of header */
        if (line[0] == '#')
            continue;
        char *colon = strstr(line, ": ");
        if (colon == NULL) {
            if (strstr(line, ":=") != NULL)
                continue; /* key/value pair: not needed */
            io_err(err, err_len, "%s: line %zu: expected '<field>: <value>'", path, ln);
            return VOLUME_ERR_FIELD;
        }
        *colon = '\0';
        const volume_err_t e = nrrd_field(path, ln, line, colon + 2, h, out, err, err_len);
        if (e != VOLUME_OK)
            return e;
    }
    if (!h->have_type || !h->have_dim || !h->have_sizes || !h->have_enc) {
        io_err(err, err_len, "%s: line %zu: header lacks the required field '%s'", path,
               it->line_no,
               !h->have_type    ? "type"
               : !h->have_dim   ? "dimension"
               : !h->have_sizes ? "sizes"
                                : "encoding");
        return VOLUME_ERR_MISSING;
    }
    if (vol_size(h->t) > 1 && !h->have_endian) {
        io_err(err, err_len, "%s: line %zu: header lacks 'endian' for a %zu-byte type", path,
               it->line_no, vol_size(h->t));
        return VOLUME_ERR_MISSING;
    }
    return VOLUME_OK;
}

/* Reads the samples h describes from h's data file, beside the header at path; err names the
 * header, then the data file and what failed. */
static volume_err_t nrrd_data_file(const char *path, const nrrd_header_t *h, volume_t *out,
                                   char *err, size_t err_len)
{
    const char *slash = strrchr(path, '/');
    const size_t dl = slash != NULL ? (size_t)(slash - path) + 1 : 0;
    char *dp = malloc(dl + strlen(h->data_file) + 1);
    if (dp == NULL)
        return VOLUME_ERR_NOMEM;
    memcpy(dp, path, dl);
    strcpy(dp + dl, h->data_file);
    uint8_t *db;
    size_t dlen;
    char inner[384] = "";
    volume_err_t e = vol_slurp_err(io_slurp(dp, IO_FILE_MAX_BYTES, &db, &dlen, inner,
                                            sizeof(inner)));
    if (e == VOLUME_OK) {
        e = vol_decode(dp, db, dlen, 0, h->dims, h->t, h->big, out, inner, sizeof(inner));
        free(db);
    }
    if (e != VOLUME_OK)
        io_err(err, err_len, "%s: data file: %s", path, inner);
    free(dp);
    return e;
}

volume_err_t volume_read_nrrd(const char *path, volume_t *out, char *err, size_t err_len)
{
    uint8_t *b;
    size_t len;
    volume_err_t e = vol_slurp("volume_read_nrrd", path, true, out, &b, &len, err, err_len);
    if (e != VOLUME_OK)
        return e;
    io_lines_t it = {(const char *)b, len, 0, 0, 0};
    nrrd_header_t h;
    e = nrrd_header(path, &it, &h, out, err, err_len);
    if (e == VOLUME_OK && h.data_file[0] != '\0')
        e = nrrd_data_file(path, &h, out, err, err_len);
    else if (e == VOLUME_OK)
        e = vol_decode(path, b + it.pos, len - it.pos, it.pos, h.dims, h.t, h.big, out, err,
                       err_len);
    free(b);
    if (e != VOLUME_OK)
        volume_free(out);
    return e;
}
