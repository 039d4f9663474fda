/* Binary PLY export, with vertex colours when the mesh has them (and a reader for exactly that
 * layout, for round-trip tests and fuzzing). */
#ifndef ARGIL_PLY_H
#define ARGIL_PLY_H

#include <stddef.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

#define PLY_HEADER_MAX_BYTES 4096 /* the reader gives up on longer headers */
#define PLY_LINE_MAX 256          /* ... and on longer header lines */

/* Writes m as binary_little_endian 1.0 PLY (vertex: float x y z nx ny nz, then uchar red green
 * blue when m has colours; face: list uchar int vertex_indices) atomically: path.tmp is written,
 * flushed, fsync'ed and renamed over path, so path holds the old file or the whole new one. The
 * bytes are mesh_export's EXPORT_PLY_BINARY (argil mesh): a mesh without colours gives exactly
 * the file it always did. ARGIL_ERR_ARG / ARGIL_ERR_NONFINITE for a mesh that cannot be written
 * (bad index, NaN, more than 2^31 vertices), ARGIL_ERR_IO with err (may be NULL) naming the path
 * and the failing call. */
argil_err_t ply_write(const char *path, const mesh_t *m, char *err, size_t err_len);

/* Reads a file in exactly ply_write's layout (comment lines allowed in the header; the vertex
 * colour optional, and out has colours exactly when the file does) into out (emptied first,
 * empty again on error). Only triangles, finite values and in-range indices are
 * accepted; declared counts are checked against the file size before anything is allocated.
 * ARGIL_ERR_PARSE with err naming the path and the header line or byte offset,
 * ARGIL_ERR_IO / ARGIL_ERR_NOMEM. */
argil_err_t ply_read_mesh(const char *path, mesh_t *out, char *err, size_t err_len);

#endif
