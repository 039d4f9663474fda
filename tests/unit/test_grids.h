/* Grid fixtures shared by the cmocka tests of the host grid and the global solve (include after
 * <cmocka.h>): a cubic grid centred on the origin holding a sphere, sample indexing, and where
 * the density crosses the clay's surface along an axis. */
#ifndef ARGIL_TEST_GRIDS_H
#define ARGIL_TEST_GRIDS_H

#include <stdint.h>
#include <stdlib.h>

#include "host/model/grid.h"

/* The index of sample (x, y, z) in g's arrays. */
static inline size_t test_gidx(const grid_t *g, int32_t x, int32_t y, int32_t z)
{
    return (size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z);
}

/* An edge³ grid at spacing_m centred on the origin holding a sphere of radius_m there (on the
 * heap; test_grid_free). */
static inline grid_t *test_sphere_grid(int32_t edge, float spacing_m, float radius_m)
{
    grid_t *g = malloc(sizeof(*g));
    assert_non_null(g);
    const int32_t dims[3] = {edge, edge, edge};
    const float o = -0.5f * (float)(edge - 1) * spacing_m;
    assert_int_equal(grid_init(g, dims, spacing_m, vec3(o, o, o)), ARGIL_OK);
    grid_fill_sphere(g, vec3(0.0f, 0.0f, 0.0f), radius_m);
    return g;
}

static inline void test_grid_free(grid_t *g)
{
    grid_free(g);
    free(g);
}

/* Where the density along +axis from the centre sample crosses 0.5 (m from the grid centre);
 * -1 when it never does. */
static inline float test_crossing_m(const grid_t *g, int axis)
{
    const int32_t n = g->dims[axis];
    int32_t at[3] = {g->dims[0] / 2, g->dims[1] / 2, g->dims[2] / 2};
    for (int32_t i = n / 2; i + 1 < n; i++) {
        at[axis] = i;
        const float a = g->density[test_gidx(g, at[0], at[1], at[2])];
        at[axis] = i + 1;
        const float b = g->density[test_gidx(g, at[0], at[1], at[2])];
        if (a >= 0.5f && b < 0.5f) {
            const float pos = (float)i + (a - 0.5f) / (a - b);
            return (pos - 0.5f * (float)(n - 1)) * g->spacing_m;
        }
    }
    return -1.0f;
}

#endif
