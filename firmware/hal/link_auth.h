/* libsodium for the board's side of the UDP link's envelope (shared/link_envelope.h): start-up,
 * the keyed BLAKE2b-128 MAC every datagram is sealed and verified with, session nonces, and
 * wiping a key. Hosted: the daemon's link thread and main, never firmware/core, never the 1 kHz
 * tick. */
#ifndef ARGIL_LINK_AUTH_H
#define ARGIL_LINK_AUTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/link_envelope.h"

/* Initialises libsodium (once per process, any thread; idempotent). False if it cannot run. */
bool link_auth_init(void);

/* The envelope's MAC (a link_auth_mac_fn): BLAKE2b keyed with key, 16 bytes of output. */
void link_auth_mac(const link_key_t *key, const uint8_t *msg, size_t len,
                   uint8_t tag[LINK_AUTH_TAG_BYTES]);

/* A fresh random nonce, never 0 (libsodium's randombytes_buf). */
uint64_t link_auth_new_nonce(void);

/* Zeroes len bytes at p in a way the compiler keeps (sodium_memzero): key copies. */
void link_auth_wipe(void *p, size_t len);

#endif
