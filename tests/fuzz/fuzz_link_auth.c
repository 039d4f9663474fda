/* libFuzzer target for the authenticated UDP path (shared/link_envelope.c with the board's MAC,
 * firmware/hal/link_auth.c; docs/protocol.md "Authenticated UDP"): arbitrary bytes as a
 * datagram into the board's verification (tag, then the nonce rule) and, when it verifies, the
 * decoder, as link_udp.c runs them; and the same bytes as a frame sealed, changed in one byte
 * chosen by the input, and opened again. Checked: a verified datagram is exactly its frame and
 * a trailer, and sealing that frame again gives the same bytes; a sealed frame opens to itself;
 * a changed byte never opens. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/hal/link_auth.h"
#include "shared/proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(int ok)
{
    if (!ok)
        abort();
}

/* The key of the sealed golden datagrams (docs/protocol.md): the seeds verify under it. */
static link_key_t test_key(void)
{
    link_key_t k;
    for (unsigned i = 0; i < LINK_KEY_BYTES; i++)
        k.k[i] = (uint8_t)i;
    return k;
}

static void as_datagram(const link_key_t *k, const uint8_t *d, size_t n)
{
    static uint8_t again[LINK_AUTH_DGRAM_MAX];
    static proto_msg_t m;
    for (uint8_t dir = LINK_AUTH_HOST_TO_BOARD; dir <= LINK_AUTH_BOARD_TO_HOST; dir++) {
        size_t flen = 0;
        uint64_t nonce = 0;
        if (link_auth_open(link_auth_mac, k, dir, d, n, &flen, &nonce) != LINK_AUTH_OK)
            continue;
        check(flen + LINK_AUTH_TRAILER_BYTES == n && flen <= PROTO_FRAME_MAX);
        check(link_auth_seal(link_auth_mac, k, dir, nonce, d, flen, again, sizeof(again)) == n);
        check(memcmp(again, d, n) == 0);
        (void)link_auth_nonce_ok(nonce, nonce, d, flen);
        (void)link_auth_nonce_ok(0x0123456789ABCDEFull, nonce, d, flen);
        size_t used = 0;
        if (proto_decode(d, flen, &m, &used) == PROTO_OK)
            check(used <= flen);
    }
}

static void as_frame(const link_key_t *k, const uint8_t *d, size_t n)
{
    static uint8_t sealed[LINK_AUTH_DGRAM_MAX];
    if (n < 3u)
        return;
    const size_t at = d[0], flip = d[1];
    const uint8_t *frame = d + 2;
    const size_t flen = n - 2u;
    const uint64_t nonce = (uint64_t)flip * 0x9E3779B97F4A7C15ull;
    const size_t len = link_auth_seal(link_auth_mac, k, LINK_AUTH_HOST_TO_BOARD, nonce, frame,
                                      flen, sealed, sizeof(sealed));
    if (len == 0) {
        check(flen > PROTO_FRAME_MAX);
        return;
    }
    size_t got = 0;
    uint64_t got_nonce = 0;
    /* opens to itself when its header's length field fits what was sealed */
    const size_t declared = flen >= PROTO_HEADER_SIZE
                                ? PROTO_HEADER_SIZE + PROTO_CRC_SIZE +
                                      ((size_t)frame[6] | (size_t)frame[7] << 8)
                                : 0;
    const link_auth_err_t e =
        link_auth_open(link_auth_mac, k, LINK_AUTH_HOST_TO_BOARD, sealed, len, &got, &got_nonce);
    if (declared == flen)
        check(e == LINK_AUTH_OK && got == flen && got_nonce == nonce);
    else
        check(e != LINK_AUTH_OK);
    sealed[at % len] ^= (uint8_t)(flip | 1u);
    check(link_auth_open(link_auth_mac, k, LINK_AUTH_HOST_TO_BOARD, sealed, len, &got,
                         &got_nonce) != LINK_AUTH_OK);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    if (!ready)
        ready = link_auth_init() ? 1 : (abort(), 0);
    const link_key_t k = test_key();
    as_datagram(&k, data, size);
    as_frame(&k, data, size);
    return 0;
}
