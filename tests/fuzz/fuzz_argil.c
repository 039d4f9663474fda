/* libFuzzer target for the argil reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "host/io/argil_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/argil_fuzz_argil_XXXXXX";
    const int fd = mkstemp(path);
    if (fd < 0)
        return 0;
    size_t done = 0;
    while (done < size) {
        const ssize_t n = write(fd, data + done, size - done);
        if (n <= 0)
            break;
        done += (size_t)n;
    }
    close(fd);
    if (done == size) {
        char err[512];
        err[0] = '\0';
        argil_doc_t d;
        const argil_err_t e = argil_file_read(path, &d, err, sizeof(err));
        if (e == ARGIL_OK) {
            if (d.grid.density == NULL)
                abort();
            argil_doc_free(&d);
        } else if (err[0] == 0 || strstr(err, path) == NULL || d.grid.density != NULL) {
            abort();
        }
    }
    unlink(path);
    return 0;
}
