/* Fixed-size 3-vector maths in single precision, header-only and freestanding. */
#ifndef ARGIL_VEC3_H
#define ARGIL_VEC3_H

#include <math.h>
#include <stdbool.h>

typedef struct {
    float x, y, z;
} vec3_t;

static inline vec3_t vec3(float x, float y, float z) { vec3_t v = {x, y, z}; return v; }
/* A double-precision triple rounded to a vec3_t. */
static inline vec3_t vec3_from_d(const double d[3])
{
    return vec3((float)d[0], (float)d[1], (float)d[2]);
}
static inline vec3_t vec3_add(vec3_t a, vec3_t b) { return vec3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3_t vec3_sub(vec3_t a, vec3_t b) { return vec3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3_t vec3_scale(vec3_t a, float s) { return vec3(a.x * s, a.y * s, a.z * s); }
static inline float vec3_dot(vec3_t a, vec3_t b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3_t vec3_cross(vec3_t a, vec3_t b)
{
    return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float vec3_norm(vec3_t a) { return sqrtf(vec3_dot(a, a)); }
static inline bool vec3_isfinite(vec3_t a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Returns a scaled so its length is at most max_len (a itself when shorter). */
static inline vec3_t vec3_clamp_len(vec3_t a, float max_len)
{
    float n = vec3_norm(a);
    return (n > max_len && n > 0.0f) ? vec3_scale(a, max_len / n) : a;
}

#endif
