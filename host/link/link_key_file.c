/* The host's link key file (link_key_file.h): the system calls and the key's random bytes; the
 * rules and the text are link_key_text.c's. */
#define _POSIX_C_SOURCE 200809L
#include "host/link/link_key_file.h"

#include <errno.h>
#include <fcntl.h>
#include <sodium.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/link/link_crypto.h"

link_key_err_t link_key_file_load(const char *path, link_key_t *key, char *err, size_t err_len)
{
    /* O_NONBLOCK: a FIFO must not hang the caller before fstat says it is no file. */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return link_key_open_failed(path, strerror(errno), true, err, err_len);
    struct stat st;
    link_key_err_t rc =
        fstat(fd, &st) != 0
            ? link_key_open_failed(path, strerror(errno), false, err, err_len)
            : link_key_check_file(path, S_ISREG(st.st_mode), (uint32_t)st.st_mode,
                                  (uint64_t)st.st_size, err, err_len);
    char text[LINK_KEY_FILE_MAX + 1u]; /* one more: a file that grew after fstat is seen */
    size_t n = 0;
    while (rc == LINK_KEY_OK && n < sizeof(text)) {
        const ssize_t r = read(fd, text + n, sizeof(text) - n);
        if (r < 0 && errno != EINTR)
            rc = link_key_open_failed(path, strerror(errno), false, err, err_len);
        else if (r == 0)
            break;
        else if (r > 0)
            n += (size_t)r;
    }
    close(fd);
    if (rc == LINK_KEY_OK)
        rc = link_key_parse_file(path, text, n, key, err, err_len);
    link_crypto_wipe(text, sizeof(text));
    return rc;
}

link_key_err_t link_key_file_load_env(const char *var, link_key_t *key, bool *found, char *err,
                                      size_t err_len)
{
    const char *path = getenv(var);
    *found = path != NULL && path[0] != '\0';
    if (!*found)
        return LINK_KEY_OK;
    if (!link_crypto_init()) {
        snprintf(err, err_len, "%s: libsodium cannot start", var);
        return LINK_KEY_ERR_OPEN;
    }
    return link_key_file_load(path, key, err, err_len);
}

link_key_err_t link_key_file_create(const char *path, char *err, size_t err_len)
{
    if (!link_crypto_init()) {
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
    link_key_t k;
    randombytes_buf(k.k, sizeof(k.k));
    char text[LINK_KEY_TEXT_MAX];
    const size_t n = link_key_format(&k, text, sizeof(text));
    link_crypto_wipe(&k, sizeof(k));
    const bool ok = n > 0 && fchmod(fd, 0600) == 0 && write(fd, text, n) == (ssize_t)n &&
                    fsync(fd) == 0;
    const int e = errno;
    link_crypto_wipe(text, sizeof(text));
    if (close(fd) != 0 || !ok) {
        snprintf(err, err_len, "%s: cannot write: %s", path, strerror(ok ? errno : e));
        unlink(path);
        return LINK_KEY_ERR_WRITE;
    }
    return LINK_KEY_OK;
}
