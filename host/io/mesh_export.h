/* Mesh export for third-party tools: PLY (binary or ASCII, with vertex colours when the mesh has
 * them), binary STL and OBJ; every file written atomically (temp file + rename). */
#ifndef ARGIL_MESH_EXPORT_H
#define ARGIL_MESH_EXPORT_H

#include <stddef.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

typedef enum {
    EXPORT_PLY_BINARY,
    EXPORT_PLY_ASCII,
    EXPORT_STL,
    EXPORT_OBJ
} export_format_t;

/* The format named by path's extension (.ply → binary PLY, .stl, .obj, case-insensitive);
 * false for any other extension. */
bool export_format_from_path(const char *path, export_format_t *fmt);

/* Writes m to path in fmt: PLY vertex x y z nx ny nz [red green blue uchar], face list uchar int;
 * STL binary with facet normals from the triangle; OBJ v [r g b in 0..1] / vn / f a//a b//b c//c.
 * ARGIL_ERR_ARG (bad index, more than 2^31 vertices, STL over 2^32 triangles),
 * ARGIL_ERR_NONFINITE, ARGIL_ERR_IO / NOMEM; err names the path and the failing rule or call. */
argil_err_t mesh_export(const char *path, const mesh_t *m, export_format_t fmt, char *err,
                        size_t err_len);

#endif
