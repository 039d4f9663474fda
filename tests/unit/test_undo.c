/* Undo journal on its own: bit-for-bit undo/redo of snapshotted and noted changes, the memory
 * budget dropping the oldest steps first, a new edit clearing redo, state errors, and the history
 * cut at a knot insertion. */
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

/* Bytes of one step of n changes along one row: a run header and n (before, after) pairs. */
static size_t row_bytes(size_t n)
{
    return sizeof(undo_run_t) + n * 2 * sizeof(float);
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
    assert_int_equal(undo_init(&u, 3 * row_bytes(10)), ARGIL_OK); /* room for three steps of 10 */
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
    /* a step larger than the whole budget (100 changes, 2.8 times it) is still kept: the newest
     * always is, and the ring grows for it */
    assert_int_equal(undo_begin(&u, &f, box_lo, box_lo, 0, box_lo, box_lo, 0), ARGIL_OK);
    for (int32_t x = 0; x < 100; x++) {
        const int32_t ijk[3] = {x, 3, -1};
        assert_int_equal(sparse_set(&f.coef, FC_P, x, 3, -1, 0.7f), ARGIL_OK);
        assert_int_equal(undo_note(&u, UNDO_STORE_COEF, FC_P, ijk, 0.0f, 0.7f), ARGIL_OK);
    }
    assert_int_equal(undo_commit(&u, &f), ARGIL_OK);
    assert_int_equal(u.nsteps, 1);
    assert_int_equal(u.steps[0].n, 100);
    assert_true(u.bytes == row_bytes(100) && u.bytes > 2 * u.budget_bytes);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    for (int32_t x = 0; x < 100; x++)
        assert_true(sparse_get(&f.coef, FC_P, x, 3, -1) == 0.0f);
    assert_int_equal(undo_redo(&u, &f), ARGIL_OK);
    assert_true(sparse_get(&f.coef, FC_P, 99, 3, -1) == 0.7f);
    /* the next small steps push it out again and fit the budget */
    edit(&u, &f, 4, 10, 0.9f);
    assert_int_equal(u.nsteps, 1);
    assert_true(u.bytes <= u.budget_bytes);
    undo_free(&u);
    field_free(&f);
}

static void test_new_edit_clears_redo(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.01f, 1, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    assert_int_equal(undo_init(&u, 1u << 20), ARGIL_OK);
    edit(&u, &f, 0, 4, 0.25f);
    edit(&u, &f, 1, 4, 0.5f);
    edit(&u, &f, 2, 4, 0.75f);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(u.nsteps, 3);
    const size_t bytes_before = u.bytes;
    edit(&u, &f, 3, 4, 1.0f);
    assert_int_equal(u.nsteps, 2);
    assert_true(u.bytes == bytes_before - row_bytes(4)); /* two dropped, one added */
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
    assert_int_equal(undo_init(&u, 1u << 20), ARGIL_OK);
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
    /* a density change with its rest moved alike (the tools' plastic edit) in one 12-byte change:
     * redo recomputes the rest by the same expression, so it is bit for bit the edited value */
    const int32_t q[3] = {3, -2, 5};
    const float d0 = 0.3f, d1 = nextafterf(0.7f, 0.0f), r0 = 0.1f + 1e-9f, r1 = r0 + (d1 - d0);
    assert_int_equal(sparse_set(&f.samp, FS_D, q[0], q[1], q[2], d0), ARGIL_OK);
    assert_int_equal(sparse_set(&f.samp, FS_REST, q[0], q[1], q[2], r0), ARGIL_OK);
    assert_int_equal(undo_note_drest(&u, q, d0, d1, r0), ARGIL_ERR_STATE);
    assert_int_equal(undo_begin(&u, &f, slo, slo, 0, slo, slo, 0), ARGIL_OK);
    assert_int_equal(undo_note(&u, UNDO_STORE_DREST, FS_D, q, d0, d1), ARGIL_ERR_ARG);
    assert_int_equal(undo_note_drest(&u, q, d0, d1, r0), ARGIL_OK);
    assert_int_equal(sparse_set(&f.samp, FS_D, q[0], q[1], q[2], d1), ARGIL_OK);
    assert_int_equal(sparse_set(&f.samp, FS_REST, q[0], q[1], q[2], r1), ARGIL_OK);
    assert_int_equal(undo_commit(&u, &f), ARGIL_OK);
    assert_int_equal(u.steps[u.nsteps - 1].len, sizeof(undo_run_t) + 3 * sizeof(float));
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    v = sparse_get(&f.samp, FS_REST, q[0], q[1], q[2]);
    assert_memory_equal(&v, &r0, sizeof(float));
    assert_true(sparse_get(&f.samp, FS_D, q[0], q[1], q[2]) == d0);
    assert_int_equal(undo_redo(&u, &f), ARGIL_OK);
    v = sparse_get(&f.samp, FS_REST, q[0], q[1], q[2]);
    assert_memory_equal(&v, &r1, sizeof(float));
    v = sparse_get(&f.samp, FS_D, q[0], q[1], q[2]);
    assert_memory_equal(&v, &d1, sizeof(float));
    undo_free(&u);
    field_free(&f);
}

#define RB_X 16
#define RB_N (RB_X * 4 * 2) /* a 16 x 4 x 2 box of coefficients */
#define RB_OPS 600

static uint32_t rng_next(uint32_t *st)
{
    *st = *st * 1664525u + 1013904223u;
    return *st >> 8;
}

static void rb_read(const field_t *f, float *out)
{
    const int32_t lo[3] = {0, 0, 0}, dims[3] = {RB_X, 4, 2};
    sparse_read_box(&f->coef, FC_P, lo, dims, out);
}

/* Random edits (noted and snapshotted), undos and redos through a ring much smaller than the
 * history: every undo and redo gives back the recorded state bit for bit while the ring wraps
 * many times, redo steps are moved aside by new edits and the budget holds. */
static void test_ring_wraps_bit_exact(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.01f, 1, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    const size_t budget = 1000;
    assert_int_equal(undo_init(&u, budget), ARGIL_OK);
    static float timeline[RB_OPS + 1][RB_N];
    size_t pos = 0, top = 0, written = 0;
    int undos = 0, redos = 0;
    rb_read(&f, timeline[0]);
    uint32_t rs = 12345u;
    for (int op = 0; op < RB_OPS; op++) {
        const uint32_t r = rng_next(&rs) % 100;
        float now[RB_N];
        if (r < 25) {
            const bool can = u.done > 0;
            assert_int_equal(undo_undo(&u, &f), can ? ARGIL_OK : ARGIL_ERR_EMPTY);
            if (can) {
                pos--;
                undos++;
            }
        } else if (r < 40) {
            const bool can = u.done < u.nsteps;
            assert_int_equal(undo_redo(&u, &f), can ? ARGIL_OK : ARGIL_ERR_EMPTY);
            if (can) {
                pos++;
                redos++;
            }
        } else {
            const bool snap = (r & 1u) != 0;
            const int32_t lo[3] = {0, 0, 0}, hi[3] = {RB_X, 4, 2};
            assert_int_equal(snap ? undo_begin(&u, &f, lo, hi, 1u << FC_P, lo, lo, 0)
                                  : undo_begin(&u, &f, lo, lo, 0, lo, lo, 0), ARGIL_OK);
            const uint32_t first = rng_next(&rs) % RB_N, count = 1 + rng_next(&rs) % 40;
            for (uint32_t k = 0; k < count && first + k < RB_N; k++) { /* distinct points */
                const uint32_t i = first + k;
                const int32_t ijk[3] = {(int32_t)(i % RB_X), (int32_t)(i / RB_X % 4), (int32_t)(i / (RB_X * 4))};
                const float before = sparse_get(&f.coef, FC_P, ijk[0], ijk[1], ijk[2]);
                const float after = (float)(rng_next(&rs) % 1000) * 1.0e-3f + 1.0e-7f;
                assert_int_equal(sparse_set(&f.coef, FC_P, ijk[0], ijk[1], ijk[2], after), ARGIL_OK);
                if (!snap && memcmp(&before, &after, sizeof(float)) != 0)
                    assert_int_equal(undo_note(&u, UNDO_STORE_COEF, FC_P, ijk, before, after), ARGIL_OK);
            }
            assert_int_equal(undo_commit(&u, &f), ARGIL_OK);
            written += u.bytes > 0 ? u.steps[u.nsteps - 1].len : 0;
            pos++;
            top = pos;
            rb_read(&f, timeline[pos]);
            assert_int_equal(u.done, u.nsteps); /* the new edit cleared redo */
        }
        rb_read(&f, now);
        assert_memory_equal(now, timeline[pos], sizeof(now));
        assert_true(pos <= top && u.nsteps - u.done == top - pos);
        assert_true(u.bytes <= u.budget_bytes || u.nsteps == 1);
    }
    assert_true(written > 20 * budget); /* the ring went round many times */
    assert_true(undos > 100 && redos > 20);
    assert_int_equal(u.ring_cap, budget); /* no step outgrew it: the ring never grew */
    undo_free(&u);
    field_free(&f);
}

/* Knot insertion (field_refine) moves every coefficient index: a step recorded before it would
 * write coarse values into fine places, so undo and redo refuse it and change nothing; steps
 * recorded after it undo as usual. */
static void test_refine_cuts_the_history(void **state)
{
    (void)state;
    field_t f;
    assert_int_equal(field_init(&f, 0.02f, 2, vec3(0, 0, 0)), ARGIL_OK);
    undo_t u;
    assert_int_equal(undo_init(&u, 1u << 20), ARGIL_OK);
    edit(&u, &f, 0, 6, 0.5f); /* coarse coefficients (-6..-1, 0, -1) = 0.5 */
    edit(&u, &f, 1, 6, 0.7f);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK); /* one redo step left */
    assert_int_equal(field_refine(&f), ARGIL_OK);
    assert_true(f.lattice_gen == 1 && f.ratio == 1);
    /* fine 2c sits on coarse c: coarse (-4, 0, -1) is fine (-8, 0, -2), (p + 6p + p) / 8 along x
     * inside the row, 6p / 8 along y and z (a single row): 0.5 * 36 / 64 */
    const float fine_before = sparse_get(&f.coef, FC_P, -8, 0, -2);
    assert_float_equal(fine_before, 0.28125f, 1e-6);
    assert_int_equal(undo_undo(&u, &f), ARGIL_ERR_STATE);
    assert_int_equal(undo_redo(&u, &f), ARGIL_ERR_STATE);
    assert_true(sparse_get(&f.coef, FC_P, -8, 0, -2) == fine_before); /* nothing written */
    /* an edit after the refinement is one step like any other */
    edit(&u, &f, 5, 4, 0.9f);
    assert_true(at(&f, 0, 5) == 0.9f);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_true(at(&f, 0, 5) == 0.0f);
    assert_int_equal(undo_redo(&u, &f), ARGIL_OK);
    assert_true(at(&f, 0, 5) == 0.9f);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(undo_undo(&u, &f), ARGIL_ERR_STATE); /* the pre-refinement step stays refused */
    undo_free(&u);
    field_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_budget_drops_oldest_first),
        cmocka_unit_test(test_new_edit_clears_redo),
        cmocka_unit_test(test_noted_and_snapshotted_changes_are_bit_exact),
        cmocka_unit_test(test_ring_wraps_bit_exact),
        cmocka_unit_test(test_refine_cuts_the_history),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
