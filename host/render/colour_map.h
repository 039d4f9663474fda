/* Material colour maps for the clay (painted stiffness / mass): a value per vertex,
 * relative to the default material, mapped onto a diverging logarithmic ramp (blue below the
 * default, red above) whose range the HUD's legend shows. */
#ifndef ARGIL_COLOUR_MAP_H
#define ARGIL_COLOUR_MAP_H

#include <stdbool.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef enum { COLOUR_MAP_NONE = 0, COLOUR_MAP_STIFFNESS, COLOUR_MAP_MASS, COLOUR_MAP_COUNT } colour_map_t;

/* "none", "stiffness", "mass". */
const char *colour_map_name(colour_map_t c);

/* Reads one of those names; false for anything else. */
bool colour_map_parse(const char *name, colour_map_t *out);

/* The ramp's colour at t (0 = lowest, 1 = highest, clamped); grey for a non-finite t. */
void colour_ramp_rgb(float t, uint8_t rgb[3]);

/* The material value at a point (ctx is the sampler's own). */
typedef float (*colour_sample_fn)(const void *ctx, vec3_t x_m);

/* Values below this are coloured as this (the map is logarithmic). */
#define COLOUR_MAP_MIN_VALUE 1e-3f

/* Colours each vertex of m by sample(ctx, its position) on a logarithmic ramp centred on 1.0
 * (the default material is the pale middle; ×k and ×1/k sit equally far above and below) and
 * returns the ramp's ends: 1/k .. k for the largest factor k between the default and any value.
 * A uniform default material paints the middle; a non-finite value paints grey and is left out
 * of the range. ARGIL_ERR_NOMEM. */
argil_err_t colour_map_mesh(mesh_t *m, colour_sample_fn sample, const void *ctx, float *lo,
                            float *hi);

#endif
