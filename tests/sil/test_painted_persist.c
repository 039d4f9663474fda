/* SIL: painted material survives save and load (issues 5, 8). A scripted session paints the
 * clay 4x stiffer and 0.5x lighter where the stylus touches it; its model.argil must hold every
 * sample's scales bit for bit as the session's B-spline model had them, store only the painted
 * samples, and a model loaded from it must hand the same scales back to a new B-spline model. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/app/session.h"
#include "host/io/argil_file.h"
#include "tests/sil/sil_runs.h"
#include "tests/unit/grid_view.h"

/* The B-spline model's scales over the whole grid, taken once the script has finished (painting
 * only happens inside the script, so these are the session's final scales). */
typedef struct {
    float *stiff, *mass;
    size_t n;
    bool taken;
} capture_t;

static void capture_hook(void *ctx, session_frame_t *f)
{
    capture_t *c = ctx;
    if (c->taken || !f->script_done || f->peer->gs == NULL)
        return;
    const grid_t *g = f->peer->grid;
    const int32_t lo[3] = {0, 0, 0};
    c->n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    c->stiff = malloc(c->n * sizeof(float));
    c->mass = malloc(c->n * sizeof(float));
    assert_non_null(c->stiff);
    assert_non_null(c->mass);
    assert_true(gsolve_material_box(f->peer->gs, GSOLVE_MAT_STIFFNESS, lo, g->dims, c->stiff));
    assert_true(gsolve_material_box(f->peer->gs, GSOLVE_MAT_MASS, lo, g->dims, c->mass));
    c->taken = true;
}

static bool no_send(void *ctx, const uint8_t *frame, size_t len)
{
    (void)ctx;
    (void)frame;
    (void)len;
    return true;
}

/* Painted samples of channel ch in doc, with their range. */
static size_t painted(const grid_t *g, grid_mat_t ch, float *lo, float *hi)
{
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    size_t k = 0;
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        const float v = gv_mat(g, ch, i);
        if (v == 1.0f)
            continue;
        k++;
        *lo = fminf(*lo, v);
        *hi = fmaxf(*hi, v);
    }
    return k;
}

static void test_paint_save_load(void **st)
{
    (void)st;
    char dir[64], script[128], model[128];
    /* Touch the pole (the clay is a 30 mm sphere), paint there, push a little, leave. */
    const char *const parts[] = {
        "set radius_mm 4\ntool touch\nmove 0 0 36 0.5\nmove 0 0 31 0.4\n"
        "paint stiffness 4 radius 10\nwait 0.1\npaint mass 0.5 radius 8\nwait 0.1\n"
        "move 0 0 45 0.3\n",
        NULL};
    assert_int_equal(sil_script_dir(dir, "argil-ppersist", "paint.scn", parts, script), 0);
    snprintf(model, sizeof(model), "%s/model.argil", dir);
    session_opts_t o;
    sil_opts(&o, script, dir);
    capture_t cap = {NULL, NULL, 0, false};
    const session_hook_t hook = {capture_hook, &cap, false};
    o.hook = &hook;
    session_summary_t sum;
    char err[1024] = "";
    sil_run(&o, &sum, "paint session");
    assert_true(cap.taken);

    /* Saved: version 2, every sample's scales bit for bit as the model had them. */
    argil_doc_t d;
    assert_int_equal(argil_file_read(model, &d, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(d.file_version, 2);
    const grid_t *g = &d.grid;
    const size_t n = (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
    assert_int_equal(n, cap.n);
    size_t diff_k = 0, diff_m = 0;
    for (size_t i = 0; i < n; i++) {
        const float k = gv_mat(g, GRID_MAT_STIFFNESS, i);
        const float m = gv_mat(g, GRID_MAT_MASS, i);
        diff_k += memcmp(&k, &cap.stiff[i], sizeof(float)) != 0;
        diff_m += memcmp(&m, &cap.mass[i], sizeof(float)) != 0;
    }
    assert_int_equal(diff_k, 0);
    assert_int_equal(diff_m, 0);
    assert_false(grid_mat_painted(g, GRID_MAT_DAMPING));
    assert_false(grid_mat_painted(g, GRID_MAT_RESTLEN));
    float klo, khi, mlo, mhi;
    const size_t nk = painted(g, GRID_MAT_STIFFNESS, &klo, &khi);
    const size_t nm = painted(g, GRID_MAT_MASS, &mlo, &mhi);
    struct stat stt;
    assert_int_equal(stat(model, &stt), 0);
    const size_t plain_bytes = 32 + 4 + 16 + 36 + 4 * n + 16 + 20 + 16 + 16 + 16 + 20;
    printf("# stiffness x%.3f..x%.3f on %zu samples, mass x%.3f..x%.3f on %zu samples; "
           "model.argil %lld bytes, %lld more than unpainted\n",
           (double)klo, (double)khi, nk, (double)mlo, (double)mhi, nm, (long long)stt.st_size,
           (long long)stt.st_size - (long long)plain_bytes);
    /* A ball of 10 mm at 1.25 mm spacing: 4/3 pi 8^3 = 2145 samples; 8 mm: 1098. */
    assert_true(nk > 1800 && nk < 2500);
    assert_true(nm > 900 && nm < 1300);
    /* Near the tip 4x (the tip lies at most half a cell's diagonal, 1.08 mm, from a sample:
     * >= 1 + 3 (1 - 1.08 / 10)); 0.5x likewise (<= 1 - 0.5 (1 - 1.08 / 8)). */
    assert_true(khi > 3.6f && khi <= 4.0f && klo > 1.0f);
    assert_true(mlo >= 0.5f && mlo < 0.57f && mhi < 1.0f);
    /* Only the painted samples are stored: under 4 bytes per grid sample more than unpainted
     * would be the whole channel; here each painted value costs 4 bytes plus its run heads. */
    assert_true((size_t)stt.st_size > plain_bytes);
    assert_true((size_t)stt.st_size - plain_bytes < 6 * (nk + nm) + 64);

    /* Loaded: a new B-spline model on the loaded grid takes the scales bit for bit. */
    peer_t p;
    memset(&p, 0, sizeof(p));
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.global_solve = PEER_SOLVE_BSPLINE;
    assert_int_equal(peer_init(&p, &pc, &d.grid, no_send, NULL, NULL), ARGIL_OK);
    float *k2 = malloc(n * sizeof(float)), *m2 = malloc(n * sizeof(float));
    assert_non_null(k2);
    assert_non_null(m2);
    const int32_t lo[3] = {0, 0, 0};
    (void)gsolve_material_box(p.gs, GSOLVE_MAT_STIFFNESS, lo, d.grid.dims, k2);
    (void)gsolve_material_box(p.gs, GSOLVE_MAT_MASS, lo, d.grid.dims, m2);
    assert_memory_equal(k2, cap.stiff, n * sizeof(float));
    assert_memory_equal(m2, cap.mass, n * sizeof(float));
    /* ... and what the session's tools read at the pole is the painted value. */
    const float at_pole = peer_material_at(&p, PEER_MAT_STIFFNESS, vec3(0, 0, 0.030f));
    printf("# loaded model: stiffness at the pole x%.3f\n", (double)at_pole);
    assert_true(at_pole > 3.0f);
    peer_free(&p);
    free(k2);
    free(m2);
    argil_doc_free(&d);
    free(cap.stiff);
    free(cap.mass);

    assert_int_equal(sil_remove_dir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paint_save_load),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
