/* Test fixture: a cube grid centred on the origin holding a sphere, as the grid and B-spline
 * model tests start from (alone or with its model), and where its density crosses 0.5 along an
 * axis. Header-only; the
 * fixture asserts with cmocka. */
#ifndef ARGIL_TEST_SPHERE_GRID_H
#define ARGIL_TEST_SPHERE_GRID_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "host/solve/gsolve.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"

/* Initialises g to n³ samples h_m apart centred on the origin (symmetric about every origin
 * plane) holding a sphere of radius r_m about the origin (grid_free frees it). */
static inline void sphere_grid_init(grid_t *g, int32_t n, float h_m, float r_m)
{
    const int32_t dims[3] = {n, n, n};
    const float o = -0.5f * (float)(n - 1) * h_m;
    assert_int_equal(grid_init(g, dims, h_m, vec3(o, o, o)), ARGIL_OK);
    grid_fill_sphere(g, vec3(0.0f, 0.0f, 0.0f), r_m);
}

/* The same grid on the heap, freed by sphere_grid_free. */
static inline grid_t *sphere_grid_new(int32_t n, float h_m, float r_m)
{
    grid_t *g = malloc(sizeof(*g));
    assert_non_null(g);
    sphere_grid_init(g, n, h_m, r_m);
    return g;
}

static inline void sphere_grid_free(grid_t *g)
{
    grid_free(g);
    free(g);
}

/* The same grid on the heap with its B-spline model in gs (gsolve_init), freed by
 * sphere_model_free. */
static inline grid_t *sphere_model_new(gsolve_t *gs, int32_t n, float h_m, float r_m)
{
    grid_t *g = sphere_grid_new(n, h_m, r_m);
    assert_int_equal(gsolve_init(gs, g), ARGIL_OK);
    return g;
}

static inline void sphere_model_free(gsolve_t *gs, grid_t *g)
{
    gsolve_free(gs);
    sphere_grid_free(g);
}

/* Where the density along +axis from the centre sample (dims / 2 on every axis) crosses 0.5,
 * m from the grid centre; -1 when it does not. */
static inline float sphere_crossing_m(const grid_t *g, int axis)
{
    const int32_t n = g->dims[axis], c = n / 2;
    int32_t at[3] = {c, c, c};
    for (int32_t i = c; i + 1 < n; i++) {
        at[axis] = i;
        const float a = gv_get(g, GRID_DENSITY, gv_idx(g, at[0], at[1], at[2]));
        at[axis] = i + 1;
        const float b = gv_get(g, GRID_DENSITY, gv_idx(g, at[0], at[1], at[2]));
        if (a >= 0.5f && b < 0.5f) {
            const float pos = (float)i + (a - 0.5f) / (a - b);
            return (pos - 0.5f * (float)(n - 1)) * g->spacing_m;
        }
    }
    return -1.0f;
}

/* Adds force_n (N) around sample (x, y, z), spread like the board's Gaussian filter (σ 1.5
 * samples over 7³ nodes, weights summing to 1). */
static inline void sphere_push_gauss(grid_t *g, int32_t x, int32_t y, int32_t z, float force_n)
{
    double wsum = 0.0;
    for (int dz = -3; dz <= 3; dz++)
        for (int dy = -3; dy <= 3; dy++)
            for (int dx = -3; dx <= 3; dx++)
                wsum += exp(-(dx * dx + dy * dy + dz * dz) / 4.5);
    for (int dz = -3; dz <= 3; dz++)
        for (int dy = -3; dy <= 3; dy++)
            for (int dx = -3; dx <= 3; dx++)
                assert_true(grid_add_force(
                    g, x + dx, y + dy, z + dz,
                    (float)(force_n * exp(-(dx * dx + dy * dy + dz * dz) / 4.5) / wsum)));
}

/* The surface sample on +y nearest density 0.5 on the centre column (dims / 2). */
static inline int32_t sphere_surface_y(const grid_t *g)
{
    const int32_t c = g->dims[0] / 2;
    int32_t sy = c;
    while (gv_get(g, GRID_DENSITY, gv_idx(g, c, sy + 1, c)) >= 0.5f)
        sy++;
    return sy;
}

/* Twelve solve steps of two models on equal sphere grids under a window box (16 samples, over
 * the sphere's top at dims / 2 + 15) that moves by shift_n samples every third step, pushed
 * with -20 N at its centre for the first 8 steps: a keeps its window (moved 3 times), b closes
 * its window before each move (opened 4 times). Asserts every step changes both the same and
 * the two grids end equal bit for bit; returns the largest change of a step. */
static inline float sphere_moved_vs_fresh_window(gsolve_t *a, grid_t *g1, gsolve_t *b, grid_t *g2,
                                                 int32_t shift_n, float dt_s)
{
    const int32_t c = g1->dims[0] / 2, sy = c + 15;
    float largest = 0.0f;
    for (int k = 0; k < 12; k++) {
        const int32_t shift = shift_n * (k / 3);
        const int32_t lo[3] = {c - 8 + shift, sy - 8, c - 8};
        const int32_t hi[3] = {c + 8 + shift, sy + 8, c + 8};
        if (k < 8) {
            assert_true(grid_add_force(g1, c + shift, sy, c, -20.0f));
            assert_true(grid_add_force(g2, c + shift, sy, c, -20.0f));
        }
        if (k % 3 == 0)
            gsolve_close_window(b);
        int32_t dlo[3], dhi[3];
        float ch1, ch2;
        assert_int_equal(gsolve_step(a, g1, lo, hi, dt_s, dlo, dhi, &ch1), ARGIL_OK);
        assert_int_equal(gsolve_step(b, g2, lo, hi, dt_s, dlo, dhi, &ch2), ARGIL_OK);
        assert_true(ch1 == ch2);
        if (ch1 > largest)
            largest = ch1;
    }
    assert_int_equal(a->stats.windows_opened, 1);
    assert_int_equal(a->stats.windows_moved, 3);
    assert_int_equal(b->stats.windows_opened, 4);
    assert_true(gv_same(g1, GRID_DENSITY, g2, GRID_DENSITY));
    return largest;
}

#endif
