/* Cuts a byte stream of the host link (USB bulk, both ends) into whole protocol frames; the
 * board's link thread and the host's USB link use the same framer. */
#ifndef ARGIL_LINK_FRAMER_H
#define ARGIL_LINK_FRAMER_H

#include <stddef.h>
#include <stdint.h>

#include "shared/proto.h"

/* Size of the frame whose header starts buf (header length field + header + CRC), or 0 when
 * fewer than PROTO_HEADER_SIZE bytes are given, the magic is wrong or it would exceed
 * PROTO_FRAME_MAX. */
size_t link_frame_size(const uint8_t *buf, size_t len);

typedef struct {
    uint8_t buf[2u * PROTO_FRAME_MAX];
    size_t len;
    uint32_t skipped_bytes;     /* bytes dropped while looking for a frame start */
} link_framer_t;

/* Empties the framer and zeroes its skipped-byte count. */
void link_framer_init(link_framer_t *fr);
/* Appends bytes (at most sizeof(buf) - len are taken; returns how many). */
size_t link_framer_feed(link_framer_t *fr, const uint8_t *data, size_t len);
/* Moves the next whole frame to out (cap ≥ PROTO_FRAME_MAX); returns its size or 0. */
size_t link_framer_next(link_framer_t *fr, uint8_t *out, size_t cap);

#endif
