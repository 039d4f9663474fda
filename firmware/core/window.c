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

proto_err_t window_feed(window_t *w, const msg_window_t *chunk)
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
    /* Finite densities, non-negative finite stiffness: checked chunk by chunk, so no tick pays
     * for a whole window at once. */
    const uint32_t n_nodes = (uint32_t)chunk->dims[0] * chunk->dims[1] * chunk->dims[2];
    const uint16_t count = chunk->sample_count <= PROTO_WINDOW_CHUNK_SAMPLES ? chunk->sample_count
                                                                             : PROTO_WINDOW_CHUNK_SAMPLES;
    for (uint16_t k = 0; k < count; k++) {
        const float v = chunk->samples[k];
        if (!isfinite(v) || (chunk->first_sample + k >= n_nodes && v < 0.0f)) {
            w->chunks_refused++;
            asm_target_back(w);
            return PROTO_ERR_VALUE;
        }
    }
    const proto_err_t e = window_asm_feed(&w->assembler, chunk);
    if (e != PROTO_OK) {
        w->chunks_refused++;
        return e;
    }
    if (!window_asm_complete(&w->assembler))
        return PROTO_OK;

    const msg_window_t *h = &w->assembler.head;
    window_buf_t *b = &w->buf[w->active ^ 1u];
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
    for (int32_t i = 0; b->node_stiffness && i < n; i++)
        if (b->node_stiffness[i] > b->max_stiffness)
            b->max_stiffness = b->node_stiffness[i];
    if (!spring_material_valid(&b->material)) {
        w->chunks_refused++;
        asm_target_back(w);
        return PROTO_ERR_VALUE;
    }
    w->pending = true;
    return PROTO_OK;
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
    const int32_t n = window_nodes(b);
    memcpy(b->rest, b->density, (size_t)n * sizeof(float));
    memset(b->velocity, 0, (size_t)n * sizeof(float));
    memset(b->force, 0, (size_t)n * sizeof(float));
    b->valid = true;
    w->buf[w->active ^ 1u].valid = false;
    w->pending = false;
    asm_target_back(w);
}

int32_t window_index(const window_buf_t *b, int32_t x, int32_t y, int32_t z)
{
    if (x < 0 || y < 0 || z < 0 || x >= b->dims[0] || y >= b->dims[1] || z >= b->dims[2])
        return -1;
    return x + b->dims[0] * (y + b->dims[1] * z);
}

vec3_t window_node_pos(const window_buf_t *b, int32_t x, int32_t y, int32_t z)
{
    return vec3(b->origin_m.x + (float)x * b->spacing_m, b->origin_m.y + (float)y * b->spacing_m,
                b->origin_m.z + (float)z * b->spacing_m);
}

bool window_sample(const window_buf_t *b, vec3_t p_m, float *density, vec3_t *gradient)
{
    const float inv = 1.0f / b->spacing_m;
    const float u[3] = {(p_m.x - b->origin_m.x) * inv, (p_m.y - b->origin_m.y) * inv,
                        (p_m.z - b->origin_m.z) * inv};
    int32_t c[3];
    float t[3];
    for (int a = 0; a < 3; a++) {
        if (!(u[a] >= 0.0f) || u[a] > (float)(b->dims[a] - 1))
            return false;
        c[a] = (int32_t)floorf(u[a]);
        if (c[a] > b->dims[a] - 2)
            c[a] = b->dims[a] - 2;
        t[a] = u[a] - (float)c[a];
    }
    const int32_t sy = b->dims[0], sz = b->dims[0] * b->dims[1];
    const int32_t i0 = c[0] + sy * c[1] + sz * c[2];
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
