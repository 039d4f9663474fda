/* argil view: renders a mesh (a session's final.ply, or any mesh file) to a PNG, or shows it in
 * a window with a virtual-trackball camera; optionally with the tool, its force and the board's
 * window box. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/commands.h"
#include "host/io/argil_file.h"
#include "host/io/mesh_import.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc_blocks.h"
#include "host/render/camera.h"
#include "host/render/offscreen.h"
#include "host/render/png_write.h"
#include "host/render/telemetry_log.h"

/* The text of `argil view --help`. */
static void usage_view(FILE *f)
{
    fprintf(f,
            "usage: argil view MODEL [--screenshot FILE.png] [--width W] [--height H]\n"
            "                  [--mode plain|clearcoat] [--backend auto|egl|glfw]\n"
            "                  [--telemetry FILE.csv] [--tool X Y Z R] [--force FX FY FZ]\n"
            "                  [--box X0 Y0 Z0 X1 Y1 Z1] [--key X Y Z] [--fill X Y Z]\n"
            "                  [--yaw DEG] [--pitch DEG] [--iso2 L]\n"
            "\n"
            "Draws MODEL (a mesh: .ply .stl .obj, e.g. a session's out/final.ply, or a .argil\n"
            "model, meshed at its surface level) lit by a key\n"
            "and a fill light. With --screenshot it renders one frame offscreen (a hidden GLFW\n"
            "window when DISPLAY is set, else EGL surfaceless) and writes a PNG; without it, it\n"
            "opens a window: drag with the left button to turn the model, wheel to zoom, Esc\n"
            "to quit.\n"
            "\n"
            "options:\n"
            "  --screenshot FILE  write one frame to FILE (PNG) and exit\n"
            "  --width W, --height H  image or window size in pixels (default 1024 x 768)\n"
            "  --mode M           plain (Blinn-Phong) or clearcoat (glossy lacquer reflecting\n"
            "                     an analytic studio); default plain\n"
            "  --backend B        auto (default), egl (offscreen, no display needed) or glfw\n"
            "  --telemetry FILE   a session's telemetry.csv: the tool is drawn where its last row\n"
            "                     puts it, with the force of that row\n"
            "  --tool X Y Z R     draw the tool sphere at (X, Y, Z) mm with radius R mm\n"
            "                     (default radius with --telemetry: 4 mm)\n"
            "  --force FX FY FZ   draw the force on the tool, N (10 mm per N)\n"
            "  --box X0 Y0 Z0 X1 Y1 Z1  draw the board's local window, corners in mm\n"
            "  --key X Y Z, --fill X Y Z  directions toward the key and fill lights in view\n"
            "                     space (+x right, +y up, +z toward you)\n"
            "  --yaw DEG, --pitch DEG  turn the model before the first frame\n"
            "  --iso2 L           a .argil model's density level L (0.05..0.95; the surface is\n"
            "                     0.5) drawn as a wireframe over it (Hua & Qin Fig. 12)\n"
            "  -h, --help         this text\n");
}

/* Parses n floats from argv[*i + 1 …], advancing *i; a bad one is said on stderr
 * (ARGIL_ERR_ARG). */
static argil_err_t take_floats(int argc, char **argv, int *i, int n, float *out)
{
    const char *opt = argv[*i];
    if (*i + n >= argc) {
        fprintf(stderr, "argil view: %s needs %d number%s (see --help)\n", opt, n,
                n > 1 ? "s" : "");
        return ARGIL_ERR_ARG;
    }
    for (int k = 0; k < n; k++) {
        const char *s = argv[*i + 1 + k];
        char *end;
        const double d = strtod(s, &end);
        if (end == s || *end != '\0' || !isfinite(d) || fabs(d) > 1e6) {
            fprintf(stderr, "argil view: %s: '%s' is not a number (within ±1e6)\n", opt, s);
            return ARGIL_ERR_ARG;
        }
        out[k] = (float)d;
    }
    *i += n;
    return ARGIL_OK;
}

/* Parses argv[*i + 1] as a whole number in lo … hi, advancing *i; a bad one is said on stderr
 * (ARGIL_ERR_ARG). */
static argil_err_t take_int(int argc, char **argv, int *i, int lo, int hi, int *out)
{
    const char *opt = argv[*i];
    if (*i + 1 >= argc) {
        fprintf(stderr, "argil view: %s needs a value (see --help)\n", opt);
        return ARGIL_ERR_ARG;
    }
    const char *s = argv[++*i];
    char *end;
    const long v = strtol(s, &end, 10);
    if (end == s || *end != '\0' || v < lo || v > hi) {
        fprintf(stderr, "argil view: %s must be a whole number %d..%d, got '%s'\n", opt, lo, hi,
                s);
        return ARGIL_ERR_ARG;
    }
    *out = (int)v;
    return ARGIL_OK;
}

/* Area-weighted vertex normals for meshes read without any. */
static void normals_from_faces(mesh_t *m)
{
    memset(m->normal, 0, sizeof(float) * 3 * m->n_vert);
    for (size_t t = 0; t < m->n_tri; t++) {
        const uint32_t *ix = m->tri + 3 * t;
        const float *a = m->pos + 3 * ix[0], *b = m->pos + 3 * ix[1], *c = m->pos + 3 * ix[2];
        const vec3_t n = vec3_cross(vec3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                                    vec3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
        for (int k = 0; k < 3; k++) {
            float *d = m->normal + 3 * ix[k];
            d[0] += n.x;
            d[1] += n.y;
            d[2] += n.z;
        }
    }
    for (size_t v = 0; v < m->n_vert; v++) {
        float *d = m->normal + 3 * v;
        const float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len > 0.0f) {
            d[0] /= len;
            d[1] /= len;
            d[2] /= len;
        }
    }
}

/* The box around the mesh, grown to hold the tool and the force's tip when they are shown. */
static void scene_bounds(const mesh_t *m, const render_scene_t *s, vec3_t *lo, vec3_t *hi)
{
    *lo = vec3(INFINITY, INFINITY, INFINITY);
    *hi = vec3(-INFINITY, -INFINITY, -INFINITY);
    for (size_t v = 0; v < m->n_vert; v++) {
        const float *p = m->pos + 3 * v;
        *lo = vec3(fminf(lo->x, p[0]), fminf(lo->y, p[1]), fminf(lo->z, p[2]));
        *hi = vec3(fmaxf(hi->x, p[0]), fmaxf(hi->y, p[1]), fmaxf(hi->z, p[2]));
    }
    if (s->show_tool) {
        const vec3_t r = vec3(s->tool_radius_m, s->tool_radius_m, s->tool_radius_m);
        const vec3_t a = vec3_sub(s->tool_pos_m, r), b = vec3_add(s->tool_pos_m, r);
        *lo = vec3(fminf(lo->x, a.x), fminf(lo->y, a.y), fminf(lo->z, a.z));
        *hi = vec3(fmaxf(hi->x, b.x), fmaxf(hi->y, b.y), fmaxf(hi->z, b.z));
    }
    if (s->show_box) {
        *lo = vec3(fminf(lo->x, s->box_lo_m.x), fminf(lo->y, s->box_lo_m.y),
                   fminf(lo->z, s->box_lo_m.z));
        *hi = vec3(fmaxf(hi->x, s->box_hi_m.x), fmaxf(hi->y, s->box_hi_m.y),
                   fmaxf(hi->z, s->box_hi_m.z));
    }
}

/* Meshes a .argil model at its surface level into m (closed: back faces culled) and, for
 * iso2 > 0, at that level into wire. */
static argil_err_t load_model(const char *path, float iso2, mesh_t *m, mesh_t *wire,
                              render_scene_t *s, char *err, size_t err_len)
{
    argil_doc_t d;
    argil_err_t rc = argil_file_err_argil(argil_file_read(path, &d, err, err_len));
    if (rc != ARGIL_OK)
        return rc;
    const grid_t *g = &d.grid;
    rc = grid_mesh_region(g, d.rgb, g->iso, m);
    if (rc == ARGIL_OK && iso2 > 0.0f)
        rc = grid_mesh_region(g, NULL, iso2, wire);
    if (rc != ARGIL_OK)
        snprintf(err, err_len, "%s: cannot mesh the model (%s)", path,
                 rc == ARGIL_ERR_NOMEM ? "out of memory" : "bad field");
    s->closed_mesh = true;
    s->show_wire = iso2 > 0.0f;
    s->wire_on_top = iso2 > g->iso;
    argil_doc_free(&d);
    return rc;
}

/* Renders one frame offscreen and writes it to png (said on stderr when it cannot). */
static argil_err_t run_screenshot(const mesh_t *m, const mesh_t *wire, render_scene_t *s,
                          camera_t *cam, render_backend_t backend, int w, int h, const char *png)
{
    char err[512] = "";
    offscreen_t *o = calloc(1, sizeof(*o));
    uint8_t *rgb = malloc((size_t)w * (size_t)h * 3);
    if (o == NULL || rgb == NULL) {
        free(o);
        free(rgb);
        fprintf(stderr, "argil view: out of memory for a %d x %d image\n", w, h);
        return ARGIL_ERR_NOMEM;
    }
    argil_err_t e = offscreen_open(o, backend, w, h, err, sizeof(err));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil view: %s\n", err);
    } else if ((e = renderer_set_mesh(&o->renderer, m)) != ARGIL_OK ||
               (e = renderer_set_wire_mesh(&o->renderer, wire)) != ARGIL_OK) {
        fprintf(stderr, "argil view: the GPU did not take the mesh (%zu triangles)\n", m->n_tri);
    } else {
        camera_matrices(cam, (float)w / (float)h, s->view, s->proj);
        offscreen_render(o, s, rgb);
        if ((e = png_write_rgb(png, w, h, rgb, err, sizeof(err))) != ARGIL_OK)
            fprintf(stderr, "argil view: %s\n", err);
    }
    offscreen_close(o);
    free(o);
    free(rgb);
    return e;
}

/* Shows the mesh in a window with a trackball camera until it is closed or Esc. */
static argil_err_t run_window(const mesh_t *m, const mesh_t *wire, render_scene_t *s, camera_t *cam,
                      int w, int h, const char *title)
{
    char err[512] = "";
    glfw_window_t win;
    gl_api_t gl;
    renderer_t r;
    argil_err_t e = glfw_window_open(&win, w, h, true, 4, title, &gl, err, sizeof(err));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil view: %s (use --screenshot FILE.png without a display)\n", err);
        return e;
    }
    if ((e = renderer_init(&r, &gl, err, sizeof(err))) != ARGIL_OK) {
        fprintf(stderr, "argil view: %s\n", err);
        glfw_window_close(&win);
        return e;
    }
    if ((e = renderer_set_mesh(&r, m)) != ARGIL_OK ||
        (e = renderer_set_wire_mesh(&r, wire)) != ARGIL_OK) {
        fprintf(stderr, "argil view: the GPU did not take the mesh (%zu triangles)\n", m->n_tri);
        renderer_free(&r);
        glfw_window_close(&win);
        return e;
    }
    gl.Enable(GL_MULTISAMPLE);
    glfw_input_t in, prev = {0};
    while (!glfw_window_should_close(&win)) {
        glfw_window_poll(&win, &in);
        if (in.escape)
            break;
        int fw = 0, fh = 0;
        glfw_window_size(&win, &fw, &fh);
        if (in.left_down && prev.left_down)
            camera_arcball(cam, prev.cursor_x, prev.cursor_y, in.cursor_x, in.cursor_y, fw, fh);
        camera_zoom(cam, glfw_window_take_scroll(&win));
        prev = in;
        if (fw > 0 && fh > 0) {
            camera_matrices(cam, (float)fw / (float)fh, s->view, s->proj);
            renderer_draw(&r, s, fw, fh);
        }
        glfw_window_swap(&win);
    }
    renderer_free(&r);
    glfw_window_close(&win);
    return ARGIL_OK;
}

/* What argil view's command line asks for. */
typedef struct {
    const char *model, *png, *csv;  /* the model, --screenshot and --telemetry (NULL: none) */
    int w, h;                       /* image or window size, pixels */
    render_backend_t backend;
    render_scene_t scene;           /* --mode, --key, --fill and --box's switch so far */
    float tool[4];                  /* --tool X Y Z R, mm */
    float force[3];                 /* --force, N */
    float box[6];                   /* --box corners, mm */
    float yaw_deg, pitch_deg, iso2;
    int have_tool, have_force;
} view_opts_t;

/* Takes the value v of --screenshot, --telemetry, --mode or --backend (a); a bad one is said
 * on stderr (ARGIL_ERR_ARG). */
static argil_err_t take_word(const char *a, const char *v, view_opts_t *o)
{
    if (strcmp(a, "--screenshot") == 0) {
        o->png = v;
    } else if (strcmp(a, "--telemetry") == 0) {
        o->csv = v;
    } else if (strcmp(a, "--mode") == 0) {
        if (strcmp(v, "plain") == 0)
            o->scene.mode = RENDER_MODE_PLAIN;
        else if (strcmp(v, "clearcoat") == 0)
            o->scene.mode = RENDER_MODE_CLEARCOAT;
        else {
            fprintf(stderr, "argil view: unknown mode '%s' (plain, clearcoat)\n", v);
            return ARGIL_ERR_ARG;
        }
    } else {
        if (strcmp(v, "auto") == 0)
            o->backend = RENDER_BACKEND_AUTO;
        else if (strcmp(v, "egl") == 0)
            o->backend = RENDER_BACKEND_EGL;
        else if (strcmp(v, "glfw") == 0)
            o->backend = RENDER_BACKEND_GLFW;
        else {
            fprintf(stderr, "argil view: unknown backend '%s' (auto, egl, glfw)\n", v);
            return ARGIL_ERR_ARG;
        }
    }
    return ARGIL_OK;
}

/* Parses the options into o: ARGIL_OK to go on, or with *help after --help (the usage printed);
 * ARGIL_ERR_ARG for a bad option (one line said why). */
static argil_err_t parse_view_opts(int argc, char **argv, view_opts_t *o, bool *help)
{
    *help = false;
    memset(o, 0, sizeof(*o));
    o->w = 1024;
    o->h = 768;
    o->backend = RENDER_BACKEND_AUTO;
    render_scene_default(&o->scene);
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        argil_err_t rc = ARGIL_OK;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage_view(stdout);
            *help = true;
            return ARGIL_OK;
        } else if (strcmp(a, "--screenshot") == 0 || strcmp(a, "--mode") == 0 ||
                   strcmp(a, "--backend") == 0 || strcmp(a, "--telemetry") == 0) {
            if (i + 1 >= argc) {
                fprintf(stderr, "argil view: %s needs a value (see --help)\n", a);
                return ARGIL_ERR_ARG;
            }
            rc = take_word(a, argv[++i], o);
        } else if (strcmp(a, "--width") == 0) {
            rc = take_int(argc, argv, &i, 16, 8192, &o->w);
        } else if (strcmp(a, "--height") == 0) {
            rc = take_int(argc, argv, &i, 16, 8192, &o->h);
        } else if (strcmp(a, "--tool") == 0) {
            rc = take_floats(argc, argv, &i, 4, o->tool);
            o->have_tool = 1;
            if (rc == ARGIL_OK && !(o->tool[3] > 0.0f)) {
                fprintf(stderr, "argil view: --tool radius must be > 0 mm\n");
                return ARGIL_ERR_ARG;
            }
        } else if (strcmp(a, "--force") == 0) {
            rc = take_floats(argc, argv, &i, 3, o->force);
            o->have_force = 1;
        } else if (strcmp(a, "--box") == 0) {
            rc = take_floats(argc, argv, &i, 6, o->box);
            o->scene.show_box = true;
        } else if (strcmp(a, "--key") == 0 || strcmp(a, "--fill") == 0) {
            float d[3];
            rc = take_floats(argc, argv, &i, 3, d);
            if (rc == ARGIL_OK && vec3_norm(vec3(d[0], d[1], d[2])) < 1e-6f) {
                fprintf(stderr, "argil view: %s needs a non-zero direction\n", a);
                return ARGIL_ERR_ARG;
            }
            if (a[2] == 'k')
                o->scene.key.dir = vec3(d[0], d[1], d[2]);
            else
                o->scene.fill.dir = vec3(d[0], d[1], d[2]);
        } else if (strcmp(a, "--yaw") == 0) {
            rc = take_floats(argc, argv, &i, 1, &o->yaw_deg);
        } else if (strcmp(a, "--pitch") == 0) {
            rc = take_floats(argc, argv, &i, 1, &o->pitch_deg);
        } else if (strcmp(a, "--iso2") == 0) {
            rc = take_floats(argc, argv, &i, 1, &o->iso2);
            if (rc == ARGIL_OK && !(o->iso2 >= 0.05f && o->iso2 <= 0.95f)) {
                fprintf(stderr, "argil view: --iso2 needs a density level 0.05..0.95 (the "
                                "surface is 0.5)\n");
                return ARGIL_ERR_ARG;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "argil view: unknown option '%s' (see --help)\n", a);
            return ARGIL_ERR_ARG;
        } else if (o->model == NULL) {
            o->model = a;
        } else {
            fprintf(stderr, "argil view: one model at a time ('%s' and '%s')\n", o->model, a);
            return ARGIL_ERR_ARG;
        }
        if (rc != ARGIL_OK)
            return rc;
    }
    if (o->model == NULL) {
        usage_view(stderr);
        return ARGIL_ERR_ARG;
    }
    return ARGIL_OK;
}

/* With --telemetry, the tool (radius 4 mm) and the force not given default to the log's last
 * row; a log that cannot be read is said on stderr. */
static argil_err_t take_telemetry(view_opts_t *o)
{
    char err[1024] = "";
    telemetry_log_t log;
    const argil_err_t e = telemetry_err_argil(telemetry_log_read(o->csv, &log, err, sizeof(err)));
    if (e != ARGIL_OK) {
        fprintf(stderr, "argil view: %s\n", err);
        return e;
    }
    const size_t last = log.n - 1;
    if (!o->have_tool) {
        memcpy(o->tool, log.pos_mm + 3 * last, 3 * sizeof(float));
        o->tool[3] = 4.0f;
        o->have_tool = 1;
    }
    if (!o->have_force) {
        memcpy(o->force, log.force_n + 3 * last, 3 * sizeof(float));
        o->have_force = 1;
    }
    telemetry_log_free(&log);
    return ARGIL_OK;
}

/* Puts the tool, the force and the box the options give into the scene, in metres. */
static void place_in_scene(view_opts_t *o)
{
    render_scene_t *s = &o->scene;
    const float *tool = o->tool, *force = o->force, *box = o->box;
    s->show_tool = o->have_tool;
    s->tool_pos_m = vec3(tool[0] * 1e-3f, tool[1] * 1e-3f, tool[2] * 1e-3f);
    s->tool_radius_m = tool[3] * 1e-3f;
    s->show_force = o->have_force;
    s->force_n = vec3(force[0], force[1], force[2]);
    s->box_lo_m = vec3(fminf(box[0], box[3]) * 1e-3f, fminf(box[1], box[4]) * 1e-3f,
                       fminf(box[2], box[5]) * 1e-3f);
    s->box_hi_m = vec3(fmaxf(box[0], box[3]) * 1e-3f, fmaxf(box[1], box[4]) * 1e-3f,
                       fmaxf(box[2], box[5]) * 1e-3f);
}

/* Reads the model into m with vertex normals (a .argil meshed at its surface level, and at
 * --iso2 into wire; else a mesh file); when it cannot, says why on stderr, sets the exit status
 * (2: --iso2 given for a mesh, else 1) and leaves nothing to free. */
static argil_err_t load_view_mesh(view_opts_t *o, mesh_t *m, mesh_t *wire, int *exit_status)
{
    char err[1024] = "";
    const char *model = o->model;
    bool has_normals = false;
    const size_t len = strlen(model);
    argil_err_t e;
    if (len > 6 && strcmp(model + len - 6, ".argil") == 0) {
        if ((e = load_model(model, o->iso2, m, wire, &o->scene, err, sizeof(err))) != ARGIL_OK) {
            fprintf(stderr, "argil view: %s\n", err);
            mesh_free(m);
            mesh_free(wire);
            return cmd_end(exit_status, 1, e);
        }
        has_normals = true;
    } else if (o->iso2 > 0.0f) {
        fprintf(stderr, "argil view: --iso2 needs a density field: %s is a mesh (give a .argil "
                        "model, or use 'argil sculpt --iso2')\n", model);
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    } else if ((e = import_err_argil(mesh_import(model, m, &has_normals, err, sizeof(err)))) !=
               ARGIL_OK) {
        fprintf(stderr, "argil view: %s\n", err);
        return cmd_end(exit_status, 1, e);
    }
    if (m->n_tri == 0) {
        fprintf(stderr, "argil view: %s: no triangles to draw (a point cloud?)\n", model);
        mesh_free(m);
        mesh_free(wire);
        return cmd_end(exit_status, 1, ARGIL_ERR_EMPTY);
    }
    if (!has_normals)
        normals_from_faces(m);
    return ARGIL_OK;
}

/* argil view: draws MODEL to a PNG or in a window; the exit status. */
argil_err_t cmd_view(int argc, char **argv, int *exit_status)
{
    view_opts_t o;
    bool help;
    argil_err_t e = parse_view_opts(argc, argv, &o, &help);
    if (e != ARGIL_OK || help)
        return cmd_end(exit_status, help ? 0 : 2, e);
    if (o.csv != NULL && (e = take_telemetry(&o)) != ARGIL_OK)
        return cmd_end(exit_status, 1, e);
    place_in_scene(&o);
    mesh_t m, wire;
    mesh_init(&m);
    mesh_init(&wire);
    if ((e = load_view_mesh(&o, &m, &wire, exit_status)) != ARGIL_OK)
        return e;
    vec3_t lo, hi;
    scene_bounds(&m, &o.scene, &lo, &hi);
    camera_t cam;
    camera_frame(&cam, lo, hi);
    camera_orbit(&cam, o.yaw_deg * (float)M_PI / 180.0f, o.pitch_deg * (float)M_PI / 180.0f);
    e = o.png ? run_screenshot(&m, &wire, &o.scene, &cam, o.backend, o.w, o.h, o.png)
              : run_window(&m, &wire, &o.scene, &cam, o.w, o.h, o.model);
    mesh_free(&m);
    mesh_free(&wire);
    return cmd_end(exit_status, e == ARGIL_OK ? 0 : 1, e);
}
