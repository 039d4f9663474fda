/* Offscreen rendering over either backend (see offscreen.h). */
#include "host/render/offscreen.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { OFFSCREEN_SAMPLES = 4, OFFSCREEN_MAX_EDGE = 8192 };

static argil_err_t open_context(offscreen_t *o, render_backend_t want, char *err, size_t err_len)
{
    const char *display = getenv("DISPLAY");
    const bool have_x = display != NULL && display[0] != '\0';
    if (want == RENDER_BACKEND_GLFW || (want == RENDER_BACKEND_AUTO && have_x)) {
        char gerr[256] = "";
        /* The window itself is never drawn to; the frame goes to the multisampled target. */
        const argil_err_t rc = glfw_window_open(&o->glfw, 64, 64, false, 0, "argil", &o->gl,
                                                gerr, sizeof(gerr));
        if (rc == ARGIL_OK) {
            o->backend = RENDER_BACKEND_GLFW;
            return ARGIL_OK;
        }
        if (want == RENDER_BACKEND_GLFW) {
            snprintf(err, err_len, "%s", gerr);
            return rc;
        }
    }
    const argil_err_t rc = egl_offscreen_open(&o->egl, &o->gl, err, err_len);
    if (rc == ARGIL_OK)
        o->backend = RENDER_BACKEND_EGL;
    return rc;
}

argil_err_t offscreen_open(offscreen_t *o, render_backend_t want, int width, int height,
                           char *err, size_t err_len)
{
    memset(o, 0, sizeof(*o));
    if (width < 1 || height < 1 || width > OFFSCREEN_MAX_EDGE || height > OFFSCREEN_MAX_EDGE) {
        snprintf(err, err_len, "image size %d x %d is outside 1..%d", width, height,
                 OFFSCREEN_MAX_EDGE);
        return ARGIL_ERR_ARG;
    }
    argil_err_t rc = open_context(o, want, err, err_len);
    if (rc != ARGIL_OK)
        return rc;
    rc = renderer_init(&o->renderer, &o->gl, err, err_len);
    if (rc == ARGIL_OK)
        rc = render_target_init(&o->target, &o->gl, width, height, OFFSCREEN_SAMPLES, err,
                                err_len);
    if (rc != ARGIL_OK)
        offscreen_close(o);
    return rc;
}

const char *offscreen_backend_name(const offscreen_t *o)
{
    switch (o->backend) {
    case RENDER_BACKEND_EGL: return "EGL surfaceless";
    case RENDER_BACKEND_GLFW: return "GLFW hidden window";
    case RENDER_BACKEND_AUTO: break;
    }
    return "none";
}

void offscreen_render(offscreen_t *o, const render_scene_t *s, uint8_t *rgb)
{
    render_target_bind(&o->target);
    renderer_draw(&o->renderer, s, o->target.width, o->target.height);
    render_target_read_rgb(&o->target, rgb);
}

void offscreen_close(offscreen_t *o)
{
    render_target_free(&o->target);
    renderer_free(&o->renderer);
    if (o->backend == RENDER_BACKEND_GLFW || o->glfw.lib != NULL)
        glfw_window_close(&o->glfw);
    if (o->backend == RENDER_BACKEND_EGL || o->egl.lib != NULL)
        egl_offscreen_close(&o->egl);
    memset(o, 0, sizeof(*o));
}
