/* Lock-free SPSC byte-record ring: release stores publish, acquire loads observe. */
#include "spsc_ring.h"

#include <string.h>

#include "wire.h"

argil_err_t spsc_init(spsc_ring_t *r, uint8_t *storage, uint32_t capacity_bytes)
{
    if (r == NULL || storage == NULL || capacity_bytes < 16u ||
        (capacity_bytes & (capacity_bytes - 1u)) != 0u)
        return ARGIL_ERR_ARG;
    r->bytes = storage;
    r->mask = capacity_bytes - 1u;
    atomic_store_explicit(&r->head, 0u, memory_order_relaxed);
    atomic_store_explicit(&r->tail, 0u, memory_order_relaxed);
    atomic_store_explicit(&r->dropped, 0u, memory_order_relaxed);
    return ARGIL_OK;
}

/* Copies len bytes into the ring at free-running index at, wrapping once at most. */
static void copy_in(spsc_ring_t *r, uint32_t at, const uint8_t *src, uint32_t len)
{
    const uint32_t off = at & r->mask;
    const uint32_t first = (r->mask + 1u - off) < len ? (r->mask + 1u - off) : len;
    memcpy(r->bytes + off, src, first);
    if (len > first)
        memcpy(r->bytes, src + first, len - first);
}

static void copy_out(const spsc_ring_t *r, uint32_t at, uint8_t *dst, uint32_t len)
{
    const uint32_t off = at & r->mask;
    const uint32_t first = (r->mask + 1u - off) < len ? (r->mask + 1u - off) : len;
    memcpy(dst, r->bytes + off, first);
    if (len > first)
        memcpy(dst + first, r->bytes, len - first);
}

argil_err_t spsc_push(spsc_ring_t *r, const uint8_t *data, size_t len)
{
    const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
    const uint32_t head = atomic_load_explicit(&r->head, memory_order_acquire);
    const uint32_t free_bytes = r->mask + 1u - (tail - head);
    if (len > SPSC_RECORD_MAX || len + 2u > free_bytes) {
        atomic_fetch_add_explicit(&r->dropped, 1u, memory_order_relaxed);
        return ARGIL_ERR_FULL;
    }
    uint8_t hdr[2];
    le_put_u16(hdr, (uint16_t)len);
    copy_in(r, tail, hdr, 2u);
    if (len > 0)
        copy_in(r, tail + 2u, data, (uint32_t)len);
    atomic_store_explicit(&r->tail, tail + 2u + (uint32_t)len, memory_order_release);
    return ARGIL_OK;
}

size_t spsc_peek_len(spsc_ring_t *r)
{
    const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
    const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_acquire);
    if (tail - head < 2u)
        return 0;
    uint8_t hdr[2];
    copy_out(r, head, hdr, 2u);
    return le_get_u16(hdr);
}

argil_err_t spsc_pop(spsc_ring_t *r, uint8_t *buf, size_t cap, size_t *len)
{
    const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
    const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_acquire);
    if (tail - head < 2u)
        return ARGIL_ERR_EMPTY;
    uint8_t hdr[2];
    copy_out(r, head, hdr, 2u);
    const uint32_t n = le_get_u16(hdr);
    if (n > cap)
        return ARGIL_ERR_FULL;
    if (n > 0)
        copy_out(r, head + 2u, buf, n);
    *len = n;
    atomic_store_explicit(&r->head, head + 2u + n, memory_order_release);
    return ARGIL_OK;
}

bool spsc_skip(spsc_ring_t *r)
{
    const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
    const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_acquire);
    if (tail - head < 2u)
        return false;
    uint8_t hdr[2];
    copy_out(r, head, hdr, 2u);
    const uint32_t n = le_get_u16(hdr);
    atomic_store_explicit(&r->head, head + 2u + n, memory_order_release);
    return true;
}

uint32_t spsc_used(spsc_ring_t *r)
{
    return atomic_load_explicit(&r->tail, memory_order_acquire) -
           atomic_load_explicit(&r->head, memory_order_acquire);
}
