/* Growable float buffers the model reuses between calls (scratch space, undo snapshots). */
#ifndef ARGIL_F32_BUF_H
#define ARGIL_F32_BUF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>

/* Grows *buf (holding *cap_n floats) to hold at least n floats; false, with *buf and *cap_n
 * unchanged, when out of memory. Never shrinks. */
static inline bool f32_buf_reserve(float **buf, size_t *cap_n, size_t n)
{
    if (n <= *cap_n)
        return true;
    float *p = realloc(*buf, n * sizeof(float));
    if (p == NULL)
        return false;
    *buf = p;
    *cap_n = n;
    return true;
}

#endif
