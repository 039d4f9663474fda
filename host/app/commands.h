/* The argil subcommands: each takes the arguments after its name, returns ARGIL_OK or the error
 * it ran into (ARGIL_ERR_ARG for a usage error) and sets *exit_status to the process's exit
 * status (0 success, 1 the work failed, 2 a usage error, 130 interrupted). A session stopped by
 * Ctrl-C that wrote its files, or a check that finds its goal unmet (plot --chatter), is no
 * error: ARGIL_OK with its status. */
#ifndef ARGIL_COMMANDS_H
#define ARGIL_COMMANDS_H

#include <stdbool.h>
#include <stddef.h>

#include "host/io/volume.h"
#include "host/mesh/mesh.h"
#include "shared/argil_err.h"

argil_err_t cmd_sculpt(int argc, char **argv, int *exit_status);
argil_err_t cmd_mesh(int argc, char **argv, int *exit_status);
argil_err_t cmd_info(int argc, char **argv, int *exit_status);
argil_err_t cmd_fit(int argc, char **argv, int *exit_status);
argil_err_t cmd_view(int argc, char **argv, int *exit_status);
argil_err_t cmd_plot(int argc, char **argv, int *exit_status);
argil_err_t cmd_connect(int argc, char **argv, int *exit_status);
argil_err_t cmd_recover(int argc, char **argv, int *exit_status);
argil_err_t cmd_keygen(int argc, char **argv, int *exit_status);

/* Before a session writes into dir: when dir holds an unfinished session's journal, says so in
 * one line and (interactive only) asks whether to recover, discard or quit; discard removes it.
 * Sets *go_on when the session may start; otherwise *exit_status is the status to end with.
 * Returns the error met (ARGIL_OK also when the person chose to quit or recovered). */
argil_err_t recover_offer(const char *dir, bool discard, bool interactive, bool *go_on,
                          int *exit_status);

/* What argil fit and argil info both read. A mesh or point cloud from path into m (its normals:
 * *normals) and the box lo..hi around its vertices; when it cannot be read, one line into err
 * and nothing left to free. */
argil_err_t cmd_read_mesh(const char *path, mesh_t *m, bool *normals, float lo[3], float hi[3],
                          char *err, size_t err_len);

/* The smallest and largest of a volume's values. */
void cmd_volume_range(const volume_t *v, float *lo, float *hi);

/* Sets *exit_status to status and returns err: how a command ends. */
static inline argil_err_t cmd_end(int *exit_status, int status, argil_err_t err)
{
    *exit_status = status;
    return err;
}

#endif
