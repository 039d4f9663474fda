/* A session's result files: both written whole (no temp file left), no PLY for an empty mesh,
 * and a failure of one file neither stops the other nor goes unsaid. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/app/session_files.h"
#include "host/io/argil_file.h"
#include "host/io/ply.h"
#include "host/mesh/grid_mesh.h"

typedef struct {
    char dir[64];
    char ply[128], model[128];
    grid_t g;
    mesh_t mesh;
    argil_doc_t doc;
} files_t;

static int setup(void **state)
{
    files_t *f = calloc(1, sizeof(*f));
    assert_non_null(f);
    snprintf(f->dir, sizeof(f->dir), "/tmp/argil-session-files-XXXXXX");
    assert_non_null(mkdtemp(f->dir));
    snprintf(f->ply, sizeof(f->ply), "%s/final.ply", f->dir);
    snprintf(f->model, sizeof(f->model), "%s/model.argil", f->dir);
    const int32_t dims[3] = {24, 24, 24};
    assert_int_equal(grid_init(&f->g, dims, 0.002f, vec3(0, 0, 0)), ARGIL_OK);
    grid_fill_sphere(&f->g, vec3(0.024f, 0.024f, 0.024f), 0.015f);
    mesh_init(&f->mesh);
    assert_int_equal(grid_mesh_extract(&f->g, f->g.iso, &f->mesh), ARGIL_OK);
    assert_true(f->mesh.n_tri > 100);
    argil_doc_init(&f->doc);
    f->doc.grid = f->g; /* borrowed */
    f->doc.state.edits = 7;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    files_t *f = *state;
    unlink(f->ply);
    unlink(f->model);
    rmdir(f->dir);
    mesh_free(&f->mesh);
    grid_free(&f->g);
    free(f);
    return 0;
}

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void test_writes_both_whole(void **state)
{
    files_t *f = *state;
    char err[1024] = "";
    assert_int_equal(session_files_write(f->ply, &f->mesh, f->model, &f->doc, err, sizeof(err)),
                     ARGIL_OK);
    mesh_t back;
    mesh_init(&back);
    assert_int_equal(ply_read_mesh(f->ply, &back, err, sizeof(err)), PLY_OK);
    assert_int_equal(back.n_tri, f->mesh.n_tri);
    mesh_free(&back);
    argil_doc_t doc;
    assert_int_equal(argil_file_read(f->model, &doc, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(doc.state.edits, 7);
    assert_int_equal(grid_count(&doc.grid), grid_count(&f->g));
    argil_doc_free(&doc);
    char tmp[160];
    snprintf(tmp, sizeof(tmp), "%s.tmp", f->ply);
    assert_false(exists(tmp));
    snprintf(tmp, sizeof(tmp), "%s.tmp", f->model);
    assert_false(exists(tmp));
}

static void test_empty_mesh_writes_no_ply(void **state)
{
    files_t *f = *state;
    mesh_t empty;
    mesh_init(&empty);
    char err[1024] = "";
    assert_int_equal(session_files_write(f->ply, &empty, f->model, &f->doc, err, sizeof(err)),
                     ARGIL_OK);
    assert_false(exists(f->ply));
    assert_true(exists(f->model));
}

static void test_one_failure_keeps_the_other(void **state)
{
    files_t *f = *state;
    char err[1024] = "", bad[160];
    snprintf(bad, sizeof(bad), "%s/no-such-dir/final.ply", f->dir);
    assert_int_equal(session_files_write(bad, &f->mesh, f->model, &f->doc, err, sizeof(err)),
                     ARGIL_ERR_IO);
    assert_non_null(strstr(err, "no-such-dir/final.ply"));
    assert_true(exists(f->model)); /* the model is written all the same */
    snprintf(bad, sizeof(bad), "%s/no-such-dir/model.argil", f->dir);
    err[0] = '\0';
    assert_int_equal(session_files_write(f->ply, &f->mesh, bad, &f->doc, err, sizeof(err)),
                     ARGIL_ERR_IO);
    assert_non_null(strstr(err, "no-such-dir/model.argil"));
    assert_true(exists(f->ply));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_writes_both_whole, setup, teardown),
        cmocka_unit_test_setup_teardown(test_empty_mesh_writes_no_ply, setup, teardown),
        cmocka_unit_test_setup_teardown(test_one_failure_keeps_the_other, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
