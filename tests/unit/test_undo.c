/* Undo journal on its own: bit-for-bit undo/redo of snapshotted and noted changes, the memory
 * budget dropping the oldest steps first, a new edit clearing redo, state errors. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "host/model/undo.h"

static const int32_t box_lo[3] = {-6, -6, -6}, box_hi[3] = {6, 6, 6};

/* One edit: n coefficients along x at row y set to v (snapshotted), as one step. */
static void edit(undo_t *u, field_t *f, int32_t y, int32_t n, float v)
{
    assert_int_equal(undo_begin(u, f, box_lo, box_hi, 1u << FC_P, box_lo, box_lo, 0), ARGIL_OK);
    for (int32_t x = 0; x < n; x++)
        assert_int_equal(sparse_set(&f->coef, FC_P, x - 6, y, -1, v), ARGIL_OK);
    assert_int_equal(undo_commit(u, f), ARGIL_OK);
}

static float at(const field_t *f, int32_t x, int32_t y)
{
    return sparse_get(&f->coef, FC_P, x - 6, y, -1);
}

static void test_budget_drops_oldest_first(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.01f, 1, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    undo_init(&u, 3 * 10 * sizeof(undo_entry_t)); /* room for three steps of 10 entries */
    for (int32_t k = 0; k < 5; k++)
        edit(&u, &f, k - 2, 10, 0.1f * (float)(k + 1));
    assert_int_equal(u.nsteps, 3);
    assert_true(u.bytes <= u.budget_bytes);
    /* the three newest steps (rows 0, 1, 2) undo; rows -2, -1 keep their edits */
    for (int k = 0; k < 3; k++)
        assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(undo_undo(&u, &f), ARGIL_ERR_EMPTY);
    for (int32_t x = 0; x < 10; x++) {
        assert_true(at(&f, x, -2) == 0.1f);
        assert_true(at(&f, x, -1) == 0.2f);
        assert_true(at(&f, x, 0) == 0.0f && at(&f, x, 1) == 0.0f && at(&f, x, 2) == 0.0f);
    }
    /* a step larger than the whole budget is still kept (the newest always is) */
    edit(&u, &f, 3, 12, 0.7f);
    assert_int_equal(u.nsteps, 1);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_true(at(&f, 11, 3) == 0.0f);
    undo_free(&u);
    field_free(&f);
}

static void test_new_edit_clears_redo(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.01f, 1, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    undo_init(&u, 1u << 20);
    edit(&u, &f, 0, 4, 0.25f);
    edit(&u, &f, 1, 4, 0.5f);
    edit(&u, &f, 2, 4, 0.75f);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(u.nsteps, 3);
    const size_t bytes_before = u.bytes;
    edit(&u, &f, 3, 4, 1.0f);
    assert_int_equal(u.nsteps, 2);
    assert_true(u.bytes == bytes_before - sizeof(undo_entry_t) * 4); /* two dropped, one added */
    assert_int_equal(undo_redo(&u, &f), ARGIL_ERR_EMPTY);
    assert_true(at(&f, 0, 1) == 0.0f && at(&f, 0, 2) == 0.0f && at(&f, 0, 3) == 1.0f);
    /* an edit that changes nothing is no step */
    edit(&u, &f, 3, 4, 1.0f);
    assert_int_equal(u.nsteps, 2);
    undo_free(&u);
    field_free(&f);
}

static void test_noted_and_snapshotted_changes_are_bit_exact(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.01f, 1, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    undo_init(&u, 1u << 20);
    const int32_t p[3] = {-9, 4, -17};
    const float odd = nextafterf(0.3f, 1.0f), tiny = 1e-39f; /* an ulp off, a subnormal */
    assert_int_equal(sparse_set(&f.samp, FS_REST, p[0], p[1], p[2], odd), ARGIL_OK);
    assert_int_equal(undo_note(&u, UNDO_STORE_SAMP, FS_REST, p, odd, tiny), ARGIL_ERR_STATE);
    const int32_t slo[3] = {-1, -1, -1}, shi[3] = {2, 2, 2};
    assert_int_equal(undo_begin(&u, &f, slo, slo, 0, slo, shi, 1u << FS_R), ARGIL_OK);
    assert_int_equal(undo_begin(&u, &f, slo, slo, 0, slo, shi, 1u << FS_R), ARGIL_ERR_STATE);
    assert_int_equal(undo_undo(&u, &f), ARGIL_ERR_STATE);
    assert_int_equal(sparse_set(&f.samp, FS_REST, p[0], p[1], p[2], tiny), ARGIL_OK);
    assert_int_equal(undo_note(&u, UNDO_STORE_SAMP, FS_REST, p, odd, tiny), ARGIL_OK);
    assert_int_equal(sparse_set(&f.samp, FS_R, 1, 0, -1, odd), ARGIL_OK);
    assert_int_equal(undo_commit(&u, &f), ARGIL_OK);
    assert_int_equal(undo_commit(&u, &f), ARGIL_ERR_STATE);
    assert_int_equal(u.nsteps, 1);
    assert_int_equal(u.steps[0].n, 2);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    float v = sparse_get(&f.samp, FS_REST, p[0], p[1], p[2]);
    assert_memory_equal(&v, &odd, sizeof(float));
    assert_true(sparse_get(&f.samp, FS_R, 1, 0, -1) == 0.8f); /* the default colour */
    assert_int_equal(undo_redo(&u, &f), ARGIL_OK);
    v = sparse_get(&f.samp, FS_REST, p[0], p[1], p[2]);
    assert_memory_equal(&v, &tiny, sizeof(float));
    v = sparse_get(&f.samp, FS_R, 1, 0, -1);
    assert_memory_equal(&v, &odd, sizeof(float));
    /* undoing marks the touched blocks dirty for the mesher */
    (void)sparse_take_dirty(&f.samp, (int32_t(*)[3])NULL, 0);
    int32_t keys[4][3];
    (void)sparse_take_dirty(&f.samp, keys, 4);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(sparse_take_dirty(&f.samp, NULL, 0), 2);
    assert_int_equal(undo_begin(&u, &f, slo, shi, 1u << FC_NCH, slo, shi, 0), ARGIL_ERR_ARG);
    undo_free(&u);
    field_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_budget_drops_oldest_first),
        cmocka_unit_test(test_new_edit_clears_redo),
        cmocka_unit_test(test_noted_and_snapshotted_changes_are_bit_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
