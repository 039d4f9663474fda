/* libFuzzer target for the argil reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/argil_file.h"
#include "tests/fuzz/fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, "argil", path)) {
        char err[512];
        err[0] = '\0';
        argil_doc_t d;
        const argil_err_t e = argil_file_read(path, &d, err, sizeof(err));
        if (e == ARGIL_OK) {
            if (d.grid.density == NULL)
                abort();
            argil_doc_free(&d);
        } else if (!fuzz_error_names_file(err, path) || d.grid.density != NULL) {
            abort();
        }
    }
    unlink(path);
    return 0;
}
