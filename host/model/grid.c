/* Sparse density grid on the host heap: GRID_B³ blocks in a hash, sphere fill, hard carving,
 * trilinear sampling, the windows cut for the board and the springs' step. Density profile after
 * Ferley et al. §3 (values ramp across a band); sparse working space after Ferley et al. §3.1. */
#include "host/model/grid.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/floor_div.h"

/* Largest |sample index| computed from a position; keeps int32 arithmetic far from overflow. */
#define GRID_INDEX_LIMIT 1.0e9
#define GRID_CAP0 64 /* hash slots of a new grid */

_Static_assert(offsetof(grid_block_t, key) == 0, "a block_table entry starts with its key");

static bool same_bits(float a, float b)
{
    return memcmp(&a, &b, sizeof(float)) == 0;
}

static grid_block_t *block_find(const grid_t *g, const int32_t k[3])
{
    return block_table_find(&g->blocks, k);
}

/* Grows the bounds of what the blocks hold by the sample box [lo, hi). */
static void bounds_box(grid_t *g, const int32_t lo[3], const int32_t hi[3])
{
    const bool none = g->blo[0] > g->bhi[0];
    for (int a = 0; a < 3; a++) {
        if (none || lo[a] < g->blo[a])
            g->blo[a] = lo[a];
        if (none || hi[a] > g->bhi[a])
            g->bhi[a] = hi[a];
    }
}

static void bounds_add(grid_t *g, const int32_t k[3])
{
    const int32_t lo[3] = {k[0] * GRID_B, k[1] * GRID_B, k[2] * GRID_B};
    const int32_t hi[3] = {lo[0] + GRID_B, lo[1] + GRID_B, lo[2] + GRID_B};
    bounds_box(g, lo, hi);
}

static void bounds_sample(grid_t *g, int32_t x, int32_t y, int32_t z)
{
    const int32_t lo[3] = {x, y, z}, hi[3] = {x + 1, y + 1, z + 1};
    bounds_box(g, lo, hi);
}

/* The block at k, made (uniform 0: empty clay) when absent; NULL when out of memory. */
static grid_block_t *block_touch(grid_t *g, const int32_t k[3])
{
    void *b;
    return block_table_insert(&g->blocks, k, &b) == ARGIL_OK ? b : NULL;
}

/* What an array-less block holds in channel ch. */
static float uniform_of(const grid_block_t *b, grid_ch_t ch)
{
    return b != NULL && (ch == GRID_DENSITY || ch == GRID_REST) ? b->uniform : 0.0f;
}

/* A block's worth of n_ch channels, channel c filled with fill[c]; NULL when out of memory. */
static float *channels_new(int n_ch, const float *fill)
{
    float *p = malloc(sizeof(float) * (size_t)n_ch * GRID_BN);
    if (p != NULL)
        for (int c = 0; c < n_ch; c++)
            for (int i = 0; i < GRID_BN; i++)
                p[c * GRID_BN + i] = fill[c];
    return p;
}

/* Gives b its sample arrays (filled with what it held); false when out of memory. */
static bool block_data(grid_t *g, grid_block_t *b)
{
    if (b->data != NULL)
        return true;
    float held[GRID_CH_N];
    for (int c = 0; c < GRID_CH_N; c++)
        held[c] = uniform_of(b, (grid_ch_t)c);
    b->data = channels_new(GRID_CH_N, held);
    g->data_blocks += b->data != NULL;
    return b->data != NULL;
}

/* Gives b its painted channels (filled with their defaults); false when out of memory. */
static bool block_mat(grid_t *g, grid_block_t *b)
{
    if (b->mat != NULL)
        return true;
    float def[GRID_MAT_N];
    for (int c = 0; c < GRID_MAT_N; c++)
        def[c] = grid_mat_default((grid_mat_t)c);
    b->mat = channels_new(GRID_MAT_N, def);
    g->mat_blocks += b->mat != NULL;
    return b->mat != NULL;
}

static void split(int32_t x, int32_t y, int32_t z, int32_t k[3], int *li)
{
    k[0] = floor_div_i32(x, GRID_B);
    k[1] = floor_div_i32(y, GRID_B);
    k[2] = floor_div_i32(z, GRID_B);
    *li = (x - k[0] * GRID_B) + GRID_B * ((y - k[1] * GRID_B) + GRID_B * (z - k[2] * GRID_B));
}

static vec3_t grid_sample_pos(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return vec3(g->origin_m.x + g->spacing_m * (float)x, g->origin_m.y + g->spacing_m * (float)y,
                g->origin_m.z + g->spacing_m * (float)z);
}

/* p in sample-index units, per axis, as doubles. */
static void grid_to_index(const grid_t *g, vec3_t p_m, double u[3])
{
    const double s = (double)g->spacing_m;
    u[0] = ((double)p_m.x - (double)g->origin_m.x) / s;
    u[1] = ((double)p_m.y - (double)g->origin_m.y) / s;
    u[2] = ((double)p_m.z - (double)g->origin_m.z) / s;
}

argil_err_t grid_init(grid_t *g, const int32_t dims[3], float spacing_m, vec3_t origin_m)
{
    memset(g, 0, sizeof(*g));
    int64_t n = 1;
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 1 || dims[a] > GRID_SAMPLES_MAX)
            return ARGIL_ERR_ARG;
        n *= dims[a];
        if (n > GRID_SAMPLES_MAX)
            return ARGIL_ERR_ARG;
    }
    if (!isfinite(spacing_m) || !(spacing_m > 0.0f))
        return ARGIL_ERR_ARG;
    if (!vec3_isfinite(origin_m))
        return ARGIL_ERR_NONFINITE;
    for (int a = 0; a < 3; a++) {
        g->dims[a] = dims[a];
        g->blo[a] = 1;
        g->bhi[a] = 0;
    }
    g->spacing_m = spacing_m;
    g->origin_m = origin_m;
    g->iso = 0.5f;
    g->band_m = 4.0f * spacing_m;
    spring_material_default(&g->material);
    const argil_err_t e = block_table_init(&g->blocks, sizeof(grid_block_t), GRID_CAP0);
    if (e != ARGIL_OK)
        grid_free(g);
    return e;
}

void grid_free(grid_t *g)
{
    size_t slot = 0;
    for (grid_block_t *b; (b = block_table_next(&g->blocks, &slot)) != NULL;) {
        free(b->data);
        free(b->mat);
        free(b->rgb);
    }
    block_table_free(&g->blocks);
    g->data_blocks = g->mat_blocks = g->rgb_blocks = 0;
    for (int c = 0; c < GRID_MAT_N; c++)
        g->painted[c] = false;
    g->dims[0] = g->dims[1] = g->dims[2] = 0;
}

float grid_mat_default(grid_mat_t ch)
{
    return ch == GRID_MAT_RESTLEN ? 0.0f : 1.0f;
}

bool grid_mat_valid(grid_mat_t ch, float v)
{
    if (!isfinite(v) || (unsigned)ch >= GRID_MAT_N)
        return false;
    if (ch == GRID_MAT_MASS)
        return v > 0.0f;
    return ch == GRID_MAT_RESTLEN || v >= 0.0f;
}

void grid_bounds(const grid_t *g, int32_t lo[3], int32_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = 0;
        hi[a] = g->dims[a];
        if (g->blo[a] <= g->bhi[a]) {
            lo[a] = g->blo[a] < lo[a] ? g->blo[a] : lo[a];
            hi[a] = g->bhi[a] > hi[a] ? g->bhi[a] : hi[a];
        }
    }
}

size_t grid_count(const grid_t *g)
{
    if (g->blocks.entries == NULL)
        return 0;
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    return (size_t)(hi[0] - lo[0]) * (size_t)(hi[1] - lo[1]) * (size_t)(hi[2] - lo[2]);
}

bool grid_clip(const grid_t *g, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
               int32_t chi[3])
{
    (void)g;
    for (int a = 0; a < 3; a++) {
        clo[a] = lo[a] < -GRID_INDEX_MAX ? -GRID_INDEX_MAX : lo[a];
        chi[a] = hi[a] > GRID_INDEX_MAX ? GRID_INDEX_MAX : hi[a];
        if (chi[a] <= clo[a])
            return false;
    }
    return true;
}

bool grid_holds(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    (void)g;
    return x >= -GRID_INDEX_MAX && y >= -GRID_INDEX_MAX && z >= -GRID_INDEX_MAX &&
           x < GRID_INDEX_MAX && y < GRID_INDEX_MAX && z < GRID_INDEX_MAX;
}

float grid_get(const grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z)
{
    if ((unsigned)ch >= GRID_CH_N || !grid_holds(g, x, y, z))
        return 0.0f;
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    const grid_block_t *b = block_find(g, k);
    if (b == NULL || b->data == NULL)
        return uniform_of(b, ch);
    return b->data[ch * GRID_BN + li];
}

argil_err_t grid_set(grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z, float v)
{
    if ((unsigned)ch >= GRID_CH_N || !grid_holds(g, x, y, z) || g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    grid_block_t *b = block_find(g, k);
    if ((b == NULL || b->data == NULL) && same_bits(v, uniform_of(b, ch)))
        return ARGIL_OK;
    if (b == NULL && (b = block_touch(g, k)) == NULL)
        return ARGIL_ERR_NOMEM;
    if (!block_data(g, b))
        return ARGIL_ERR_NOMEM;
    b->data[ch * GRID_BN + li] = v;
    if (!same_bits(v, 0.0f))
        bounds_sample(g, x, y, z);
    return ARGIL_OK;
}

/* Samples in a box of n per axis; 0 when any axis is empty. */
static size_t box_count(const int32_t n[3])
{
    if (n[0] <= 0 || n[1] <= 0 || n[2] <= 0)
        return 0;
    return (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
}

/* Sets lo and n to the grid's bounding box and returns its sample count. */
static size_t dense_box(const grid_t *g, int32_t lo[3], int32_t n[3])
{
    int32_t hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        n[a] = hi[a] - lo[a];
    return box_count(n);
}

/* True when a and b have the same bounding box, which lo and n are set to (n: samples per axis). */
static bool same_box(const grid_t *a, const grid_t *b, int32_t lo[3], int32_t n[3])
{
    int32_t blo[3], bhi[3];
    (void)dense_box(a, lo, n);
    grid_bounds(b, blo, bhi);
    for (int q = 0; q < 3; q++)
        if (lo[q] != blo[q] || lo[q] + n[q] != bhi[q])
            return false;
    return true;
}

/* Calls fn for each block overlapping the box [lo, lo+n) with the part [a0, a1) of the box it
 * covers (clipped to the held indices); stops at the first false. */
typedef bool (*box_fn)(void *ctx, const int32_t k[3], const int32_t a0[3], const int32_t a1[3]);

static bool for_blocks(const grid_t *g, const int32_t lo[3], const int32_t n[3], box_fn fn,
                       void *ctx)
{
    int32_t c0[3], c1[3], hi[3];
    for (int a = 0; a < 3; a++) {
        if (n[a] <= 0)
            return true;
        hi[a] = (int32_t)((int64_t)lo[a] + n[a] > GRID_INDEX_MAX ? GRID_INDEX_MAX
                                                                  : (int64_t)lo[a] + n[a]);
    }
    if (!grid_clip(g, lo, hi, c0, c1))
        return true;
    int32_t k0[3], k1[3];
    for (int a = 0; a < 3; a++) {
        k0[a] = floor_div_i32(c0[a], GRID_B);
        k1[a] = floor_div_i32(c1[a] - 1, GRID_B);
    }
    int32_t k[3];
    for (k[2] = k0[2]; k[2] <= k1[2]; k[2]++)
        for (k[1] = k0[1]; k[1] <= k1[1]; k[1]++)
            for (k[0] = k0[0]; k[0] <= k1[0]; k[0]++) {
                int32_t a0[3], a1[3];
                for (int a = 0; a < 3; a++) {
                    const int32_t b0 = k[a] * GRID_B, b1 = b0 + GRID_B;
                    a0[a] = c0[a] > b0 ? c0[a] : b0;
                    a1[a] = c1[a] < b1 ? c1[a] : b1;
                }
                if (!fn(ctx, k, a0, a1))
                    return false;
            }
    return true;
}

typedef struct {
    grid_t *g;
    int ch;           /* grid_ch_t, or GRID_CH_N + grid_mat_t for a painted channel */
    const int32_t *lo, *n;
    float *buf;
    bool write;
    argil_err_t err;
} box_ctx_t;

static size_t buf_at(const box_ctx_t *c, int32_t x, int32_t y, int32_t z)
{
    return (size_t)(x - c->lo[0]) +
           (size_t)c->n[0] * ((size_t)(y - c->lo[1]) + (size_t)c->n[1] * (size_t)(z - c->lo[2]));
}

static int local_at(const int32_t k[3], int32_t x, int32_t y, int32_t z)
{
    return (x - k[0] * GRID_B) + GRID_B * ((y - k[1] * GRID_B) + GRID_B * (z - k[2] * GRID_B));
}

/* The array of ctx's channel in b (NULL when b holds none for it) and its default value. */
static float *chan_of(const box_ctx_t *c, const grid_block_t *b, float *def)
{
    if (c->ch < GRID_CH_N) {
        *def = uniform_of(b, (grid_ch_t)c->ch);
        return b != NULL && b->data != NULL ? b->data + c->ch * GRID_BN : NULL;
    }
    const int m = c->ch - GRID_CH_N;
    *def = grid_mat_default((grid_mat_t)m);
    return b != NULL && b->mat != NULL ? b->mat + m * GRID_BN : NULL;
}

static bool box_block(void *vctx, const int32_t k[3], const int32_t a0[3], const int32_t a1[3])
{
    box_ctx_t *c = vctx;
    grid_block_t *b = block_find(c->g, k);
    float def;
    float *arr = chan_of(c, b, &def);
    const int32_t w = a1[0] - a0[0];
    if (!c->write) {
        const size_t row = (size_t)c->n[0];
        for (int32_t z = a0[2]; z < a1[2]; z++) {
            float *o = c->buf + buf_at(c, a0[0], a0[1], z);
            if (arr == NULL) {
                for (int32_t y = a0[1]; y < a1[1]; y++, o += row)
                    for (int32_t x = 0; x < w; x++)
                        o[x] = def;
                continue;
            }
            const float *src = arr + local_at(k, a0[0], a0[1], z);
            if (w == GRID_B) /* a whole block row: a fixed-size copy the compiler inlines */
                for (int32_t y = a0[1]; y < a1[1]; y++, o += row, src += GRID_B)
                    memcpy(o, src, GRID_B * sizeof(float));
            else
                for (int32_t y = a0[1]; y < a1[1]; y++, o += row, src += GRID_B)
                    memcpy(o, src, (size_t)w * sizeof(float));
        }
        return true;
    }
    if (arr == NULL) {
        /* Nothing to store when every value is what the block already reads. */
        bool same = true;
        for (int32_t z = a0[2]; z < a1[2] && same; z++)
            for (int32_t y = a0[1]; y < a1[1] && same; y++) {
                const float *in = c->buf + buf_at(c, a0[0], y, z);
                for (int32_t x = 0; x < w && same; x++)
                    same = same_bits(in[x], def);
            }
        if (same)
            return true;
        if (b == NULL && (b = block_touch(c->g, k)) == NULL) {
            c->err = ARGIL_ERR_NOMEM;
            return false;
        }
        if (!(c->ch < GRID_CH_N ? block_data(c->g, b) : block_mat(c->g, b))) {
            c->err = ARGIL_ERR_NOMEM;
            return false;
        }
        arr = chan_of(c, b, &def);
    }
    const float empty =
        c->ch < GRID_CH_N ? 0.0f : grid_mat_default((grid_mat_t)(c->ch - GRID_CH_N));
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const float *in = c->buf + buf_at(c, a0[0], y, z);
            memcpy(arr + local_at(k, a0[0], y, z), in, (size_t)w * sizeof(float));
            int32_t first = 0, last = w - 1;
            while (first < w && same_bits(in[first], empty))
                first++;
            while (last > first && same_bits(in[last], empty))
                last--;
            if (first < w) {
                const int32_t lo[3] = {a0[0] + first, y, z};
                const int32_t hi[3] = {a0[0] + last + 1, y + 1, z + 1};
                bounds_box(c->g, lo, hi);
            }
        }
    return true;
}

static void fill(float *out, size_t n, float v)
{
    for (size_t i = 0; i < n; i++)
        out[i] = v;
}

static argil_err_t box_io(const grid_t *g, int ch, const int32_t lo[3], const int32_t n[3],
                          float *buf, bool write)
{
    box_ctx_t c = {(grid_t *)g, ch, lo, n, buf, write, ARGIL_OK};
    (void)for_blocks(g, lo, n, box_block, &c);
    return c.err;
}

/* True when the box [lo, lo+n) lies wholly within the held indices (every sample is read). */
static bool box_held(const int32_t lo[3], const int32_t n[3])
{
    for (int a = 0; a < 3; a++)
        if (lo[a] < -GRID_INDEX_MAX || (int64_t)lo[a] + n[a] > GRID_INDEX_MAX)
            return false;
    return true;
}

void grid_read_box(const grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                   float *out)
{
    if ((unsigned)ch >= GRID_CH_N || !box_held(lo, n))
        fill(out, box_count(n), 0.0f);
    if ((unsigned)ch < GRID_CH_N)
        (void)box_io(g, ch, lo, n, out, false);
}

argil_err_t grid_write_box(grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                           const float *in)
{
    if ((unsigned)ch >= GRID_CH_N || g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    return box_io(g, ch, lo, n, (float *)in, true);
}

float grid_mat_get(const grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z)
{
    if ((unsigned)ch >= GRID_MAT_N)
        return 0.0f;
    if (!grid_holds(g, x, y, z))
        return grid_mat_default(ch);
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    const grid_block_t *b = block_find(g, k);
    return b != NULL && b->mat != NULL ? b->mat[ch * GRID_BN + li] : grid_mat_default(ch);
}

argil_err_t grid_mat_set(grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z, float v)
{
    if ((unsigned)ch >= GRID_MAT_N || !grid_holds(g, x, y, z) || g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    g->painted[ch] = true;
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    grid_block_t *b = block_find(g, k);
    if ((b == NULL || b->mat == NULL) && same_bits(v, grid_mat_default(ch)))
        return ARGIL_OK;
    if (b == NULL && (b = block_touch(g, k)) == NULL)
        return ARGIL_ERR_NOMEM;
    if (!block_mat(g, b))
        return ARGIL_ERR_NOMEM;
    b->mat[ch * GRID_BN + li] = v;
    if (!same_bits(v, grid_mat_default(ch)))
        bounds_sample(g, x, y, z);
    return ARGIL_OK;
}

void grid_mat_read_box(const grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                       float *out)
{
    if ((unsigned)ch >= GRID_MAT_N)
        return;
    if (!box_held(lo, n))
        fill(out, box_count(n), grid_mat_default(ch));
    (void)box_io(g, GRID_CH_N + (int)ch, lo, n, out, false);
}

argil_err_t grid_mat_write_box(grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                               const float *in)
{
    if ((unsigned)ch >= GRID_MAT_N || g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    g->painted[ch] = true;
    return box_io(g, GRID_CH_N + (int)ch, lo, n, (float *)in, true);
}

bool grid_mat_painted(const grid_t *g, grid_mat_t ch)
{
    return (unsigned)ch < GRID_MAT_N && g->painted[ch];
}

bool grid_mat_equal(const grid_t *a, const grid_t *b, grid_mat_t ch)
{
    int32_t alo[3], n[3];
    if (!same_box(a, b, alo, n))
        return false;
    const size_t cnt = box_count(n);
    float *u = malloc(2 * cnt * sizeof(float));
    if (u == NULL)
        return false;
    grid_mat_read_box(a, ch, alo, n, u);
    grid_mat_read_box(b, ch, alo, n, u + cnt);
    const bool eq = memcmp(u, u + cnt, cnt * sizeof(float)) == 0;
    free(u);
    return eq;
}

/* ---- Painted colour ---- */

static bool rgb_default(const uint8_t *c, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (c[i] != GRID_RGB_DEFAULT)
            return false;
    return true;
}

static bool block_rgb(grid_t *g, grid_block_t *b)
{
    if (b->rgb != NULL)
        return true;
    b->rgb = malloc(3 * GRID_BN);
    if (b->rgb == NULL)
        return false;
    memset(b->rgb, (int)GRID_RGB_DEFAULT, 3 * GRID_BN);
    g->rgb_blocks++;
    return true;
}

void grid_rgb_get(const grid_t *g, int32_t x, int32_t y, int32_t z, uint8_t rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = (uint8_t)GRID_RGB_DEFAULT;
    if (!grid_holds(g, x, y, z))
        return;
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    const grid_block_t *b = block_find(g, k);
    if (b != NULL && b->rgb != NULL)
        memcpy(rgb, b->rgb + 3 * li, 3);
}

argil_err_t grid_rgb_set(grid_t *g, int32_t x, int32_t y, int32_t z, const uint8_t rgb[3])
{
    if (!grid_holds(g, x, y, z) || g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    int32_t k[3];
    int li;
    split(x, y, z, k, &li);
    grid_block_t *b = block_find(g, k);
    const bool def = rgb_default(rgb, 3);
    if ((b == NULL || b->rgb == NULL) && def)
        return ARGIL_OK;
    if (b == NULL && (b = block_touch(g, k)) == NULL)
        return ARGIL_ERR_NOMEM;
    if (!block_rgb(g, b))
        return ARGIL_ERR_NOMEM;
    memcpy(b->rgb + 3 * li, rgb, 3);
    if (!def)
        bounds_sample(g, x, y, z);
    return ARGIL_OK;
}

typedef struct {
    grid_t *g;
    const int32_t *lo, *n;
    uint8_t *buf;
    bool write;
    argil_err_t err;
} rgb_ctx_t;

static bool rgb_block(void *vctx, const int32_t k[3], const int32_t a0[3], const int32_t a1[3])
{
    rgb_ctx_t *c = vctx;
    grid_block_t *b = block_find(c->g, k);
    const size_t w = (size_t)(a1[0] - a0[0]);
    const box_ctx_t at = {c->g, 0, c->lo, c->n, NULL, false, ARGIL_OK};
    if (!c->write) {
        for (int32_t z = a0[2]; z < a1[2]; z++)
            for (int32_t y = a0[1]; y < a1[1]; y++) {
                uint8_t *o = c->buf + 3 * buf_at(&at, a0[0], y, z);
                if (b == NULL || b->rgb == NULL)
                    memset(o, (int)GRID_RGB_DEFAULT, 3 * w);
                else
                    memcpy(o, b->rgb + 3 * local_at(k, a0[0], y, z), 3 * w);
            }
        return true;
    }
    if (b == NULL || b->rgb == NULL) {
        bool same = true;
        for (int32_t z = a0[2]; z < a1[2] && same; z++)
            for (int32_t y = a0[1]; y < a1[1] && same; y++)
                same = rgb_default(c->buf + 3 * buf_at(&at, a0[0], y, z), 3 * w);
        if (same)
            return true;
        if ((b == NULL && (b = block_touch(c->g, k)) == NULL) || !block_rgb(c->g, b)) {
            c->err = ARGIL_ERR_NOMEM;
            return false;
        }
    }
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            const uint8_t *in = c->buf + 3 * buf_at(&at, a0[0], y, z);
            memcpy(b->rgb + 3 * local_at(k, a0[0], y, z), in, 3 * w);
            size_t first = 0, last = w;
            while (first < w && rgb_default(in + 3 * first, 3))
                first++;
            while (last > first && rgb_default(in + 3 * (last - 1), 3))
                last--;
            if (first < last) {
                const int32_t lo[3] = {a0[0] + (int32_t)first, y, z};
                const int32_t hi[3] = {a0[0] + (int32_t)last, y + 1, z + 1};
                bounds_box(c->g, lo, hi);
            }
        }
    return true;
}

void grid_rgb_read_box(const grid_t *g, const int32_t lo[3], const int32_t n[3], uint8_t *out)
{
    if (!box_held(lo, n))
        memset(out, (int)GRID_RGB_DEFAULT, 3 * box_count(n));
    rgb_ctx_t c = {(grid_t *)g, lo, n, out, false, ARGIL_OK};
    (void)for_blocks(g, lo, n, rgb_block, &c);
}

argil_err_t grid_rgb_write_box(grid_t *g, const int32_t lo[3], const int32_t n[3],
                               const uint8_t *in)
{
    if (g->blocks.entries == NULL)
        return ARGIL_ERR_ARG;
    rgb_ctx_t c = {g, lo, n, (uint8_t *)in, true, ARGIL_OK};
    (void)for_blocks(g, lo, n, rgb_block, &c);
    return c.err;
}

bool grid_rgb_any(const grid_t *g)
{
    return g->rgb_blocks > 0;
}

bool grid_rgb_painted(const grid_t *g)
{
    size_t slot = 0;
    const grid_block_t *b;
    while (g->rgb_blocks > 0 && (b = block_table_next(&g->blocks, &slot)) != NULL)
        if (b->rgb != NULL && !rgb_default(b->rgb, 3 * GRID_BN))
            return true;
    return false;
}

uint8_t *grid_dense_copy_rgb(const grid_t *g, int32_t lo[3], int32_t n[3])
{
    uint8_t *out = malloc(3 * dense_box(g, lo, n));
    if (out != NULL)
        grid_rgb_read_box(g, lo, n, out);
    return out;
}

bool grid_rgb_equal(const grid_t *a, const grid_t *b)
{
    int32_t alo[3], n[3];
    if (!same_box(a, b, alo, n))
        return false;
    if (!grid_rgb_any(a) && !grid_rgb_any(b))
        return true;
    const size_t cnt = 3 * box_count(n);
    uint8_t *u = malloc(2 * cnt);
    if (u == NULL)
        return false;
    grid_rgb_read_box(a, alo, n, u);
    grid_rgb_read_box(b, alo, n, u + cnt);
    const bool eq = memcmp(u, u + cnt, cnt) == 0;
    free(u);
    return eq;
}

float *grid_dense_copy(const grid_t *g, grid_ch_t ch, int32_t lo[3], int32_t n[3])
{
    float *out = malloc(dense_box(g, lo, n) * sizeof(float));
    if (out != NULL)
        grid_read_box(g, ch, lo, n, out);
    return out;
}

float *grid_dense_copy_mat(const grid_t *g, grid_mat_t ch, int32_t lo[3], int32_t n[3])
{
    float *out = malloc(dense_box(g, lo, n) * sizeof(float));
    if (out != NULL)
        grid_mat_read_box(g, ch, lo, n, out);
    return out;
}

vec3_t grid_box_origin(const grid_t *g, const int32_t lo[3])
{
    if (lo[0] == 0 && lo[1] == 0 && lo[2] == 0)
        return g->origin_m;
    return grid_sample_pos(g, lo[0], lo[1], lo[2]);
}

size_t grid_bytes(const grid_t *g)
{
    return block_table_bytes(&g->blocks) +
           (g->data_blocks * GRID_CH_N + g->mat_blocks * GRID_MAT_N) * GRID_BN * sizeof(float) +
           g->rgb_blocks * 3 * GRID_BN;
}

/* True when b's arrays say nothing an array-less block would not: sets b->uniform. */
static bool data_uniform(grid_block_t *b)
{
    const float *d = b->data;
    const float u = d[0];
    for (int i = 0; i < GRID_BN; i++)
        if (!same_bits(d[i], u) || !same_bits(d[GRID_REST * GRID_BN + i], u) ||
            !same_bits(d[GRID_VELOCITY * GRID_BN + i], 0.0f) ||
            !same_bits(d[GRID_FORCE * GRID_BN + i], 0.0f))
            return false;
    b->uniform = u;
    return true;
}

static bool mat_default(const grid_block_t *b)
{
    for (int c = 0; c < GRID_MAT_N; c++) {
        const float def = grid_mat_default((grid_mat_t)c);
        for (int i = 0; i < GRID_BN; i++)
            if (!same_bits(b->mat[c * GRID_BN + i], def))
                return false;
    }
    return true;
}

/* Grows the bounds by the samples of b that hold anything. */
static void block_extent(grid_t *g, const grid_block_t *b)
{
    for (int i = 0; i < GRID_BN; i++) {
        bool held = false;
        for (int c = 0; c < GRID_CH_N && b->data != NULL && !held; c++)
            held = !same_bits(b->data[c * GRID_BN + i], 0.0f);
        for (int c = 0; c < GRID_MAT_N && b->mat != NULL && !held; c++)
            held = !same_bits(b->mat[c * GRID_BN + i], grid_mat_default((grid_mat_t)c));
        if (!held && b->rgb != NULL)
            held = !rgb_default(b->rgb + 3 * i, 3);
        if (!held && b->data == NULL)
            held = !same_bits(b->uniform, 0.0f);
        if (held)
            bounds_sample(g, b->key[0] * GRID_B + i % GRID_B,
                          b->key[1] * GRID_B + i / GRID_B % GRID_B,
                          b->key[2] * GRID_B + i / (GRID_B * GRID_B));
    }
}

void grid_compact(grid_t *g)
{
    for (int a = 0; a < 3; a++) {
        g->blo[a] = 1;
        g->bhi[a] = 0;
    }
    size_t slot = 0;
    for (grid_block_t *b; (b = block_table_next(&g->blocks, &slot)) != NULL;) {
        if (b->data != NULL && data_uniform(b)) {
            free(b->data);
            b->data = NULL;
            g->data_blocks--;
        }
        if (b->mat != NULL && mat_default(b)) {
            free(b->mat);
            b->mat = NULL;
            g->mat_blocks--;
        }
        if (b->rgb != NULL && rgb_default(b->rgb, 3 * GRID_BN)) {
            free(b->rgb);
            b->rgb = NULL;
            g->rgb_blocks--;
        }
        if (b->data == NULL && !same_bits(b->uniform, 0.0f))
            bounds_add(g, b->key);
        else if (b->data != NULL || b->mat != NULL || b->rgb != NULL)
            block_extent(g, b);
    }
}

/* One explicit spring step over [lo, hi) on a dense copy of the box and its one-sample rim
 * (the rim is the fixed boundary), written back inside the box. */
float grid_springs_step(grid_t *g, const int32_t lo[3], const int32_t hi[3], float dt_s)
{
    int32_t c0[3], c1[3], r0[3], n[3], in_lo[3], in_hi[3];
    if (!grid_clip(g, lo, hi, c0, c1))
        return 0.0f;
    for (int a = 0; a < 3; a++) {
        r0[a] = c0[a] - 1;
        n[a] = c1[a] - c0[a] + 2;
        in_lo[a] = 1;
        in_hi[a] = n[a] - 1;
    }
    const size_t cnt = box_count(n);
    float *buf = malloc(4 * cnt * sizeof(float));
    if (buf == NULL)
        return 0.0f;
    spring_field_t f;
    for (int a = 0; a < 3; a++)
        f.dims[a] = n[a];
    f.density = buf;
    f.rest = buf + cnt;
    f.velocity = buf + 2 * cnt;
    f.force = buf + 3 * cnt;
    f.stiffness = NULL; /* uniform: g->material.stiffness */
    float *ch[GRID_CH_N] = {f.density, f.rest, f.velocity, f.force};
    for (int c = 0; c < GRID_CH_N; c++)
        grid_read_box(g, (grid_ch_t)c, r0, n, ch[c]);
    const float acc = springs_step(&f, &g->material, in_lo, in_hi, dt_s);
    /* Back inside the box only: the rim did not move. */
    int32_t m[3];
    for (int a = 0; a < 3; a++)
        m[a] = n[a] - 2;
    const size_t mc = box_count(m);
    float *inner = malloc(mc * sizeof(float));
    if (inner != NULL) {
        for (int c = 0; c < GRID_CH_N; c++) {
            size_t k = 0;
            for (int32_t z = 1; z < n[2] - 1; z++)
                for (int32_t y = 1; y < n[1] - 1; y++)
                    for (int32_t x = 1; x < n[0] - 1; x++)
                        inner[k++] = ch[c][(size_t)x + (size_t)n[0] * ((size_t)y +
                                                                     (size_t)n[1] * (size_t)z)];
            (void)grid_write_box(g, (grid_ch_t)c, c0, m, inner);
        }
    }
    free(inner);
    free(buf);
    return acc;
}

float grid_profile(float signed_dist_m, float band_m)
{
    const float d = 0.5f + 0.5f * signed_dist_m / band_m;
    if (!(d > 0.0f))
        return 0.0f; /* also NaN */
    return d > 1.0f ? 1.0f : d;
}

typedef struct {
    grid_t *g;
    vec3_t centre_m;
    float radius_m;
    argil_err_t err;
} fill_ctx_t;

/* One block of the nominal box: the sphere's profile, at rest; array-less when uniform. */
static bool fill_block(void *vctx, const int32_t k[3], const int32_t a0[3], const int32_t a1[3])
{
    fill_ctx_t *c = vctx;
    grid_t *g = c->g;
    float v[GRID_BN];
    bool whole = true;
    for (int a = 0; a < 3; a++)
        whole = whole && a0[a] == k[a] * GRID_B && a1[a] == k[a] * GRID_B + GRID_B;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++)
            for (int32_t x = a0[0]; x < a1[0]; x++) {
                const float r = vec3_norm(vec3_sub(grid_sample_pos(g, x, y, z), c->centre_m));
                v[local_at(k, x, y, z)] = grid_profile(c->radius_m - r, g->band_m);
            }
    grid_block_t *b = block_find(g, k);
    if (whole) {
        bool same = true;
        for (int i = 1; i < GRID_BN && same; i++)
            same = same_bits(v[i], v[0]);
        if (same) {
            if (b == NULL && same_bits(v[0], 0.0f))
                return true;
            if (b == NULL && (b = block_touch(g, k)) == NULL) {
                c->err = ARGIL_ERR_NOMEM;
                return false;
            }
            if (b->data != NULL) {
                free(b->data);
                b->data = NULL;
                g->data_blocks--;
            }
            b->uniform = v[0];
            if (!same_bits(v[0], 0.0f))
                bounds_box(g, a0, a1);
            return true;
        }
    }
    if ((b == NULL && (b = block_touch(g, k)) == NULL) || !block_data(g, b)) {
        c->err = ARGIL_ERR_NOMEM;
        return false;
    }
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++)
            for (int32_t x = a0[0]; x < a1[0]; x++) {
                const int li = local_at(k, x, y, z);
                b->data[GRID_DENSITY * GRID_BN + li] = v[li];
                b->data[GRID_REST * GRID_BN + li] = v[li];
                b->data[GRID_VELOCITY * GRID_BN + li] = 0.0f;
                b->data[GRID_FORCE * GRID_BN + li] = 0.0f;
                if (!same_bits(v[li], 0.0f))
                    bounds_sample(g, x, y, z);
            }
    return true;
}

void grid_fill_sphere(grid_t *g, vec3_t centre_m, float radius_m)
{
    if (!vec3_isfinite(centre_m) || !isfinite(radius_m) || radius_m < 0.0f ||
        g->blocks.entries == NULL)
        return;
    const int32_t zero[3] = {0, 0, 0};
    fill_ctx_t c = {g, centre_m, radius_m, ARGIL_OK};
    (void)for_blocks(g, zero, g->dims, fill_block, &c);
}

/* Finds the cell holding p: lower corner i and fractions f; false far outside the held indices
 * (the interpolant is 0 there) or for a non-finite p. */
static bool grid_cell(const grid_t *g, vec3_t p_m, int64_t i[3], float f[3])
{
    double u[3];
    grid_to_index(g, p_m, u);
    for (int a = 0; a < 3; a++) {
        if (!(u[a] >= -(double)GRID_INDEX_MAX && u[a] < (double)GRID_INDEX_MAX - 1.0))
            return false; /* also NaN */
        const double fl = floor(u[a]);
        i[a] = (int64_t)fl;
        f[a] = (float)(u[a] - fl);
    }
    return true;
}

/* The eight corner densities of cell i (x fastest). */
static void cell_corners(const grid_t *g, const int64_t i[3], float c[8])
{
    const int32_t lo[3] = {(int32_t)i[0], (int32_t)i[1], (int32_t)i[2]}, n[3] = {2, 2, 2};
    grid_read_box(g, GRID_DENSITY, lo, n, c);
}

float grid_density_at(const grid_t *g, vec3_t p_m)
{
    int64_t i[3];
    float f[3];
    if (!grid_cell(g, p_m, i, f))
        return 0.0f;
    float c[8];
    cell_corners(g, i, c);
    const float x00 = c[0] + f[0] * (c[1] - c[0]);
    const float x10 = c[2] + f[0] * (c[3] - c[2]);
    const float x01 = c[4] + f[0] * (c[5] - c[4]);
    const float x11 = c[6] + f[0] * (c[7] - c[6]);
    const float y0 = x00 + f[1] * (x10 - x00);
    const float y1 = x01 + f[1] * (x11 - x01);
    return y0 + f[2] * (y1 - y0);
}

vec3_t grid_gradient_at(const grid_t *g, vec3_t p_m)
{
    int64_t i[3];
    float f[3];
    if (!grid_cell(g, p_m, i, f))
        return vec3(0.0f, 0.0f, 0.0f);
    float c[8];
    cell_corners(g, i, c);
    const float gx = 1.0f - f[0], gy = 1.0f - f[1], gz = 1.0f - f[2];
    const float dx = gy * gz * (c[1] - c[0]) + f[1] * gz * (c[3] - c[2]) +
                     gy * f[2] * (c[5] - c[4]) + f[1] * f[2] * (c[7] - c[6]);
    const float dy = gx * gz * (c[2] - c[0]) + f[0] * gz * (c[3] - c[1]) +
                     gx * f[2] * (c[6] - c[4]) + f[0] * f[2] * (c[7] - c[5]);
    const float dz = gx * gy * (c[4] - c[0]) + f[0] * gy * (c[5] - c[1]) +
                     gx * f[1] * (c[6] - c[2]) + f[0] * f[1] * (c[7] - c[3]);
    return vec3_scale(vec3(dx, dy, dz), 1.0f / g->spacing_m);
}

/* Clamps a sample index computed in double to [lo, hi]. */
static int32_t clamp_index(double v, int32_t lo, int32_t hi)
{
    if (!(v > (double)lo))
        return lo;
    if (v > (double)hi)
        return hi;
    return (int32_t)v;
}

void grid_carve_sphere(grid_t *g, vec3_t centre_m, float radius_m, int32_t lo[3], int32_t hi[3])
{
    int32_t b0[3], b1[3];
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = 0;
    if (!vec3_isfinite(centre_m) || !isfinite(radius_m) || radius_m < 0.0f)
        return;
    /* Only samples closer than radius + band can have a profile below 1; only samples that
     * hold clay can lose it, and those lie within the bounds. */
    int32_t glo[3], ghi[3];
    grid_bounds(g, glo, ghi);
    double u[3];
    grid_to_index(g, centre_m, u);
    const double reach = ((double)radius_m + (double)g->band_m) / (double)g->spacing_m + 1.0;
    for (int a = 0; a < 3; a++) {
        b0[a] = clamp_index(floor(u[a] - reach), glo[a], ghi[a]);
        b1[a] = clamp_index(ceil(u[a] + reach) + 1.0, glo[a], ghi[a]);
        if (b1[a] <= b0[a])
            return;
    }
    int32_t c0[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, c1[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (int32_t z = b0[2]; z < b1[2]; z++) {
        for (int32_t y = b0[1]; y < b1[1]; y++) {
            for (int32_t x = b0[0]; x < b1[0]; x++) {
                const float r = vec3_norm(vec3_sub(grid_sample_pos(g, x, y, z), centre_m));
                const float keep = grid_profile(r - radius_m, g->band_m);
                bool changed = false;
                if (keep < grid_get(g, GRID_DENSITY, x, y, z)) {
                    (void)grid_set(g, GRID_DENSITY, x, y, z, keep);
                    changed = true;
                }
                if (keep < grid_get(g, GRID_REST, x, y, z)) {
                    (void)grid_set(g, GRID_REST, x, y, z, keep);
                    changed = true;
                }
                if (!changed)
                    continue;
                (void)grid_set(g, GRID_VELOCITY, x, y, z, 0.0f);
                const int32_t s[3] = {x, y, z};
                for (int a = 0; a < 3; a++) {
                    if (s[a] < c0[a])
                        c0[a] = s[a];
                    if (s[a] + 1 > c1[a])
                        c1[a] = s[a] + 1;
                }
            }
        }
    }
    if (c0[0] == INT32_MAX)
        return;
    for (int a = 0; a < 3; a++) {
        lo[a] = c0[a];
        hi[a] = c1[a];
    }
}

void grid_window_corner(const grid_t *g, vec3_t p_m, const int32_t win_dims[3],
                        int32_t corner[3])
{
    double u[3];
    grid_to_index(g, p_m, u);
    for (int a = 0; a < 3; a++) {
        const double c = floor(u[a] - 0.5 * ((double)win_dims[a] - 1.0) + 0.5);
        if (!isfinite(c))
            corner[a] = 0;
        else
            corner[a] = clamp_index(c, (int32_t)-GRID_INDEX_LIMIT, (int32_t)GRID_INDEX_LIMIT);
    }
}

void grid_extract(const grid_t *g, const int32_t corner[3], const int32_t win_dims[3],
                  float *out)
{
    if (win_dims[0] <= 0 || win_dims[1] <= 0 || win_dims[2] <= 0)
        return;
    grid_read_box(g, GRID_DENSITY, corner, win_dims, out);
}

bool grid_add_force(grid_t *g, int32_t x, int32_t y, int32_t z, float force)
{
    if (!grid_holds(g, x, y, z) || !isfinite(force))
        return false;
    const float sum = grid_get(g, GRID_FORCE, x, y, z) + force;
    if (!isfinite(sum))
        return false;
    return grid_set(g, GRID_FORCE, x, y, z, sum) == ARGIL_OK;
}

/* ---- Block access, for copies of the grid kept per block (the autosave journal's) ---- */

static void block_view_fill(const grid_block_t *b, const int32_t k[3], grid_block_view_t *v)
{
    memcpy(v->key, k, sizeof(v->key));
    v->density = b != NULL && b->data != NULL ? b->data + GRID_DENSITY * GRID_BN : NULL;
    v->uniform = uniform_of(b, GRID_DENSITY);
    v->mat = b != NULL ? b->mat : NULL;
    v->rgb = b != NULL ? b->rgb : NULL;
}

int32_t grid_block_index(int32_t i)
{
    return floor_div_i32(i, GRID_B);
}

bool grid_block_view(const grid_t *g, const int32_t k[3], grid_block_view_t *v)
{
    const grid_block_t *b = block_find(g, k);
    block_view_fill(b, k, v);
    return b != NULL;
}

bool grid_block_next(const grid_t *g, size_t *slot, grid_block_view_t *v)
{
    const grid_block_t *b = block_table_next(&g->blocks, slot);
    if (b != NULL)
        block_view_fill(b, b->key, v);
    return b != NULL;
}

/* ---- Queries for the live mesher (host/mesh/grid_mesh.c) ---- */

typedef struct {
    const grid_t *g;
    float v;
} at_most_ctx_t;

/* True when every density of block k over [a0, a1) is at most ctx's v (an absent block reads 0). */
static bool block_at_most(void *vctx, const int32_t k[3], const int32_t a0[3], const int32_t a1[3])
{
    const at_most_ctx_t *c = vctx;
    const grid_block_t *b = block_find(c->g, k);
    if (b == NULL)
        return true;
    if (b->data == NULL)
        return b->uniform <= c->v;
    const float *d = b->data + GRID_DENSITY * GRID_BN;
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++)
            for (int32_t x = a0[0]; x < a1[0]; x++)
                if (!(d[local_at(k, x, y, z)] <= c->v))
                    return false;
    return true;
}

bool grid_box_density_at_most(const grid_t *g, const int32_t lo[3], const int32_t hi[3], float v)
{
    if (!(v >= 0.0f))
        return false; /* blocks not held read 0 */
    int32_t clo[3], chi[3], n[3];
    for (int a = 0; a < 3; a++)
        if (lo[a] >= hi[a])
            return true;
    if (!grid_clip(g, lo, hi, clo, chi))
        return true; /* outside what the grid can hold: all 0 */
    for (int a = 0; a < 3; a++)
        n[a] = chi[a] - clo[a];
    at_most_ctx_t c = {g, v};
    return for_blocks(g, clo, n, block_at_most, &c);
}
