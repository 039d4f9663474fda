/* Painted colour (docs/model.md "In the session"): the model's FS_R/G/B mirrored to and from
 * the grid's rgb bytes, which the journal and .argil record. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve_internal.h"

/* A colour channel value (0..1) as the grid's byte. */
static uint8_t colour_byte(float v)
{
    const float c = gsolve_clamp01(v) * 255.0f;
    return (uint8_t)lrintf(isfinite(c) ? c : 0.0f);
}

/* Copies the model's FS_R/G/B in sample box [lo, hi) (clipped to the grid) into the grid's colour
 * as bytes (a block holds a colour array only once one of its samples differs from
 * GRID_RGB_DEFAULT); bumps g->rgb_writes when anything changed. Returns 1 when something
 * changed, 0 when nothing did, -1 when out of memory. */
float gsolve_colour_box_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                const int32_t hi[3])
{
    int32_t a0[3], a1[3], n[3];
    if (!grid_clip(g, lo, hi, a0, a1))
        return 0.0f;
    for (int a = 0; a < 3; a++)
        n[a] = a1[a] - a0[a];
    const size_t vol = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    float *v = malloc(3 * vol * sizeof(float));
    if (v == NULL)
        return -1.0f;
    for (int c = 0; c < 3; c++)
        sparse_read_box(&gs->field.samp, FS_R + c, a0, n, v + (size_t)c * vol);
    uint8_t *cur = malloc(3 * vol), *want = malloc(3 * vol);
    if (cur == NULL || want == NULL) {
        free(cur);
        free(want);
        free(v);
        return -1.0f;
    }
    grid_rgb_read_box(g, a0, n, cur);
    for (size_t k = 0; k < vol; k++) {
        want[3 * k] = colour_byte(v[k]);
        want[3 * k + 1] = colour_byte(v[vol + k]);
        want[3 * k + 2] = colour_byte(v[2 * vol + k]);
    }
    const bool changed = memcmp(cur, want, 3 * vol) != 0;
    const bool nomem = changed && grid_rgb_write_box(g, a0, n, want) != ARGIL_OK;
    free(cur);
    free(want);
    free(v);
    if (changed)
        g->rgb_writes++;
    return nomem ? -1.0f : (changed ? 1.0f : 0.0f);
}

/* gsolve_colour_box_to_grid as an error code. */
argil_err_t gsolve_colour_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                  const int32_t hi[3])
{
    return gsolve_colour_box_to_grid(gs, g, lo, hi) < 0.0f ? ARGIL_ERR_NOMEM : ARGIL_OK;
}

/* The grid's rgb, when present, becomes the model's FS_R/G/B. */
argil_err_t gsolve_colour_from_grid(gsolve_t *gs, const grid_t *g)
{
    if (!grid_rgb_any(g))
        return ARGIL_OK;
    int32_t lo[3], n[3];
    uint8_t *rgb = grid_dense_copy_rgb(g, lo, n);
    const size_t cnt = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    float *v = rgb != NULL ? malloc(cnt * sizeof(float)) : NULL;
    if (v == NULL) {
        free(rgb);
        return ARGIL_ERR_NOMEM;
    }
    argil_err_t e = ARGIL_OK;
    for (int c = 0; c < 3 && e == ARGIL_OK; c++) {
        for (size_t i = 0; i < cnt; i++)
            v[i] = (float)rgb[3 * i + (size_t)c] / 255.0f;
        e = sparse_write_box(&gs->field.samp, FS_R + c, lo, n, v);
    }
    free(v);
    free(rgb);
    return e;
}
