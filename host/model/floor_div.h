/* Integer floor division and floor modulo: block keys and knot spans of lattice indices of any
 * sign (index i lies in block floor_div_i32(i, B) at offset floor_mod_i32(i, B)). */
#ifndef ARGIL_FLOOR_DIV_H
#define ARGIL_FLOOR_DIV_H

#include <stdint.h>

/* floor(a / b) for a of any sign; b > 0. */
static inline int32_t floor_div_i32(int32_t a, int32_t b)
{
    return a / b - (a % b < 0);
}

/* a - b * floor(a / b), in [0, b) for a of any sign; b > 0. */
static inline int32_t floor_mod_i32(int32_t a, int32_t b)
{
    const int32_t r = a % b;
    return r < 0 ? r + b : r;
}

#endif
