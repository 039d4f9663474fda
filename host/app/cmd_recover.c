/* argil recover: rebuilds the model of an unfinished session from its autosave journal; and the
 * offer to do so when a new session starts in a directory that still holds one. */
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "host/app/cli_opts.h"
#include "host/app/commands.h"
#include "host/app/session_files.h"
#include "host/io/argil_file.h"
#include "host/io/journal.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc.h"
#include "host/mesh/mesh.h"

/* The text of `argil recover --help`. */
static void usage_recover(FILE *f)
{
    fprintf(f,
            "usage: argil recover DIR [-o FILE.argil] [--keep-journal]\n"
            "\n"
            "Rebuilds the model of a session that did not end cleanly (a crash, kill -9, power\n"
            "loss) from the autosave journal in DIR (DIR/" JOURNAL_FILE " on its base snapshot\n"
            "DIR/" JOURNAL_BASE_PREFIX "N.argil), exactly as of the last whole journal record, and\n"
            "writes it as a model and a PLY mesh (with the painted colour as vertex colours).\n"
            "A record cut short by the crash is ignored.\n"
            "\n"
            "options:\n"
            "  -o FILE.argil   where to write the model (default DIR/recovered.argil); the mesh\n"
            "                  goes beside it with the extension .ply\n"
            "  --keep-journal  keep the journal afterwards (by default it is removed once the\n"
            "                  model is written, so the next session starts fresh)\n"
            "  -h, --help      this text\n"
            "\n"
            "Exit status: 0 recovered; 1 nothing recovered, or the journal was damaged before its\n"
            "end (the model is still written as of the last good record, and the journal kept).\n");
}

/* The line that says dir holds an unfinished session and how to restore it. */
static void describe(const char *dir, const journal_info_t *info, FILE *f)
{
    fprintf(f, "argil: found an unfinished session in %s (%u edits, last at %.3f s); run "
               "'argil recover %s' to restore it, or --discard-journal\n",
            dir, info->records, info->last_sim_s, dir);
}

argil_err_t recover_offer(const char *dir, bool discard, bool interactive, bool *go_on,
                          int *exit_status)
{
    *go_on = false;
    if (dir == NULL || !journal_exists(dir)) {
        *go_on = true;
        return ARGIL_OK;
    }
    char err[1024];
    if (discard) {
        const argil_err_t de = journal_discard(dir, err, sizeof(err));
        if (de != ARGIL_OK) {
            fprintf(stderr, "argil sculpt: %s\n", err);
            return cmd_end(exit_status, 1, de);
        }
        fprintf(stderr, "argil: discarded the unfinished session's journal in %s\n", dir);
        *go_on = true;
        return ARGIL_OK;
    }
    journal_info_t info;
    const argil_err_t e = journal_err_argil(journal_probe(dir, &info, err, sizeof(err)));
    if (e != ARGIL_OK && e != ARGIL_ERR_PARSE) {
        fprintf(stderr, "argil sculpt: %s holds a journal that cannot be read (%s); run 'argil "
                        "recover %s' or --discard-journal\n",
                dir, err, dir);
        return cmd_end(exit_status, 1, e);
    }
    describe(dir, &info, stderr);
    if (!interactive)
        return cmd_end(exit_status, 1, ARGIL_ERR_STATE);
    fprintf(stderr, "argil: recover it now [r], discard it and start a new session [d], or quit "
                    "[q]? ");
    char line[64];
    if (fgets(line, sizeof(line), stdin) == NULL)
        return cmd_end(exit_status, 1, ARGIL_ERR_STATE);
    if (line[0] == 'r' || line[0] == 'R') {
        char *argv[] = {(char *)dir};
        return cmd_recover(1, argv, exit_status);
    }
    if (line[0] == 'd' || line[0] == 'D')
        return recover_offer(dir, true, false, go_on, exit_status);
    return cmd_end(exit_status, 1, ARGIL_OK);
}

/* A copy of src with its .argil extension (if any) replaced by ext. */
static char *with_ext(const char *src, const char *ext)
{
    size_t len = strlen(src);
    if (len >= 6 && strcmp(src + len - 6, ".argil") == 0)
        len -= 6;
    char *p = malloc(len + strlen(ext) + 1);
    if (p == NULL)
        return NULL;
    memcpy(p, src, len);
    strcpy(p + len, ext);
    return p;
}

/* A second directory on the command line. */
static void second_dir(const char *first, const char *a)
{
    (void)first;
    (void)a;
    fprintf(stderr, "argil recover: one directory only (see --help)\n");
}

/* What argil recover's command line asks for. */
typedef struct {
    const char *dir, *out;          /* the session's directory; -o (NULL: DIR/recovered.argil) */
    bool keep;                      /* --keep-journal */
} recover_opts_t;

/* argil recover's command line (cli_parse). */
static const cli_flag_t RECOVER_FLAGS[] = {{"--keep-journal", offsetof(recover_opts_t, keep), true}};
static const cli_cmd_t RECOVER_CLI = {
    .name = "recover", .usage = usage_recover,
    .flags = RECOVER_FLAGS, .n_flags = 1, .second_input = second_dir,
    .out_needs = "a file name", .out = offsetof(recover_opts_t, out),
    .inputs = true, .input = offsetof(recover_opts_t, dir),
};

/* argil recover DIR: the model of DIR's unfinished session, from its journal. */
argil_err_t cmd_recover(int argc, char **argv, int *exit_status)
{
    recover_opts_t ro = {NULL, NULL, false};
    bool done;
    const argil_err_t pe = cli_parse(&RECOVER_CLI, &ro, argc, argv, &done, exit_status);
    if (done)
        return pe;
    const char *dir = ro.dir, *out = ro.out;
    const bool keep = ro.keep;
    if (dir == NULL) {
        usage_recover(stderr);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    char err[1024] = "", werr[1024] = "";
    if (!journal_exists(dir)) {
        fprintf(stderr, "argil recover: %s holds no journal (%s): nothing to recover\n", dir,
                JOURNAL_FILE);
        return cmd_end(exit_status, 1, ARGIL_ERR_EMPTY);
    }
    char *model_path = NULL, *ply_path = NULL;
    if (out == NULL) {
        model_path = malloc(strlen(dir) + 32);
        if (model_path != NULL)
            sprintf(model_path, "%s/recovered.argil", dir);
    } else {
        model_path = strdup(out);
    }
    ply_path = model_path ? with_ext(model_path, ".ply") : NULL;
    if (model_path == NULL || ply_path == NULL) {
        fprintf(stderr, "argil recover: out of memory\n");
        free(model_path);
        free(ply_path);
        return cmd_end(exit_status, 1, ARGIL_ERR_NOMEM);
    }
    argil_doc_t doc;
    journal_info_t info;
    const argil_err_t e = journal_err_argil(journal_recover(dir, &doc, &info, err, sizeof(err)));
    argil_err_t status = ARGIL_OK; /* the error the command ends with */
    if (grid_count(&doc.grid) == 0) {
        fprintf(stderr, "argil recover: %s\n", err);
        status = e != ARGIL_OK ? e : ARGIL_ERR_EMPTY;
        goto out;
    }
    mesh_t mesh;
    mesh_init(&mesh);
    const grid_t *g = &doc.grid;
    /* The painted colour (doc.rgb, over the grid's box as COLR) as vertex colours. */
    const argil_err_t me = doc.rgb != NULL ? grid_mesh_region(g, doc.rgb, g->iso, &mesh)
                                           : grid_mesh_extract(g, g->iso, &mesh);
    if (me != ARGIL_OK)
        mesh_clear(&mesh); /* the model is written all the same */
    const argil_err_t we =
        session_files_write(ply_path, &mesh, model_path, &doc, werr, sizeof(werr));
    const size_t tris = mesh.n_tri;
    mesh_free(&mesh);
    if (we != ARGIL_OK || me != ARGIL_OK) {
        fprintf(stderr, "argil recover: %s\n", we != ARGIL_OK ? werr : "meshing the model failed");
        status = we != ARGIL_OK ? we : me;
        goto out;
    }
    const time_t wall = (time_t)(info.last_wall_ms / 1000u);
    char when[64] = "never";
    struct tm tmv;
    if (info.records > 0 && gmtime_r(&wall, &tmv) != NULL)
        strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S UTC", &tmv);
    printf("argil: recovered the session in %s\n", dir);
    printf("  base snapshot       %s/%s (checkpoint %u)\n", dir, info.base_name, info.checkpoint);
    printf("  journal records     %u (numbers %u..%u), %llu samples replayed\n", info.records,
           info.first_seq, info.last_seq, (unsigned long long)info.samples);
    printf("  painted material    %llu values replayed; %s\n",
           (unsigned long long)info.mat_samples,
           grid_mat_painted(&doc.grid, GRID_MAT_STIFFNESS) ||
                   grid_mat_painted(&doc.grid, GRID_MAT_MASS) ||
                   grid_mat_painted(&doc.grid, GRID_MAT_DAMPING) ||
                   grid_mat_painted(&doc.grid, GRID_MAT_RESTLEN)
               ? "the model holds painted channels"
               : "the model holds none");
    printf("  painted colour      %llu samples replayed; %s\n",
           (unsigned long long)info.rgb_samples,
           doc.rgb != NULL ? "the model holds painted colour" : "the model holds none");
    printf("  model as of         edit %u, %.3f s into the session\n", info.edits,
           info.last_sim_s);
    printf("  last record written %s (unix ms %llu)\n", when,
           (unsigned long long)info.last_wall_ms);
    if (info.torn_bytes > 0)
        printf("  ignored             an incomplete last record (%zu bytes, cut short by the "
               "crash)\n",
               info.torn_bytes);
    printf("  wrote               %s, %s (%zu triangles)\n", model_path, ply_path, tris);
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil recover: %s; the model above is as of the record before it, and "
                        "the journal is kept\n",
                err);
        status = e;
    } else if (!keep && (status = journal_discard(dir, err, sizeof(err))) != ARGIL_OK) {
        fprintf(stderr, "argil recover: %s\n", err);
    }
out:
    argil_doc_free(&doc);
    free(model_path);
    free(ply_path);
    return cmd_end(exit_status, status == ARGIL_OK ? 0 : 1, status);
}
