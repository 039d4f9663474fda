/* The result files of a session, written the one way every command writes them. */
#include "host/app/session_files.h"

#include <stdio.h>

#include "host/io/ply.h"

argil_err_t session_files_write(const char *ply_path, const mesh_t *mesh, const char *model_path,
                                const argil_doc_t *doc, char *err, size_t err_len)
{
    char ply_err[512] = "", model_err[512] = "";
    const argil_err_t pe =
        mesh->n_tri > 0 ? ply_write(ply_path, mesh, ply_err, sizeof(ply_err)) : ARGIL_OK;
    const argil_err_t me = argil_file_write(model_path, doc, model_err, sizeof(model_err));
    if (err != NULL && err_len > 0) {
        if (pe != ARGIL_OK && me != ARGIL_OK)
            snprintf(err, err_len, "%s; %s", ply_err, model_err);
        else if (pe != ARGIL_OK || me != ARGIL_OK)
            snprintf(err, err_len, "%s", pe != ARGIL_OK ? ply_err : model_err);
    }
    return pe != ARGIL_OK ? pe : me;
}
