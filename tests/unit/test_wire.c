/* Unit tests for shared/wire.h: the little-endian loads and stores every encoder uses, byte by
 * byte against the layout, and the cursors that stop at their end. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <string.h>

#include "shared/wire.h"

static void test_stores_put_the_least_significant_byte_first(void **st)
{
    (void)st;
    uint8_t b[8];
    memset(b, 0xAA, sizeof b);
    le_put_u16(b, 0x1234u);
    const uint8_t u16[3] = {0x34, 0x12, 0xAA};
    assert_memory_equal(b, u16, 3);
    le_put_u32(b, 0x89ABCDEFu);
    const uint8_t u32[5] = {0xEF, 0xCD, 0xAB, 0x89, 0xAA};
    assert_memory_equal(b, u32, 5);
    le_put_u64(b, 0x0102030405060708ull);
    const uint8_t u64[8] = {8, 7, 6, 5, 4, 3, 2, 1};
    assert_memory_equal(b, u64, 8);
    le_put_f32(b, 1.0f); /* 0x3F800000 */
    const uint8_t f32[4] = {0x00, 0x00, 0x80, 0x3F};
    assert_memory_equal(b, f32, 4);
    memset(b, 0xAA, sizeof b);
    le_put(b, 0xC0FFEEu, 3u);
    const uint8_t u24[4] = {0xEE, 0xFF, 0xC0, 0xAA};
    assert_memory_equal(b, u24, 4);
}

static void test_loads_read_the_least_significant_byte_first(void **st)
{
    (void)st;
    const uint8_t b[8] = {0xF0, 0xDE, 0xBC, 0x9A, 0x78, 0x56, 0x34, 0x12};
    assert_int_equal(le_get_u16(b), 0xDEF0u);
    assert_int_equal(le_get_u32(b), 0x9ABCDEF0u);
    assert_true(le_get_u64(b) == 0x123456789ABCDEF0ull);
    assert_int_equal(le_get(b, 3u), 0xBCDEF0u);
    assert_int_equal(le_get(b, 0u), 0u);
    const uint8_t half[4] = {0x00, 0x00, 0x00, 0xBF};
    assert_true(le_get_f32(half) == -0.5f);
}

static void test_a_float_keeps_its_bits(void **st)
{
    (void)st;
    const uint32_t bits = 0x7FA00001u; /* a NaN with a payload */
    float f;
    memcpy(&f, &bits, sizeof f);
    uint8_t b[4];
    le_put_f32(b, f);
    assert_int_equal(le_get_u32(b), bits);
}

static void test_cursors_stop_at_their_end(void **st)
{
    (void)st;
    uint8_t b[6];
    wire_writer_t w = wire_writer(b, sizeof b);
    wire_put_u32(&w, 0x04030201u);
    wire_put_f32(&w, 2.0f);
    assert_false(w.ok);
    assert_int_equal(w.pos, 4u);
    wire_put_u16(&w, 0x0605u);
    assert_int_equal(w.pos, 4u);
    w = wire_writer(b, sizeof b);
    wire_put_u32(&w, 0x04030201u);
    wire_put_u16(&w, 0x0605u);
    assert_true(w.ok);
    const uint8_t want[6] = {1, 2, 3, 4, 5, 6};
    assert_memory_equal(b, want, 6);
    wire_reader_t r = wire_reader(b, sizeof b);
    assert_int_equal(wire_get_u16(&r), 0x0201u);
    assert_true(wire_get_f32(&r) == le_get_f32(b + 2));
    assert_true(wire_get_f32(&r) == 0.0f);
    assert_false(r.ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stores_put_the_least_significant_byte_first),
        cmocka_unit_test(test_loads_read_the_least_significant_byte_first),
        cmocka_unit_test(test_a_float_keeps_its_bits),
        cmocka_unit_test(test_cursors_stop_at_their_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
