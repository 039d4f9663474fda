/* One call's worth of rendering to memory: picks a backend (a hidden GLFW window when there is
 * an X display, else EGL surfaceless), sets up the renderer and a 4× multisampled target, and
 * reads frames back as RGB. */
#ifndef ARGIL_OFFSCREEN_H
#define ARGIL_OFFSCREEN_H

#include <stddef.h>
#include <stdint.h>

#include "host/render/backend_egl.h"
#include "host/render/backend_glfw.h"
#include "host/render/renderer.h"

typedef enum {
    RENDER_BACKEND_AUTO = 0,  /* GLFW when DISPLAY is set (EGL if that fails), else EGL */
    RENDER_BACKEND_EGL,
    RENDER_BACKEND_GLFW
} render_backend_t;

typedef struct {
    render_backend_t backend;  /* the one in use after offscreen_open */
    egl_offscreen_t egl;
    glfw_window_t glfw;
    gl_api_t gl;
    renderer_t renderer;
    render_target_t target;
} offscreen_t;

/* Opens a width × height (1..8192) offscreen renderer. o must not move while open.
 * ARGIL_ERR_ARG for a bad size; ARGIL_ERR_STATE with a one-line reason when no backend works. */
argil_err_t offscreen_open(offscreen_t *o, render_backend_t want, int width, int height,
                           char *err, size_t err_len);

/* The name of the backend in use ("EGL surfaceless", "GLFW hidden window"). */
const char *offscreen_backend_name(const offscreen_t *o);

/* Draws s (with the mesh given to renderer_set_mesh(&o->renderer, …)) and copies the frame
 * into rgb (width × height × 3 bytes, top row first). */
void offscreen_render(offscreen_t *o, const render_scene_t *s, uint8_t *rgb);

/* Frees everything; safe on a zeroed or failed o. */
void offscreen_close(offscreen_t *o);

#endif
