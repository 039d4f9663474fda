/* HUD text over the 3D view (see hud.h): each lit font pixel is a quad of two triangles. */
#include "host/render/hud.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/render/hud_font.h"
#include "host/render/renderer.h"

static const char *HUD_VS = "#version 330 core\n"
                            "layout(location = 0) in vec2 a_px;\n"
                            "uniform vec3 u_viewport;\n"
                            "void main() {\n"
                            "    vec2 ndc = a_px / u_viewport.xy * 2.0 - 1.0;\n"
                            "    gl_Position = vec4(ndc.x, -ndc.y, 0.0, 1.0);\n"
                            "}\n";

static const char *HUD_FS = "#version 330 core\n"
                            "uniform vec4 u_color;\n"
                            "out vec4 o_color;\n"
                            "void main() { o_color = u_color; }\n";

argil_err_t hud_init(hud_t *h, const gl_api_t *gl, char *err, size_t err_len)
{
    memset(h, 0, sizeof(*h));
    h->gl = gl;
    h->prog = renderer_program(gl, HUD_VS, HUD_FS, err, err_len);
    if (h->prog == 0)
        return ARGIL_ERR_STATE;
    gl->GenVertexArrays(1, &h->vao);
    gl->GenBuffers(1, &h->vbo);
    gl->BindVertexArray(h->vao);
    gl->BindBuffer(GL_ARRAY_BUFFER, h->vbo);
    gl->EnableVertexAttribArray(0);
    gl->VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
    gl->BindVertexArray(0);
    return ARGIL_OK;
}

static size_t put_quad(float *v, size_t n, const float *q)
{
    const float x0 = q[0], y0 = q[1], x1 = q[2], y1 = q[3];
    const float t[12] = {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1};
    memcpy(v + 12 * n, t, sizeof(t));
    return n + 1;
}

/* Readies the HUD's program and buffers over a width x height viewport, depth testing off;
 * returns the location of its colour uniform. */
static GLint hud_begin(const hud_t *h, int width, int height)
{
    const gl_api_t *gl = h->gl;
    gl->Viewport(0, 0, width, height);
    gl->Disable(GL_DEPTH_TEST);
    gl->UseProgram(h->prog);
    const float vp[3] = {(float)width, (float)height, 0.0f};
    gl->Uniform3fv(gl->GetUniformLocation(h->prog, "u_viewport"), 1, vp);
    gl->BindVertexArray(h->vao);
    gl->BindBuffer(GL_ARRAY_BUFFER, h->vbo);
    return gl->GetUniformLocation(h->prog, "u_color");
}

/* Fills the pixel rectangle q (x0, y0, x1, y1) with colour rgba (after hud_begin). */
static void hud_quad(const gl_api_t *gl, GLint color, const float q[4], const float rgba[4])
{
    float v[12];
    put_quad(v, 0, q);
    gl->Uniform4fv(color, 1, rgba);
    gl->BufferData(GL_ARRAY_BUFFER, sizeof(v), v, GL_STREAM_DRAW);
    gl->DrawArrays(GL_TRIANGLES, 0, 6);
}

/* Unbinds what hud_begin bound and turns depth testing back on. */
static void hud_end(const gl_api_t *gl)
{
    gl->BindVertexArray(0);
    gl->UseProgram(0);
    gl->Enable(GL_DEPTH_TEST);
}

void hud_draw(hud_t *h, const char *text, float scale, int width, int height)
{
    const gl_api_t *gl = h->gl;
    const size_t need = hud_font_layout(text, 0, 0, scale, NULL, 0) + 1;
    if (need > h->cap_quads) {
        float *q = realloc(h->quads, need * 4 * sizeof(float));
        if (q == NULL)
            return;
        h->quads = q;
        float *v = realloc(h->verts, need * 12 * sizeof(float));
        if (v == NULL)
            return;
        h->verts = v;
        h->cap_quads = need;
    }
    const float pad = 2.0f * scale;
    size_t lines = 1;
    for (const char *p = text; *p; p++)
        lines += *p == '\n';
    const size_t n = hud_font_layout(text, pad, pad, scale, h->quads, h->cap_quads);
    size_t nv = 0;
    for (size_t i = 0; i < n; i++)
        nv = put_quad(h->verts, nv, h->quads + 4 * i);
    const float band[4] = {0.0f, 0.0f, (float)width,
                           2.0f * pad + (float)lines * (HUD_GLYPH_H + 3) * scale - 3.0f * scale};

    const GLint color = hud_begin(h, width, height);
    gl->Enable(GL_BLEND);
    gl->BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    /* The band first, then the text on it. */
    const float dark[4] = {0.0f, 0.0f, 0.0f, 0.55f};
    hud_quad(gl, color, band, dark);
    const float ink[4] = {1.0f, 0.93f, 0.55f, 1.0f};
    gl->Uniform4fv(color, 1, ink);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 12 * sizeof(float)), h->verts,
                   GL_STREAM_DRAW);
    gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)(nv * 6));
    hud_end(gl);
    gl->Disable(GL_BLEND);
}

float hud_band_height(const char *text, float scale)
{
    size_t lines = 1;
    for (const char *p = text; *p; p++)
        lines += *p == '\n';
    return 4.0f * scale + (float)lines * (HUD_GLYPH_H + 3) * scale - 3.0f * scale;
}

void hud_draw_ramp(hud_t *h, void (*ramp)(float t, uint8_t rgb[3]), int n_steps, float x,
                   float y, float bar_w, float bar_h, int width, int height)
{
    const gl_api_t *gl = h->gl;
    if (n_steps < 2)
        return;
    const GLint color = hud_begin(h, width, height);
    const float step = bar_w / (float)n_steps;
    for (int i = 0; i < n_steps; i++) {
        uint8_t rgb[3];
        ramp((float)i / (float)(n_steps - 1), rgb);
        const float c[4] = {rgb[0] / 255.0f, rgb[1] / 255.0f, rgb[2] / 255.0f, 1.0f};
        const float q[4] = {x + step * (float)i, y, x + step * (float)(i + 1), y + bar_h};
        hud_quad(gl, color, q, c);
    }
    hud_end(gl);
}

void hud_free(hud_t *h)
{
    const gl_api_t *gl = h->gl;
    if (gl != NULL) {
        if (h->vbo)
            gl->DeleteBuffers(1, &h->vbo);
        if (h->vao)
            gl->DeleteVertexArrays(1, &h->vao);
        if (h->prog)
            gl->DeleteProgram(h->prog);
    }
    free(h->quads);
    free(h->verts);
    memset(h, 0, sizeof(*h));
}
