/* The board's libsodium for the UDP link's envelope (link_auth.h). */
#include "link_auth.h"

#include <sodium.h>

#include "shared/wire.h"

bool link_auth_init(void)
{
    return sodium_init() >= 0; /* 1 when it was already initialised */
}

void link_auth_mac(const link_key_t *key, const uint8_t *msg, size_t len,
                   uint8_t tag[LINK_AUTH_TAG_BYTES])
{
    crypto_generichash_state st;
    crypto_generichash_init(&st, key->k, LINK_KEY_BYTES, LINK_AUTH_TAG_BYTES);
    crypto_generichash_update(&st, msg, len);
    crypto_generichash_final(&st, tag, LINK_AUTH_TAG_BYTES);
    sodium_memzero(&st, sizeof(st));
}

uint64_t link_auth_new_nonce(void)
{
    uint8_t b[8];
    uint64_t n = 0;
    while (n == 0) {
        randombytes_buf(b, sizeof(b));
        wire_reader_t r = wire_reader(b, sizeof(b));
        n = wire_get_u64(&r);
    }
    return n;
}

void link_auth_wipe(void *p, size_t len)
{
    sodium_memzero(p, len);
}
