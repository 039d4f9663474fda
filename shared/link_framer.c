/* Cuts a byte stream from the host link into whole protocol frames. */
#include <string.h>

#include "link_framer.h"
#include "wire.h"

size_t link_frame_size(const uint8_t *buf, size_t len)
{
    if (len < PROTO_HEADER_SIZE)
        return 0;
    if (le_get_u32(buf) != PROTO_MAGIC)
        return 0;
    const size_t payload = le_get_u16(buf + 6);
    const size_t total = PROTO_HEADER_SIZE + payload + PROTO_CRC_SIZE;
    return total <= PROTO_FRAME_MAX ? total : 0;
}

void link_framer_init(link_framer_t *fr)
{
    fr->len = 0;
    fr->skipped_bytes = 0;
}

size_t link_framer_feed(link_framer_t *fr, const uint8_t *data, size_t len)
{
    const size_t room = sizeof(fr->buf) - fr->len;
    const size_t n = len < room ? len : room;
    memcpy(fr->buf + fr->len, data, n);
    fr->len += n;
    return n;
}

size_t link_framer_next(link_framer_t *fr, uint8_t *out, size_t cap)
{
    for (;;) {
        if (fr->len < PROTO_HEADER_SIZE)
            return 0;
        const size_t size = link_frame_size(fr->buf, fr->len);
        if (size == 0) {
            /* Not a frame start: drop one byte and look again. */
            memmove(fr->buf, fr->buf + 1, fr->len - 1u);
            fr->len--;
            fr->skipped_bytes++;
            continue;
        }
        if (size > fr->len)
            return 0; /* wait for the rest */
        if (size > cap)
            return 0;
        memcpy(out, fr->buf, size);
        memmove(fr->buf, fr->buf + size, fr->len - size);
        fr->len -= size;
        return size;
    }
}
