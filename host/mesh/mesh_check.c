/* Mesh checks for tests and export: volume, edge manifoldness, degenerate triangles. */
#include "host/mesh/mesh_check.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MESH_CHECK_VERT_MAX ((size_t)1 << 31)

double mesh_volume_m3(const mesh_t *m)
{
    double v6 = 0.0;
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *tr = m->tri + 3 * t;
        if (tr[0] >= m->n_vert || tr[1] >= m->n_vert || tr[2] >= m->n_vert)
            continue;
        const float *a = m->pos + 3 * (size_t)tr[0];
        const float *b = m->pos + 3 * (size_t)tr[1];
        const float *c = m->pos + 3 * (size_t)tr[2];
        /* a · (b × c): six times the tetrahedron (origin, a, b, c). */
        const double cx = (double)b[1] * c[2] - (double)b[2] * c[1];
        const double cy = (double)b[2] * c[0] - (double)b[0] * c[2];
        const double cz = (double)b[0] * c[1] - (double)b[1] * c[0];
        v6 += (double)a[0] * cx + (double)a[1] * cy + (double)a[2] * cz;
    }
    return v6 / 6.0;
}

/* LSD radix sort of 64-bit keys, 8 bits per pass; tmp has n entries. */
static void radix_sort_u64(uint64_t *keys, uint64_t *tmp, size_t n)
{
    size_t count[256];
    for (int shift = 0; shift < 64; shift += 8) {
        memset(count, 0, sizeof(count));
        for (size_t i = 0; i < n; i++)
            count[(keys[i] >> shift) & 0xFFu]++;
        size_t sum = 0;
        for (size_t b = 0; b < 256; b++) {
            const size_t c = count[b];
            count[b] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            tmp[count[(keys[i] >> shift) & 0xFFu]++] = keys[i];
        uint64_t *sw = keys;
        keys = tmp;
        tmp = sw;
    }
    /* An even number of passes: the sorted data is back in the caller's keys array. */
}

/* Walks the sorted undirected edges: counts distinct valid edges, boundary and non-manifold
 * ones. Returns false when the check cannot run. */
static bool mesh_edge_scan(const mesh_t *m, size_t *edges, size_t *boundary, size_t *nonmanifold)
{
    *edges = 0;
    *boundary = 0;
    *nonmanifold = 0;
    if (m->n_vert > MESH_CHECK_VERT_MAX || m->n_tri > SIZE_MAX / (6 * sizeof(uint64_t)))
        return false;
    const size_t n = 3 * m->n_tri;
    if (n == 0)
        return true;
    uint64_t *keys = malloc(n * sizeof(uint64_t));
    uint64_t *tmp = malloc(n * sizeof(uint64_t));
    if (keys == NULL || tmp == NULL) {
        free(keys);
        free(tmp);
        return false;
    }
    size_t k = 0;
    for (size_t t = 0; t < m->n_tri; t++) {
        for (int j = 0; j < 3; j++) {
            const uint32_t a = m->tri[3 * t + (size_t)j];
            const uint32_t b = m->tri[3 * t + (size_t)((j + 1) % 3)];
            if (a == b || a >= m->n_vert || b >= m->n_vert) {
                (*nonmanifold)++;
                continue;
            }
            const uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            /* 31 + 31 bits of vertex, 1 bit of direction. */
            keys[k++] = lo << 33 | hi << 1 | (uint64_t)(a > b);
        }
    }
    radix_sort_u64(keys, tmp, k);
    for (size_t i = 0; i < k;) {
        size_t j = i + 1;
        while (j < k && (keys[j] >> 1) == (keys[i] >> 1))
            j++;
        (*edges)++;
        if (j - i == 1)
            (*boundary)++;
        else if (j - i > 2 || (keys[i] & 1u) == (keys[i + 1] & 1u))
            (*nonmanifold)++;
        i = j;
    }
    free(keys);
    free(tmp);
    return true;
}

bool mesh_watertight(const mesh_t *m, size_t *boundary_edges, size_t *nonmanifold_edges)
{
    size_t e, b, nm;
    const bool ran = mesh_edge_scan(m, &e, &b, &nm);
    if (!ran)
        b = nm = SIZE_MAX;
    if (boundary_edges != NULL)
        *boundary_edges = b;
    if (nonmanifold_edges != NULL)
        *nonmanifold_edges = nm;
    return ran && b == 0 && nm == 0;
}

size_t mesh_edge_count(const mesh_t *m)
{
    size_t e, b, nm;
    return mesh_edge_scan(m, &e, &b, &nm) ? e : SIZE_MAX;
}

size_t mesh_degenerate_triangles(const mesh_t *m, float min_area_m2)
{
    size_t bad = 0;
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *tr = m->tri + 3 * t;
        if (tr[0] >= m->n_vert || tr[1] >= m->n_vert || tr[2] >= m->n_vert) {
            bad++;
            continue;
        }
        const float *a = m->pos + 3 * (size_t)tr[0];
        const float *b = m->pos + 3 * (size_t)tr[1];
        const float *c = m->pos + 3 * (size_t)tr[2];
        const double u[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
        const double v[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
        const double x = u[1] * v[2] - u[2] * v[1];
        const double y = u[2] * v[0] - u[0] * v[2];
        const double z = u[0] * v[1] - u[1] * v[0];
        const double area = 0.5 * sqrt(x * x + y * y + z * z);
        if (!isfinite(area) || !(area >= (double)min_area_m2))
            bad++;
    }
    return bad;
}
