/* The board's link key file (link_key.h): the system calls; the rules are link_key_text.c's. */
#define _POSIX_C_SOURCE 200809L
#include "link_key.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

link_key_err_t link_key_load(const char *path, link_key_t *key, char *err, size_t err_len)
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
    link_auth_wipe(text, sizeof(text));
    return rc;
}
