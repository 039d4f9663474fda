/* libFuzzer target for the nrrd reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>

#include "host/io/volume.h"
#include "tests/fuzz/fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, "nrrd", path)) {
        char err[512];
        err[0] = '\0';
        volume_t v;
        const volume_err_t e = volume_read_nrrd(path, &v, err, sizeof(err));
        if (e == VOLUME_OK) {
            const size_t n = (size_t)v.dims[0] * (size_t)v.dims[1] * (size_t)v.dims[2];
            for (size_t i = 0; i < n; i++)
                if (!isfinite(v.value[i]))
                    abort();
            volume_free(&v);
        } else if (!fuzz_error_names_file(err, path) || v.value != NULL) {
            abort();
        }
    }
    unlink(path);
    return 0;
}
