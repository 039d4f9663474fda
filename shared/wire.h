/* The one little-endian codec: loads and stores at a pointer (le_*: the wire protocol, CANopen
 * frames, USB descriptors and the host's files), and bounded cursors over them (wire_*) for the
 * wire protocol. A cursor that would run past its end stops moving and latches ok = false. */
#ifndef ARGIL_WIRE_H
#define ARGIL_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Stores the low n bytes of v at p, least significant first (n <= 8). */
static inline void le_put(uint8_t *p, uint64_t v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        p[i] = (uint8_t)(v >> (8u * i));
}

/* The n-byte little-endian value at p (n <= 8). */
static inline uint64_t le_get(const uint8_t *p, size_t n)
{
    uint64_t v = 0u;
    for (size_t i = 0; i < n; i++)
        v |= (uint64_t)p[i] << (8u * i);
    return v;
}

/* Stores v at p as a little-endian u16. */
static inline void le_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

/* Stores v at p as a little-endian u32. */
static inline void le_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* Stores v at p as a little-endian u64. */
static inline void le_put_u64(uint8_t *p, uint64_t v)
{
    le_put_u32(p, (uint32_t)v);
    le_put_u32(p + 4, (uint32_t)(v >> 32));
}

/* Stores v at p as its IEEE-754 bit pattern, little-endian. */
static inline void le_put_f32(uint8_t *p, float v)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    le_put_u32(p, bits);
}

/* The little-endian u16 at p. */
static inline uint16_t le_get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (uint16_t)p[1] << 8);
}

/* The little-endian u32 at p. */
static inline uint32_t le_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The little-endian u64 at p. */
static inline uint64_t le_get_u64(const uint8_t *p)
{
    return (uint64_t)le_get_u32(p) | (uint64_t)le_get_u32(p + 4) << 32;
}

/* The float whose little-endian IEEE-754 bit pattern is at p. */
static inline float le_get_f32(const uint8_t *p)
{
    const uint32_t bits = le_get_u32(p);
    float v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

typedef struct {
    uint8_t *buf;
    size_t cap;
    size_t pos;
    bool ok;
} wire_writer_t;

typedef struct {
    const uint8_t *buf;
    size_t len;
    size_t pos;
    bool ok;
} wire_reader_t;

/* A writer over buf[0..cap). */
static inline wire_writer_t wire_writer(uint8_t *buf, size_t cap)
{
    wire_writer_t w = { buf, cap, 0u, true };
    return w;
}

/* A reader over buf[0..len). */
static inline wire_reader_t wire_reader(const uint8_t *buf, size_t len)
{
    wire_reader_t r = { buf, len, 0u, true };
    return r;
}

/* Reserves n bytes at the cursor; NULL (and ok = false) when they do not fit. */
static inline uint8_t *wire_put_span(wire_writer_t *w, size_t n)
{
    if (!w->ok || n > w->cap - w->pos) {
        w->ok = false;
        return NULL;
    }
    uint8_t *p = w->buf + w->pos;
    w->pos += n;
    return p;
}

/* Writes v as n little-endian bytes (n <= 8). */
static inline void wire_put_le(wire_writer_t *w, uint64_t v, size_t n)
{
    uint8_t *p = wire_put_span(w, n);
    if (p != NULL)
        le_put(p, v, n);
}

/* Writes one byte. */
static inline void wire_put_u8(wire_writer_t *w, uint8_t v) { wire_put_le(w, v, 1u); }
/* Writes a little-endian u16. */
static inline void wire_put_u16(wire_writer_t *w, uint16_t v) { wire_put_le(w, v, 2u); }
/* Writes a little-endian u32. */
static inline void wire_put_u32(wire_writer_t *w, uint32_t v) { wire_put_le(w, v, 4u); }
/* Writes a little-endian u64. */
static inline void wire_put_u64(wire_writer_t *w, uint64_t v) { wire_put_le(w, v, 8u); }

/* Writes a float as its IEEE-754 bit pattern, little-endian. */
static inline void wire_put_f32(wire_writer_t *w, float v)
{
    uint8_t *p = wire_put_span(w, 4u);
    if (p != NULL)
        le_put_f32(p, v);
}

/* Writes n raw bytes. */
static inline void wire_put_bytes(wire_writer_t *w, const void *src, size_t n)
{
    uint8_t *p = wire_put_span(w, n);
    if (p != NULL && n > 0u)
        memcpy(p, src, n);
}

/* Returns the next n bytes and advances; NULL (and ok = false) when fewer remain. */
static inline const uint8_t *wire_get_span(wire_reader_t *r, size_t n)
{
    if (!r->ok || n > r->len - r->pos) {
        r->ok = false;
        return NULL;
    }
    const uint8_t *p = r->buf + r->pos;
    r->pos += n;
    return p;
}

/* Reads n little-endian bytes (n <= 8); 0 past the end. */
static inline uint64_t wire_get_le(wire_reader_t *r, size_t n)
{
    const uint8_t *p = wire_get_span(r, n);
    return p == NULL ? 0u : le_get(p, n);
}

/* Reads one byte. */
static inline uint8_t wire_get_u8(wire_reader_t *r) { return (uint8_t)wire_get_le(r, 1u); }
/* Reads a little-endian u16. */
static inline uint16_t wire_get_u16(wire_reader_t *r) { return (uint16_t)wire_get_le(r, 2u); }
/* Reads a little-endian u32. */
static inline uint32_t wire_get_u32(wire_reader_t *r) { return (uint32_t)wire_get_le(r, 4u); }
/* Reads a little-endian u64. */
static inline uint64_t wire_get_u64(wire_reader_t *r) { return wire_get_le(r, 8u); }

/* Reads a float from its little-endian IEEE-754 bit pattern. */
static inline float wire_get_f32(wire_reader_t *r)
{
    const uint8_t *p = wire_get_span(r, 4u);
    return p == NULL ? 0.0f : le_get_f32(p);
}

/* Copies n raw bytes into dst; zeros past the end. */
static inline void wire_get_bytes(wire_reader_t *r, void *dst, size_t n)
{
    const uint8_t *p = wire_get_span(r, n);
    if (p == NULL)
        memset(dst, 0, n);
    else if (n > 0u)
        memcpy(dst, p, n);
}

#endif
