/* Sparse block store: blocks only where values differ from the default, any sign of index,
 * memory that follows the surface rather than the bounding box, dirty flags for the mesher. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "host/model/sparse.h"

static void test_init_rejects_bad_arguments(void **state)
{
    (void)state;
    sparse_t s;
    const float defs[2] = {0.0f, NAN};
    assert_int_equal(sparse_init(&s, 0, defs), ARGIL_ERR_ARG);
    assert_int_equal(sparse_init(&s, SPARSE_CH_MAX + 1, defs), ARGIL_ERR_ARG);
    assert_int_equal(sparse_init(&s, 1, NULL), ARGIL_ERR_ARG);
    assert_int_equal(sparse_init(&s, 2, defs), ARGIL_ERR_NONFINITE);
}

static void test_negative_indices_and_block_of(void **state)
{
    (void)state;
    assert_int_equal(sparse_block_of(0), 0);
    assert_int_equal(sparse_block_of(7), 0);
    assert_int_equal(sparse_block_of(8), 1);
    assert_int_equal(sparse_block_of(-1), -1);
    assert_int_equal(sparse_block_of(-8), -1);
    assert_int_equal(sparse_block_of(-9), -2);
    sparse_t s;
    const float defs[2] = {0.0f, 0.8f};
    assert_int_equal(sparse_init(&s, 2, defs), ARGIL_OK);
    assert_true(sparse_get(&s, 1, -5, 3, -1000) == 0.8f); /* absent: the default */
    assert_int_equal(sparse_set(&s, 0, -1, -8, -9, 2.5f), ARGIL_OK);
    assert_int_equal(sparse_set(&s, 0, 0, -8, -9, 3.5f), ARGIL_OK);
    assert_int_equal(s.blocks.count, 2); /* x = -1 and x = 0 lie in different blocks */
    assert_true(sparse_get(&s, 0, -1, -8, -9) == 2.5f);
    assert_true(sparse_get(&s, 0, 0, -8, -9) == 3.5f);
    assert_true(sparse_get(&s, 1, -1, -8, -9) == 0.8f); /* other channel of an allocated block */
    assert_int_equal(sparse_set(&s, 2, 0, 0, 0, 1.0f), ARGIL_ERR_ARG);
    /* a box across the origin reads what was set, the default elsewhere */
    const int32_t lo[3] = {-3, -9, -10}, dims[3] = {6, 3, 3};
    float box[54];
    sparse_read_box(&s, 0, lo, dims, box);
    for (int32_t z = 0; z < 3; z++)
        for (int32_t y = 0; y < 3; y++)
            for (int32_t x = 0; x < 6; x++)
                assert_true(box[x + 6 * (y + 3 * z)] == sparse_get(&s, 0, lo[0] + x, lo[1] + y, lo[2] + z));
    assert_true(box[2 + 6 * (1 + 3 * 1)] == 2.5f);
    sparse_free(&s);
}

static void test_blocks_only_where_values_differ(void **state)
{
    (void)state;
    sparse_t s;
    const float def = 0.25f;
    assert_int_equal(sparse_init(&s, 1, &def), ARGIL_OK);
    const int32_t lo[3] = {-20, -20, -20}, dims[3] = {40, 40, 40};
    float *v = malloc(sizeof(float) * 64000);
    for (int i = 0; i < 64000; i++)
        v[i] = def;
    assert_int_equal(sparse_write_box(&s, 0, lo, dims, v), ARGIL_OK);
    assert_int_equal(s.blocks.count, 0); /* writing defaults into empty space allocates nothing */
    v[5 + 40 * (5 + 40 * 5)] = 1.0f; /* point (-15, -15, -15) */
    assert_int_equal(sparse_write_box(&s, 0, lo, dims, v), ARGIL_OK);
    assert_int_equal(s.blocks.count, 1);
    assert_true(sparse_get(&s, 0, -15, -15, -15) == 1.0f);
    const int32_t bad[3] = {1, -1, 1};
    assert_int_equal(sparse_write_box(&s, 0, lo, bad, v), ARGIL_ERR_ARG);
    assert_int_equal(sparse_write_box(&s, 1, lo, dims, v), ARGIL_ERR_ARG);
    free(v);
    sparse_free(&s);
}

/* Bytes for a one-point-thick spherical shell of radius r (lattice units). */
static size_t shell_bytes(int32_t r, size_t *blocks)
{
    sparse_t s;
    const float def = 0.0f;
    assert_int_equal(sparse_init(&s, 1, &def), ARGIL_OK);
    for (int32_t z = -r - 1; z <= r + 1; z++)
        for (int32_t y = -r - 1; y <= r + 1; y++)
            for (int32_t x = -r - 1; x <= r + 1; x++) {
                const double d = sqrt((double)x * x + (double)y * y + (double)z * z);
                if (fabs(d - r) < 0.5)
                    assert_int_equal(sparse_set(&s, 0, x, y, z, 1.0f), ARGIL_OK);
            }
    const size_t b = sparse_bytes(&s);
    *blocks = s.blocks.count;
    sparse_free(&s);
    return b;
}

static void test_memory_follows_the_surface(void **state)
{
    (void)state;
    size_t b40, b80;
    const size_t m40 = shell_bytes(40, &b40), m80 = shell_bytes(80, &b80);
    const double box80 = pow(2.0 * 80 + 3, 3) * sizeof(float); /* dense bounding box */
    assert_true((double)m80 < 0.25 * box80);
    /* twice the radius: about 4x the blocks (area), far from the 8x of the volume */
    assert_true((double)b80 < 5.0 * (double)b40);
    assert_true((double)m80 < 5.0 * (double)m40);
    assert_true(b80 > 3 * b40);
}

static void test_dirty_flags(void **state)
{
    (void)state;
    sparse_t s;
    const float def = 0.0f;
    assert_int_equal(sparse_init(&s, 1, &def), ARGIL_OK);
    const int32_t lo[3] = {-4, -4, -4}, dims[3] = {8, 8, 8};
    float v[512];
    for (int i = 0; i < 512; i++)
        v[i] = 1.0f;
    assert_int_equal(sparse_write_box(&s, 0, lo, dims, v), ARGIL_OK);
    assert_int_equal(s.blocks.count, 8);
    assert_int_equal(sparse_take_dirty(&s, NULL, 0), 8); /* counting does not clear */
    int32_t keys[8][3];
    assert_int_equal(sparse_take_dirty(&s, keys, 8), 8);
    for (int k = 0; k < 8; k++)
        for (int a = 0; a < 3; a++)
            assert_true(keys[k][a] == -1 || keys[k][a] == 0);
    assert_int_equal(sparse_take_dirty(&s, NULL, 0), 0);
    assert_int_equal(sparse_write_box(&s, 0, lo, dims, v), ARGIL_OK); /* same values */
    assert_int_equal(sparse_take_dirty(&s, NULL, 0), 0);
    v[0] = 2.0f; /* point (-4, -4, -4): block (-1, -1, -1) */
    assert_int_equal(sparse_write_box(&s, 0, lo, dims, v), ARGIL_OK);
    assert_int_equal(sparse_take_dirty(&s, keys, 8), 1);
    assert_true(keys[0][0] == -1 && keys[0][1] == -1 && keys[0][2] == -1);
    assert_int_equal(sparse_set(&s, 0, 3, 3, 3, 5.0f), ARGIL_OK);
    assert_int_equal(sparse_take_dirty(&s, keys, 8), 1);
    assert_true(keys[0][0] == 0 && keys[0][1] == 0 && keys[0][2] == 0);
    sparse_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_rejects_bad_arguments),
        cmocka_unit_test(test_negative_indices_and_block_of),
        cmocka_unit_test(test_blocks_only_where_values_differ),
        cmocka_unit_test(test_memory_follows_the_surface),
        cmocka_unit_test(test_dirty_flags),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
