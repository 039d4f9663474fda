/* OpenGL 3.3 core drawing of the clay, the tool, the force and the window box (see renderer.h). */
#include "host/render/renderer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { ATTR_POS = 0, ATTR_NORMAL = 1, ATTR_RGB = 2 };
enum { SPHERE_SLICES = 32, SPHERE_STACKS = 16 };
enum { LINE_VERTS_MAX = 24 + 10 };  /* 12 box edges + the force line and its 4-stroke head */

/* The base colour is linearised per vertex: for the clay's one colour and the tool's tint that is
 * the same as per pixel, and a colour-mapped mesh blends its colours in linear light. */
static const char *SURF_VS =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "layout(location = 2) in vec3 a_rgb;\n"
    "uniform mat4 u_model, u_view, u_proj;\n"
    "uniform vec4 u_tint;\n"
    "uniform float u_tint_mix;\n"
    "out vec3 v_pos, v_normal, v_base;\n"
    "void main() {\n"
    "    mat4 mv = u_view * u_model;\n"
    "    vec4 p = mv * vec4(a_pos, 1.0);\n"
    "    v_pos = p.xyz;\n"
    "    v_normal = mat3(mv) * a_normal;\n"
    "    v_base = pow(mix(a_rgb, u_tint.rgb, u_tint_mix), vec3(2.2));\n"
    "    gl_Position = u_proj * p;\n"
    "}\n";

/* Lights and the environment are in view space: the studio turns with the camera. One program
 * per shading mode (CLEARCOAT 0 or 1): llvmpipe would shade both sides of a branch on a
 * uniform, about a sixth more work per pixel of clay. */
#define SURF_FS_BODY                                                                             \
    "in vec3 v_pos, v_normal, v_base;\n"                                                         \
    "uniform vec3 u_key_dir, u_key_rgb, u_fill_dir, u_fill_rgb, u_ambient;\n"                    \
    "uniform vec4 u_tint;\n"                                                                     \
    "out vec4 o_color;\n"                                                                        \
    "\n"                                                                                         \
    "vec3 studio(vec3 r, vec3 kd, vec3 fd) {\n"                                                  \
    "    vec3 zenith = vec3(0.80, 0.86, 0.95), horizon = vec3(0.34, 0.36, 0.40);\n"              \
    "    vec3 ground = vec3(0.12, 0.10, 0.09);\n"                                                \
    "    vec3 sky = mix(horizon, zenith, smoothstep(0.0, 0.8, r.y));\n"                          \
    "    vec3 c = mix(ground, sky, smoothstep(-0.12, 0.04, r.y));\n"                             \
    "    c += 3.0 * u_key_rgb * smoothstep(0.93, 0.99, dot(r, kd));\n"                           \
    "    c += 1.5 * u_fill_rgb * smoothstep(0.88, 0.97, dot(r, fd));\n"                          \
    "    return c;\n"                                                                            \
    "}\n"                                                                                        \
    "\n"                                                                                         \
    "vec3 blinn(vec3 n, vec3 v, vec3 l, vec3 light, vec3 base, float shininess, float ks) {\n"   \
    "    float ndl = max(dot(n, l), 0.0);\n"                                                     \
    "    float nh = max(dot(n, normalize(l + v)), 0.0);\n"                                       \
    "    float spec = ndl > 0.0 ? ks * (shininess + 8.0) / 25.13 * pow(nh, shininess) : 0.0;\n"  \
    "    return light * (base * ndl + vec3(spec));\n"                                            \
    "}\n"                                                                                        \
    "\n"                                                                                         \
    "void main() {\n"                                                                            \
    "    vec3 n = normalize(v_normal);\n"                                                        \
    "    if (!gl_FrontFacing) n = -n;\n"                                                         \
    "    vec3 v = normalize(-v_pos);\n"                                                          \
    "    vec3 kd = normalize(u_key_dir), fd = normalize(u_fill_dir);\n"                          \
    "    vec3 base = v_base;\n"                                                                  \
    "#if CLEARCOAT\n"                                                                            \
    "    vec3 under = u_ambient * base + blinn(n, v, kd, u_key_rgb, base, 6.0, 0.02)\n"          \
    "               + blinn(n, v, fd, u_fill_rgb, base, 6.0, 0.02);\n"                           \
    "    float fresnel = 0.04 + 0.96 * pow(1.0 - max(dot(n, v), 0.0), 5.0);\n"                   \
    "    float coat = 0.06 + 0.7 * fresnel;\n"                                                   \
    "    vec3 c = under * (1.0 - coat) + coat * studio(reflect(-v, n), kd, fd);\n"               \
    "#else\n"                                                                                    \
    "    vec3 c = u_ambient * base + blinn(n, v, kd, u_key_rgb, base, 40.0, 0.12)\n"             \
    "           + blinn(n, v, fd, u_fill_rgb, base, 40.0, 0.12);\n"                              \
    "#endif\n"                                                                                   \
    "    o_color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), u_tint.a);\n"                  \
    "}\n"
static const char *SURF_FS_PLAIN = "#version 330 core\n#define CLEARCOAT 0\n" SURF_FS_BODY;
static const char *SURF_FS_COAT = "#version 330 core\n#define CLEARCOAT 1\n" SURF_FS_BODY;

static const char *LINE_VS = "#version 330 core\n"
                             "layout(location = 0) in vec3 a_pos;\n"
                             "uniform mat4 u_view, u_proj;\n"
                             "void main() { gl_Position = u_proj * u_view * vec4(a_pos, 1.0); }\n";

static const char *LINE_FS = "#version 330 core\n"
                             "uniform vec4 u_color;\n"
                             "out vec4 o_color;\n"
                             "void main() { o_color = u_color; }\n";

void render_scene_default(render_scene_t *s)
{
    memset(s, 0, sizeof(*s));
    for (int i = 0; i < 4; i++)
        s->view[i * 5] = s->proj[i * 5] = 1.0f;
    s->mode = RENDER_MODE_PLAIN;
    s->key.dir = vec3(-0.45f, 0.65f, 0.62f);
    s->key.rgb = vec3(1.0f, 0.97f, 0.92f);
    s->fill.dir = vec3(0.75f, -0.15f, 0.45f);
    s->fill.rgb = vec3(0.28f, 0.32f, 0.40f);
    s->ambient = vec3(0.06f, 0.06f, 0.07f);
    s->background = vec3(0.17f, 0.18f, 0.21f);
    s->clay_rgb = vec3(0.80f, 0.56f, 0.42f);
    s->tool_rgb = vec3(0.15f, 0.75f, 1.0f);
    s->tool_alpha = 0.45f;
    s->tool_radius_m = 0.004f;
    s->force_m_per_n = 0.01f;
    s->wire_rgb = vec3(0.90f, 0.40f, 1.0f);
}

/* Writes "what: " and the first line of object obj's info log into err (get reads a shader's
 * or a program's log). */
static void say_log(PFNGLGETSHADERINFOLOGPROC get, GLuint obj, const char *what, char *err,
                    size_t err_len)
{
    char log[512] = "";
    get(obj, sizeof(log), NULL, log);
    log[strcspn(log, "\n")] = '\0';
    snprintf(err, err_len, "%s: %s", what, log);
}

/* Compiles one stage; 0 with the log's first line in err on failure. */
static unsigned compile(const gl_api_t *gl, GLenum type, const char *src, char *err,
                        size_t err_len)
{
    const GLuint sh = gl->CreateShader(type);
    gl->ShaderSource(sh, 1, &src, NULL);
    gl->CompileShader(sh);
    GLint ok = 0;
    gl->GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        say_log(gl->GetShaderInfoLog, sh,
                type == GL_VERTEX_SHADER ? "vertex shader does not compile"
                                         : "fragment shader does not compile",
                err, err_len);
        gl->DeleteShader(sh);
        return 0;
    }
    return sh;
}

static unsigned link_program(const gl_api_t *gl, const char *vs_src, const char *fs_src,
                             char *err, size_t err_len)
{
    const GLuint vs = compile(gl, GL_VERTEX_SHADER, vs_src, err, err_len);
    if (vs == 0)
        return 0;
    const GLuint fs = compile(gl, GL_FRAGMENT_SHADER, fs_src, err, err_len);
    if (fs == 0) {
        gl->DeleteShader(vs);
        return 0;
    }
    const GLuint p = gl->CreateProgram();
    gl->AttachShader(p, vs);
    gl->AttachShader(p, fs);
    gl->LinkProgram(p);
    gl->DeleteShader(vs);
    gl->DeleteShader(fs);
    GLint ok = 0;
    gl->GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        say_log(gl->GetProgramInfoLog, p, "shaders do not link", err, err_len);
        gl->DeleteProgram(p);
        return 0;
    }
    return p;
}

/* The linked program of vs_src and fs_src; 0 with the reason in err. */
unsigned renderer_program(const gl_api_t *gl, const char *vs_src, const char *fs_src,
                          char *err, size_t err_len)
{
    return link_program(gl, vs_src, fs_src, err, err_len);
}

/* A unit UV sphere whose positions are also its normals. */
static argil_err_t make_sphere(renderer_t *r)
{
    const gl_api_t *gl = r->gl;
    enum { NV = (SPHERE_SLICES + 1) * (SPHERE_STACKS + 1), NI = SPHERE_SLICES * SPHERE_STACKS * 6 };
    float *v = malloc(sizeof(float) * 3 * NV);
    uint32_t *idx = malloc(sizeof(uint32_t) * NI);
    if (v == NULL || idx == NULL) {
        free(v);
        free(idx);
        return ARGIL_ERR_NOMEM;
    }
    size_t k = 0;
    for (int j = 0; j <= SPHERE_STACKS; j++) {
        const float th = (float)M_PI * (float)j / SPHERE_STACKS;
        for (int i = 0; i <= SPHERE_SLICES; i++) {
            const float ph = 2.0f * (float)M_PI * (float)i / SPHERE_SLICES;
            v[k++] = sinf(th) * cosf(ph);
            v[k++] = cosf(th);
            v[k++] = -sinf(th) * sinf(ph);
        }
    }
    k = 0;
    for (int j = 0; j < SPHERE_STACKS; j++)
        for (int i = 0; i < SPHERE_SLICES; i++) {
            const uint32_t a = (uint32_t)(j * (SPHERE_SLICES + 1) + i);
            const uint32_t b = a + SPHERE_SLICES + 1;
            idx[k++] = a; idx[k++] = b; idx[k++] = a + 1;
            idx[k++] = a + 1; idx[k++] = b; idx[k++] = b + 1;
        }
    gl->GenVertexArrays(1, &r->vao_sphere);
    gl->BindVertexArray(r->vao_sphere);
    gl->GenBuffers(1, &r->vbo_sphere);
    gl->BindBuffer(GL_ARRAY_BUFFER, r->vbo_sphere);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * NV), v, GL_STATIC_DRAW);
    gl->VertexAttribPointer(ATTR_POS, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    gl->EnableVertexAttribArray(ATTR_POS);
    gl->VertexAttribPointer(ATTR_NORMAL, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    gl->EnableVertexAttribArray(ATTR_NORMAL);
    gl->GenBuffers(1, &r->ibo_sphere);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->ibo_sphere);
    gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(uint32_t) * NI), idx,
                   GL_STATIC_DRAW);
    gl->BindVertexArray(0);
    r->sphere_index_count = NI;
    free(v);
    free(idx);
    return ARGIL_OK;
}

argil_err_t renderer_init(renderer_t *r, const gl_api_t *gl, char *err, size_t err_len)
{
    memset(r, 0, sizeof(*r));
    r->gl = gl;
    r->prog_surf = link_program(gl, SURF_VS, SURF_FS_PLAIN, err, err_len);
    if (r->prog_surf == 0)
        return ARGIL_ERR_STATE;
    r->prog_coat = link_program(gl, SURF_VS, SURF_FS_COAT, err, err_len);
    if (r->prog_coat == 0) {
        renderer_free(r);
        return ARGIL_ERR_STATE;
    }
    r->prog_line = link_program(gl, LINE_VS, LINE_FS, err, err_len);
    if (r->prog_line == 0) {
        renderer_free(r);
        return ARGIL_ERR_STATE;
    }
    if (make_sphere(r) != ARGIL_OK) {
        renderer_free(r);
        snprintf(err, err_len, "renderer: out of memory");
        return ARGIL_ERR_NOMEM;
    }
    gl->GenVertexArrays(1, &r->vao_line);
    gl->BindVertexArray(r->vao_line);
    gl->GenBuffers(1, &r->vbo_line);
    gl->BindBuffer(GL_ARRAY_BUFFER, r->vbo_line);
    gl->BufferData(GL_ARRAY_BUFFER, sizeof(float) * 3 * LINE_VERTS_MAX, NULL, GL_DYNAMIC_DRAW);
    gl->VertexAttribPointer(ATTR_POS, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    gl->EnableVertexAttribArray(ATTR_POS);
    gl->GenVertexArrays(1, &r->vao_mesh);
    gl->BindVertexArray(r->vao_mesh);
    gl->GenBuffers(1, &r->vbo_pos);
    gl->GenBuffers(1, &r->vbo_nrm);
    gl->GenBuffers(1, &r->vbo_rgb);
    gl->GenBuffers(1, &r->ibo_mesh);
    gl->GenVertexArrays(1, &r->vao_wire);
    gl->BindVertexArray(r->vao_wire);
    gl->GenBuffers(1, &r->vbo_wire);
    gl->GenBuffers(1, &r->ibo_wire);
    gl->BindVertexArray(0);
    if (gl->GetError() != GL_NO_ERROR) {
        renderer_free(r);
        snprintf(err, err_len, "renderer: OpenGL refused to create its buffers");
        return ARGIL_ERR_STATE;
    }
    return ARGIL_OK;
}

/* Loads n_vert 3-float vectors into buffer vbo and feeds them to attribute attr of the bound
 * vertex array. */
static void upload_vec3(const gl_api_t *gl, unsigned vbo, unsigned attr, size_t n_vert,
                        const float *v)
{
    gl->BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * n_vert), v, GL_STATIC_DRAW);
    gl->VertexAttribPointer(attr, 3, GL_FLOAT, GL_FALSE, 0, NULL);
    gl->EnableVertexAttribArray(attr);
}

/* Loads m's triangles into index buffer ibo of the bound vertex array, unbinds the array and
 * returns the index count. */
static size_t upload_tris(const gl_api_t *gl, unsigned ibo, const mesh_t *m)
{
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(uint32_t) * 3 * m->n_tri), m->tri,
                   GL_STATIC_DRAW);
    gl->BindVertexArray(0);
    return 3 * m->n_tri;
}

/* Binds vertex array vao and loads m's positions into vbo_pos; false, with nothing bound, when
 * m lacks an array it needs (normals too when with_normals) or has more indices than GL counts. */
static bool upload_begin(const gl_api_t *gl, const mesh_t *m, bool with_normals, unsigned vao,
                         unsigned vbo_pos)
{
    if (m->n_tri > 0 && (m->pos == NULL || (with_normals && m->normal == NULL) || m->tri == NULL))
        return false;
    if (m->n_tri > (size_t)INT32_MAX / 3)
        return false;
    gl->BindVertexArray(vao);
    upload_vec3(gl, vbo_pos, ATTR_POS, m->n_vert, m->pos);
    return true;
}

argil_err_t renderer_set_mesh(renderer_t *r, const mesh_t *m)
{
    const gl_api_t *gl = r->gl;
    if (!upload_begin(gl, m, true, r->vao_mesh, r->vbo_pos))
        return ARGIL_ERR_ARG;
    upload_vec3(gl, r->vbo_nrm, ATTR_NORMAL, m->n_vert, m->normal);
    r->mesh_has_rgb = m->has_rgb && m->rgb != NULL;
    if (r->mesh_has_rgb) {
        gl->BindBuffer(GL_ARRAY_BUFFER, r->vbo_rgb);
        gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(3 * m->n_vert), m->rgb, GL_STATIC_DRAW);
        gl->VertexAttribPointer(ATTR_RGB, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0, NULL);
        gl->EnableVertexAttribArray(ATTR_RGB);
    } else {
        gl->DisableVertexAttribArray(ATTR_RGB);
    }
    r->mesh_index_count = upload_tris(gl, r->ibo_mesh, m);
    return gl->GetError() == GL_NO_ERROR ? ARGIL_OK : ARGIL_ERR_NOMEM;
}

argil_err_t renderer_set_wire_mesh(renderer_t *r, const mesh_t *m)
{
    const gl_api_t *gl = r->gl;
    if (!upload_begin(gl, m, false, r->vao_wire, r->vbo_wire))
        return ARGIL_ERR_ARG;
    r->wire_index_count = upload_tris(gl, r->ibo_wire, m);
    return gl->GetError() == GL_NO_ERROR ? ARGIL_OK : ARGIL_ERR_NOMEM;
}

static void set_vec3(const gl_api_t *gl, unsigned prog, const char *name, vec3_t v)
{
    const float f[3] = {v.x, v.y, v.z};
    gl->Uniform3fv(gl->GetUniformLocation(prog, name), 1, f);
}

static void set_mat4(const gl_api_t *gl, unsigned prog, const char *name, const float m[16])
{
    gl->UniformMatrix4fv(gl->GetUniformLocation(prog, name), 1, GL_FALSE, m);
}

static void set_color(const gl_api_t *gl, unsigned prog, const char *name, vec3_t rgb, float a)
{
    const float f[4] = {rgb.x, rgb.y, rgb.z, a};
    gl->Uniform4fv(gl->GetUniformLocation(prog, name), 1, f);
}

static size_t put(float *buf, size_t n, vec3_t p)
{
    buf[3 * n] = p.x;
    buf[3 * n + 1] = p.y;
    buf[3 * n + 2] = p.z;
    return n + 1;
}

static void draw_lines(const renderer_t *r, const float *verts, size_t n, vec3_t rgb, float a)
{
    const gl_api_t *gl = r->gl;
    set_color(gl, r->prog_line, "u_color", rgb, a);
    gl->BindVertexArray(r->vao_line);
    gl->BindBuffer(GL_ARRAY_BUFFER, r->vbo_line);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * n), verts, GL_STREAM_DRAW);
    gl->DrawArrays(GL_LINES, 0, (GLsizei)n);
}

static void draw_wire(const renderer_t *r, const render_scene_t *s)
{
    const gl_api_t *gl = r->gl;
    gl->UseProgram(r->prog_line);
    set_color(gl, r->prog_line, "u_color", s->wire_rgb, s->wire_on_top ? 0.35f : 0.6f);
    gl->Enable(GL_BLEND);
    gl->BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    if (s->wire_on_top)
        gl->Disable(GL_DEPTH_TEST);
    gl->DepthMask(GL_FALSE);
    gl->PolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    gl->BindVertexArray(r->vao_wire);
    gl->DrawElements(GL_TRIANGLES, (GLsizei)r->wire_index_count, GL_UNSIGNED_INT, NULL);
    gl->PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    gl->DepthMask(GL_TRUE);
    gl->Disable(GL_BLEND);
    gl->Enable(GL_DEPTH_TEST);
}

/* Binds a surface program with the scene's camera and lights. */
static void use_surface(const renderer_t *r, unsigned prog, const render_scene_t *s)
{
    const gl_api_t *gl = r->gl;
    gl->UseProgram(prog);
    set_mat4(gl, prog, "u_view", s->view);
    set_mat4(gl, prog, "u_proj", s->proj);
    set_vec3(gl, prog, "u_key_dir", s->key.dir);
    set_vec3(gl, prog, "u_key_rgb", s->key.rgb);
    set_vec3(gl, prog, "u_fill_dir", s->fill.dir);
    set_vec3(gl, prog, "u_fill_rgb", s->fill.rgb);
    set_vec3(gl, prog, "u_ambient", s->ambient);
}

void renderer_draw(const renderer_t *r, const render_scene_t *s, int width, int height)
{
    const gl_api_t *gl = r->gl;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    gl->Viewport(0, 0, width, height);
    gl->ClearColor(s->background.x, s->background.y, s->background.z, 1.0f);
    gl->Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->DepthMask(GL_TRUE);
    gl->Disable(GL_BLEND);
    gl->Disable(GL_CULL_FACE);

    /* The clay: opaque, both sides lit (an open or clipped mesh shows its inside). */
    const unsigned clay_prog = s->mode == RENDER_MODE_PLAIN ? r->prog_surf : r->prog_coat;
    use_surface(r, clay_prog, s);
    set_mat4(gl, clay_prog, "u_model", identity);
    set_color(gl, clay_prog, "u_tint", s->clay_rgb, 1.0f);
    gl->Uniform1f(gl->GetUniformLocation(clay_prog, "u_tint_mix"), 0.0f);
    if (r->mesh_index_count > 0) {
        gl->BindVertexArray(r->vao_mesh);
        if (!r->mesh_has_rgb)
            gl->VertexAttrib3f(ATTR_RGB, s->clay_rgb.x, s->clay_rgb.y, s->clay_rgb.z);
        if (s->closed_mesh) {
            /* Back faces of a closed surface are hidden anyway; skipping them halves
             * llvmpipe's shading work (measured in make bench). */
            gl->Enable(GL_CULL_FACE);
            gl->CullFace(GL_BACK);
        }
        gl->DrawElements(GL_TRIANGLES, (GLsizei)r->mesh_index_count, GL_UNSIGNED_INT, NULL);
        gl->Disable(GL_CULL_FACE);
    }

    /* The local window: a wire box, hidden where the clay is in front of it. */
    float lines[3 * LINE_VERTS_MAX];
    gl->UseProgram(r->prog_line);
    set_mat4(gl, r->prog_line, "u_view", s->view);
    set_mat4(gl, r->prog_line, "u_proj", s->proj);
    if (s->show_box) {
        const vec3_t lo = s->box_lo_m, hi = s->box_hi_m;
        size_t n = 0;
        for (int e = 0; e < 12; e++) {
            /* Edge e runs along axis e / 4; its other two coordinates are the bits of e % 4. */
            const int axis = e / 4, b0 = e & 1, b1 = (e >> 1) & 1;
            float a[3], c[3];
            const float l3[3] = {lo.x, lo.y, lo.z}, h3[3] = {hi.x, hi.y, hi.z};
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            a[axis] = l3[axis];
            c[axis] = h3[axis];
            a[u] = c[u] = b0 ? h3[u] : l3[u];
            a[w] = c[w] = b1 ? h3[w] : l3[w];
            n = put(lines, n, vec3(a[0], a[1], a[2]));
            n = put(lines, n, vec3(c[0], c[1], c[2]));
        }
        draw_lines(r, lines, n, vec3(0.55f, 0.95f, 0.55f), 1.0f);
    }

    /* The second iso-surface (Hua & Qin Fig. 12): a wireframe over the shaded clay. */
    if (s->show_wire && r->wire_index_count > 0) {
        draw_wire(r, s);
        gl->UseProgram(r->prog_line);
    }

    /* The tool: a translucent sphere over everything drawn so far. */
    if (s->show_tool && s->tool_radius_m > 0.0f) {
        use_surface(r, r->prog_surf, s);
        const float rad = s->tool_radius_m;
        const float model[16] = {rad, 0, 0, 0, 0, rad, 0, 0, 0, 0, rad, 0,
                                 s->tool_pos_m.x, s->tool_pos_m.y, s->tool_pos_m.z, 1};
        set_mat4(gl, r->prog_surf, "u_model", model);
        set_color(gl, r->prog_surf, "u_tint", s->tool_rgb, s->tool_alpha);
        gl->Uniform1f(gl->GetUniformLocation(r->prog_surf, "u_tint_mix"), 1.0f);
        gl->Enable(GL_BLEND);
        gl->BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        gl->DepthMask(GL_FALSE);
        gl->Enable(GL_CULL_FACE);
        gl->CullFace(GL_BACK);
        gl->BindVertexArray(r->vao_sphere);
        gl->DrawElements(GL_TRIANGLES, (GLsizei)r->sphere_index_count, GL_UNSIGNED_INT, NULL);
        gl->Disable(GL_CULL_FACE);
        gl->DepthMask(GL_TRUE);
        gl->Disable(GL_BLEND);
    }

    /* The force on the tool: a line with a small head, always on top. */
    const float f_len = vec3_norm(s->force_n) * s->force_m_per_n;
    if (s->show_force && f_len > 1e-6f) {
        gl->UseProgram(r->prog_line);
        const vec3_t p = s->tool_pos_m;
        const vec3_t d = vec3_scale(s->force_n, 1.0f / vec3_norm(s->force_n));
        const vec3_t tip = vec3_add(p, vec3_scale(d, f_len));
        vec3_t side = vec3_cross(d, fabsf(d.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0));
        side = vec3_scale(side, 1.0f / vec3_norm(side));
        const vec3_t side2 = vec3_cross(d, side);
        const float head = 0.2f * f_len;
        const vec3_t back = vec3_sub(tip, vec3_scale(d, head));
        size_t n = 0;
        n = put(lines, n, p);
        n = put(lines, n, tip);
        const vec3_t dirs[4] = {side, vec3_scale(side, -1.0f), side2, vec3_scale(side2, -1.0f)};
        for (int i = 0; i < 4; i++) {
            n = put(lines, n, tip);
            n = put(lines, n, vec3_add(back, vec3_scale(dirs[i], 0.5f * head)));
        }
        gl->Disable(GL_DEPTH_TEST);
        draw_lines(r, lines, n, vec3(1.0f, 0.25f, 0.2f), 1.0f);
        gl->Enable(GL_DEPTH_TEST);
    }
    gl->BindVertexArray(0);
    gl->UseProgram(0);
}

void renderer_free(renderer_t *r)
{
    const gl_api_t *gl = r->gl;
    if (gl == NULL)
        return;
    const GLuint bufs[] = {r->vbo_pos,    r->vbo_nrm,    r->vbo_rgb,  r->ibo_mesh, r->vbo_sphere,
                           r->ibo_sphere, r->vbo_line, r->vbo_wire, r->ibo_wire};
    gl->DeleteBuffers((GLsizei)(sizeof(bufs) / sizeof(bufs[0])), bufs);
    const GLuint vaos[] = {r->vao_mesh, r->vao_sphere, r->vao_line, r->vao_wire};
    gl->DeleteVertexArrays(4, vaos);
    if (r->prog_surf)
        gl->DeleteProgram(r->prog_surf);
    if (r->prog_coat)
        gl->DeleteProgram(r->prog_coat);
    if (r->prog_line)
        gl->DeleteProgram(r->prog_line);
    memset(r, 0, sizeof(*r));
}

argil_err_t render_target_init(render_target_t *t, const gl_api_t *gl, int width, int height,
                               int samples, char *err, size_t err_len)
{
    memset(t, 0, sizeof(*t));
    t->gl = gl;
    t->width = width;
    t->height = height;
    GLint max_samples = 0;
    gl->GetIntegerv(GL_MAX_SAMPLES, &max_samples);
    t->samples = samples < max_samples ? samples : max_samples;
    if (t->samples < 0)
        t->samples = 0;
    gl->GenRenderbuffers(1, &t->rb_color_ms);
    gl->BindRenderbuffer(GL_RENDERBUFFER, t->rb_color_ms);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, t->samples, GL_RGBA8, width, height);
    gl->GenRenderbuffers(1, &t->rb_depth_ms);
    gl->BindRenderbuffer(GL_RENDERBUFFER, t->rb_depth_ms);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, t->samples, GL_DEPTH_COMPONENT24, width,
                                       height);
    gl->GenFramebuffers(1, &t->fbo_ms);
    gl->BindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                t->rb_color_ms);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                t->rb_depth_ms);
    const GLenum st_ms = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl->GenRenderbuffers(1, &t->rb_color_out);
    gl->BindRenderbuffer(GL_RENDERBUFFER, t->rb_color_out);
    gl->RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    gl->GenFramebuffers(1, &t->fbo_out);
    gl->BindFramebuffer(GL_FRAMEBUFFER, t->fbo_out);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                t->rb_color_out);
    const GLenum st_out = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (st_ms != GL_FRAMEBUFFER_COMPLETE || st_out != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, err_len, "offscreen framebuffer of %d x %d is incomplete (0x%04x, 0x%04x)",
                 width, height, (unsigned)st_ms, (unsigned)st_out);
        render_target_free(t);
        return ARGIL_ERR_STATE;
    }
    render_target_bind(t);
    return ARGIL_OK;
}

void render_target_bind(const render_target_t *t)
{
    t->gl->BindFramebuffer(GL_FRAMEBUFFER, t->fbo_ms);
}

void render_target_read_rgb(const render_target_t *t, uint8_t *rgb)
{
    const gl_api_t *gl = t->gl;
    const int w = t->width, h = t->height;
    gl->BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_ms);
    gl->BindFramebuffer(GL_DRAW_FRAMEBUFFER, t->fbo_out);
    gl->BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl->BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_out);
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl->ReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    /* GL's rows run bottom-up; images run top-down. */
    const size_t row = (size_t)w * 3;
    for (int y = 0; y < h / 2; y++) {
        uint8_t *a = rgb + (size_t)y * row, *b = rgb + (size_t)(h - 1 - y) * row;
        for (size_t i = 0; i < row; i++) {
            const uint8_t tmp = a[i];
            a[i] = b[i];
            b[i] = tmp;
        }
    }
    render_target_bind(t);
}

void render_target_present(const render_target_t *t)
{
    const gl_api_t *gl = t->gl;
    gl->BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo_ms);
    gl->BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    gl->BlitFramebuffer(0, 0, t->width, t->height, 0, 0, t->width, t->height,
                        GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl->BindFramebuffer(GL_FRAMEBUFFER, 0);
}

void render_target_free(render_target_t *t)
{
    const gl_api_t *gl = t->gl;
    if (gl == NULL)
        return;
    gl->BindFramebuffer(GL_FRAMEBUFFER, 0);
    const GLuint fbos[] = {t->fbo_ms, t->fbo_out};
    gl->DeleteFramebuffers(2, fbos);
    const GLuint rbs[] = {t->rb_color_ms, t->rb_depth_ms, t->rb_color_out};
    gl->DeleteRenderbuffers(3, rbs);
    memset(t, 0, sizeof(*t));
}
