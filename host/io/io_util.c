/* Shared file helpers for host/io: bounded whole-file reads, atomic writes, strict parsing. */
#include "host/io/io_util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "shared/tokens.h"

void io_err(char *err, size_t err_len, const char *fmt, ...)
{
    if (err == NULL || err_len == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_len, fmt, ap);
    va_end(ap);
}

argil_err_t io_slurp(const char *path, uint64_t max_bytes, uint8_t **data, size_t *len, char *err,
                     size_t err_len)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        io_err(err, err_len, "%s: cannot open: %s", path, strerror(errno));
        return ARGIL_ERR_IO;
    }
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        io_err(err, err_len, "%s: not a regular file", path);
        fclose(f);
        return ARGIL_ERR_IO;
    }
    const uint64_t size = (uint64_t)st.st_size;
    if (size > max_bytes || size > (uint64_t)SIZE_MAX - 1) {
        io_err(err, err_len, "%s: byte 0: file is %llu bytes, more than the %llu this reader takes",
               path, (unsigned long long)size, (unsigned long long)max_bytes);
        fclose(f);
        return ARGIL_ERR_PARSE;
    }
    uint8_t *buf = malloc((size_t)size + 1);
    if (buf == NULL) {
        io_err(err, err_len, "%s: out of memory for %llu bytes", path, (unsigned long long)size);
        fclose(f);
        return ARGIL_ERR_NOMEM;
    }
    const size_t got = fread(buf, 1, (size_t)size, f);
    const int bad = ferror(f);
    fclose(f);
    if (got != (size_t)size || bad) {
        io_err(err, err_len, "%s: read failed at byte %zu", path, got);
        free(buf);
        return ARGIL_ERR_IO;
    }
    buf[size] = 0;
    *data = buf;
    *len = (size_t)size;
    return ARGIL_OK;
}

/* Best effort: makes the rename durable by syncing the directory. */
static void io_sync_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    char *dir = slash == NULL ? strdup(".") : strndup(path, (size_t)(slash - path) + 1);
    if (dir == NULL)
        return;
    const int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        (void)fsync(fd);
        (void)close(fd);
    }
    free(dir);
}

argil_err_t io_write_atomic(const char *path, io_write_fn fn, const void *ctx, const char *who,
                            char *err, size_t err_len)
{
    const size_t plen = strlen(path);
    char *tmp = malloc(plen + 5);
    if (tmp == NULL) {
        io_err(err, err_len, "%s: %s: out of memory", who, path);
        return ARGIL_ERR_NOMEM;
    }
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp", 5);
    argil_err_t e = ARGIL_ERR_IO;
    FILE *f = fopen(tmp, "wb");
    if (f == NULL) {
        io_err(err, err_len, "%s: fopen(\"%s\") failed: %s", who, tmp, strerror(errno));
    } else {
        const char *failed = fn(f, ctx);
        if (failed == NULL && fflush(f) != 0)
            failed = "fflush";
        if (failed == NULL && fsync(fileno(f)) != 0)
            failed = "fsync";
        const int saved = errno;
        if (failed != NULL) {
            (void)fclose(f);
            (void)remove(tmp);
            io_err(err, err_len, "%s: %s(\"%s\") failed: %s", who, failed, tmp, strerror(saved));
        } else if (fclose(f) != 0) {
            io_err(err, err_len, "%s: fclose(\"%s\") failed: %s", who, tmp, strerror(errno));
            (void)remove(tmp);
        } else if (rename(tmp, path) != 0) {
            io_err(err, err_len, "%s: rename(\"%s\", \"%s\") failed: %s", who, tmp, path,
                   strerror(errno));
            (void)remove(tmp);
        } else {
            io_sync_dir(path);
            e = ARGIL_OK;
        }
    }
    free(tmp);
    return e;
}

bool io_parse_double(const char *tok, double *out)
{
    if (tok == NULL || *tok == '\0')
        return false;
    /* only plain decimal numbers: no hex floats, no inf/nan words */
    for (const char *p = tok; *p; p++)
        if (!((*p >= '0' && *p <= '9') || *p == '.' || *p == '-' || *p == '+' || *p == 'e' ||
              *p == 'E'))
            return false;
    char *end = NULL;
    errno = 0;
    const double v = strtod(tok, &end);
    if (end == tok || *end != '\0' || errno == ERANGE || !isfinite(v))
        return false;
    *out = v;
    return true;
}

bool io_parse_u64(const char *tok, uint64_t limit, uint64_t *out)
{
    uint64_t v = 0;
    if (tok == NULL || *tok == '\0')
        return false;
    for (; *tok; tok++) {
        if (*tok < '0' || *tok > '9')
            return false;
        const uint64_t d = (uint64_t)(*tok - '0');
        if (v > (limit - d) / 10)
            return false;
        v = v * 10 + d;
    }
    *out = v;
    return true;
}

long io_next_line(io_lines_t *it, char *line, size_t cap)
{
    if (it->pos >= it->len)
        return -1;
    const char *start = it->buf + it->pos;
    const char *nl = memchr(start, '\n', it->len - it->pos);
    size_t n = nl != NULL ? (size_t)(nl - start) : it->len - it->pos;
    it->line_no++;
    it->line_offset = it->pos;
    it->pos += n + (nl != NULL ? 1 : 0);
    if (n > 0 && start[n - 1] == '\r')
        n--;
    if (n + 1 > cap)
        return -2;
    if (memchr(start, '\0', n) != NULL)
        return -3;
    memcpy(line, start, n);
    line[n] = '\0';
    return (long)n;
}

int io_tokens(char *line, char **tok, int max)
{
    return (int)tokens_split(line, strlen(line) + 1u, TOKENS_SPACE_TAB, '\0', tok, (size_t)max);
}
