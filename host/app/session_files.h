/* What a session leaves on disk (argil sculpt, argil connect, argil recover): the final surface
 * as binary PLY and the model as .argil (docs/files.md). */
#ifndef ARGIL_SESSION_FILES_H
#define ARGIL_SESSION_FILES_H

#include <stddef.h>

#include "host/io/argil_file.h"
#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

/* Writes mesh to ply_path (no file when it has no triangles) and doc to model_path, each
 * atomically: a temp file, fsync'ed and renamed over the old one, so each path holds its old
 * file or the whole new one. The model is written even when the mesh fails. ARGIL_OK, or the
 * first failure's code with each failure's message (naming the file and the call) in err. */
argil_err_t session_files_write(const char *ply_path, const mesh_t *mesh, const char *model_path,
                                const argil_doc_t *doc, char *err, size_t err_len);

#endif
