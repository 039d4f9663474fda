/* make bench: frame time of the renderer for a 500k-triangle sculpture (a rippled sphere) at
 * 1024 × 768 with 4× multisampling, offscreen through EGL (Mesa's llvmpipe on this machine),
 * with the tool, force and window box and the HUD drawn as in the live window; median and
 * 90th percentile of N frames, each finished with glFinish. Usage: bench_render [FRAMES] */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "host/render/camera.h"
#include "host/render/hud.h"
#include "host/render/offscreen.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A UV sphere of radius 30 mm with a 0.6 mm ripple: 2 · slices · (stacks − 1) triangles. */
static int make_sphere(mesh_t *m, int slices, int stacks)
{
    if (mesh_reserve(m, (size_t)slices * (stacks + 1), (size_t)2 * slices * stacks) != ARGIL_OK)
        return -1;
    for (int j = 0; j <= stacks; j++) {
        const float th = (float)M_PI * (float)j / (float)stacks;
        for (int i = 0; i < slices; i++) {
            const float ph = 2.0f * (float)M_PI * (float)i / (float)slices;
            const vec3_t n = vec3(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
            const float r = 0.030f + 0.0006f * sinf(9.0f * ph) * sinf(7.0f * th);
            if (mesh_add_vertex(m, vec3_scale(n, r), n, NULL) != ARGIL_OK)
                return -1;
        }
    }
    for (int j = 0; j < stacks; j++) {
        for (int i = 0; i < slices; i++) {
            const uint32_t a = (uint32_t)(j * slices + i), b = (uint32_t)(j * slices + (i + 1) % slices);
            const uint32_t c = a + (uint32_t)slices, d = b + (uint32_t)slices;
            if (j > 0 && mesh_add_triangle(m, a, b, c) != ARGIL_OK)
                return -1;
            if (j < stacks - 1 && mesh_add_triangle(m, b, d, c) != ARGIL_OK)
                return -1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    const int frames = argc > 1 ? atoi(argv[1]) : 30;
    if (frames < 3 || frames > 10000) {
        fprintf(stderr, "bench_render: FRAMES must be 3..10000\n");
        return 2;
    }
    const int w = 1024, h = 768;
    char err[512] = "";
    offscreen_t *o = calloc(1, sizeof(*o));
    mesh_t m;
    mesh_init(&m);
    if (o == NULL || make_sphere(&m, 500, 501) != 0) {
        fprintf(stderr, "bench_render: out of memory\n");
        return 1;
    }
    if (offscreen_open(o, RENDER_BACKEND_EGL, w, h, err, sizeof(err)) != ARGIL_OK) {
        printf("  renderer did not open: %s (skipped)\n", err);
        return 0;
    }
    hud_t hud;
    if (hud_init(&hud, &o->gl, err, sizeof(err)) != ARGIL_OK ||
        renderer_set_mesh(&o->renderer, &m) != ARGIL_OK) {
        printf("  renderer refused the mesh or the HUD: %s\n", err);
        return 1;
    }
    render_scene_t s;
    render_scene_default(&s);
    s.show_tool = s.show_force = s.show_box = true;
    s.closed_mesh = true; /* a closed sculpture, as the live window draws its mc_blocks mesh */
    s.tool_pos_m = vec3(0.01f, 0.01f, 0.031f);
    s.force_n = vec3(0.3f, 0.2f, 1.0f);
    s.box_lo_m = vec3(0.0f, 0.0f, 0.02f);
    s.box_hi_m = vec3(0.02f, 0.02f, 0.04f);
    camera_t cam;
    camera_frame(&cam, vec3(-0.036f, -0.036f, -0.036f), vec3(0.036f, 0.036f, 0.036f));
    double *t = malloc(sizeof(double) * (size_t)frames);
    if (t == NULL)
        return 1;
    const char *text = "ACTIVE  loop 1000 Hz  worst tick 52 us  link 0.0 ms  force 0.83 N\n"
                       "tool push  beta gaussian  radius 4.0 mm  stiffness 0.80 N/mm";
    for (int i = -2; i < frames; i++) { /* two warm-up frames */
        camera_orbit(&cam, 0.02f, 0.0f);
        camera_matrices(&cam, (float)w / (float)h, s.view, s.proj);
        const double t0 = now_ms();
        render_target_bind(&o->target);
        renderer_draw(&o->renderer, &s, w, h);
        hud_draw(&hud, text, 1.0f, w, h);
        o->gl.Finish();
        if (i >= 0)
            t[i] = now_ms() - t0;
    }
    qsort(t, (size_t)frames, sizeof(double), cmp);
    printf("  %zu triangles, %d x %d, %d samples, %s (%s): frame time median %.1f ms, "
           "p90 %.1f ms over %d frames\n",
           m.n_tri, w, h, o->target.samples, offscreen_backend_name(o),
           (const char *)o->gl.GetString(GL_RENDERER), t[frames / 2], t[frames * 9 / 10], frames);
    free(t);
    hud_free(&hud);
    offscreen_close(o);
    free(o);
    mesh_free(&m);
    return 0;
}
