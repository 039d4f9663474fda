/* libFuzzer target for the ply_load reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>
#include <stdbool.h>

#include "host/io/mesh_import.h"
#include "tests/fuzz/fuzz_file.h"
#include "tests/fuzz/fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, "ply_load", path)) {
        char err[512];
        err[0] = '\0';
        mesh_t m;
        mesh_init(&m);
        bool nrm = false;
        const argil_err_t e = ply_load(path, &m, &nrm, err, sizeof(err));
        if (e == ARGIL_OK) {
            fuzz_check_mesh(&m);
        } else if (!fuzz_error_names_file(err, path)) {
            abort(); /* every error is one line naming the file */
        }
        (void)nrm;
        mesh_free(&m);
    }
    unlink(path);
    return 0;
}
