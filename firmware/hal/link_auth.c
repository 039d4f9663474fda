/* The UDP link's envelope (link_auth.h): keyed BLAKE2b-128 from libsodium. */
#include "link_auth.h"

#include <sodium.h>
#include <string.h>

#include "shared/proto.h"

static const uint8_t DOMAIN[8] = {'A', 'R', 'G', 'L', '-', 'U', 'D', 'P'};

bool link_auth_init(void)
{
    return sodium_init() >= 0; /* 1 when it was already initialised */
}

static void put_u64(uint8_t *p, uint64_t v)
{
    for (unsigned i = 0; i < 8u; i++)
        p[i] = (uint8_t)(v >> (8u * i));
}

static uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < 8u; i++)
        v |= (uint64_t)p[i] << (8u * i);
    return v;
}

/* tag = BLAKE2b-128(key; "ARGL-UDP" ‖ direction ‖ nonce LE ‖ frame). */
static void compute_tag(const link_key_t *key, uint8_t direction, const uint8_t nonce_le[8],
                        const uint8_t *frame, size_t len, uint8_t tag[LINK_AUTH_TAG_BYTES])
{
    crypto_generichash_state st;
    crypto_generichash_init(&st, key->k, LINK_KEY_BYTES, LINK_AUTH_TAG_BYTES);
    crypto_generichash_update(&st, DOMAIN, sizeof(DOMAIN));
    crypto_generichash_update(&st, &direction, 1u);
    crypto_generichash_update(&st, nonce_le, LINK_AUTH_NONCE_BYTES);
    crypto_generichash_update(&st, frame, len);
    crypto_generichash_final(&st, tag, LINK_AUTH_TAG_BYTES);
    sodium_memzero(&st, sizeof(st));
}

size_t link_auth_seal(const link_key_t *key, uint8_t direction, uint64_t nonce,
                      const uint8_t *frame, size_t len, uint8_t *out, size_t cap)
{
    if (len == 0 || len > PROTO_FRAME_MAX || cap < len + LINK_AUTH_TRAILER_BYTES)
        return 0;
    memcpy(out, frame, len);
    put_u64(out + len, nonce);
    compute_tag(key, direction, out + len, frame, len, out + len + LINK_AUTH_NONCE_BYTES);
    return len + LINK_AUTH_TRAILER_BYTES;
}

link_auth_err_t link_auth_open(const link_key_t *key, uint8_t direction, const uint8_t *dgram,
                               size_t len, size_t *frame_len, uint64_t *nonce)
{
    if (len < PROTO_HEADER_SIZE + PROTO_CRC_SIZE + LINK_AUTH_TRAILER_BYTES)
        return LINK_AUTH_ERR_SIZE;
    const size_t flen = PROTO_HEADER_SIZE + PROTO_CRC_SIZE + ((size_t)dgram[6] | (size_t)dgram[7] << 8);
    if (flen > PROTO_FRAME_MAX || len != flen + LINK_AUTH_TRAILER_BYTES)
        return LINK_AUTH_ERR_SIZE;
    uint8_t tag[LINK_AUTH_TAG_BYTES];
    compute_tag(key, direction, dgram + flen, dgram, flen, tag);
    if (sodium_memcmp(tag, dgram + flen + LINK_AUTH_NONCE_BYTES, LINK_AUTH_TAG_BYTES) != 0)
        return LINK_AUTH_ERR_TAG;
    *frame_len = flen;
    *nonce = get_u64(dgram + flen);
    return LINK_AUTH_OK;
}

bool link_auth_nonce_ok(uint64_t session_nonce, uint64_t nonce, const uint8_t *frame,
                        size_t frame_len)
{
    if (nonce == 0)
        return frame_len > PROTO_HEADER_SIZE && frame[5] == MSG_HELLO;
    return nonce == session_nonce;
}

uint64_t link_auth_new_nonce(void)
{
    uint8_t b[8];
    uint64_t n = 0;
    while (n == 0) {
        randombytes_buf(b, sizeof(b));
        n = get_u64(b);
    }
    return n;
}

void link_auth_host_init(link_auth_host_t *h, const link_key_t *key)
{
    memset(h, 0, sizeof(*h));
    h->key = *key;
}

size_t link_auth_host_seal(link_auth_host_t *h, const uint8_t *frame, size_t len, uint8_t *out,
                           size_t cap)
{
    const bool hello = len > PROTO_HEADER_SIZE && frame[5] == MSG_HELLO;
    if (!hello && h->nonce == 0) {
        h->held++;
        return 0;
    }
    return link_auth_seal(&h->key, LINK_AUTH_HOST_TO_BOARD, hello ? 0u : h->nonce, frame, len,
                          out, cap);
}

link_auth_err_t link_auth_host_open(link_auth_host_t *h, const uint8_t *dgram, size_t len,
                                    size_t *frame_len)
{
    uint64_t nonce = 0;
    const link_auth_err_t e =
        link_auth_open(&h->key, LINK_AUTH_BOARD_TO_HOST, dgram, len, frame_len, &nonce);
    if (e != LINK_AUTH_OK) {
        h->refused++;
        return e;
    }
    h->nonce = nonce;
    return LINK_AUTH_OK;
}

const char *link_auth_err_text(link_auth_err_t e)
{
    switch (e) {
    case LINK_AUTH_OK: return "ok";
    case LINK_AUTH_ERR_SIZE: return "not one frame and a trailer";
    case LINK_AUTH_ERR_TAG: return "bad tag";
    case LINK_AUTH_ERR_NONCE: return "not the session's nonce";
    }
    return "?";
}
