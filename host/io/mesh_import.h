/* Importers for meshes and point clouds: PLY (ASCII, binary little/big-endian, any property
 * types, extra elements skipped), STL (binary and ASCII; coincident corners welded), OBJ, and XYZ
 * text (x y z or x y z nx ny nz per line). A point cloud is a mesh_t with no triangles.
 * Every error is one line: "<path>: line N: ..." or "<path>: byte N: ..." plus the rule broken;
 * declared counts are checked against the file's real size before anything is allocated. */
#ifndef ARGIL_MESH_IMPORT_H
#define ARGIL_MESH_IMPORT_H

#include <stdbool.h>
#include <stddef.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

#define IMPORT_LINE_MAX 1024 /* longest text line the text readers take */

/* Reads any PLY with a vertex element (x y z required; nx ny nz and red green blue optional) and
 * an optional face element (list vertex_indices / vertex_index, polygons fanned into triangles).
 * *has_normals (may be NULL) says whether nx ny nz were present. out is replaced (empty on
 * error). ARGIL_ERR_PARSE / IO / NOMEM with err as above. */
argil_err_t ply_load(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Reads binary or ASCII STL; corners with bit-identical positions become one vertex; vertex
 * normals are the normalised sum of their facets' normals. */
argil_err_t stl_read(const char *path, mesh_t *out, char *err, size_t err_len);

/* Reads OBJ: v (x y z, optionally r g b), vn, f (v, v/t, v//n, v/t/n, negative = relative),
 * polygons fanned; vt, o, g, s, usemtl, mtllib, l, # ignored; anything else is an error. */
argil_err_t obj_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Reads XYZ text: each non-blank line not starting with '#' holds 3 or 6 numbers, the same
 * count on every line (6 = with normals). */
argil_err_t xyz_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Dispatches on the extension: .ply, .stl, .obj, .xyz / .txt / .pts. ARGIL_ERR_ARG with err
 * for any other extension. */
argil_err_t mesh_import(const char *path, mesh_t *out, bool *has_normals, char *err,
                        size_t err_len);

#endif
