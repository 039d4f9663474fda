/* Dense density grid on the host heap: sphere fill, hard carving, trilinear sampling, and the
 * windows cut for the board. Density profile after Ferley et al. §3 (values ramp across a band). */
#include "host/model/grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest |sample index| computed from a position; keeps int32 arithmetic far from overflow. */
#define GRID_INDEX_LIMIT 1.0e9

static size_t grid_index(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return (size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
}

/* Density of sample (x,y,z), 0 beyond the grid. */
static float grid_sample(const grid_t *g, int64_t x, int64_t y, int64_t z)
{
    if (x < 0 || y < 0 || z < 0 || x >= g->dims[0] || y >= g->dims[1] || z >= g->dims[2])
        return 0.0f;
    return g->density[grid_index(g, (int32_t)x, (int32_t)y, (int32_t)z)];
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
    for (int a = 0; a < 3; a++)
        g->dims[a] = dims[a];
    g->spacing_m = spacing_m;
    g->origin_m = origin_m;
    g->iso = 0.5f;
    g->band_m = 4.0f * spacing_m;
    spring_material_default(&g->material);
    g->density = calloc((size_t)n, sizeof(float));
    g->rest = calloc((size_t)n, sizeof(float));
    g->velocity = calloc((size_t)n, sizeof(float));
    g->force = calloc((size_t)n, sizeof(float));
    if (g->density == NULL || g->rest == NULL || g->velocity == NULL || g->force == NULL) {
        grid_free(g);
        return ARGIL_ERR_NOMEM;
    }
    return ARGIL_OK;
}

void grid_free(grid_t *g)
{
    free(g->density);
    free(g->rest);
    free(g->velocity);
    free(g->force);
    g->density = g->rest = g->velocity = g->force = NULL;
    for (int c = 0; c < GRID_MAT_N; c++) {
        free(g->mat[c]);
        g->mat[c] = NULL;
    }
    g->dims[0] = g->dims[1] = g->dims[2] = 0;
}

size_t grid_count(const grid_t *g)
{
    return (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
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

/* Channel ch's storage (NULL for an unpainted mat channel). */
static float *grid_channel(const grid_t *g, grid_ch_t ch)
{
    switch (ch) {
    case GRID_DENSITY: return g->density;
    case GRID_REST: return g->rest;
    case GRID_VELOCITY: return g->velocity;
    case GRID_FORCE: return g->force;
    default: return NULL;
    }
}

static float *grid_mat_alloc(grid_t *g, grid_mat_t ch)
{
    if ((unsigned)ch >= GRID_MAT_N || g->density == NULL)
        return NULL;
    if (g->mat[ch] != NULL)
        return g->mat[ch];
    const size_t n = grid_count(g);
    float *m = malloc(n * sizeof(float));
    if (m == NULL)
        return NULL;
    const float def = grid_mat_default(ch);
    for (size_t i = 0; i < n; i++)
        m[i] = def;
    g->mat[ch] = m;
    return m;
}

void grid_bounds(const grid_t *g, int32_t lo[3], int32_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = 0;
        hi[a] = g->dims[a];
    }
}

bool grid_holds(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return x >= 0 && y >= 0 && z >= 0 && x < g->dims[0] && y < g->dims[1] && z < g->dims[2];
}

float grid_get(const grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z)
{
    const float *c = grid_channel(g, ch);
    if (c == NULL || !grid_holds(g, x, y, z))
        return 0.0f;
    return c[grid_index(g, x, y, z)];
}

argil_err_t grid_set(grid_t *g, grid_ch_t ch, int32_t x, int32_t y, int32_t z, float v)
{
    float *c = grid_channel(g, ch);
    if (c == NULL || !grid_holds(g, x, y, z))
        return ARGIL_ERR_ARG;
    c[grid_index(g, x, y, z)] = v;
    return ARGIL_OK;
}

bool grid_clip(const grid_t *g, const int32_t lo[3], const int32_t hi[3], int32_t clo[3],
               int32_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = lo[a] < 0 ? 0 : lo[a];
        chi[a] = hi[a] > g->dims[a] ? g->dims[a] : hi[a];
        if (chi[a] <= clo[a])
            return false;
    }
    return true;
}

/* The part of box [lo, lo+n) inside the grid: [a0, a1); false when empty. */
static bool grid_clip_n(const grid_t *g, const int32_t lo[3], const int32_t n[3], int32_t a0[3],
                      int32_t a1[3])
{
    for (int a = 0; a < 3; a++) {
        if (n[a] <= 0)
            return false;
        const int64_t l = lo[a] < 0 ? 0 : lo[a];
        const int64_t h = (int64_t)lo[a] + n[a] > g->dims[a] ? g->dims[a] : (int64_t)lo[a] + n[a];
        if (h <= l)
            return false;
        a0[a] = (int32_t)l;
        a1[a] = (int32_t)h;
    }
    return true;
}

/* Copies the grid's part of box [lo, lo+n) between array c and buf (x fastest over the box):
 * into buf when to_buf, else into c. */
static void grid_copy_box(const grid_t *g, float *c, const int32_t lo[3], const int32_t n[3],
                          float *buf, bool to_buf)
{
    int32_t a0[3], a1[3];
    if (!grid_clip_n(g, lo, n, a0, a1))
        return;
    const size_t w = (size_t)(a1[0] - a0[0]);
    for (int32_t z = a0[2]; z < a1[2]; z++)
        for (int32_t y = a0[1]; y < a1[1]; y++) {
            float *gp = c + grid_index(g, a0[0], y, z);
            float *bp = buf + (size_t)(a0[0] - lo[0]) +
                        (size_t)n[0] * ((size_t)(y - lo[1]) + (size_t)n[1] * (size_t)(z - lo[2]));
            if (to_buf)
                memcpy(bp, gp, w * sizeof(float));
            else
                memcpy(gp, bp, w * sizeof(float));
        }
}

static void fill(float *out, size_t n, float v)
{
    for (size_t i = 0; i < n; i++)
        out[i] = v;
}

static size_t box_count(const int32_t n[3])
{
    if (n[0] <= 0 || n[1] <= 0 || n[2] <= 0)
        return 0;
    return (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
}

void grid_read_box(const grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                   float *out)
{
    fill(out, box_count(n), 0.0f);
    float *c = grid_channel(g, ch);
    if (c != NULL)
        grid_copy_box(g, c, lo, n, out, true);
}

argil_err_t grid_write_box(grid_t *g, grid_ch_t ch, const int32_t lo[3], const int32_t n[3],
                           const float *in)
{
    float *c = grid_channel(g, ch);
    if (c == NULL)
        return ARGIL_ERR_ARG;
    grid_copy_box(g, c, lo, n, (float *)in, false);
    return ARGIL_OK;
}

float grid_mat_get(const grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z)
{
    if ((unsigned)ch >= GRID_MAT_N)
        return 0.0f;
    if (g->mat[ch] == NULL || !grid_holds(g, x, y, z))
        return grid_mat_default(ch);
    return g->mat[ch][grid_index(g, x, y, z)];
}

argil_err_t grid_mat_set(grid_t *g, grid_mat_t ch, int32_t x, int32_t y, int32_t z, float v)
{
    if ((unsigned)ch >= GRID_MAT_N || !grid_holds(g, x, y, z))
        return ARGIL_ERR_ARG;
    float *m = grid_mat_alloc(g, ch);
    if (m == NULL)
        return ARGIL_ERR_NOMEM;
    m[grid_index(g, x, y, z)] = v;
    return ARGIL_OK;
}

void grid_mat_read_box(const grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                       float *out)
{
    if ((unsigned)ch >= GRID_MAT_N)
        return;
    fill(out, box_count(n), grid_mat_default(ch));
    if (g->mat[ch] != NULL)
        grid_copy_box(g, g->mat[ch], lo, n, out, true);
}

argil_err_t grid_mat_write_box(grid_t *g, grid_mat_t ch, const int32_t lo[3], const int32_t n[3],
                               const float *in)
{
    if ((unsigned)ch >= GRID_MAT_N)
        return ARGIL_ERR_ARG;
    float *m = grid_mat_alloc(g, ch);
    if (m == NULL)
        return ARGIL_ERR_NOMEM;
    grid_copy_box(g, m, lo, n, (float *)in, false);
    return ARGIL_OK;
}

bool grid_mat_painted(const grid_t *g, grid_mat_t ch)
{
    return (unsigned)ch < GRID_MAT_N && g->mat[ch] != NULL;
}

float *grid_dense_copy(const grid_t *g, grid_ch_t ch, int32_t lo[3], int32_t n[3])
{
    int32_t hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        n[a] = hi[a] - lo[a];
    float *out = malloc(box_count(n) * sizeof(float));
    if (out != NULL)
        grid_read_box(g, ch, lo, n, out);
    return out;
}

float *grid_dense_copy_mat(const grid_t *g, grid_mat_t ch, int32_t lo[3], int32_t n[3])
{
    int32_t hi[3];
    grid_bounds(g, lo, hi);
    for (int a = 0; a < 3; a++)
        n[a] = hi[a] - lo[a];
    float *out = malloc(box_count(n) * sizeof(float));
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
    size_t chans = 4;
    for (int c = 0; c < GRID_MAT_N; c++)
        chans += g->mat[c] != NULL;
    return chans * grid_count(g) * sizeof(float);
}

bool grid_mat_equal(const grid_t *a, const grid_t *b, grid_mat_t ch)
{
    const size_t n = grid_count(a);
    if (n != grid_count(b))
        return false;
    if (a->mat[ch] != NULL && b->mat[ch] != NULL)
        return memcmp(a->mat[ch], b->mat[ch], n * sizeof(float)) == 0;
    const float *m = a->mat[ch] != NULL ? a->mat[ch] : b->mat[ch];
    if (m == NULL)
        return true;
    const float def = grid_mat_default(ch);
    for (size_t i = 0; i < n; i++)
        if (memcmp(&m[i], &def, sizeof(float)) != 0)
            return false;
    return true;
}

float grid_springs_step(grid_t *g, const int32_t lo[3], const int32_t hi[3], float dt_s)
{
    spring_field_t f;
    for (int a = 0; a < 3; a++)
        f.dims[a] = g->dims[a];
    f.density = g->density;
    f.rest = g->rest;
    f.velocity = g->velocity;
    f.force = g->force;
    f.stiffness = NULL; /* uniform: g->material.stiffness */
    return springs_step(&f, &g->material, lo, hi, dt_s);
}

float grid_profile(float signed_dist_m, float band_m)
{
    const float d = 0.5f + 0.5f * signed_dist_m / band_m;
    if (!(d > 0.0f))
        return 0.0f; /* also NaN */
    return d > 1.0f ? 1.0f : d;
}

void grid_fill_sphere(grid_t *g, vec3_t centre_m, float radius_m)
{
    if (!vec3_isfinite(centre_m) || !isfinite(radius_m) || radius_m < 0.0f)
        return;
    for (int32_t z = 0; z < g->dims[2]; z++) {
        for (int32_t y = 0; y < g->dims[1]; y++) {
            for (int32_t x = 0; x < g->dims[0]; x++) {
                const size_t i = grid_index(g, x, y, z);
                const float r = vec3_norm(vec3_sub(grid_sample_pos(g, x, y, z), centre_m));
                const float d = grid_profile(radius_m - r, g->band_m);
                g->density[i] = d;
                g->rest[i] = d;
                g->velocity[i] = 0.0f;
                g->force[i] = 0.0f;
            }
        }
    }
}

/* Finds the cell holding p: lower corner i (may be -1) and fractions f; false when all eight
 * corners lie beyond the grid, so the interpolant is 0 there. */
static bool grid_cell(const grid_t *g, vec3_t p_m, int64_t i[3], float f[3])
{
    double u[3];
    grid_to_index(g, p_m, u);
    for (int a = 0; a < 3; a++) {
        if (!(u[a] >= -1.0 && u[a] < (double)g->dims[a]))
            return false; /* also NaN */
        const double fl = floor(u[a]);
        i[a] = (int64_t)fl;
        f[a] = (float)(u[a] - fl);
    }
    return true;
}

float grid_density_at(const grid_t *g, vec3_t p_m)
{
    int64_t i[3];
    float f[3];
    if (!grid_cell(g, p_m, i, f))
        return 0.0f;
    float c[8];
    for (int k = 0; k < 8; k++)
        c[k] = grid_sample(g, i[0] + (k & 1), i[1] + ((k >> 1) & 1), i[2] + ((k >> 2) & 1));
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
    for (int k = 0; k < 8; k++)
        c[k] = grid_sample(g, i[0] + (k & 1), i[1] + ((k >> 1) & 1), i[2] + ((k >> 2) & 1));
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
    /* Only samples closer than radius + band can have a profile below 1. */
    double u[3];
    grid_to_index(g, centre_m, u);
    const double reach = ((double)radius_m + (double)g->band_m) / (double)g->spacing_m + 1.0;
    for (int a = 0; a < 3; a++) {
        b0[a] = clamp_index(floor(u[a] - reach), 0, g->dims[a]);
        b1[a] = clamp_index(ceil(u[a] + reach) + 1.0, 0, g->dims[a]);
        if (b1[a] <= b0[a])
            return;
    }
    int32_t c0[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, c1[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (int32_t z = b0[2]; z < b1[2]; z++) {
        for (int32_t y = b0[1]; y < b1[1]; y++) {
            for (int32_t x = b0[0]; x < b1[0]; x++) {
                const float r = vec3_norm(vec3_sub(grid_sample_pos(g, x, y, z), centre_m));
                const float keep = grid_profile(r - radius_m, g->band_m);
                const size_t i = grid_index(g, x, y, z);
                bool changed = false;
                if (keep < g->density[i]) {
                    g->density[i] = keep;
                    changed = true;
                }
                if (keep < g->rest[i]) {
                    g->rest[i] = keep;
                    changed = true;
                }
                if (!changed)
                    continue;
                g->velocity[i] = 0.0f;
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
    size_t o = 0;
    for (int32_t z = 0; z < win_dims[2]; z++) {
        for (int32_t y = 0; y < win_dims[1]; y++) {
            for (int32_t x = 0; x < win_dims[0]; x++)
                out[o++] = grid_sample(g, (int64_t)corner[0] + x, (int64_t)corner[1] + y,
                                       (int64_t)corner[2] + z);
        }
    }
}

bool grid_add_force(grid_t *g, int32_t x, int32_t y, int32_t z, float force)
{
    if (x < 0 || y < 0 || z < 0 || x >= g->dims[0] || y >= g->dims[1] || z >= g->dims[2])
        return false;
    if (!isfinite(force))
        return false;
    const size_t i = grid_index(g, x, y, z);
    const float sum = g->force[i] + force;
    if (!isfinite(sum))
        return false;
    g->force[i] = sum;
    return true;
}
