/* Shared by the mesh-reader fuzz targets: what any accepted mesh must satisfy. */
#ifndef ARGIL_FUZZ_MESH_H
#define ARGIL_FUZZ_MESH_H

#include <math.h>
#include <stdlib.h>

#include <stdint.h>
#include <unistd.h>

#include "host/io/mesh_import.h"
#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "tests/fuzz/fuzz_file.h"

/* Aborts (a fuzzer finding) unless every triangle names existing vertices and every position
 * is finite. */
static inline void fuzz_check_mesh(const mesh_t *m)
{
    for (size_t i = 0; i < 3 * m->n_tri; i++)
        if (m->tri[i] >= m->n_vert)
            abort();
    for (size_t i = 0; i < 3 * m->n_vert; i++)
        if (!isfinite(m->pos[i]))
            abort();
}

/* A mesh reader with the shape every importer shares (normals flag dropped where it has one). */
typedef import_err_t (*fuzz_mesh_reader_fn)(const char *path, mesh_t *m, char *err, size_t err_len);

/* The whole body of a mesh-reader target: the input bytes become a temporary file with the
 * given extension; an accepted mesh must pass fuzz_check_mesh, and any error must be one line
 * naming the file. */
static inline int fuzz_mesh_reader(const uint8_t *data, size_t size, const char *ext,
                                   fuzz_mesh_reader_fn read)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, ext, path)) {
        char err[512];
        err[0] = '\0';
        mesh_t m;
        mesh_init(&m);
        const import_err_t e = read(path, &m, err, sizeof(err));
        if (e == IMPORT_OK)
            fuzz_check_mesh(&m);
        else if (!fuzz_error_names_file(err, path))
            abort(); /* every error is one line naming the file */
        mesh_free(&m);
    }
    unlink(path);
    return 0;
}

#endif
