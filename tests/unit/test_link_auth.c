/* The UDP link's envelope (shared/link_envelope.c with the board's and the host's libsodium
 * MAC, firmware/hal/link_auth.c and host/link/link_crypto.c): the sealed golden datagrams of
 * docs/protocol.md byte for byte from both sides, and every way a datagram is refused (a
 * flipped bit anywhere, another direction or key, a torn trailer, a nonce that is not the
 * session's). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "firmware/hal/link_auth.h"
#include "host/link/link_crypto.h"
#include "shared/proto.h"

/* docs/protocol.md "Sealed golden datagrams": key 00 01 … 1f, nonce 0x0123456789ABCDEF; the
 * tags were made with Python's hashlib.blake2b(key=…, digest_size=16), not with this code. */
#define TEST_NONCE 0x0123456789ABCDEFull

/* The board's HELLO of test_proto.c's golden vectors, sealed board → host. */
static const uint8_t sealed_hello[62] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x01, 0x16, 0x00, 0x01, 0x00, 0x00, 0x00,
    0x01, 0x03, 0x20, 0x00, 0xe8, 0x03, 0x61, 0x72, 0x67, 0x69, 0x6c, 0x2d,
    0x62, 0x6f, 0x61, 0x72, 0x64, 0x20, 0x30, 0x2e, 0x31, 0x00, 0xa7, 0x62,
    0x8f, 0x0d, 0xef, 0xcd, 0xab, 0x89, 0x67, 0x45, 0x23, 0x01, 0xff, 0x17,
    0x14, 0x6c, 0x5e, 0x14, 0x19, 0x5a, 0x21, 0xe6, 0x37, 0x75, 0x40, 0xbe,
    0x81, 0xbd,
};
/* The golden HEARTBEAT (command arm), sealed host → board. */
static const uint8_t sealed_heartbeat[57] = {
    0x41, 0x52, 0x47, 0x4c, 0x03, 0x02, 0x11, 0x00, 0x02, 0x00, 0x00, 0x00,
    0xcb, 0x04, 0xfb, 0x71, 0x1f, 0x01, 0x00, 0x00, 0x07, 0x00, 0x00, 0x00,
    0x2a, 0x00, 0x00, 0x00, 0x01, 0xa6, 0x03, 0xc6, 0xe4, 0xef, 0xcd, 0xab,
    0x89, 0x67, 0x45, 0x23, 0x01, 0x11, 0x95, 0xc2, 0x69, 0x30, 0x35, 0x31,
    0xa1, 0x7d, 0x4a, 0x5c, 0xa0, 0xf1, 0xc8, 0x16, 0x14,
};

static link_key_t test_key(void)
{
    link_key_t k;
    for (unsigned i = 0; i < LINK_KEY_BYTES; i++)
        k.k[i] = (uint8_t)i;
    return k;
}

static int setup(void **st)
{
    (void)st;
    return link_auth_init() && link_crypto_init() ? 0 : -1;
}

static void check_golden(link_auth_mac_fn mac, const uint8_t *sealed, size_t len,
                         uint8_t direction)
{
    const link_key_t k = test_key();
    const size_t flen = len - LINK_AUTH_TRAILER_BYTES;
    uint8_t out[LINK_AUTH_DGRAM_MAX];
    assert_int_equal(
        link_auth_seal(mac, &k, direction, TEST_NONCE, sealed, flen, out, sizeof(out)), len);
    assert_memory_equal(out, sealed, len);
    size_t got_len = 0;
    uint64_t nonce = 0;
    assert_int_equal(link_auth_open(mac, &k, direction, sealed, len, &got_len, &nonce),
                     LINK_AUTH_OK);
    assert_int_equal(got_len, flen);
    assert_true(nonce == TEST_NONCE);
    /* the frame inside is still a frame the decoder takes */
    proto_msg_t m;
    size_t used = 0;
    assert_int_equal(proto_decode(sealed, got_len, &m, &used), PROTO_OK);
    assert_int_equal(used, flen);
}

static void test_golden_sealed_hello_matches_the_spec(void **st)
{
    (void)st;
    check_golden(link_auth_mac, sealed_hello, sizeof sealed_hello, LINK_AUTH_BOARD_TO_HOST);
    check_golden(link_crypto_mac, sealed_hello, sizeof sealed_hello, LINK_AUTH_BOARD_TO_HOST);
}

static void test_golden_sealed_heartbeat_matches_the_spec(void **st)
{
    (void)st;
    check_golden(link_auth_mac, sealed_heartbeat, sizeof sealed_heartbeat, LINK_AUTH_HOST_TO_BOARD);
    check_golden(link_crypto_mac, sealed_heartbeat, sizeof sealed_heartbeat,
                 LINK_AUTH_HOST_TO_BOARD);
}

/* Any one bit changed in frame, nonce or tag: refused, and nothing handed out. */
static void test_every_flipped_bit_is_refused(void **st)
{
    (void)st;
    const link_key_t k = test_key();
    uint8_t d[sizeof sealed_heartbeat];
    for (size_t bit = 0; bit < 8u * sizeof d; bit++) {
        memcpy(d, sealed_heartbeat, sizeof d);
        d[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        size_t flen = 12345;
        uint64_t nonce = 777;
        const link_auth_err_t e =
            link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD, d, sizeof d, &flen,
                           &nonce);
        /* the header's length field (bytes 6, 7) no longer fits the datagram: SIZE */
        const size_t byte = bit / 8u;
        if (e != ((byte == 6u || byte == 7u) ? LINK_AUTH_ERR_SIZE : LINK_AUTH_ERR_TAG))
            fail_msg("bit %zu: %s", bit, link_auth_err_text(e));
        assert_int_equal(flen, 12345);
        assert_true(nonce == 777);
    }
}

static void test_another_direction_or_key_is_refused(void **st)
{
    (void)st;
    link_key_t k = test_key();
    size_t flen;
    uint64_t nonce;
    /* a board's datagram reflected back to it */
    assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD, sealed_hello,
                                    sizeof sealed_hello, &flen, &nonce), LINK_AUTH_ERR_TAG);
    assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_BOARD_TO_HOST, sealed_heartbeat,
                                    sizeof sealed_heartbeat, &flen, &nonce), LINK_AUTH_ERR_TAG);
    for (unsigned i = 0; i < LINK_KEY_BYTES; i++) {
        k = test_key();
        k.k[i] ^= 0x80u;
        assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD,
                                        sealed_heartbeat,
                                        sizeof sealed_heartbeat, &flen, &nonce),
                         LINK_AUTH_ERR_TAG);
    }
}

/* A trailer cut short, a byte too many, a bare frame, a few bytes: SIZE, before any hashing. */
static void test_a_torn_or_missing_trailer_is_refused(void **st)
{
    (void)st;
    const link_key_t k = test_key();
    size_t flen;
    uint64_t nonce;
    uint8_t d[sizeof sealed_heartbeat + 1u];
    memcpy(d, sealed_heartbeat, sizeof sealed_heartbeat);
    d[sizeof sealed_heartbeat] = 0;
    for (size_t len = 0; len < sizeof sealed_heartbeat; len++)
        assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD, d, len,
                                        &flen, &nonce),
                         LINK_AUTH_ERR_SIZE);
    assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD, d, sizeof d,
                                    &flen, &nonce),
                     LINK_AUTH_ERR_SIZE);
    /* a header claiming more than a frame may hold */
    d[6] = 0xff;
    d[7] = 0xff;
    assert_int_equal(link_auth_open(link_auth_mac, &k, LINK_AUTH_HOST_TO_BOARD, d, sizeof d,
                                    &flen, &nonce),
                     LINK_AUTH_ERR_SIZE);
}

/* The board's nonce rule: its session's nonce, or 0 on a HELLO only. */
static void test_nonce_zero_only_for_a_hello(void **st)
{
    (void)st;
    const uint8_t *hb = sealed_heartbeat, *hello = sealed_hello;
    const size_t hbl = sizeof sealed_heartbeat - LINK_AUTH_TRAILER_BYTES;
    const size_t hl = sizeof sealed_hello - LINK_AUTH_TRAILER_BYTES;
    assert_true(link_auth_nonce_ok(TEST_NONCE, TEST_NONCE, hb, hbl));
    assert_false(link_auth_nonce_ok(TEST_NONCE, TEST_NONCE + 1u, hb, hbl)); /* another session */
    assert_false(link_auth_nonce_ok(TEST_NONCE, 0, hb, hbl));
    assert_true(link_auth_nonce_ok(TEST_NONCE, 0, hello, hl));
    assert_true(link_auth_nonce_ok(0, 0, hello, hl));      /* no session yet: a HELLO starts one */
    assert_false(link_auth_nonce_ok(0, 0, hb, hbl));
    assert_false(link_auth_nonce_ok(0, TEST_NONCE, hb, hbl));
    assert_false(link_auth_nonce_ok(0, 0, hello, PROTO_HEADER_SIZE)); /* not even a header */
}

static void test_seal_refuses_what_it_cannot_hold(void **st)
{
    (void)st;
    const link_key_t k = test_key();
    static uint8_t big[PROTO_FRAME_MAX + 1u], out[LINK_AUTH_DGRAM_MAX + 1u];
    assert_int_equal(link_auth_seal(link_auth_mac, &k, 1, 1, big, 0, out, sizeof out), 0);
    assert_int_equal(link_auth_seal(link_auth_mac, &k, 1, 1, big, sizeof big, out, sizeof out), 0);
    assert_int_equal(
        link_auth_seal(link_auth_mac, &k, 1, 1, big, 33, out, 33 + LINK_AUTH_TRAILER_BYTES - 1u),
        0);
    assert_int_equal(
        link_auth_seal(link_auth_mac, &k, 1, 1, big, PROTO_FRAME_MAX, out, LINK_AUTH_DGRAM_MAX),
                     LINK_AUTH_DGRAM_MAX);
}

static void test_new_nonces_are_never_zero_and_differ(void **st)
{
    (void)st;
    uint64_t prev = link_auth_new_nonce();
    for (int i = 0; i < 1000; i++) {
        const uint64_t n = link_auth_new_nonce();
        assert_true(n != 0);
        assert_true(n != prev);
        prev = n;
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_golden_sealed_hello_matches_the_spec),
        cmocka_unit_test(test_golden_sealed_heartbeat_matches_the_spec),
        cmocka_unit_test(test_every_flipped_bit_is_refused),
        cmocka_unit_test(test_another_direction_or_key_is_refused),
        cmocka_unit_test(test_a_torn_or_missing_trailer_is_refused),
        cmocka_unit_test(test_nonce_zero_only_for_a_hello),
        cmocka_unit_test(test_seal_refuses_what_it_cannot_hold),
        cmocka_unit_test(test_new_nonces_are_never_zero_and_differ),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
