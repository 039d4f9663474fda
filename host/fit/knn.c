/* Uniform-grid k-nearest-neighbour search: cells are visited in growing cubic shells around the
 * query until no unvisited cell can hold a point nearer than the k-th found. */
#include "host/fit/knn.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

argil_err_t knn_grid_build(knn_grid_t *g, const float *pos, size_t n)
{
    memset(g, 0, sizeof(*g));
    if (pos == NULL || n == 0 || n >= UINT32_MAX)
        return ARGIL_ERR_ARG;
    float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int a = 0; a < 3; a++)
        g->lo[a] = INFINITY;
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            const float v = pos[3 * i + (size_t)a];
            if (!isfinite(v))
                return ARGIL_ERR_ARG;
            g->lo[a] = fminf(g->lo[a], v);
            hi[a] = fmaxf(hi[a], v);
        }
    float ext = 0.0f;
    for (int a = 0; a < 3; a++)
        ext = fmaxf(ext, hi[a] - g->lo[a]);
    /* a sampled surface of extent S holds about n (cell / S)^2 points per occupied cell: ~4 */
    float cell = ext > 0.0f ? ext * sqrtf(4.0f / (float)n) : 1.0f;
    for (;;) {
        uint64_t cells = 1;
        for (int a = 0; a < 3; a++) {
            g->dims[a] = (int32_t)((hi[a] - g->lo[a]) / cell) + 1;
            cells *= (uint64_t)g->dims[a];
        }
        if (cells <= KNN_CELLS_MAX && cells <= 8u * (uint64_t)n + 64u)
            break;
        cell *= 1.25f;
    }
    g->cell_m = cell;
    const size_t cells = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    g->start = calloc(cells + 1, sizeof(uint32_t));
    g->idx = malloc(n * sizeof(uint32_t));
    uint32_t *cell_of = malloc(n * sizeof(uint32_t));
    if (g->start == NULL || g->idx == NULL || cell_of == NULL) {
        free(cell_of);
        knn_grid_free(g);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) {
        int32_t c[3];
        for (int a = 0; a < 3; a++) {
            c[a] = (int32_t)((pos[3 * i + (size_t)a] - g->lo[a]) / cell);
            c[a] = c[a] < 0 ? 0 : (c[a] >= g->dims[a] ? g->dims[a] - 1 : c[a]);
        }
        cell_of[i] = (uint32_t)((size_t)c[0] + (size_t)g->dims[0] * ((size_t)c[1] + (size_t)g->dims[1] * (size_t)c[2]));
        g->start[cell_of[i] + 1]++;
    }
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    uint32_t *fill = malloc(cells * sizeof(uint32_t));
    if (fill == NULL) {
        free(cell_of);
        knn_grid_free(g);
        return ARGIL_ERR_NOMEM;
    }
    memcpy(fill, g->start, cells * sizeof(uint32_t));
    for (size_t i = 0; i < n; i++)
        g->idx[fill[cell_of[i]]++] = (uint32_t)i;
    free(fill);
    free(cell_of);
    g->pos = pos;
    g->n = (uint32_t)n;
    return ARGIL_OK;
}

void knn_grid_free(knn_grid_t *g)
{
    free(g->start);
    free(g->idx);
    memset(g, 0, sizeof(*g));
}

/* Inserts (i, d) into the sorted best list of length *m (capacity k). */
static void knn_insert(uint32_t *idx, float *d2, uint32_t *m, uint32_t k, uint32_t i, float d)
{
    if (*m == k && d >= d2[k - 1])
        return;
    uint32_t j = *m < k ? (*m)++ : k - 1;
    while (j > 0 && d2[j - 1] > d) {
        d2[j] = d2[j - 1];
        idx[j] = idx[j - 1];
        j--;
    }
    d2[j] = d;
    idx[j] = i;
}

/* Offers every point of cell (x, y, z) to the best list. */
static void knn_visit(const knn_grid_t *g, const float q[3], int32_t x, int32_t y, int32_t z,
                      uint32_t k, uint32_t *idx, float *d2, uint32_t *m)
{
    const size_t cell = (size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
    for (uint32_t s = g->start[cell]; s < g->start[cell + 1]; s++) {
        const uint32_t i = g->idx[s];
        const float dx = g->pos[3 * (size_t)i] - q[0], dy = g->pos[3 * (size_t)i + 1] - q[1],
                    dz = g->pos[3 * (size_t)i + 2] - q[2];
        knn_insert(idx, d2, m, k, i, dx * dx + dy * dy + dz * dz);
    }
}

uint32_t knn_grid_query(const knn_grid_t *g, vec3_t p, uint32_t k, uint32_t *idx, float *d2_out)
{
    if (g->n == 0 || k == 0 || !vec3_isfinite(p))
        return 0;
    if (k > KNN_K_MAX)
        k = KNN_K_MAX;
    if (k > g->n)
        k = g->n;
    float d2[KNN_K_MAX];
    uint32_t m = 0;
    const float q[3] = {p.x, p.y, p.z};
    int32_t c[3];
    for (int a = 0; a < 3; a++) {
        const float t = floorf((q[a] - g->lo[a]) / g->cell_m);
        c[a] = t < 0.0f ? 0 : (t >= (float)g->dims[a] ? g->dims[a] - 1 : (int32_t)t);
    }
    for (int32_t r = 0;; r++) {
        bool covers = true;
        int32_t lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = c[a] - r;
            hi[a] = c[a] + r;
            if (lo[a] > 0 || hi[a] < g->dims[a] - 1)
                covers = false;
            lo[a] = lo[a] < 0 ? 0 : lo[a];
            hi[a] = hi[a] >= g->dims[a] ? g->dims[a] - 1 : hi[a];
        }
        for (int32_t z = lo[2]; z <= hi[2]; z++)
            for (int32_t y = lo[1]; y <= hi[1]; y++) {
                const bool face = z == c[2] - r || z == c[2] + r || y == c[1] - r || y == c[1] + r;
                if (face) {
                    for (int32_t x = lo[0]; x <= hi[0]; x++)
                        knn_visit(g, q, x, y, z, k, idx, d2, &m);
                } else {
                    if (c[0] - r >= 0)
                        knn_visit(g, q, c[0] - r, y, z, k, idx, d2, &m);
                    if (c[0] + r < g->dims[0])
                        knn_visit(g, q, c[0] + r, y, z, k, idx, d2, &m);
                }
            }
        if (covers)
            break;
        if (m == k) {
            /* every unvisited cell lies beyond one of the shell's faces that still has grid
             * cells behind it: at least this far from q */
            float gap = INFINITY;
            for (int a = 0; a < 3; a++) {
                if (c[a] - r > 0)
                    gap = fminf(gap, fmaxf(0.0f, q[a] - (g->lo[a] + g->cell_m * (float)(c[a] - r))));
                if (c[a] + r < g->dims[a] - 1)
                    gap = fminf(gap, fmaxf(0.0f, g->lo[a] + g->cell_m * (float)(c[a] + r + 1) - q[a]));
            }
            if (gap > 0.0f && d2[k - 1] <= gap * gap)
                break;
        }
    }
    if (d2_out != NULL)
        memcpy(d2_out, d2, m * sizeof(float));
    return m;
}
