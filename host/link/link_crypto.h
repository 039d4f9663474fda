/* libsodium for the host's side of the UDP link's envelope (shared/link_envelope.h): start-up,
 * the keyed BLAKE2b-128 MAC every datagram is sealed and verified with, and wiping a key. The
 * host's UDP link (link_dgram.c), the key file (link_key_file.h) and the test hosts use it. */
#ifndef ARGIL_LINK_CRYPTO_H
#define ARGIL_LINK_CRYPTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/link_envelope.h"

/* Initialises libsodium (once per process, any thread; idempotent). False if it cannot run. */
bool link_crypto_init(void);

/* The envelope's MAC (a link_auth_mac_fn): BLAKE2b keyed with key, 16 bytes of output. */
void link_crypto_mac(const link_key_t *key, const uint8_t *msg, size_t len,
                     uint8_t tag[LINK_AUTH_TAG_BYTES]);

/* Zeroes len bytes at p in a way the compiler keeps (sodium_memzero): key copies. */
void link_crypto_wipe(void *p, size_t len);

#endif
