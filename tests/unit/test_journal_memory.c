/* The autosave journal's memory follows the clay's surface, not its box: a sphere of radius
 * 30 mm in a 176^3 box costs the journal a small part of a dense copy, an edit in a far corner
 * adds only the blocks it touched, and the records replay bit for bit. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/journal.h"

#include "tests/unit/test_files.h"

#define EDGE 176                          /* samples per axis of the box */
#define SPACING_M 0.0005f                 /* 0.5 mm: the sphere spans 120 samples */
#define RADIUS_M 0.030f
#define CORNER 10                         /* the corner edit: a CORNER^3 cube from sample 0 */

static int setup_dir(void **state)
{
    (void)state;
    return test_dir_make("argil_test_journal_memory");
}

/* Densities of g over [lo, lo + n), newly allocated. */
static float *dense(const grid_t *g, const int32_t lo[3], const int32_t n[3])
{
    float *d = malloc((size_t)n[0] * (size_t)n[1] * (size_t)n[2] * sizeof(float));
    assert_non_null(d);
    grid_read_box(g, GRID_DENSITY, lo, n, d);
    return d;
}

static void test_sphere_in_a_large_box(void **state)
{
    (void)state;
    grid_t g;
    const int32_t dims[3] = {EDGE, EDGE, EDGE};
    const float half_m = 0.5f * SPACING_M * (float)(EDGE - 1);
    assert_int_equal(grid_init(&g, dims, SPACING_M, vec3(-half_m, -half_m, -half_m)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0.0f, 0.0f, 0.0f), RADIUS_M);
    journal_cfg_t cfg;
    journal_cfg_default(&cfg);
    journal_t j;
    char err[512] = "";
    assert_int_equal(journal_open(&j, g_test_dir, &g, &cfg, 0.0, 0.0, err, sizeof(err)), ARGIL_OK);

    /* A dense copy of the box would be 176^3 floats, 21.8 MB (the journal used to hold two). */
    const size_t dense_bytes = (size_t)EDGE * EDGE * EDGE * sizeof(float);
    const size_t held = journal_bytes(&j);
    printf("journal memory %.1f KiB for a 30 mm sphere in a 176^3 box (dense copy %.1f KiB, "
           "grid %.1f KiB)\n", (double)held / 1024.0, (double)dense_bytes / 1024.0,
           (double)grid_bytes(&g) / 1024.0);
    assert_true(held < dense_bytes / 4);
    /* Densities only, of the blocks that hold more than one value: under a third of the grid,
     * which holds four channels per such block. */
    assert_true(held < grid_bytes(&g) / 3);

    /* An edit in the far corner (empty clay, blocks the grid never held), across the block
     * boundary at 8 on every axis: 2 x 2 x 2 blocks. */
    uint32_t bits = 0x3c000001u; /* 0.0078 .. 0.012 */
    for (int32_t z = 0; z < CORNER; z++)
        for (int32_t y = 0; y < CORNER; y++)
            for (int32_t x = 0; x < CORNER; x++) {
                float v;
                bits += 0x00001234u;
                memcpy(&v, &bits, sizeof(v)); /* odd bit patterns below 1 */
                assert_int_equal(grid_set(&g, GRID_DENSITY, x, y, z, v), ARGIL_OK);
            }
    const size_t arrays0 = j.shadow.arrays_bytes;
    bool appended = false;
    const journal_box_t box = {{0, 0, 0}, {CORNER, CORNER, CORNER}};
    assert_int_equal(journal_record(&j, &g, &box, 1, 0.01, 0.0, 0, &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_int_equal(j.stats.records, 1);
    assert_int_equal(j.stats.samples, CORNER * CORNER * CORNER);
    assert_int_equal(j.shadow.arrays_bytes - arrays0, 8 * GRID_BN * sizeof(float));
    /* The whole box compared again: nothing else changed, so no record. */
    assert_int_equal(journal_record(&j, &g, NULL, 1, 0.02, 0.0, 0, &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_false(appended);
    /* A carve through the sphere's surface, found by the whole-box comparison. */
    int32_t clo[3], chi[3];
    grid_carve_sphere(&g, vec3(RADIUS_M, 0.0f, 0.0f), 0.004f, clo, chi);
    assert_true(chi[0] > clo[0]);
    assert_int_equal(journal_record(&j, &g, NULL, 2, 0.03, 0.0, 0, &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_true(journal_bytes(&j) < dense_bytes / 4);
    assert_int_equal(journal_sync(&j, err, sizeof(err)), ARGIL_OK);

    /* Recovery: the base and the two records give the grid as it is, bit for bit. */
    argil_doc_t doc;
    journal_info_t info;
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 2);
    assert_int_equal(info.samples, j.stats.samples);
    const int32_t zero[3] = {0, 0, 0};
    float *want = dense(&g, zero, dims), *got = dense(&doc.grid, zero, dims);
    size_t differ = 0;
    for (size_t i = 0; i < (size_t)EDGE * EDGE * EDGE; i++)
        differ += memcmp(&want[i], &got[i], sizeof(float)) != 0;
    assert_int_equal(differ, 0);
    free(want);
    free(got);
    argil_doc_free(&doc);
    journal_close(&j);
    grid_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_sphere_in_a_large_box, setup_dir, test_dir_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
