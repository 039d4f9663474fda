/* The UDP link's envelope (link_envelope.h): the message a tag covers, sealing and opening with
 * the caller's MAC, the nonce rule and the host's side. */
#include "shared/link_envelope.h"

#include <string.h>

#include "shared/proto.h"
#include "shared/wire.h"

_Static_assert(LINK_AUTH_DGRAM_MAX == PROTO_FRAME_MAX + LINK_AUTH_TRAILER_BYTES,
               "a datagram holds the largest frame and a trailer");
_Static_assert(LINK_AUTH_MSG_MAX == LINK_AUTH_DOMAIN_BYTES + 1u + LINK_AUTH_NONCE_BYTES +
                                        PROTO_FRAME_MAX,
               "a message holds the largest frame");

static const uint8_t AUTH_DOMAIN[LINK_AUTH_DOMAIN_BYTES] = {'A', 'R', 'G', 'L',
                                                            '-', 'U', 'D', 'P'};

/* tag = mac(key; "ARGL-UDP" ‖ direction ‖ nonce LE ‖ frame); len is at most PROTO_FRAME_MAX. */
static void compute_tag(link_auth_mac_fn mac, const link_key_t *key, uint8_t direction,
                        const uint8_t nonce_le[LINK_AUTH_NONCE_BYTES], const uint8_t *frame,
                        size_t len, uint8_t tag[LINK_AUTH_TAG_BYTES])
{
    uint8_t msg[LINK_AUTH_MSG_MAX];
    wire_writer_t w = wire_writer(msg, sizeof(msg));
    wire_put_bytes(&w, AUTH_DOMAIN, sizeof(AUTH_DOMAIN));
    wire_put_u8(&w, direction);
    wire_put_bytes(&w, nonce_le, LINK_AUTH_NONCE_BYTES);
    wire_put_bytes(&w, frame, len);
    mac(key, msg, w.pos, tag);
}

/* True when the n bytes at a and b are equal, in a time that does not depend on where they
 * differ: every byte's difference is gathered before the one test. */
static bool tags_equal(const uint8_t *a, const uint8_t *b, size_t n)
{
    volatile uint8_t diff = 0;
    for (size_t i = 0; i < n; i++)
        diff = (uint8_t)(diff | (a[i] ^ b[i]));
    return diff == 0;
}

size_t link_auth_seal(link_auth_mac_fn mac, const link_key_t *key, uint8_t direction,
                      uint64_t nonce, const uint8_t *frame, size_t len, uint8_t *out, size_t cap)
{
    if (len == 0 || len > PROTO_FRAME_MAX || cap < len + LINK_AUTH_TRAILER_BYTES)
        return 0;
    wire_writer_t w = wire_writer(out, cap);
    wire_put_bytes(&w, frame, len);
    wire_put_u64(&w, nonce);
    compute_tag(mac, key, direction, out + len, frame, len, out + len + LINK_AUTH_NONCE_BYTES);
    return len + LINK_AUTH_TRAILER_BYTES;
}

link_auth_err_t link_auth_open(link_auth_mac_fn mac, const link_key_t *key, uint8_t direction,
                               const uint8_t *dgram, size_t len, size_t *frame_len,
                               uint64_t *nonce)
{
    if (len < PROTO_HEADER_SIZE + PROTO_CRC_SIZE + LINK_AUTH_TRAILER_BYTES)
        return LINK_AUTH_ERR_SIZE;
    const size_t flen = PROTO_HEADER_SIZE + PROTO_CRC_SIZE + le_get_u16(dgram + 6);
    if (flen > PROTO_FRAME_MAX || len != flen + LINK_AUTH_TRAILER_BYTES)
        return LINK_AUTH_ERR_SIZE;
    uint8_t tag[LINK_AUTH_TAG_BYTES];
    compute_tag(mac, key, direction, dgram + flen, dgram, flen, tag);
    if (!tags_equal(tag, dgram + flen + LINK_AUTH_NONCE_BYTES, LINK_AUTH_TAG_BYTES))
        return LINK_AUTH_ERR_TAG;
    wire_reader_t r = wire_reader(dgram + flen, LINK_AUTH_NONCE_BYTES);
    *frame_len = flen;
    *nonce = wire_get_u64(&r);
    return LINK_AUTH_OK;
}

bool link_auth_nonce_ok(uint64_t session_nonce, uint64_t nonce, const uint8_t *frame,
                        size_t frame_len)
{
    if (nonce == 0)
        return frame_len > PROTO_HEADER_SIZE && frame[5] == MSG_HELLO;
    return nonce == session_nonce;
}

void link_auth_host_init(link_auth_host_t *h, const link_key_t *key, link_auth_mac_fn mac)
{
    memset(h, 0, sizeof(*h));
    h->key = *key;
    h->mac = mac;
}

size_t link_auth_host_seal(link_auth_host_t *h, const uint8_t *frame, size_t len, uint8_t *out,
                           size_t cap)
{
    const bool hello = len > PROTO_HEADER_SIZE && frame[5] == MSG_HELLO;
    if (!hello && h->nonce == 0) {
        h->held++;
        return 0;
    }
    return link_auth_seal(h->mac, &h->key, LINK_AUTH_HOST_TO_BOARD, hello ? 0u : h->nonce, frame,
                          len, out, cap);
}

link_auth_err_t link_auth_host_open(link_auth_host_t *h, const uint8_t *dgram, size_t len,
                                    size_t *frame_len)
{
    uint64_t nonce = 0;
    const link_auth_err_t e =
        link_auth_open(h->mac, &h->key, LINK_AUTH_BOARD_TO_HOST, dgram, len, frame_len, &nonce);
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
