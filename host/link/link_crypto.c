/* The host's libsodium for the UDP link's envelope (link_crypto.h). */
#include "host/link/link_crypto.h"

#include <sodium.h>

bool link_crypto_init(void)
{
    return sodium_init() >= 0; /* 1 when it was already initialised */
}

void link_crypto_mac(const link_key_t *key, const uint8_t *msg, size_t len,
                     uint8_t tag[LINK_AUTH_TAG_BYTES])
{
    crypto_generichash_state st;
    crypto_generichash_init(&st, key->k, LINK_KEY_BYTES, LINK_AUTH_TAG_BYTES);
    crypto_generichash_update(&st, msg, len);
    crypto_generichash_final(&st, tag, LINK_AUTH_TAG_BYTES);
    sodium_memzero(&st, sizeof(st));
}

void link_crypto_wipe(void *p, size_t len)
{
    sodium_memzero(p, len);
}
