/* The UDP link's envelope (docs/protocol.md "Authenticated UDP"): a datagram is one protocol
 * frame followed by a trailer, the session nonce (u64 LE) and a 16-byte tag over
 * "ARGL-UDP" ‖ direction ‖ nonce ‖ frame. The board's link thread and the host's UDP link both
 * build it; each supplies the keyed MAC (libsodium's BLAKE2b-128: firmware/hal/link_auth.h,
 * host/link/link_crypto.h), so this file stays freestanding: byte buffers in and out, no
 * sockets, no clock, no library. Never in the 1 kHz tick. */
#ifndef ARGIL_LINK_ENVELOPE_H
#define ARGIL_LINK_ENVELOPE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define LINK_KEY_BYTES 32u
#define LINK_AUTH_DOMAIN_BYTES 8u /* "ARGL-UDP" */
#define LINK_AUTH_NONCE_BYTES 8u
#define LINK_AUTH_TAG_BYTES 16u
#define LINK_AUTH_TRAILER_BYTES (LINK_AUTH_NONCE_BYTES + LINK_AUTH_TAG_BYTES)
#define LINK_AUTH_DGRAM_MAX (1024u + LINK_AUTH_TRAILER_BYTES) /* PROTO_FRAME_MAX + trailer */
/* The longest message a tag covers: domain, direction, nonce and the largest frame. */
#define LINK_AUTH_MSG_MAX (LINK_AUTH_DOMAIN_BYTES + 1u + LINK_AUTH_NONCE_BYTES + 1024u)

/* Who sent the datagram: part of what the tag covers, so a frame cannot be reflected. */
#define LINK_AUTH_HOST_TO_BOARD 1u
#define LINK_AUTH_BOARD_TO_HOST 2u

typedef struct {
    uint8_t k[LINK_KEY_BYTES];
} link_key_t;

typedef enum {
    LINK_AUTH_OK = 0,
    LINK_AUTH_ERR_SIZE = -1,  /* not exactly one whole frame (its header's length) + trailer */
    LINK_AUTH_ERR_TAG = -2,   /* the tag does not verify: another key, direction, or a changed
                               * byte of frame, nonce or tag */
    LINK_AUTH_ERR_NONCE = -3  /* the tag verifies, but the nonce is not the session's (nor 0 on a
                               * HELLO) */
} link_auth_err_t;

/* Writes the keyed tag of msg[0 … len) under key into tag (each side's libsodium BLAKE2b-128). */
typedef void (*link_auth_mac_fn)(const link_key_t *key, const uint8_t *msg, size_t len,
                                 uint8_t tag[LINK_AUTH_TAG_BYTES]);

/* Writes frame ‖ nonce ‖ tag (mac over the message) into out; returns len +
 * LINK_AUTH_TRAILER_BYTES, or 0 when cap is short or len is 0 or above 1024. out may not
 * overlap frame. */
size_t link_auth_seal(link_auth_mac_fn mac, const link_key_t *key, uint8_t direction,
                      uint64_t nonce, const uint8_t *frame, size_t len, uint8_t *out, size_t cap);

/* Verifies a datagram's tag (constant-time compare). On LINK_AUTH_OK *frame_len is the frame's
 * size (the frame is dgram[0 … *frame_len)) and *nonce the nonce it carried. */
link_auth_err_t link_auth_open(link_auth_mac_fn mac, const link_key_t *key, uint8_t direction,
                               const uint8_t *dgram, size_t len, size_t *frame_len,
                               uint64_t *nonce);

/* The board's rule for a verified host frame's nonce: the session's nonce (never 0), or 0 on a
 * HELLO (the host cannot know the nonce of a session it has not started yet). */
bool link_auth_nonce_ok(uint64_t session_nonce, uint64_t nonce, const uint8_t *frame,
                        size_t frame_len);

/* A host's side of the envelope: its key and MAC, and the board's session nonce as last heard
 * (0 until a datagram from the board told it). The host's UDP link and the test hosts use it. */
typedef struct {
    link_key_t key;
    link_auth_mac_fn mac;
    uint64_t nonce;
    uint32_t refused;            /* datagrams from the board whose tag did not verify */
    uint32_t held;               /* frames not sealed: no nonce known yet, and not a HELLO */
} link_auth_host_t;

void link_auth_host_init(link_auth_host_t *h, const link_key_t *key, link_auth_mac_fn mac);

/* Seals a host frame into out: a HELLO with nonce 0 (it starts a session whose nonce the host
 * cannot know), anything else with the board's nonce. 0 (counted in held) for a non-HELLO frame
 * while no nonce is known: the board would refuse it; 0 too when it does not fit. */
size_t link_auth_host_seal(link_auth_host_t *h, const uint8_t *frame, size_t len, uint8_t *out,
                           size_t cap);

/* Verifies a datagram from the board and learns its nonce (each session's arrives with the
 * board's answer to the HELLO). On LINK_AUTH_OK the frame is dgram[0 … *frame_len); a refusal
 * is counted in refused. */
link_auth_err_t link_auth_host_open(link_auth_host_t *h, const uint8_t *dgram, size_t len,
                                    size_t *frame_len);

/* Verdict names for logs and tests ("bad tag"). */
const char *link_auth_err_text(link_auth_err_t e);

#endif
