/* libFuzzer target for the xyz reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent (tests/fuzz/fuzz_mesh.h). */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/io/mesh_import.h"
#include "tests/fuzz/fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static import_err_t read_xyz(const char *path, mesh_t *m, char *err, size_t err_len)
{
    bool normals = false;
    return xyz_read(path, m, &normals, err, err_len);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_mesh_reader(data, size, "xyz", read_xyz);
}
