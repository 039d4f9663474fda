/* libFuzzer target for the PLY reader: the input bytes become a file that ply_read_mesh parses. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/ply.h"
#include "host/mesh/mesh_check.h"
#include "tests/fuzz/fuzz_file.h"
#include "tests/fuzz/fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, "ply", path)) {
        mesh_t m;
        mesh_init(&m);
        char err[256];
        err[0] = '\0';
        const ply_err_t e = ply_read_mesh(path, &m, err, sizeof(err));
        if (e == PLY_OK) {
            /* Whatever was accepted must be a consistent mesh. */
            fuzz_check_mesh(&m);
            (void)mesh_volume_m3(&m);
        } else if (!fuzz_error_names_file(err, path)) {
            abort(); /* every error names the file */
        }
        mesh_free(&m);
    }
    unlink(path);
    return 0;
}
