/* The heads-up text drawn over the 3D view: lines of the 5 × 7 font on a translucent dark band
 * along the top of the window (OpenGL 3.3 core, no texture). */
#ifndef ARGIL_HUD_H
#define ARGIL_HUD_H

#include <stddef.h>
#include <stdint.h>

#include "host/render/gl_api.h"
#include "shared/argil_err.h"

typedef struct {
    const gl_api_t *gl;
    unsigned prog, vao, vbo;
    float *quads, *verts;         /* scratch: 4 floats per quad, 12 per quad's two triangles */
    size_t cap_quads;
} hud_t;

/* Compiles the HUD's shader; the GL context must be current. ARGIL_ERR_STATE with the
 * compiler's first line, ARGIL_ERR_NOMEM. */
argil_err_t hud_init(hud_t *h, const gl_api_t *gl, char *err, size_t err_len);

/* Draws text ('\n' between lines) at scale pixels per font pixel from the top-left corner of a
 * width × height framebuffer, over a band as tall as the text. */
void hud_draw(hud_t *h, const char *text, float scale, int width, int height);

/* The height in pixels of the band hud_draw puts under text at scale. */
float hud_band_height(const char *text, float scale);

/* Draws a colour bar of n_steps quads from left to right, colour i from ramp(i / (n_steps-1)),
 * with its top-left corner at (x, y) pixels from the framebuffer's top-left corner. */
void hud_draw_ramp(hud_t *h, void (*ramp)(float t, uint8_t rgb[3]), int n_steps, float x,
                   float y, float bar_w, float bar_h, int width, int height);

/* Deletes the GL objects and the scratch; the context must still be current. */
void hud_free(hud_t *h);

#endif
