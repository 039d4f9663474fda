/* Shared by the mesh-reader fuzz targets: what any accepted mesh must satisfy. */
#ifndef ARGIL_FUZZ_MESH_H
#define ARGIL_FUZZ_MESH_H

#include <math.h>
#include <stdlib.h>

#include "host/mesh/mesh.h"

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

#endif
