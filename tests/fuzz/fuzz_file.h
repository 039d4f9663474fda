/* Shared by the file-reader fuzz targets: the input bytes become a temporary file the reader
 * parses, and a refusal must be one line naming that file. */
#ifndef ARGIL_FUZZ_FILE_H
#define ARGIL_FUZZ_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define FUZZ_PATH_MAX 64

/* The folder for the inputs' files: /dev/shm (memory) where there is one, else /tmp, whose
 * disk made a file per input cost tens of microseconds. */
static inline const char *fuzz_temp_dir(void)
{
    static const char *dir;
    if (dir == NULL)
        dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return dir;
}

/* Writes data to a new file <fuzz_temp_dir>/argil_fuzz_<tag>_XXXXXX; false (nothing to unlink)
 * when that failed. */
static inline bool fuzz_write_temp(const uint8_t *data, size_t size, const char *tag,
                                   char path[FUZZ_PATH_MAX])
{
    snprintf(path, FUZZ_PATH_MAX, "%s/argil_fuzz_%s_XXXXXX", fuzz_temp_dir(), tag);
    const int fd = mkstemp(path);
    if (fd < 0)
        return false;
    size_t done = 0;
    while (done < size) {
        const ssize_t n = write(fd, data + done, size - done);
        if (n <= 0)
            break;
        done += (size_t)n;
    }
    close(fd);
    if (done != size) {
        unlink(path);
        return false;
    }
    return true;
}

/* True when err is a non-empty single line that names path. */
static inline bool fuzz_error_names_file(const char *err, const char *path)
{
    return err[0] != '\0' && strstr(err, path) != NULL && strchr(err, '\n') == NULL;
}

#endif
