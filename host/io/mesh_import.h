/* Importers for meshes and point clouds: PLY (ASCII, binary little/big-endian, any property
 * types, extra elements skipped), STL (binary and ASCII; coincident corners welded), OBJ, and XYZ
 * text (x y z or x y z nx ny nz per line). A point cloud is a mesh_t with no triangles.
 * Every error is one line: "<path>: line N: ..." or "<path>: byte N: ..." plus the rule broken;
 * declared counts are checked against the file's real size before anything is allocated. */
#ifndef ARGIL_MESH_IMPORT_H
#define ARGIL_MESH_IMPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

#define IMPORT_LINE_MAX 1024 /* longest text line the text readers take */

/* What an import reader returns: IMPORT_OK, a failure outside the file (argument, system call,
 * memory), or the rule the file broke. One enum for all four formats: they share the line,
 * number, count and index rules; a rule only one format has carries its name. */
typedef enum {
    IMPORT_OK = 0,
    IMPORT_ERR_ARG = -1,           /* no path or no mesh, or an extension not read here */
    IMPORT_ERR_IO = -2,            /* a file cannot be opened or read, or is not a regular file */
    IMPORT_ERR_NOMEM = -3,         /* an allocation failed, or the mesh holds no more */
    IMPORT_ERR_FILE_SIZE = -4,     /* a file larger than IO_FILE_MAX_BYTES */
    IMPORT_ERR_LINE_LONG = -5,     /* a text line longer than 1023 bytes */
    IMPORT_ERR_LINE_NUL = -6,      /* a text line holds a NUL byte */
    IMPORT_ERR_NUMBER = -7,        /* a value is not a number, not finite, or overflows a float */
    IMPORT_ERR_TRUNCATED = -8,     /* the file ends inside a record, or before endsolid */
    IMPORT_ERR_FACE_SIZE = -9,     /* a face has fewer than 3 corners (OBJ: or more than 64) */
    IMPORT_ERR_INDEX = -10,        /* a face names a vertex (or normal) that does not exist */
    IMPORT_ERR_PLY_MAGIC = -11,    /* line 1 is not 'ply' */
    IMPORT_ERR_PLY_FORMAT = -12,   /* line 2 is not 'format ascii|binary_little_endian|
                                    * binary_big_endian 1.0' */
    IMPORT_ERR_PLY_HEADER_END = -13, /* no end_header before the file ends or by line 512 */
    IMPORT_ERR_PLY_ELEMENT = -14,  /* not 'element <name> <count>' with a whole count up to 2^40 */
    IMPORT_ERR_PLY_LIMIT = -15,    /* more than 16 elements, or more than 32 properties in one */
    IMPORT_ERR_PLY_PROPERTY = -16, /* a property before any element, malformed, or of a type
                                    * that is unknown or unusable (a float list count) */
    IMPORT_ERR_PLY_KEYWORD = -17,  /* a header line starts with an unknown keyword */
    IMPORT_ERR_PLY_COUNTS = -18,   /* element counts declare more records than the bytes after the
                                    * header hold */
    IMPORT_ERR_PLY_NO_VERTEX = -19, /* no 'vertex' element with scalar x, y and z */
    IMPORT_ERR_PLY_WHOLE = -20,    /* an integer property holds a fraction (ASCII) */
    IMPORT_ERR_PLY_LIST_LENGTH = -21, /* a list length outside 0..10^6 */
    IMPORT_ERR_PLY_FACE_ORDER = -22, /* the face element comes before the vertex element */
    IMPORT_ERR_PLY_TRAILING = -23, /* bytes after the last element (binary) */
    IMPORT_ERR_STL_SIZE = -24,     /* neither ASCII STL ('solid') nor binary STL whose facet count
                                    * matches the file size */
    IMPORT_ERR_STL_SYNTAX = -25,   /* an ASCII STL line other than the one the grammar expects */
    IMPORT_ERR_OBJ_VERTEX = -26,   /* 'v' is not 3, 4 or 6 finite numbers, or 'vn' not 3 */
    IMPORT_ERR_OBJ_STATEMENT = -27, /* an OBJ statement the reader does not know */
    IMPORT_ERR_XYZ_COLUMNS = -28,  /* a line holds neither 3 nor 6 values, or not as many as the
                                    * first point's line */
    IMPORT_ERR_XYZ_EMPTY = -29     /* no points in the file */
} import_err_t;

/* The argil_err_t a command reports for e: ARG, IO and NOMEM as themselves, every rule of the
 * file (and a file too large) ARGIL_ERR_PARSE. */
argil_err_t import_err_argil(import_err_t e);

/* Checks path and out (err names who when either is NULL), empties out and reads the whole file
 * at path into *data (caller frees) and its length into *len. IMPORT_ERR_ARG, IO, FILE_SIZE or
 * NOMEM with err naming the path. */
import_err_t import_slurp(const char *who, const char *path, mesh_t *out, uint8_t **data,
                          size_t *len, char *err, size_t err_len);

/* Reads any PLY with a vertex element (x y z required; nx ny nz and red green blue optional) and
 * an optional face element (list vertex_indices / vertex_index, polygons fanned into triangles).
 * *has_normals (may be NULL) says whether nx ny nz were present. out is replaced (empty on
 * error). The rule broken, or IMPORT_ERR_IO / NOMEM, with err as above. */
import_err_t ply_load(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Reads binary or ASCII STL; corners with bit-identical positions become one vertex; vertex
 * normals are the normalised sum of their facets' normals. */
import_err_t stl_read(const char *path, mesh_t *out, char *err, size_t err_len);

/* Reads OBJ: v (x y z, optionally r g b), vn, f (v, v/t, v//n, v/t/n, negative = relative),
 * polygons fanned; vt, o, g, s, usemtl, mtllib, l, # ignored; anything else is an error. */
import_err_t obj_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Reads XYZ text: each non-blank line not starting with '#' holds 3 or 6 numbers, the same
 * count on every line (6 = with normals). */
import_err_t xyz_read(const char *path, mesh_t *out, bool *has_normals, char *err, size_t err_len);

/* Dispatches on the extension: .ply, .stl, .obj, .xyz / .txt / .pts. IMPORT_ERR_ARG with err
 * for any other extension. */
import_err_t mesh_import(const char *path, mesh_t *out, bool *has_normals, char *err,
                         size_t err_len);

#endif
