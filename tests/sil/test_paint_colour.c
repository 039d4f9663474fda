/* SIL: painting colour in a scripted session (`action paint`; docs/script.md). The
 * board's carve tool is held and drawn 2 mm deep along the top of the clay with the host action
 * `paint rgb 230 20 20`: the final model's mesh must carry that colour on the vertices within the
 * tool's radius of where the stylus went and the clay's grey (GRID_RGB_DEFAULT) two radii away,
 * the volume must not change, and model.argil must hold every sample's colour bit for bit as the
 * session's grid had it (and a new B-spline model loaded from it the same colour) with the paint
 * colour chosen in its tool settings; final.ply is that coloured mesh (red only along the
 * stroke, grey elsewhere). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/session.h"
#include "host/io/argil_file.h"
#include "host/io/ply.h"
#include "host/mesh/mc_blocks.h"
#include "tests/sil/sil_runs.h"
#include "tests/unit/grid_view.h"

#define RADIUS_MM 4.0
#define PATH_MAX_POINTS 20000u
static const uint8_t PAINT[3] = {230, 20, 20};

/* Touch down above the top (the clay is a 30 mm sphere), switch to carve + paint, draw the ball
 * along z about 2 mm under the surface, lift off. */
static const char *const SCRIPT =
    "set radius_mm 4\ntool touch\nmove 0 45 -9 0.5\nmove 0 36 -9 0.3\ntool carve\n"
    "action paint rgb 230 20 20\npress 1\nmove 0 27.8 -9 0.2\nmove 0 28 0 0.6\n"
    "move 0 27.8 9 0.6\nrelease 1\nmove 0 45 9 0.3\n";

typedef struct {
    uint8_t *rgb;          /* the grid's colour once the script is done (3 per sample) */
    size_t n;
    bool taken;
    float *path;           /* stylus positions (m) while painting, 3 per point */
    size_t n_path;
} capture_t;

static void hook(void *ctx, session_frame_t *f)
{
    capture_t *c = ctx;
    const peer_t *p = f->peer;
    if (p->have_tm && p->last_tm.state == SAFETY_ACTIVE && p->last_tm.tool_kind == TOOL_CARVE &&
        (p->last_tm.buttons & 1u) && c->n_path < PATH_MAX_POINTS) {
        memcpy(&c->path[3 * c->n_path], p->last_tm.pos_m, 3 * sizeof(float));
        c->n_path++;
    }
    if (c->taken || !f->script_done)
        return;
    const grid_t *g = p->grid;
    /* over the grid's bounds, as model.argil holds it */
    int32_t lo[3], dims[3];
    c->n = grid_count(g);
    c->rgb = grid_dense_copy_rgb(g, lo, dims);
    assert_non_null(c->rgb);
    c->taken = true;
}

/* Distance (mm) from x to the stylus path. */
static double path_dist_mm(const capture_t *c, const float *x)
{
    double best = 1e30;
    for (size_t i = 0; i < c->n_path; i++) {
        const float *q = &c->path[3 * i];
        const double d = ((double)x[0] - q[0]) * ((double)x[0] - q[0]) +
                         ((double)x[1] - q[1]) * ((double)x[1] - q[1]) +
                         ((double)x[2] - q[2]) * ((double)x[2] - q[2]);
        best = d < best ? d : best;
    }
    return sqrt(best) * 1e3;
}

static bool near_colour(const uint8_t *v, const uint8_t *want)
{
    for (int a = 0; a < 3; a++)
        if (abs((int)v[a] - (int)want[a]) > 8)
            return false;
    return true;
}

static void test_paint_stroke_shows_and_persists(void **st)
{
    (void)st;
    char dir[64], script[128], model[128];
    const char *const parts[] = {SCRIPT, NULL};
    assert_int_equal(sil_script_dir(dir, "argil-pcolour", "paint.scn", parts, script), 0);
    snprintf(model, sizeof(model), "%s/model.argil", dir);
    session_opts_t o;
    sil_opts(&o, script, dir);
    capture_t cap;
    memset(&cap, 0, sizeof(cap));
    cap.path = malloc(3 * PATH_MAX_POINTS * sizeof(float));
    assert_non_null(cap.path);
    const session_hook_t hk = {hook, &cap, false};
    o.hook = &hk;
    session_summary_t sum;
    char err[1024] = "";
    sil_run(&o, &sum, "paint session");
    assert_true(cap.taken);
    assert_int_equal(sum.solve_errors, 0);
    assert_true(sum.watertight);
    assert_true(cap.n_path > 500); /* held for ~1.2 s of 1 ms ticks */

    /* Painting moves no clay: the volume is the start's to 0.01 %. */
    const double dv = (sum.volume_after_m3 - sum.volume_before_m3) / sum.volume_before_m3;
    printf("# volume %.4f -> %.4f cm3 (%+.5f %%)\n", sum.volume_before_m3 * 1e6,
           sum.volume_after_m3 * 1e6, dv * 100.0);
    assert_true(fabs(dv) <= 1e-4);

    /* model.argil: the session's colour, bit for bit; version 1 (COLR is a version-1 section). */
    argil_doc_t d;
    assert_int_equal(argil_file_read(model, &d, err, sizeof(err)), ARGIL_OK);
    assert_non_null(d.rgb);
    assert_int_equal(d.file_version, 1);
    /* ... and the paint settings the script chose, for the next session (TOOL + PNTS) */
    assert_true(d.tool.paint_chosen);
    assert_memory_equal(d.tool.paint_rgb, PAINT, 3);
    assert_float_equal(d.tool.soft_paint_per_s, 20.0f, 0); /* soft paint's default, unused */
    const grid_t *g = &d.grid;
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    assert_int_equal(n, cap.n);
    assert_memory_equal(d.rgb, cap.rgb, 3 * n);
    size_t painted = 0, exact = 0;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *c = &d.rgb[3 * i];
        painted += c[0] != GRID_RGB_DEFAULT || c[1] != GRID_RGB_DEFAULT || c[2] != GRID_RGB_DEFAULT;
        exact += memcmp(c, PAINT, 3) == 0;
    }

    /* The final mesh, coloured as the window's mesher colours it. */
    mesh_t m;
    mesh_init(&m);
    float *dens = malloc(n * sizeof(float));
    assert_non_null(dens);
    assert_int_equal(mc_extract_region(gv_copy(g, GRID_DENSITY, dens), d.rgb, g->dims,
                                       g->spacing_m, g->origin_m, g->iso, NULL, NULL, &m),
                     ARGIL_OK);
    free(dens);
    assert_true(m.has_rgb);
    size_t in_n = 0, in_paint = 0, far_n = 0, far_base = 0;
    const uint8_t base[3] = {GRID_RGB_DEFAULT, GRID_RGB_DEFAULT, GRID_RGB_DEFAULT};
    for (size_t v = 0; v < m.n_vert; v++) {
        const double dist = path_dist_mm(&cap, &m.pos[3 * v]);
        if (dist < RADIUS_MM) {
            in_n++;
            in_paint += near_colour(&m.rgb[3 * v], PAINT);
        } else if (dist > 2.0 * RADIUS_MM) {
            far_n++;
            far_base += near_colour(&m.rgb[3 * v], base);
        }
    }
    printf("# %zu samples painted (%zu exactly 230 20 20); %zu path points; vertices within "
           "4 mm of the path: %zu, %.1f %% painted; beyond 8 mm: %zu, %.2f %% grey\n",
           painted, exact, cap.n_path, in_n, 100.0 * (double)in_paint / (double)in_n, far_n,
           100.0 * (double)far_base / (double)far_n);
    assert_true(in_n > 100);
    assert_true((double)in_paint >= 0.90 * (double)in_n);
    assert_true((double)far_base >= 0.99 * (double)far_n);

    /* final.ply is that mesh with its colours, bit for bit (ply_write writes what argil mesh
     * writes): red along the stroke, the clay's grey elsewhere. */
    char ply[160];
    snprintf(ply, sizeof(ply), "%s/final.ply", dir);
    mesh_t fm;
    mesh_init(&fm);
    if (ply_read_mesh(ply, &fm, err, sizeof(err)) != PLY_OK)
        fail_msg("%s", err);
    assert_true(fm.has_rgb);
    assert_int_equal(fm.n_vert, m.n_vert);
    assert_int_equal(fm.n_tri, m.n_tri);
    assert_memory_equal(fm.pos, m.pos, 3 * sizeof(float) * m.n_vert);
    assert_memory_equal(fm.rgb, m.rgb, 3 * m.n_vert);
    assert_memory_equal(fm.tri, m.tri, 3 * sizeof(uint32_t) * m.n_tri);
    size_t red = 0, red_near = 0, grey = 0, near_n = 0, near_red = 0;
    double red_far_mm = 0.0;
    for (size_t v = 0; v < fm.n_vert; v++) {
        const uint8_t *c = &fm.rgb[3 * v];
        const double dist = path_dist_mm(&cap, &fm.pos[3 * v]);
        const bool is_red = memcmp(c, PAINT, 3) == 0;
        red += is_red;
        grey += memcmp(c, base, 3) == 0;
        if (is_red) {
            red_near += dist < RADIUS_MM + 2.5; /* the tool's radius + 2 sample spacings */
            red_far_mm = dist > red_far_mm ? dist : red_far_mm;
        }
        if (dist < RADIUS_MM - 1.0) {
            near_n++;
            near_red += is_red;
        }
    }
    printf("# final.ply: %zu vertices, %zu red 230 20 20 (farthest %.2f mm from the path), %zu "
           "grey 204; within 3 mm of the path %zu, %zu of them red\n",
           fm.n_vert, red, red_far_mm, grey, near_n, near_red);
    assert_true(red >= 100);
    assert_int_equal(red_near, red);               /* no red off the stroke */
    assert_int_equal(red + grey, fm.n_vert);       /* a stroke of one colour on grey clay */
    assert_true(near_n >= 50);
    assert_true((double)near_red >= 0.95 * (double)near_n);
    mesh_free(&fm);
    mesh_free(&m);

    /* Loaded into a new session's B-spline model: the same colour comes back to the grid. */
    grid_t *lg = &d.grid;
    /* the grid takes the file's colour (as a loading session would) */
    assert_int_equal(gv_rgb_store(lg, d.rgb), ARGIL_OK);
    gsolve_t gs;
    memset(&gs, 0, sizeof(gs));
    assert_int_equal(gsolve_init(&gs, lg), ARGIL_OK);
    assert_int_equal(gsolve_colour_from_grid(&gs, lg), ARGIL_OK);
    uint8_t *keep = malloc(3 * n);
    assert_non_null(keep);
    gv_rgb_copy(lg, keep);
    memset(d.rgb, 0, 3 * n);
    assert_int_equal(gv_rgb_store(lg, d.rgb), ARGIL_OK);
    const int32_t lo[3] = {0, 0, 0};
    assert_int_equal(gsolve_colour_to_grid(&gs, lg, lo, lg->dims), ARGIL_OK);
    assert_memory_equal(gv_rgb_copy(lg, d.rgb), keep, 3 * n);
    gsolve_free(&gs);
    free(keep);
    argil_doc_free(&d);
    free(cap.rgb);
    free(cap.path);

    assert_int_equal(sil_remove_dir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paint_stroke_shows_and_persists),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
