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

/* What ply_read_mesh returns: PLY_OK, a failure outside the file (argument, system call,
 * memory), or the rule the file broke. */
typedef enum {
    PLY_OK = 0,
    PLY_ERR_ARG = -1,       /* no path or no mesh */
    PLY_ERR_IO = -2,        /* the file cannot be opened, examined or read, or is not regular */
    PLY_ERR_NOMEM = -3,     /* an allocation failed, or the mesh holds no more */
    PLY_ERR_HEADER = -4,    /* a header line other than the one ply_write's layout has there */
    PLY_ERR_COUNT = -5,     /* a vertex or face count that is not a number within its limit */
    PLY_ERR_LINE_END = -6,  /* a header line without an end of line within PLY_HEADER_MAX_BYTES */
    PLY_ERR_LINE_LONG = -7, /* a header line longer than PLY_LINE_MAX - 1 bytes */
    PLY_ERR_LINE_NUL = -8,  /* a header line holds a NUL byte */
    PLY_ERR_SIZE = -9,      /* the declared records do not fill the rest of the file exactly */
    PLY_ERR_TRUNCATED = -10, /* the file ends inside a record */
    PLY_ERR_NONFINITE = -11, /* a vertex value is NaN or infinite */
    PLY_ERR_FACE_SIZE = -12, /* a face that is not a triangle */
    PLY_ERR_INDEX = -13     /* a face names a vertex that does not exist */
} ply_err_t;

/* The argil_err_t a command reports for e: ARG, IO and NOMEM as themselves, every rule of the
 * file ARGIL_ERR_PARSE. */
argil_err_t ply_err_argil(ply_err_t e);

/* Reads a file in exactly ply_write's layout (comment lines allowed in the header; the vertex
 * colour optional, and out has colours exactly when the file does) into out (emptied first,
 * empty again on error). Only triangles, finite values and in-range indices are
 * accepted; declared counts are checked against the file size before anything is allocated.
 * Returns the rule the file broke, with err naming the path and the header line or byte
 * offset, or PLY_ERR_ARG / IO / NOMEM. */
ply_err_t ply_read_mesh(const char *path, mesh_t *out, char *err, size_t err_len);

#endif
