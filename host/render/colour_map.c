/* Material colour maps (see colour_map.h). */
#include "host/render/colour_map.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const NAMES[COLOUR_MAP_COUNT] = {"none", "stiffness", "mass"};

/* Five stops, even in t: deep blue, light blue, pale (the middle), orange, deep red; red minus
 * blue rises all along, so "redder" always means "more". */
static const float STOPS[5][3] = {{0.13f, 0.24f, 0.72f},
                                  {0.36f, 0.66f, 0.92f},
                                  {0.93f, 0.93f, 0.86f},
                                  {0.96f, 0.58f, 0.22f},
                                  {0.82f, 0.08f, 0.04f}};

const char *colour_map_name(colour_map_t c)
{
    return c >= 0 && c < COLOUR_MAP_COUNT ? NAMES[c] : "?";
}

bool colour_map_parse(const char *name, colour_map_t *out)
{
    for (int i = 0; i < COLOUR_MAP_COUNT; i++)
        if (strcmp(name, NAMES[i]) == 0) {
            *out = (colour_map_t)i;
            return true;
        }
    return false;
}

void colour_ramp_rgb(float t, uint8_t rgb[3])
{
    if (!isfinite(t)) {
        rgb[0] = rgb[1] = rgb[2] = 128;
        return;
    }
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    const float x = t * 4.0f;
    int k = (int)x;
    if (k > 3)
        k = 3;
    const float f = x - (float)k;
    for (int c = 0; c < 3; c++) {
        const float v = STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f;
        rgb[c] = (uint8_t)lroundf(v * 255.0f);
    }
}

argil_err_t colour_map_mesh(mesh_t *m, colour_sample_fn sample, const void *ctx, float *lo,
                            float *hi)
{
    *lo = *hi = 1.0f;
    if (!m->has_rgb && mesh_enable_rgb(m) != ARGIL_OK)
        return ARGIL_ERR_NOMEM;
    float *val = malloc(sizeof(float) * (m->n_vert > 0 ? m->n_vert : 1));
    if (val == NULL)
        return ARGIL_ERR_NOMEM;
    for (size_t i = 0; i < m->n_vert; i++) {
        float v = sample(ctx, vec3(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]));
        if (v < COLOUR_MAP_MIN_VALUE)
            v = COLOUR_MAP_MIN_VALUE; /* stiffness may be painted to 0: keep the log finite */
        val[i] = v;
        if (!isfinite(v))
            continue;
        if (v < *lo)
            *lo = v;
        if (v > *hi)
            *hi = v;
    }
    /* Logarithmic and centred on the default: half as stiff sits as far below the ramp's pale
     * middle as twice as stiff sits above it, and the default material is always the middle. */
    const float l = fmaxf(fabsf(logf(*lo)), fabsf(logf(*hi)));
    if (l > 1e-6f) {
        *lo = expf(-l);
        *hi = expf(l);
    }
    for (size_t i = 0; i < m->n_vert; i++) {
        const float v = val[i];
        const float t = !isfinite(v) ? NAN : l > 1e-6f ? 0.5f + 0.5f * logf(v) / l : 0.5f;
        colour_ramp_rgb(t, m->rgb + 3 * i);
    }
    free(val);
    return ARGIL_OK;
}
