/* libFuzzer target for the PLY reader: the input bytes become a file that ply_read_mesh parses. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "host/io/ply.h"
#include "host/mesh/mesh_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/argil_fuzz_ply_XXXXXX";
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
        mesh_t m;
        mesh_init(&m);
        char err[256];
        err[0] = '\0';
        const argil_err_t e = ply_read_mesh(path, &m, err, sizeof(err));
        if (e == ARGIL_OK) {
            /* Whatever was accepted must be a consistent mesh. */
            for (size_t i = 0; i < 3 * m.n_tri; i++)
                if (m.tri[i] >= m.n_vert)
                    abort();
            (void)mesh_volume_m3(&m);
        } else if (err[0] == '\0' || strstr(err, path) == NULL) {
            abort(); /* every error names the file */
        }
        mesh_free(&m);
    }
    unlink(path);
    return 0;
}
