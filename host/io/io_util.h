/* Helpers every reader and writer shares: error text, whole-file reads bounded by the real file
 * size, atomic writes (temp file + fsync + rename), strict number parsing and line walking. */
#ifndef ARGIL_IO_UTIL_H
#define ARGIL_IO_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "shared/argil_err.h"

#define IO_FILE_MAX_BYTES ((uint64_t)1 << 32) /* readers refuse larger files (4 GiB) */
#define IMPORT_NUM_LINE 256 /* longest NRRD header line */

/* Writes a formatted message into err (when err is not NULL and err_len > 0). */
void io_err(char *err, size_t err_len, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Reads the whole regular file at path into *data (NUL-terminated, caller frees) and its length
 * into *len. ARGIL_ERR_IO (cannot open, not a regular file, read failed), ARGIL_ERR_PARSE (larger
 * than max_bytes), ARGIL_ERR_NOMEM; err names the path and what failed. */
argil_err_t io_slurp(const char *path, uint64_t max_bytes, uint8_t **data, size_t *len, char *err,
                     size_t err_len);

/* Writer callback: writes the body to f; returns NULL or the name of the failing call. */
typedef const char *(*io_write_fn)(FILE *f, const void *ctx);

/* Writes path atomically: fn writes path.tmp, which is flushed, fsync'ed and renamed over path, so
 * path holds the old file or the whole new one. ARGIL_ERR_IO with err naming the call and path. */
argil_err_t io_write_atomic(const char *path, io_write_fn fn, const void *ctx, const char *who,
                            char *err, size_t err_len);

/* Strict decimal/float parse of the whole token (no trailing garbage); false otherwise. */
bool io_parse_double(const char *tok, double *out);

/* Strict parse of a non-negative integer token up to limit. */
bool io_parse_u64(const char *tok, uint64_t limit, uint64_t *out);

/* Text cursor over a buffer: one line at a time. */
typedef struct {
    const char *buf;
    size_t len, pos;
    size_t line_no;      /* of the line last returned (1-based) */
    size_t line_offset;  /* its byte offset */
} io_lines_t;

/* Copies the next line (without \n or \r\n) into line (NUL-terminated) and returns its length;
 * -1 at the end of the buffer, -2 when the line does not fit in cap bytes, -3 when it holds a NUL. */
long io_next_line(io_lines_t *it, char *line, size_t cap);

/* Splits line (modified) at spaces and tabs into at most max tokens (tokens_split); returns the
 * count, max + 1 if more. */
int io_tokens(char *line, char **tok, int max);

#endif
