/* Offscreen OpenGL 3.3 core context with no window system: EGL on Mesa's surfaceless platform
 * (llvmpipe when there is no GPU). libEGL is opened at run time, so nothing links to it. */
#ifndef ARGIL_BACKEND_EGL_H
#define ARGIL_BACKEND_EGL_H

#include <stddef.h>

#include "host/render/gl_api.h"
#include "shared/argil_err.h"

typedef struct {
    void *lib;      /* dlopen handle of libEGL.so.1 */
    void *display;  /* EGLDisplay */
    void *context;  /* EGLContext */
    void *fns;      /* the EGL entry points (backend-private) */
} egl_offscreen_t;

/* Creates a current GL 3.3 core context with no surface (draw into an FBO) and loads gl.
 * ARGIL_ERR_STATE with a one-line reason when EGL, the platform or the context is missing. */
argil_err_t egl_offscreen_open(egl_offscreen_t *e, gl_api_t *gl, char *err, size_t err_len);

/* Releases the context and display; safe on a zeroed or failed e. */
void egl_offscreen_close(egl_offscreen_t *e);

#endif
