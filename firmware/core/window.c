/* Local density window: double buffer, chunk reassembly, trilinear sampling. */
#include "window.h"

#include <math.h>
#include <string.h>

static void asm_target_back(window_t *w)
{
    window_buf_t *back = &w->buf[w->active ^ 1u];
    window_asm_init(&w->assembler, back->field, PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX);
}

void window_init(window_t *w)
{
    w->active = 0;
    w->pending = false;
    w->chunks_refused = 0;
    w->asm_max_stiffness = 0.0f;
    for (int k = 0; k < 2; k++) {
        w->buf[k].valid = false;
        w->buf[k].density = w->buf[k].field;
        w->buf[k].node_stiffness = 0;
        w->buf[k].max_stiffness = 0.0f;
    }
    asm_target_back(w);
}

const window_buf_t *window_active(const window_t *w)
{
    const window_buf_t *b = &w->buf[w->active];
    return b->valid ? b : 0;
}

window_buf_t *window_active_mut(window_t *w)
{
    window_buf_t *b = &w->buf[w->active];
    return b->valid ? b : 0;
}

/* window_feed, with the chunk's own checks skipped when it came from proto_decode. */
static proto_err_t feed(window_t *w, const msg_window_t *chunk, bool decoded)
{
    const window_buf_t *cur = window_active(w);
    if (cur && chunk->version <= cur->version) {
        w->chunks_refused++;
        return PROTO_ERR_CHUNK; /* stale: older than or equal to the window in use */
    }
    if (w->pending && chunk->version > w->buf[w->active ^ 1u].version) {
        /* A newer window started before the pending one was swapped in: replace it. */
        w->pending = false;
    } else if (w->pending) {
        return PROTO_OK; /* a late copy of the pending window's chunks */
    }
    /* window_asm_feed checks the chunk (finite densities, finite non-negative stiffness:
     * chunk by chunk, so no tick pays for a whole window at once). A non-finite or negative
     * sample refuses the window being assembled. */
    const proto_err_t e = decoded ? window_asm_feed_decoded(&w->assembler, chunk)
                                  : window_asm_feed(&w->assembler, chunk);
    if (e != PROTO_OK) {
        w->chunks_refused++;
        if (e == PROTO_ERR_VALUE)
            asm_target_back(w);
        return e;
    }
    /* What window_swap would do for the whole window, done chunk by chunk so no tick pays for
     * it at once: the back buffer's springs start at rest (rest = density, no velocity, no
     * force) on the nodes whose densities this chunk carried. */
    window_buf_t *b = &w->buf[w->active ^ 1u];
    const uint32_t n_nodes = (uint32_t)chunk->dims[0] * chunk->dims[1] * chunk->dims[2];
    for (uint32_t k = 0; k < chunk->sample_count && chunk->first_sample + k < n_nodes; k++) {
        const uint32_t i = chunk->first_sample + k;
        b->rest[i] = b->field[i];
        b->velocity[i] = 0.0f;
        b->force[i] = 0.0f;
    }
    /* Likewise the largest node stiffness (channel 2: array index ≥ nodes); the first distinct
     * chunk of an assembly starts it again. */
    if (w->assembler.received == 1u)
        w->asm_max_stiffness = 0.0f;
    for (uint32_t k = chunk->first_sample < n_nodes ? n_nodes - chunk->first_sample : 0u;
         k < chunk->sample_count; k++)
        if (chunk->samples[k] > w->asm_max_stiffness)
            w->asm_max_stiffness = chunk->samples[k];
    if (!window_asm_complete(&w->assembler))
        return PROTO_OK;

    const msg_window_t *h = &w->assembler.head;
    const int32_t n = (int32_t)h->dims[0] * h->dims[1] * h->dims[2];
    b->version = h->version;
    b->impulse_seq = h->impulse_seq;
    for (int a = 0; a < 3; a++)
        b->dims[a] = h->dims[a];
    b->origin_m = vec3(h->origin_m[0], h->origin_m[1], h->origin_m[2]);
    b->spacing_m = h->spacing_m;
    b->iso = h->iso;
    /* Neighbour coupling is not on the wire: both sides use the default clay's. */
    spring_material_default(&b->material);
    b->material.node_mass = h->node_mass;
    b->material.stiffness = h->stiffness;
    b->material.damping = h->damping;
    b->material.plastic_rate_hz = h->plastic_rate_hz;
    b->density = b->field;
    b->node_stiffness = h->channels > 1 ? b->field + n : 0;
    b->max_stiffness = h->stiffness;
    if (b->node_stiffness && w->asm_max_stiffness > b->max_stiffness)
        b->max_stiffness = w->asm_max_stiffness;
    if (!spring_material_valid(&b->material)) {
        w->chunks_refused++;
        asm_target_back(w);
        return PROTO_ERR_VALUE;
    }
    w->pending = true;
    return PROTO_OK;
}

proto_err_t window_feed(window_t *w, const msg_window_t *chunk)
{
    return feed(w, chunk, false);
}

proto_err_t window_feed_decoded(window_t *w, const msg_window_t *chunk)
{
    return feed(w, chunk, true);
}

bool window_pending(const window_t *w)
{
    return w->pending;
}

void window_swap(window_t *w)
{
    if (!w->pending)
        return;
    w->active ^= 1u;
    window_buf_t *b = &w->buf[w->active];
    /* rest, velocity and force were set as the chunks arrived (window_feed). */
    b->valid = true;
    w->buf[w->active ^ 1u].valid = false;
    w->pending = false;
    asm_target_back(w);
}

/* Cell of p_m and the position within it: the corner's linear index in *i0 and the fractions
 * in t[3]; false outside the window. */
static bool window_cell(const window_buf_t *b, vec3_t p_m, int32_t *i0, float t[3])
{
    const float inv = 1.0f / b->spacing_m;
    const float u[3] = {(p_m.x - b->origin_m.x) * inv, (p_m.y - b->origin_m.y) * inv,
                        (p_m.z - b->origin_m.z) * inv};
    int32_t c[3];
    for (int a = 0; a < 3; a++) {
        if (!(u[a] >= 0.0f) || u[a] > (float)(b->dims[a] - 1))
            return false;
        c[a] = (int32_t)u[a]; /* u ≥ 0: truncation is the floor */
        if (c[a] > b->dims[a] - 2)
            c[a] = b->dims[a] - 2;
        t[a] = u[a] - (float)c[a];
    }
    *i0 = c[0] + b->dims[0] * c[1] + b->dims[0] * b->dims[1] * c[2];
    return true;
}

bool window_sample(const window_buf_t *b, vec3_t p_m, float *density, vec3_t *gradient)
{
    int32_t i0;
    float t[3];
    if (!window_cell(b, p_m, &i0, t))
        return false;
    const float inv = 1.0f / b->spacing_m;
    const int32_t sy = b->dims[0], sz = b->dims[0] * b->dims[1];
    const float *d = b->density;
    const float d000 = d[i0], d100 = d[i0 + 1], d010 = d[i0 + sy], d110 = d[i0 + sy + 1];
    const float d001 = d[i0 + sz], d101 = d[i0 + sz + 1], d011 = d[i0 + sz + sy],
                d111 = d[i0 + sz + sy + 1];
    const float tx = t[0], ty = t[1], tz = t[2];
    /* Trilinear interpolant and its exact derivatives within the cell. */
    const float x00 = d000 + tx * (d100 - d000), x10 = d010 + tx * (d110 - d010);
    const float x01 = d001 + tx * (d101 - d001), x11 = d011 + tx * (d111 - d011);
    const float y0 = x00 + ty * (x10 - x00), y1 = x01 + ty * (x11 - x01);
    *density = y0 + tz * (y1 - y0);
    const float dx00 = d100 - d000, dx10 = d110 - d010, dx01 = d101 - d001, dx11 = d111 - d011;
    const float dx0 = dx00 + ty * (dx10 - dx00), dx1 = dx01 + ty * (dx11 - dx01);
    const float gx = dx0 + tz * (dx1 - dx0);
    const float gy = (x10 - x00) + tz * ((x11 - x01) - (x10 - x00));
    const float gz = y1 - y0;
    *gradient = vec3(gx * inv, gy * inv, gz * inv);
    return true;
}

bool window_density(const window_buf_t *b, vec3_t p_m, float *density)
{
    int32_t i0;
    float t[3];
    if (!window_cell(b, p_m, &i0, t))
        return false;
    const int32_t sy = b->dims[0], sz = b->dims[0] * b->dims[1];
    const float *d = b->density;
    const float tx = t[0], ty = t[1], tz = t[2];
    /* The same operations, in the same order, as window_sample's density. */
    const float x00 = d[i0] + tx * (d[i0 + 1] - d[i0]);
    const float x10 = d[i0 + sy] + tx * (d[i0 + sy + 1] - d[i0 + sy]);
    const float x01 = d[i0 + sz] + tx * (d[i0 + sz + 1] - d[i0 + sz]);
    const float x11 = d[i0 + sz + sy] + tx * (d[i0 + sz + sy + 1] - d[i0 + sz + sy]);
    const float y0 = x00 + ty * (x10 - x00), y1 = x01 + ty * (x11 - x01);
    *density = y0 + tz * (y1 - y0);
    return true;
}

float window_edge_distance_m(const window_buf_t *b, vec3_t p_m)
{
    const float p[3] = {p_m.x - b->origin_m.x, p_m.y - b->origin_m.y, p_m.z - b->origin_m.z};
    float best = 1e30f;
    for (int a = 0; a < 3; a++) {
        const float ext = (float)(b->dims[a] - 1) * b->spacing_m;
        const float lo = p[a], hi = ext - p[a];
        if (lo < best) best = lo;
        if (hi < best) best = hi;
    }
    return best;
}
