/* libFuzzer target for the raw reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <math.h>

#include "host/io/volume.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/argil_fuzz_raw_XXXXXX";
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
        volume_t v;
        /* the first three bytes choose the dimensions, the fourth the type */
        const int32_t dims[3] = {size > 0 ? 1 + data[0] % 8 : 1, size > 1 ? 1 + data[1] % 8 : 1,
                                 size > 2 ? 1 + data[2] % 8 : 1};
        const vol_type_t t = (vol_type_t)(size > 3 ? data[3] % 8 : 0);
        const argil_err_t e = volume_read_raw(path, dims, t, size > 4 && (data[4] & 1), &v, err,
                                              sizeof(err));
        if (e == ARGIL_OK) {
            const size_t n = (size_t)v.dims[0] * (size_t)v.dims[1] * (size_t)v.dims[2];
            for (size_t i = 0; i < n; i++)
                if (!isfinite(v.value[i]))
                    abort();
            volume_free(&v);
        } else if (err[0] == 0 || strstr(err, path) == NULL) {
            abort();
        }
    }
    unlink(path);
    return 0;
}
