/* Test helpers: a grid's samples by linear index over its dims box (x fastest), read and written
 * through the grid's accessors, so tests keep their dense arithmetic whatever the storage. */
#ifndef ARGIL_TEST_GRID_VIEW_H
#define ARGIL_TEST_GRID_VIEW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/grid.h"

/* Sample (x, y, z) of linear index i over the dims box, x fastest. */
typedef struct {
    int32_t x, y, z;
} gv_at_t;

static inline gv_at_t gv_at(const grid_t *g, size_t i)
{
    const gv_at_t a = {(int32_t)(i % (size_t)g->dims[0]),
                       (int32_t)(i / (size_t)g->dims[0] % (size_t)g->dims[1]),
                       (int32_t)(i / ((size_t)g->dims[0] * (size_t)g->dims[1]))};
    return a;
}

static inline void gv_xyz(const grid_t *g, size_t i, int32_t *x, int32_t *y, int32_t *z)
{
    const gv_at_t a = gv_at(g, i);
    *x = a.x;
    *y = a.y;
    *z = a.z;
}

/* The linear index of sample (x, y, z) over the dims box (the inverse of gv_at). */
static inline size_t gv_idx(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return (size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
}

/* Channel ch of sample i. */
static inline float gv_get(const grid_t *g, grid_ch_t ch, size_t i)
{
    const gv_at_t a = gv_at(g, i);
    return grid_get(g, ch, a.x, a.y, a.z);
}

/* Stores v in channel ch of sample i (and returns v). */
static inline float gv_set(grid_t *g, grid_ch_t ch, size_t i, float v)
{
    const gv_at_t a = gv_at(g, i);
    (void)grid_set(g, ch, a.x, a.y, a.z, v);
    return v;
}

/* Painted channel ch of sample i. */
static inline float gv_mat(const grid_t *g, grid_mat_t ch, size_t i)
{
    const gv_at_t a = gv_at(g, i);
    return grid_mat_get(g, ch, a.x, a.y, a.z);
}

/* Stores v in painted channel ch of sample i (and returns v). */
static inline float gv_mat_set(grid_t *g, grid_mat_t ch, size_t i, float v)
{
    const gv_at_t a = gv_at(g, i);
    (void)grid_mat_set(g, ch, a.x, a.y, a.z, v);
    return v;
}

/* Copies channel ch over the dims box into out (dims[0]*dims[1]*dims[2] floats); returns out. */
static inline float *gv_copy(const grid_t *g, grid_ch_t ch, float *out)
{
    const int32_t zero[3] = {0, 0, 0};
    grid_read_box(g, ch, zero, g->dims, out);
    return out;
}

/* Stores the dims box of channel ch from in. */
static inline void gv_put(grid_t *g, grid_ch_t ch, const float *in)
{
    const int32_t zero[3] = {0, 0, 0};
    (void)grid_write_box(g, ch, zero, g->dims, in);
}

/* True when a and b hold the same bits. */
static inline bool gv_bits(float a, float b)
{
    return memcmp(&a, &b, sizeof(float)) == 0;
}

/* True when channel ch over the dims box holds the bits of buf. */
static inline bool gv_equal(const grid_t *g, grid_ch_t ch, const float *buf)
{
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    for (size_t i = 0; i < n; i++) {
        const float v = gv_get(g, ch, i);
        if (memcmp(&v, &buf[i], sizeof(float)) != 0)
            return false;
    }
    return true;
}

/* True when channel ca of a and channel cb of b (same dims) hold the same bits. */
static inline bool gv_same(const grid_t *a, grid_ch_t ca, const grid_t *b, grid_ch_t cb)
{
    const size_t n = (size_t)a->dims[0] * (size_t)a->dims[1] * (size_t)a->dims[2];
    for (size_t i = 0; i < n; i++) {
        const float u = gv_get(a, ca, i), v = gv_get(b, cb, i);
        if (memcmp(&u, &v, sizeof(float)) != 0)
            return false;
    }
    return true;
}

/* A newly allocated copy of channel ch over the dims box (the caller frees it). */
static inline float *gv_dup(const grid_t *g, grid_ch_t ch)
{
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    float *out = malloc(n * sizeof(float));
    if (out != NULL)
        gv_copy(g, ch, out);
    return out;
}

/* Channel density over the dims box in a buffer the helper keeps (valid until the next call;
 * for handing a grid to the dense meshers). NULL when out of memory. */
static inline const float *gv_dense(const grid_t *g)
{
    static float *buf;
    static size_t cap;
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    if (n > cap) {
        float *b = realloc(buf, n * sizeof(float));
        if (b == NULL)
            return NULL;
        buf = b;
        cap = n;
    }
    return gv_copy(g, GRID_DENSITY, buf);
}

/* The colour of sample i into rgb (3 bytes); returns rgb. */
static inline uint8_t *gv_rgb(const grid_t *g, size_t i, uint8_t rgb[3])
{
    const gv_at_t a = gv_at(g, i);
    grid_rgb_get(g, a.x, a.y, a.z, rgb);
    return rgb;
}

/* Copies the colour over the dims box into out (3 bytes per sample); returns out. */
static inline uint8_t *gv_rgb_copy(const grid_t *g, uint8_t *out)
{
    const int32_t zero[3] = {0, 0, 0};
    grid_rgb_read_box(g, zero, g->dims, out);
    return out;
}

/* Stores the colour over the dims box from in (3 bytes per sample). */
static inline argil_err_t gv_rgb_store(grid_t *g, const uint8_t *in)
{
    const int32_t zero[3] = {0, 0, 0};
    return grid_rgb_write_box(g, zero, g->dims, in);
}

#endif
