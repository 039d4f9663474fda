/* Draws the clay (a mesh_t), the tool as a translucent sphere, the force as a line and the
 * board's local window as a wire box with OpenGL 3.3 core, lit by a key and a fill light in a
 * plain Blinn–Phong mode or a clear-coat mode (an analytic environment reflected in a glossy
 * layer over the clay, in the spirit of Ferley et al. §5). Also: an offscreen multisampled
 * target to read frames back. */
#ifndef ARGIL_RENDERER_H
#define ARGIL_RENDERER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "host/render/gl_api.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef enum { RENDER_MODE_PLAIN = 0, RENDER_MODE_CLEARCOAT = 1 } render_mode_t;

typedef struct {
    vec3_t dir;   /* toward the light, in view space (+z toward the viewer, +y up) */
    vec3_t rgb;   /* intensity per channel, 0..1 */
} render_light_t;

typedef struct {
    float view[16], proj[16];      /* column-major (camera_matrices) */
    render_mode_t mode;
    render_light_t key, fill;
    vec3_t ambient;
    vec3_t background;
    vec3_t clay_rgb;               /* for meshes without per-vertex colour */
    bool closed_mesh;              /* the clay is closed and CCW outside: back faces are culled */
    bool show_tool;
    vec3_t tool_pos_m;
    float tool_radius_m;
    vec3_t tool_rgb;
    float tool_alpha;
    bool show_force;
    vec3_t force_n;                /* drawn from the tool's centre */
    float force_m_per_n;           /* line length per newton */
    bool show_box;
    vec3_t box_lo_m, box_hi_m;
    bool show_wire;                /* the second iso-surface (renderer_set_wire_mesh) */
    bool wire_on_top;              /* drawn through the clay (an inner level), else hidden by it */
    vec3_t wire_rgb;
} render_scene_t;

/* The defaults: identity camera, plain mode, key light upper-left-front, fill lower-right,
 * nothing but the clay shown. */
void render_scene_default(render_scene_t *s);

typedef struct {
    const gl_api_t *gl;
    unsigned prog_surf, prog_line;
    unsigned prog_coat;            /* prog_surf's clear-coat twin (RENDER_MODE_CLEARCOAT) */
    unsigned vao_mesh, vbo_pos, vbo_nrm, vbo_rgb, ibo_mesh;
    size_t mesh_index_count;
    bool mesh_has_rgb;
    unsigned vao_sphere, vbo_sphere, ibo_sphere;
    size_t sphere_index_count;
    unsigned vao_line, vbo_line;
    unsigned vao_wire, vbo_wire, ibo_wire;
    size_t wire_index_count;
} renderer_t;

/* Compiles the shaders and makes the tool sphere; the GL context must be current.
 * ARGIL_ERR_STATE with the compiler's first line on failure. */
argil_err_t renderer_init(renderer_t *r, const gl_api_t *gl, char *err, size_t err_len);

/* Uploads m (positions, normals, colours when it has them) to draw from now on. */
argil_err_t renderer_set_mesh(renderer_t *r, const mesh_t *m);

/* Uploads m's positions and triangles as the second iso-surface, drawn as a wireframe. */
argil_err_t renderer_set_wire_mesh(renderer_t *r, const mesh_t *m);

/* Draws the scene into the bound framebuffer's width × height pixels. */
void renderer_draw(const renderer_t *r, const render_scene_t *s, int width, int height);

/* Deletes every GL object; the context must still be current. */
void renderer_free(renderer_t *r);

/* Compiles and links a vertex + fragment program; 0 with the first line of the log in err. */
unsigned renderer_program(const gl_api_t *gl, const char *vs_src, const char *fs_src,
                          char *err, size_t err_len);

/* An offscreen frame: a multisampled colour + depth framebuffer resolved into a plain one. */
typedef struct {
    const gl_api_t *gl;
    unsigned fbo_ms, rb_color_ms, rb_depth_ms;
    unsigned fbo_out, rb_color_out;
    int width, height;
    int samples;                   /* what the driver gave (0: no multisampling) */
} render_target_t;

/* Makes a width × height target with min(samples, GL_MAX_SAMPLES) samples and binds it. */
argil_err_t render_target_init(render_target_t *t, const gl_api_t *gl, int width, int height,
                               int samples, char *err, size_t err_len);

/* Binds t for drawing. */
void render_target_bind(const render_target_t *t);

/* Resolves the samples and copies the frame into rgb (width × height × 3 bytes, top row
 * first). */
void render_target_read_rgb(const render_target_t *t, uint8_t *rgb);

/* Resolves t's samples into the default framebuffer (a window of t's size) and binds it. */
void render_target_present(const render_target_t *t);

void render_target_free(render_target_t *t);

#endif
