/* Tools on the sparse B-spline field: carve volume against the analytic cap / sphere, add-undo-redo
 * bit for bit, mirror, chisel depth, interior carving, stamp, contact, paint, freeform. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/mc.h"
#include "host/mesh/mesh_check.h"
#include "host/model/tools.h"

#define HC 0.01f  /* knot spacing (m); 2 samples per span */

static float sd_slab(void *ctx, vec3_t x)
{
    (void)ctx;
    return -x.z; /* material below z = 0 */
}

static void make_slab(field_t *f)
{
    assert_int_equal(field_init(f, HC, 2, vec3(0, 0, 0)), ARGIL_OK);
    assert_int_equal(field_fill(f, sd_slab, NULL, vec3(-0.2f, -0.2f, -0.32f), vec3(0.2f, 0.2f, 0.1f)), ARGIL_OK);
}

/* Enclosed volume (m³) of the samples in a fixed box around the edits. */
static double volume(const field_t *f)
{
    const int32_t lo[3] = {-24, -24, -54}, dims[3] = {49, 49, 68};
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *d = malloc(n * sizeof(float));
    assert_non_null(d);
    sparse_read_box(&f->samp, FS_D, lo, dims, d);
    mesh_t m;
    memset(&m, 0, sizeof(m));
    const int32_t s[3] = {lo[0], lo[1], lo[2]};
    assert_int_equal(mc_extract(d, dims, f->sample_spacing_m, field_sample_pos(f, s), f->iso, &m), ARGIL_OK);
    const double v = mesh_volume_m3(&m);
    mesh_free(&m);
    free(d);
    return v;
}

static tool_shape_t sphere(float r)
{
    tool_shape_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_SPHERE;
    t.radius_m = r;
    return t;
}

static void test_carve_cap_volume(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    const double v0 = volume(&f);
    const float r = 0.08f, zc = 0.03f;
    tool_shape_t t = sphere(r);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0.0f, 0.0f, zc));
    tool_params_t p;
    tool_params_default(&p, TOOL_CARVE);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    const double removed = v0 - volume(&f);
    const double h = r - zc, cap = M_PI * h * h * (3 * r - h) / 3.0;
    assert_true(fabs(removed - cap) / cap < 0.03);
    field_free(&f);
}

static void test_carve_sphere_volume(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    const double v0 = volume(&f);
    const float r = 0.08f;
    tool_shape_t t = sphere(r);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0.003f, -0.002f, -0.15f));
    tool_params_t p;
    tool_params_default(&p, TOOL_CARVE);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    const double removed = v0 - volume(&f), ball = 4.0 / 3.0 * M_PI * r * r * r;
    assert_true(fabs(removed - ball) / ball < 0.03);
    field_free(&f);
}

/* RMS over the samples of the tool's reach of (density after the carve - the carve's target
 * min(d_before, 1 - profile(sd))), the quantity Hua & Qin's least-squares fit minimises. */
static double carve_rms(const field_t *f, const float *before, const int32_t lo[3], const int32_t dims[3],
                        const tool_shape_t *t, vec3_t centre)
{
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    float *d = malloc(n * sizeof(float));
    assert_non_null(d);
    sparse_read_box(&f->samp, FS_D, lo, dims, d);
    double e2 = 0.0;
    size_t i = 0;
    for (int32_t z = 0; z < dims[2]; z++)
        for (int32_t y = 0; y < dims[1]; y++)
            for (int32_t x = 0; x < dims[0]; x++, i++) {
                const int32_t sidx[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                const float sd = tool_sd(t, vec3_sub(field_sample_pos(f, sidx), centre));
                const float cut = 1.0f - field_profile(sd, f->band_m);
                const float target = before[i] < cut ? before[i] : cut;
                e2 += ((double)d[i] - target) * ((double)d[i] - target);
            }
    free(d);
    return sqrt(e2 / (double)n);
}

/* The least-squares mode fits the tool-modified samples better than quasi-interpolation and still
 * removes the analytic cap volume within 3 %. */
static void test_least_squares_fit_beats_quasi_interpolation(void **state)
{
    (void)state;
    const float r = 0.08f, zc = 0.03f;
    const tool_shape_t t = sphere(r);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0.0f, 0.0f, zc));
    /* the samples the tool reaches: |x| <= r + band + h_c round the centre (2 samples per h_c) */
    const int32_t lo[3] = {-28, -28, -22}, dims[3] = {57, 57, 57};
    const size_t n = (size_t)dims[0] * dims[1] * dims[2];
    double rms[2], removed[2];
    for (int mode = 0; mode < 2; mode++) {
        field_t f;
        make_slab(&f);
        const double v0 = volume(&f);
        float *before = malloc(n * sizeof(float));
        assert_non_null(before);
        sparse_read_box(&f.samp, FS_D, lo, dims, before);
        tool_params_t p;
        tool_params_default(&p, TOOL_CARVE);
        p.fit = mode ? TOOL_FIT_LSQ : TOOL_FIT_QUASI;
        assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
        rms[mode] = carve_rms(&f, before, lo, dims, &t, pose.pos_m);
        removed[mode] = v0 - volume(&f);
        free(before);
        field_free(&f);
    }
    const double h = r - zc, cap = M_PI * h * h * (3 * r - h) / 3.0;
    print_message("carve r = 8 cm: RMS to the target samples quasi %.4f, least squares %.4f; "
                  "removed volume error quasi %.2f %%, least squares %.2f %%\n",
                  rms[0], rms[1], 100.0 * (removed[0] - cap) / cap, 100.0 * (removed[1] - cap) / cap);
    assert_true(rms[1] < 0.7 * rms[0]);
    assert_true(fabs(removed[1] - cap) / cap < 0.03);
    /* actions whose rule needs more than the point's own value have no least-squares mode */
    field_t f;
    make_slab(&f);
    tool_params_t p;
    tool_params_default(&p, TOOL_SMOOTH);
    p.fit = TOOL_FIT_LSQ;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_ERR_ARG);
    tool_params_default(&p, TOOL_CARVE);
    p.fit = TOOL_FIT_LSQ;
    p.fit_iters = 0;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_ERR_ARG);
    field_free(&f);
}

/* Every coefficient and sample channel of the edit region, for bitwise comparisons. */
static float *snapshot(const field_t *f, size_t *n)
{
    const int32_t clo[3] = {-20, -20, -32}, cd[3] = {41, 41, 43};
    const int32_t slo[3] = {-42, -42, -66}, sd[3] = {85, 85, 88};
    const size_t nc = (size_t)cd[0] * cd[1] * cd[2], ns = (size_t)sd[0] * sd[1] * sd[2];
    *n = nc * FC_NCH + ns * FS_NCH;
    float *s = malloc(*n * sizeof(float));
    assert_non_null(s);
    for (int c = 0; c < FC_NCH; c++)
        sparse_read_box(&f->coef, c, clo, cd, s + nc * (size_t)c);
    for (int c = 0; c < FS_NCH; c++)
        sparse_read_box(&f->samp, c, slo, sd, s + nc * FC_NCH + ns * (size_t)c);
    return s;
}

static void test_add_undo_redo_bit_exact(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    undo_t u;
    undo_init(&u, 64u << 20);
    size_t n;
    float *before = snapshot(&f, &n);
    tool_shape_t t = sphere(0.05f);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0.02f, 0.01f, 0.02f));
    tool_params_t p;
    tool_params_default(&p, TOOL_ADD);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, &u, NULL), ARGIL_OK);
    float *after = snapshot(&f, &n);
    assert_true(memcmp(before, after, n * sizeof(float)) != 0);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    float *undone = snapshot(&f, &n);
    assert_memory_equal(before, undone, n * sizeof(float));
    assert_int_equal(undo_redo(&u, &f), ARGIL_OK);
    float *redone = snapshot(&f, &n);
    assert_memory_equal(after, redone, n * sizeof(float));
    assert_int_equal(undo_redo(&u, &f), ARGIL_ERR_EMPTY);
    /* a new edit after an undo clears the redo step */
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    tool_params_default(&p, TOOL_CARVE);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, &u, NULL), ARGIL_OK);
    assert_int_equal(undo_redo(&u, &f), ARGIL_ERR_EMPTY);
    assert_int_equal(undo_undo(&u, &f), ARGIL_OK);
    assert_int_equal(undo_undo(&u, &f), ARGIL_ERR_EMPTY);
    float *back = snapshot(&f, &n);
    assert_memory_equal(before, back, n * sizeof(float));
    free(before);
    free(after);
    free(undone);
    free(redone);
    free(back);
    undo_free(&u);
    field_free(&f);
}

static void test_undo_budget_drops_oldest(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    undo_t u;
    undo_init(&u, 200000); /* bytes: room for a few small steps */
    tool_shape_t t = sphere(0.02f);
    tool_params_t p;
    tool_params_default(&p, TOOL_CARVE);
    for (int i = 0; i < 12; i++) {
        tool_pose_t pose;
        tool_pose_at(&pose, vec3(-0.1f + 0.018f * (float)i, 0.0f, 0.0f));
        assert_int_equal(tool_apply(&f, &t, &pose, &p, &u, NULL), ARGIL_OK);
        assert_true(u.bytes <= u.budget_bytes || u.nsteps == 1);
    }
    assert_true(u.nsteps < 12 && u.nsteps >= 1);
    size_t undone = 0;
    while (undo_undo(&u, &f) == ARGIL_OK)
        undone++;
    assert_int_equal(undone, u.nsteps);
    undo_free(&u);
    field_free(&f);
}

static void test_mirror_is_symmetric(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    tool_shape_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_BOX;
    t.half_m = vec3(0.03f, 0.02f, 0.04f);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0.06f, 0.02f, 0.0f));
    tool_params_t p;
    tool_params_default(&p, TOOL_CARVE);
    p.mirror = 1u; /* across x = 0 */
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    for (int32_t z = -10; z <= 2; z += 3)
        for (int32_t y = -6; y <= 10; y += 2)
            for (int32_t x = 2; x <= 20; x += 3) {
                const float a = sparse_get(&f.samp, FS_D, x, y, z), b = sparse_get(&f.samp, FS_D, -x, y, z);
                assert_float_equal(a, b, 1e-5);
            }
    assert_true(sparse_get(&f.samp, FS_D, 12, 4, -2) < 0.5f);  /* carved at (0.06, 0.02, -0.01) */
    assert_true(sparse_get(&f.samp, FS_D, -12, 4, -2) < 0.5f); /* and its mirror image */
    field_free(&f);
}

/* Height (m) of the slab's surface along the z axis at (x, y) = (0, 0). */
static float surface_z(const field_t *f)
{
    for (float z = 0.09f; z > -0.2f; z -= 0.0005f) {
        if (field_eval(f, vec3(0, 0, z), NULL) >= f->iso) {
            const float a = field_eval(f, vec3(0, 0, z + 0.0005f), NULL), b = field_eval(f, vec3(0, 0, z), NULL);
            return z + 0.0005f * (b - f->iso) / (b - a);
        }
    }
    return NAN;
}

static void test_chisel_and_squirt_move_the_surface_by_the_depth(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    const float z0 = surface_z(&f);
    assert_float_equal(z0, 0.0f, 1e-4);
    tool_shape_t t = sphere(0.04f);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0, 0, 0));
    tool_params_t p;
    tool_params_default(&p, TOOL_CHISEL);
    p.depth_m = 0.004f;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    const float z1 = surface_z(&f);
    assert_float_equal(z0 - z1, 0.004f, 0.0006f);
    p.action = TOOL_SQUIRT;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_float_equal(surface_z(&f), z0, 0.0006f);
    field_free(&f);
}

static void test_interior_carve_keeps_the_shell(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    const double v0 = volume(&f);
    float top[11];
    for (int32_t i = 0; i < 11; i++)
        top[i] = sparse_get(&f.samp, FS_D, 2 * i - 10, 0, 0);
    tool_shape_t t;
    memset(&t, 0, sizeof(t));
    t.kind = TOOL_CYLINDER;
    t.radius_m = 0.05f;
    t.half_len_m = 0.12f; /* reaches through the top surface at z = 0 */
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0, 0, -0.1f));
    tool_params_t p;
    tool_params_default(&p, TOOL_INTERIOR_CARVE);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(v0 - volume(&f) > 0.3 * M_PI * 0.05 * 0.05 * 0.2); /* a cavity opened */
    for (int32_t i = 0; i < 11; i++) /* the outer surface did not move, bit for bit */
        assert_true(sparse_get(&f.samp, FS_D, 2 * i - 10, 0, 0) == top[i]);
    field_free(&f);
}

static void test_stamp_contact_toothpaste_erase_smooth(void **state)
{
    (void)state;
    tool_stamp_t st = {1.0f, 0.3f, 0.5f, 2.0f, 0.3f};
    assert_float_equal(tool_stamp_def(&st, 0.0f), -1.0f, 1e-6);
    assert_float_equal(tool_stamp_def(&st, 1.0f), 0.0f, 1e-5);
    assert_float_equal(tool_stamp_def(&st, 1.3f), 0.3f, 1e-5);
    assert_float_equal(tool_stamp_def(&st, 1.8f), 0.0f, 1e-5);
    assert_float_equal(tool_stamp_def(&st, 1.0f - 1e-4f), tool_stamp_def(&st, 1.0f + 1e-4f), 1e-3); /* C0 */
    assert_float_equal(tool_stamp_def(&st, 1.3f - 1e-4f), tool_stamp_def(&st, 1.3f + 1e-4f), 1e-3);
    field_t f;
    make_slab(&f);
    tool_shape_t t = sphere(0.03f);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0, 0, 0.01f));
    tool_params_t p;
    tool_params_default(&p, TOOL_STAMP);
    p.strength = 0.5f;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(field_eval(&f, vec3(0, 0, -0.005f), NULL) < 0.3f);       /* dent under the tool */
    assert_true(field_eval(&f, vec3(0.043f, 0, 0.0f), NULL) > f.iso + 0.02f); /* bulge around it */
    tool_params_default(&p, TOOL_CONTACT);
    p.alpha = -2.0f;
    tool_pose_at(&pose, vec3(0.1f, 0.1f, 0.0f));
    const float c0 = field_eval(&f, vec3(0.1f, 0.1f, -0.01f), NULL);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(field_eval(&f, vec3(0.1f, 0.1f, -0.01f), NULL) < c0 - 0.2f); /* α < 0 dents */
    p.alpha = 2.0f;
    tool_pose_at(&pose, vec3(-0.1f, 0.1f, 0.0f));
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(field_eval(&f, vec3(-0.1f, 0.1f, 0.01f), NULL) > f.iso); /* α > 0 bulges */
    tool_params_default(&p, TOOL_TOOTHPASTE);
    tool_pose_at(&pose, vec3(-0.1f, -0.1f, 0.02f));
    const float a0 = field_eval(&f, vec3(-0.1f, -0.1f, 0.02f), NULL);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    const float a1 = field_eval(&f, vec3(-0.1f, -0.1f, 0.02f), NULL);
    assert_true(a1 > a0 + 0.2f);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK); /* progressive */
    assert_true(field_eval(&f, vec3(-0.1f, -0.1f, 0.02f), NULL) > a1);
    tool_params_default(&p, TOOL_SOFT_ERASE);
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(field_eval(&f, vec3(-0.1f, -0.1f, 0.02f), NULL) < a1);
    /* smoothing lowers the stamp's bulge */
    const float bulge = field_eval(&f, vec3(0.043f, 0, 0.0f), NULL);
    tool_params_default(&p, TOOL_SMOOTH);
    p.strength = 1.0f;
    tool_pose_at(&pose, vec3(0, 0, 0));
    t.radius_m = 0.06f;
    for (int i = 0; i < 3; i++)
        assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_true(field_eval(&f, vec3(0.043f, 0, 0.0f), NULL) < bulge);
    field_free(&f);
}

static void test_paint_and_freeform_and_sweep(void **state)
{
    (void)state;
    field_t f;
    make_slab(&f);
    tool_shape_t t = sphere(0.02f);
    tool_pose_t pose;
    tool_pose_at(&pose, vec3(0, 0, 0));
    tool_params_t p;
    tool_params_default(&p, TOOL_PAINT);
    p.rgb[0] = 0.1f;
    p.rgb[1] = 0.9f;
    p.rgb[2] = 0.2f;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    assert_float_equal(sparse_get(&f.samp, FS_G, 0, 0, -1), 0.9f, 1e-6);
    assert_float_equal(sparse_get(&f.samp, FS_G, 10, 0, -1), 0.8f, 1e-6); /* outside: untouched */
    p.action = TOOL_SOFT_PAINT;
    p.rgb[1] = 0.0f;
    tool_pose_at(&pose, vec3(0.05f, 0, 0));
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_OK);
    const float g_in = sparse_get(&f.samp, FS_G, 10, 0, -2), g_out = sparse_get(&f.samp, FS_G, 10, 0, 2);
    assert_true(g_in < 0.8f && g_in > 0.0f);
    assert_true(g_out > g_in); /* weighted by the sample's own density */
    /* sweep: a small sphere dragged along a line adds a continuous ridge */
    const vec3_t path[2] = {vec3(-0.1f, 0.1f, 0.01f), vec3(0.1f, 0.1f, 0.01f)};
    tool_params_default(&p, TOOL_ADD);
    assert_int_equal(tool_stroke(&f, &t, &pose, path, 2, &p, NULL), ARGIL_OK);
    for (float x = -0.09f; x <= 0.09f; x += 0.007f)
        assert_true(field_eval(&f, vec3(x, 0.1f, 0.02f), NULL) > f.iso);
    /* freeform: copy the ridge's end as a tool and stamp it elsewhere with ADD */
    tool_freeform_t ff;
    const int32_t slo[3] = {-28, 12, -2}, shi[3] = {-12, 28, 12};
    assert_int_equal(tool_freeform_from_field(&ff, &f, slo, shi), ARGIL_OK);
    tool_shape_t ft;
    memset(&ft, 0, sizeof(ft));
    ft.kind = TOOL_FREEFORM;
    ft.freeform = &ff;
    tool_pose_at(&pose, vec3(-0.1f, -0.1f, 0.1f)); /* in empty space above the slab */
    assert_int_equal(tool_apply(&f, &ft, &pose, &p, NULL, NULL), ARGIL_OK);
    const float src = field_eval(&f, vec3(-0.1f, 0.1f, 0.02f), NULL);
    const float dst = field_eval(&f, vec3(-0.1f, -0.1f, 0.1f + (0.02f - 0.025f)), NULL);
    assert_true(src > f.iso && dst > f.iso);
    tool_freeform_free(&ff);
    /* errors */
    t.radius_m = -1.0f;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_ERR_ARG);
    t.radius_m = 0.01f;
    p.mirror = 8u;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_ERR_ARG);
    p.mirror = 0;
    pose.pos_m.x = NAN;
    assert_int_equal(tool_apply(&f, &t, &pose, &p, NULL, NULL), ARGIL_ERR_NONFINITE);
    field_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_carve_cap_volume),
        cmocka_unit_test(test_carve_sphere_volume),
        cmocka_unit_test(test_least_squares_fit_beats_quasi_interpolation),
        cmocka_unit_test(test_add_undo_redo_bit_exact),
        cmocka_unit_test(test_undo_budget_drops_oldest),
        cmocka_unit_test(test_mirror_is_symmetric),
        cmocka_unit_test(test_chisel_and_squirt_move_the_surface_by_the_depth),
        cmocka_unit_test(test_interior_carve_keeps_the_shell),
        cmocka_unit_test(test_stamp_contact_toothpaste_erase_smooth),
        cmocka_unit_test(test_paint_and_freeform_and_sweep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
