/* The block-key hash: keys of any sign found after growth and removal, probing that ends on a
 * full table, iteration over every entry once. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "host/model/block_table.h"

typedef struct {
    int32_t key[3];
    int32_t value;
} entry_t;

/* The n-th key of a spread of keys of both signs. */
static void key_of(int n, int32_t k[3])
{
    k[0] = (n % 7) - 3;
    k[1] = ((n / 7) % 11) - 5;
    k[2] = n / 77 - 4;
}

/* Inserts keys 0..n-1 of key_of, entry i holding value i. */
static void fill(block_table_t *t, int n)
{
    for (int i = 0; i < n; i++) {
        int32_t k[3];
        key_of(i, k);
        entry_t *e;
        assert_int_equal(block_table_insert(t, k, (void **)&e), ARGIL_OK);
        e->value = i;
        assert_true(t->count * 2 <= t->cap || t->cap == t->cap_max); /* grown at half load */
    }
}

/* Asserts that keys 0..n-1 of key_of are all held with their values. */
static void expect_all(const block_table_t *t, int n)
{
    for (int i = 0; i < n; i++) {
        int32_t k[3];
        key_of(i, k);
        const entry_t *e = block_table_find(t, k);
        assert_non_null(e);
        assert_int_equal(e->value, i);
    }
}

static size_t slot_of(const block_table_t *t, const void *e)
{
    return (size_t)((const unsigned char *)e - t->entries) / t->entry_bytes;
}

static void test_init_rejects_bad_arguments(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, 8, 64), ARGIL_ERR_ARG);  /* no room for the key */
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 48), ARGIL_ERR_ARG);
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 1), ARGIL_ERR_ARG);
    const int32_t k[3] = {1, 2, 3};
    void *e;
    assert_null(block_table_find(&t, k));
    assert_int_equal(block_table_insert(&t, k, &e), ARGIL_ERR_STATE);
    assert_null(e);
    block_table_free(&t);
}

static void test_insert_find_any_sign(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 64), ARGIL_OK);
    const int32_t a[3] = {-1, 0, 7}, b[3] = {-1, 0, -7}, c[3] = {INT32_MIN, INT32_MAX, -1};
    entry_t *ea, *eb, *ec, *again;
    assert_int_equal(block_table_insert(&t, a, (void **)&ea), ARGIL_OK);
    assert_true(ea->key[0] == -1 && ea->key[1] == 0 && ea->key[2] == 7 && ea->value == 0);
    ea->value = 11;
    assert_int_equal(block_table_insert(&t, b, (void **)&eb), ARGIL_OK);
    eb->value = 22;
    assert_int_equal(block_table_insert(&t, c, (void **)&ec), ARGIL_OK);
    ec->value = 33;
    assert_int_equal(t.count, 3);
    assert_int_equal(block_table_insert(&t, a, (void **)&again), ARGIL_OK);
    assert_ptr_equal(again, block_table_find(&t, a)); /* held: the same entry, no new one */
    assert_int_equal(again->value, 11);
    assert_int_equal(t.count, 3);
    assert_int_equal(((entry_t *)block_table_find(&t, b))->value, 22);
    assert_int_equal(((entry_t *)block_table_find(&t, c))->value, 33);
    const int32_t absent[3] = {1, 0, 7};
    assert_null(block_table_find(&t, absent));
    block_table_free(&t);
}

static void test_growth_keeps_every_key(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 4), ARGIL_OK);
    const int n = 3000;
    fill(&t, n);
    assert_int_equal(t.count, (size_t)n);
    assert_int_equal(t.cap, 8192);
    expect_all(&t, n);
    assert_int_equal(block_table_grow(&t), ARGIL_OK);
    assert_int_equal(t.cap, 16384);
    expect_all(&t, n);
    assert_int_equal(block_table_bytes(&t), 16384 * (sizeof(entry_t) + 1));
    block_table_free(&t);
}

static void test_full_table_probes_end(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 8), ARGIL_OK);
    t.cap_max = 8; /* no growth: the table fills every slot */
    fill(&t, 8);
    assert_int_equal(t.count, 8);
    assert_int_equal(block_table_grow(&t), ARGIL_ERR_FULL);
    int32_t k[3];
    key_of(100, k);
    assert_null(block_table_find(&t, k)); /* every slot looked at once, then no */
    void *e;
    assert_int_equal(block_table_insert(&t, k, &e), ARGIL_ERR_FULL);
    assert_null(e);
    int32_t k3[3];
    key_of(3, k3);
    block_table_remove(&t, block_table_find(&t, k3));
    assert_int_equal(t.count, 7);
    assert_int_equal(block_table_insert(&t, k, &e), ARGIL_OK);
    for (int i = 0; i < 8; i++) {
        key_of(i, k3);
        assert_true((block_table_find(&t, k3) != NULL) == (i != 3));
    }
    block_table_free(&t);
}

static void test_removal_keeps_later_keys_findable(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 64), ARGIL_OK);
    t.cap_max = 64;
    const int n = 32; /* half load: runs of several keys */
    fill(&t, n);
    bool gone[32] = {false}, moved = false;
    for (int r = 0; r < n; r++) {
        const int victim = (r * 13) % n; /* every key once, in a scattered order */
        int32_t k[3];
        key_of(victim, k);
        size_t before[32];
        for (int i = 0; i < n; i++) {
            int32_t ki[3];
            key_of(i, ki);
            const void *e = block_table_find(&t, ki);
            before[i] = e != NULL ? slot_of(&t, e) : 0;
        }
        block_table_remove(&t, block_table_find(&t, k));
        gone[victim] = true;
        assert_int_equal(t.count, (size_t)(n - r - 1));
        for (int i = 0; i < n; i++) {
            int32_t ki[3];
            key_of(i, ki);
            const entry_t *e = block_table_find(&t, ki);
            if (gone[i]) {
                assert_null(e);
                continue;
            }
            assert_non_null(e);
            assert_int_equal(e->value, i);
            moved = moved || slot_of(&t, e) != before[i];
        }
    }
    assert_true(moved); /* some removal shifted a later key back */
    for (size_t s = 0; s < t.cap; s++)
        assert_int_equal(t.used[s], 0);
    block_table_free(&t);
}

static void test_next_visits_each_entry_once(void **state)
{
    (void)state;
    block_table_t t;
    assert_int_equal(block_table_init(&t, sizeof(entry_t), 16), ARGIL_OK);
    const int n = 200;
    fill(&t, n);
    int seen[200] = {0}, visits = 0;
    size_t slot = 0, last = 0;
    for (entry_t *e; (e = block_table_next(&t, &slot)) != NULL; visits++) {
        assert_true(e->value >= 0 && e->value < n);
        seen[e->value]++;
        assert_true(slot > last || visits == 0); /* slot order */
        last = slot;
    }
    assert_int_equal(visits, n);
    for (int i = 0; i < n; i++)
        assert_int_equal(seen[i], 1);
    block_table_free(&t);
    slot = 0;
    assert_null(block_table_next(&t, &slot)); /* a freed table holds nothing */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_rejects_bad_arguments),
        cmocka_unit_test(test_insert_find_any_sign),
        cmocka_unit_test(test_growth_keeps_every_key),
        cmocka_unit_test(test_full_table_probes_end),
        cmocka_unit_test(test_removal_keeps_later_keys_findable),
        cmocka_unit_test(test_next_visits_each_entry_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
