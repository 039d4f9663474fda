/* The board's local density window: the part of the host's field around the tool, double
 * buffered. The host's chunks fill the back buffer; a complete window is swapped in at a tick
 * boundary, and the active one takes one density-spring step per tick. */
#ifndef ARGIL_WINDOW_H
#define ARGIL_WINDOW_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/density_springs.h"
#include "shared/proto.h"
#include "shared/vec3.h"

typedef struct {
    bool valid;
    uint32_t version;
    uint32_t impulse_seq;          /* host had applied impulses up to this batch */
    int32_t dims[3];
    vec3_t origin_m;
    float spacing_m;
    float iso;
    spring_material_t material;
    /* What the host sent: densities, then (channels = 2) per-node stiffness. */
    float field[PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX];
    float *density;                /* = field */
    const float *node_stiffness;   /* = field + N, or NULL when the stiffness is uniform */
    float max_stiffness;           /* largest node stiffness (or the uniform one) */
    float rest[ARGIL_WINDOW_SAMPLES_MAX];
    float velocity[ARGIL_WINDOW_SAMPLES_MAX];
    float force[ARGIL_WINDOW_SAMPLES_MAX];
} window_buf_t;

typedef struct {
    window_buf_t buf[2];
    uint8_t active;                /* index of the buffer in use */
    bool pending;                  /* the back buffer holds a complete, checked window */
    window_asm_t assembler;        /* writes into buf[!active].field */
    float asm_max_stiffness;       /* largest node stiffness among the chunks assembled so far
                                    * (kept chunk by chunk: no tick scans a whole window) */
    uint32_t chunks_refused;
} window_t;

void window_init(window_t *w);

/* The window the tick uses, or NULL before the first one arrived. */
const window_buf_t *window_active(const window_t *w);
window_buf_t *window_active_mut(window_t *w);

/* Feeds one decoded WINDOW chunk. Returns PROTO_OK, PROTO_ERR_CHUNK (inconsistent) or
 * PROTO_ERR_VALUE (non-finite samples: the window is refused). */
proto_err_t window_feed(window_t *w, const msg_window_t *chunk);

/* window_feed for a chunk proto_decode accepted (PROTO_OK): its checks are not repeated. */
proto_err_t window_feed_decoded(window_t *w, const msg_window_t *chunk);

/* True when a complete window waits to be swapped in. */
bool window_pending(const window_t *w);

/* Makes the pending window active (call at a tick boundary); its springs start at rest (set up
 * chunk by chunk by window_feed, so the swap itself only flips the buffers). */
void window_swap(window_t *w);

/* Trilinear density and its gradient (1/m) at a model-space point; false outside the window. */
bool window_sample(const window_buf_t *b, vec3_t p_m, float *density, vec3_t *gradient);

/* window_sample's density alone (bit for bit the same value), without the gradient. */
bool window_density(const window_buf_t *b, vec3_t p_m, float *density);

/* Linear index of sample (x,y,z), or -1 outside. */
static inline int32_t window_index(const window_buf_t *b, int32_t x, int32_t y, int32_t z)
{
    if (x < 0 || y < 0 || z < 0 || x >= b->dims[0] || y >= b->dims[1] || z >= b->dims[2])
        return -1;
    return x + b->dims[0] * (y + b->dims[1] * z);
}

/* Stiffness of the density spring at node i (per-node when the host sent it). */
static inline float window_node_stiffness(const window_buf_t *b, int32_t i)
{
    return b->node_stiffness ? b->node_stiffness[i] : b->material.stiffness;
}

/* Nodes in the window. */
static inline int32_t window_nodes(const window_buf_t *b)
{
    return b->dims[0] * b->dims[1] * b->dims[2];
}

/* Model-space position of sample (x,y,z). */
static inline vec3_t window_node_pos(const window_buf_t *b, int32_t x, int32_t y, int32_t z)
{
    return vec3(b->origin_m.x + (float)x * b->spacing_m, b->origin_m.y + (float)y * b->spacing_m,
                b->origin_m.z + (float)z * b->spacing_m);
}

/* Distance (m) from p to the nearest face of the window; negative outside. */
float window_edge_distance_m(const window_buf_t *b, vec3_t p_m);

#endif
