/* The link key file (link_key.h). */
#define _POSIX_C_SOURCE 200809L
#include "link_key.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <sodium.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

link_key_err_t link_key_parse(const char *text, size_t len, link_key_t *key, uint32_t *line)
{
    uint8_t k[LINK_KEY_BYTES];
    bool have = false;
    uint32_t ln = 1;
    size_t at = 0;
    link_key_err_t rc = LINK_KEY_OK;
    while (at < len && rc == LINK_KEY_OK) {
        size_t end = at;
        while (end < len && text[end] != '\n')
            end++;
        /* The line's content: up to a '#', without blanks around it. */
        size_t a = at, b = end;
        for (size_t i = at; i < end; i++)
            if (text[i] == '#') {
                b = i;
                break;
            }
        while (a < b && is_blank(text[a]))
            a++;
        while (b > a && is_blank(text[b - 1u]))
            b--;
        if (a < b) {
            for (size_t i = a; i < b && rc == LINK_KEY_OK; i++)
                if (!isxdigit((unsigned char)text[i]))
                    rc = LINK_KEY_ERR_HEX;
            size_t got = 0;
            if (rc == LINK_KEY_OK && have)
                rc = LINK_KEY_ERR_EXTRA;
            else if (rc == LINK_KEY_OK && b - a > 2u * LINK_KEY_BYTES)
                rc = LINK_KEY_ERR_LONG;
            else if (rc == LINK_KEY_OK &&
                     (b - a < 2u * LINK_KEY_BYTES ||
                      sodium_hex2bin(k, sizeof(k), text + a, b - a, NULL, &got, NULL) != 0 ||
                      got != LINK_KEY_BYTES))
                rc = LINK_KEY_ERR_SHORT;
            have = true;
        }
        if (rc != LINK_KEY_OK)
            break;
        at = end + 1u;
        if (end < len)
            ln++;
    }
    if (rc == LINK_KEY_OK && !have)
        rc = LINK_KEY_ERR_NO_KEY;
    *line = ln;
    if (rc == LINK_KEY_OK)
        memcpy(key->k, k, sizeof(k));
    sodium_memzero(k, sizeof(k));
    return rc;
}

link_key_err_t link_key_load(const char *path, link_key_t *key, char *err, size_t err_len)
{
    /* O_NONBLOCK: a FIFO must not hang the caller before fstat says it is no file. */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, err_len, "key file '%s': %s (make one with 'argil keygen %s')", path,
                 strerror(errno), path);
        return LINK_KEY_ERR_OPEN;
    }
    struct stat st;
    link_key_err_t rc = LINK_KEY_OK;
    if (fstat(fd, &st) != 0) {
        snprintf(err, err_len, "key file '%s': %s", path, strerror(errno));
        rc = LINK_KEY_ERR_OPEN;
    } else if (!S_ISREG(st.st_mode)) {
        snprintf(err, err_len, "key file '%s' is not a regular file (make one with 'argil keygen "
                 "FILE')", path);
        rc = LINK_KEY_ERR_NOT_FILE;
    } else if ((st.st_mode & 077) != 0) {
        snprintf(err, err_len, "key file '%s' may be read or written by group or others (mode "
                 "%04o): chmod 600 %s", path, (unsigned)(st.st_mode & 07777), path);
        rc = LINK_KEY_ERR_MODE;
    } else if (st.st_size > (off_t)LINK_KEY_FILE_MAX) {
        snprintf(err, err_len, "key file '%s' is larger than %u bytes: not a key file", path,
                 LINK_KEY_FILE_MAX);
        rc = LINK_KEY_ERR_BIG;
    }
    if (rc != LINK_KEY_OK) {
        close(fd);
        return rc;
    }
    char text[LINK_KEY_FILE_MAX + 1u];
    size_t n = 0;
    for (;;) {
        const ssize_t r = read(fd, text + n, sizeof(text) - n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            snprintf(err, err_len, "key file '%s': %s", path, strerror(errno));
            close(fd);
            sodium_memzero(text, sizeof(text));
            return LINK_KEY_ERR_OPEN;
        }
        if (r == 0 || (n += (size_t)r) == sizeof(text))
            break;
    }
    close(fd);
    if (n > LINK_KEY_FILE_MAX) { /* it grew after fstat */
        snprintf(err, err_len, "key file '%s' is larger than %u bytes: not a key file", path,
                 LINK_KEY_FILE_MAX);
        sodium_memzero(text, sizeof(text));
        return LINK_KEY_ERR_BIG;
    }
    uint32_t line = 0;
    rc = link_key_parse(text, n, key, &line);
    sodium_memzero(text, sizeof(text));
    if (rc != LINK_KEY_OK)
        snprintf(err, err_len, "key file '%s':%u: %s (a key file is one line of 64 hex digits; "
                 "make a new one with 'argil keygen FILE')", path, line, link_key_err_text(rc));
    return rc;
}

link_key_err_t link_key_load_env(const char *var, link_key_t *key, bool *found, char *err,
                                 size_t err_len)
{
    const char *path = getenv(var);
    *found = path != NULL && path[0] != '\0';
    if (!*found)
        return LINK_KEY_OK;
    if (!link_auth_init()) {
        snprintf(err, err_len, "%s: libsodium cannot start", var);
        return LINK_KEY_ERR_OPEN;
    }
    return link_key_load(path, key, err, err_len);
}

link_key_err_t link_key_create(const char *path, char *err, size_t err_len)
{
    if (!link_auth_init()) {
        snprintf(err, err_len, "%s: libsodium cannot start", path);
        return LINK_KEY_ERR_WRITE;
    }
    const int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) {
        const bool exists = errno == EEXIST;
        snprintf(err, err_len, "%s: %s%s", path, strerror(errno),
                 exists ? " (a key file is never overwritten: remove it first, then give the "
                          "new key to the board and every host)" : "");
        return exists ? LINK_KEY_ERR_EXISTS : LINK_KEY_ERR_WRITE;
    }
    uint8_t k[LINK_KEY_BYTES];
    randombytes_buf(k, sizeof(k));
    static const char head[] = "# argil link key (docs/link.md): the board's and the host's copy "
                               "must match; keep it mode 0600\n";
    char text[sizeof(head) + 2u * LINK_KEY_BYTES + 2u];
    memcpy(text, head, sizeof(head) - 1u);
    sodium_bin2hex(text + sizeof(head) - 1u, 2u * LINK_KEY_BYTES + 1u, k, sizeof(k));
    size_t n = sizeof(head) - 1u + 2u * LINK_KEY_BYTES;
    text[n++] = '\n';
    sodium_memzero(k, sizeof(k));
    const bool ok = fchmod(fd, 0600) == 0 && write(fd, text, n) == (ssize_t)n && fsync(fd) == 0;
    const int e = errno;
    sodium_memzero(text, sizeof(text));
    if (close(fd) != 0 || !ok) {
        snprintf(err, err_len, "%s: cannot write: %s", path, strerror(ok ? errno : e));
        unlink(path);
        return LINK_KEY_ERR_WRITE;
    }
    return LINK_KEY_OK;
}

const char *link_key_err_text(link_key_err_t e)
{
    switch (e) {
    case LINK_KEY_OK: return "ok";
    case LINK_KEY_ERR_NO_KEY: return "no key line";
    case LINK_KEY_ERR_HEX: return "a character that is not a hex digit";
    case LINK_KEY_ERR_SHORT: return "fewer than 64 hex digits (truncated)";
    case LINK_KEY_ERR_LONG: return "more than 64 hex digits";
    case LINK_KEY_ERR_EXTRA: return "a second key line";
    case LINK_KEY_ERR_OPEN: return "cannot be read";
    case LINK_KEY_ERR_NOT_FILE: return "not a regular file";
    case LINK_KEY_ERR_MODE: return "readable or writable by group or others";
    case LINK_KEY_ERR_BIG: return "too large";
    case LINK_KEY_ERR_EXISTS: return "exists already";
    case LINK_KEY_ERR_WRITE: return "cannot be written";
    }
    return "?";
}
