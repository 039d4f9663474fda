/* Hua & Qin §4 octree B-spline fit: a sphere, a torus and a box sampled as point clouds (clean,
 * noisy, with a missing cap) are fitted, sampled into a density grid and meshed by marching
 * cubes; the mesh vertices lie within the stated distances of the true surface. Also: the
 * subdivision obeys the error bound and the depth limit, volumes fit the same way, errors. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "host/fit/normals.h"
#include "host/fit/octree_fit.h"
#include "tests/unit/fit_shapes.h"

typedef double (*sdf_fn)(vec3_t p); /* true signed distance, positive inside */

static double sd_sphere(vec3_t p) { return 0.03 - sqrt((double)vec3_dot(p, p)); }

static double sd_torus(vec3_t p)
{
    const double q = sqrt((double)p.x * p.x + (double)p.y * p.y) - 0.03;
    return 0.01 - sqrt(q * q + (double)p.z * p.z);
}

static double sd_box(vec3_t p) /* half-edges 0.02, 0.015, 0.01 */
{
    const double h[3] = {0.02, 0.015, 0.01}, q[3] = {fabs(p.x) - h[0], fabs(p.y) - h[1], fabs(p.z) - h[2]};
    const double mx = fmax(q[0], fmax(q[1], q[2]));
    double out = 0.0;
    for (int a = 0; a < 3; a++)
        out += q[a] > 0 ? q[a] * q[a] : 0.0;
    return mx > 0 ? -sqrt(out) : -mx;
}

/* A deterministic normal deviate (Box-Muller on a small LCG). */
static uint64_t g_rng = 12345;
static double urand(void)
{
    g_rng = g_rng * 6364136223846793005ull + 1442695040888963407ull;
    return ((double)(g_rng >> 11) + 0.5) / 9007199254740992.0;
}
static double nrand(void) { return sqrt(-2.0 * log(urand())) * cos(2.0 * M_PI * urand()); }

static void add(mesh_t *m, vec3_t p, vec3_t n, double noise_m)
{
    const vec3_t q = vec3((float)(p.x + noise_m * nrand()), (float)(p.y + noise_m * nrand()),
                          (float)(p.z + noise_m * nrand()));
    assert_int_equal(mesh_add_vertex(m, q, n, NULL), ARGIL_OK);
}

static void sphere_cloud(mesh_t *m, int n, double noise_m, double cap_z)
{
    mesh_init(m);
    for (int i = 0; i < n; i++) {
        const double z = 1 - 2 * (i + 0.5) / n, rr = sqrt(1 - z * z), t = i * M_PI * (3 - sqrt(5));
        const vec3_t nn = vec3((float)(rr * cos(t)), (float)(rr * sin(t)), (float)z);
        if (z > cap_z)
            continue;
        add(m, vec3_scale(nn, 0.03f), nn, noise_m);
    }
}

static void torus_cloud(mesh_t *m, int nu, int nv, double noise_m)
{
    mesh_init(m);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            const double u = 2 * M_PI * (i + 0.5 * (j & 1)) / nu, v = 2 * M_PI * j / nv;
            const vec3_t n = vec3((float)(cos(v) * cos(u)), (float)(cos(v) * sin(u)), (float)sin(v));
            const vec3_t p = vec3((float)((0.03 + 0.01 * cos(v)) * cos(u)),
                                  (float)((0.03 + 0.01 * cos(v)) * sin(u)), (float)(0.01 * sin(v)));
            add(m, p, n, noise_m);
        }
}

static void box_cloud(mesh_t *m, double step_m, double noise_m)
{
    mesh_init(m);
    const double h[3] = {0.02, 0.015, 0.01};
    for (int a = 0; a < 3; a++) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const int nb = (int)(2 * h[b] / step_m), nc = (int)(2 * h[c] / step_m);
        for (int s = -1; s <= 1; s += 2)
            for (int i = 0; i <= nb; i++)
                for (int j = 0; j <= nc; j++) {
                    float p[3], n[3] = {0, 0, 0};
                    p[a] = (float)(s * h[a]);
                    p[b] = (float)(-h[b] + 2 * h[b] * i / nb);
                    p[c] = (float)(-h[c] + 2 * h[c] * j / nc);
                    n[a] = (float)s;
                    add(m, vec3(p[0], p[1], p[2]), vec3(n[0], n[1], n[2]), noise_m);
                }
    }
}

typedef fs_measure_t dist_t;

typedef struct {
    sdf_fn sd;
} sd_ctx_t;

static double sd_call(const void *ctx, const double p[3])
{
    return ((const sd_ctx_t *)ctx)->sd(vec3((float)p[0], (float)p[1], (float)p[2]));
}

static dist_t measure(const octfit_model_t *m, sdf_fn sd, const float half[3], float size, int res)
{
    const sd_ctx_t c = {sd};
    dist_t r;
    assert_int_equal(fs_measure(m, sd_call, &c, half, size, res, &r), ARGIL_OK);
    return r;
}

static dist_t fit_and_measure(const char *name, mesh_t *cloud, sdf_fn sd, const float half[3],
                              float size, float tol_frac, uint32_t depth, octfit_model_t *keep)
{
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = tol_frac * size;
    o.max_depth = depth;
    octfit_model_t m;
    assert_int_equal(octfit_points(cloud, &o, &m), ARGIL_OK);
    const dist_t d = measure(&m, sd, half, size, 48);
    printf("  %-22s %6zu pts: %5u nodes (%u leaves, depth %u), samples rms %.4f %%; "
           "mesh %zu verts: mean %.4f %%, max %.4f %% of size\n",
           name, cloud->n_vert, m.n_nodes, m.n_leaves, m.depth, 100.0 * m.rms_err / size, d.verts,
           100.0 * d.mean, 100.0 * d.max);
    assert_true(d.verts > 500);
    if (keep != NULL)
        *keep = m;
    else
        octfit_free(&m);
    return d;
}

static void test_sphere(void **state)
{
    (void)state;
    mesh_t c;
    const float half[3] = {0.03f, 0.03f, 0.03f};
    sphere_cloud(&c, 2000, 0.0, 2.0);
    dist_t d = fit_and_measure("sphere", &c, sd_sphere, half, 0.06f, 0.0005f, 5, NULL);
    assert_true(d.mean <= 0.005 && d.max <= 0.02);
    mesh_free(&c);
    sphere_cloud(&c, 2000, 0.002 * 0.06, 2.0); /* noise sigma 0.2 % of the size */
    d = fit_and_measure("sphere, noise 0.2 %", &c, sd_sphere, half, 0.06f, 0.003f, 5, NULL);
    assert_true(d.mean <= 0.005 && d.max <= 0.02);
    mesh_free(&c);
    sphere_cloud(&c, 2000, 0.0, 0.8); /* cap above z = 0.8 r missing */
    d = fit_and_measure("sphere, cap missing", &c, sd_sphere, half, 0.06f, 0.0005f, 5, NULL);
    assert_true(d.mean <= 0.01 && d.max <= 0.05);
    mesh_free(&c);
}

static void test_torus(void **state)
{
    (void)state;
    mesh_t c;
    const float half[3] = {0.04f, 0.04f, 0.01f};
    torus_cloud(&c, 72, 24, 0.0);
    dist_t d = fit_and_measure("torus", &c, sd_torus, half, 0.08f, 0.0005f, 5, NULL);
    assert_true(d.mean <= 0.005 && d.max <= 0.02);
    mesh_free(&c);
    torus_cloud(&c, 72, 24, 0.002 * 0.08);
    d = fit_and_measure("torus, noise 0.2 %", &c, sd_torus, half, 0.08f, 0.003f, 5, NULL);
    assert_true(d.mean <= 0.01 && d.max <= 0.04);
    mesh_free(&c);
}

static void test_box(void **state)
{
    (void)state;
    mesh_t c;
    const float half[3] = {0.02f, 0.015f, 0.01f};
    box_cloud(&c, 0.0012, 0.0);
    dist_t d = fit_and_measure("box", &c, sd_box, half, 0.04f, 0.002f, 2, NULL);
    assert_true(d.mean <= 0.005 && d.max <= 0.02);
    mesh_free(&c);
}

static void test_torus_estimated_normals(void **state)
{
    (void)state;
    mesh_t c;
    const float half[3] = {0.04f, 0.04f, 0.01f};
    torus_cloud(&c, 72, 24, 0.0);
    for (size_t i = 0; i < 3 * c.n_vert; i++)
        c.normal[i] = 0.0f;
    assert_int_equal(normals_estimate(&c, NULL, NULL), ARGIL_OK);
    const dist_t d = fit_and_measure("torus, PCA normals", &c, sd_torus, half, 0.08f, 0.0005f, 5, NULL);
    assert_true(d.mean <= 0.005 && d.max <= 0.02);
    mesh_free(&c);
}

#define SCAN_POINTS 12000u /* the bench fits 30,000; this keeps the test quick under ASan */

typedef struct {
    dist_t d;
    uint32_t nodes;
    double seconds;
} scan_fit_t;

/* A scan of shape s (SCAN_POINTS samples, noise sigma noise_frac of the diagonal, its true
 * normals or PCA ones) fitted with the CLI's defaults (tolerance 0.2 % of the longest extent,
 * depth 5) and meshed on a grid of diagonal / 64. Prints the figures. */
static scan_fit_t scan_fit(fs_shape_t s, double noise_frac, bool normals)
{
    const float *h = fs_half[s];
    const double diag = fs_diag(s);
    mesh_t c;
    mesh_init(&c);
    assert_int_equal(fs_sample(s, SCAN_POINTS, noise_frac * diag, 777 + (uint64_t)s, &c), ARGIL_OK);
    if (!normals) {
        for (size_t i = 0; i < 3 * c.n_vert; i++)
            c.normal[i] = 0.0f;
        assert_int_equal(normals_estimate(&c, NULL, NULL), ARGIL_OK);
    }
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = 0.002f * 2.0f * fmaxf(h[0], fmaxf(h[1], h[2]));
    octfit_model_t m;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    scan_fit_t r;
    assert_int_equal(fs_measure(&m, fs_dist_cb, &s, h, (float)diag, 64, &r.d), ARGIL_OK);
    r.nodes = m.n_nodes;
    r.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("  %-16s noise %.1f %% %-9s: %5u nodes (depth %u) %.2f s; mesh %zu verts, %u components, "
           "Euler %ld; distance mean %.3f %% max %.3f %% of the diagonal\n",
           s == FS_HOLED_BOX ? "holed box" : "plate, 2 holes", 100.0 * noise_frac,
           normals ? "normals" : "PCA", m.n_nodes, m.depth, r.seconds, r.d.verts, r.d.components,
           r.d.euler, 100.0 * r.d.mean, 100.0 * r.d.max);
    octfit_free(&m);
    mesh_free(&c);
    return r;
}

/* A scanned solid with through-holes and sharp edges, clean and with Gaussian noise of 0.5 % of
 * the diagonal, with and without normals: one surface of the object's genus, every mesh vertex
 * within 2 % of the diagonal of the true surface; the noisy scan needs at most 1.5 x the clean
 * scan's octree nodes (a fit that follows the noise needed 16-33 x). */
static void scan_case(fs_shape_t s, bool normals)
{
    const scan_fit_t clean = scan_fit(s, 0.0, normals), noisy = scan_fit(s, 0.005, normals);
    const scan_fit_t *r[2] = {&clean, &noisy};
    for (int k = 0; k < 2; k++) {
        assert_true(r[k]->d.verts > 2000);
        assert_true(r[k]->d.max <= 0.02);
        assert_int_equal(r[k]->d.components, 1);
        assert_int_equal(r[k]->d.euler, 2 - 2 * fs_genus[s]);
    }
    assert_true(noisy.nodes <= clean.nodes + clean.nodes / 2);
}

typedef struct {
    fs_shape_t shape;
    bool normals; /* the true ones, else PCA */
} scan_kind_t;

static scan_kind_t g_scans[4] = {
    {FS_HOLED_BOX, true}, {FS_HOLED_BOX, false}, {FS_PLATE_2_HOLES, true}, {FS_PLATE_2_HOLES, false}};

static void test_scan(void **state)
{
    const scan_kind_t *k = *state;
    scan_case(k->shape, k->normals);
}

/* A 40^3 volume of intensities 10..90 (a sphere of radius 12 mm, 2 mm ramp) fits so that the
 * zero set lies within a tenth of a voxel of the sphere. */
static void test_volume(void **state)
{
    (void)state;
    enum { N = 40 };
    const float h = 0.001f;
    const int32_t dims[3] = {N, N, N};
    float *v = malloc(N * N * N * sizeof(float));
    size_t i = 0;
    const float o = -0.5f * (N - 1) * h;
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++, i++) {
                const float r = vec3_norm(vec3(o + h * x, o + h * y, o + h * z));
                v[i] = 50.0f + 40.0f * tanhf((0.012f - r) / 0.002f);
            }
    octfit_opts_t opt;
    octfit_opts_default(&opt);
    opt.tolerance = 0.005f; /* of the normalised intensity range */
    octfit_model_t m;
    assert_int_equal(octfit_volume(v, dims, h, vec3(o, o, o), 10.0f, 90.0f, 0.5f, &opt, &m), ARGIL_OK);
    assert_int_equal(m.kind, OCTFIT_INTENSITY);
    assert_true(m.rms_err < 0.005f);
    for (int k = 0; k < 20; k++) { /* the zero crossing along 20 directions */
        const vec3_t dir = vec3(cosf(0.7f * k) * sinf(0.3f * k + 0.2f), sinf(0.7f * k) * sinf(0.3f * k + 0.2f),
                                cosf(0.3f * k + 0.2f));
        float lo = 0.0f, hi = 0.018f;
        for (int it = 0; it < 30; it++) {
            const float mid = 0.5f * (lo + hi);
            if (octfit_eval(&m, vec3_scale(dir, mid)) > 0.0f)
                lo = mid;
            else
                hi = mid;
        }
        assert_float_equal(lo, 0.012f, 0.1f * h);
    }
    octfit_free(&m);
    free(v);
}

/* Clouds that bound no solid are refused with the rule they break, never fitted or crashed on:
 * too few points, NaN, duplicates of fewer than 4 positions, points on a plane (clean or noisy)
 * or on a line. A cloud whose every point is repeated still fits. */
static void test_bad_clouds(void **state)
{
    (void)state;
    octfit_opts_t o;
    octfit_opts_default(&o);
    o.tolerance = 1e-4f;
    octfit_model_t m;
    mesh_t c;
    mesh_init(&c);
    for (int i = 0; i < 3; i++)
        add(&c, vec3(0.01f * (float)i, 0, 0), vec3(0, 0, 1), 0.0);
    assert_int_equal(octfit_check_points(&c, NULL, NULL), OCTFIT_CLOUD_FEW);
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG);
    mesh_free(&c);
    mesh_init(&c); /* 500 copies of three positions */
    for (int i = 0; i < 500; i++)
        add(&c, vec3(0.01f * (float)(i % 3), 0.02f, 0), vec3(0, 0, 1), 0.0);
    assert_int_equal(octfit_check_points(&c, NULL, NULL), OCTFIT_CLOUD_DUPLICATES);
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG);
    assert_int_equal(normals_estimate(&c, NULL, NULL), ARGIL_OK); /* no crash on duplicates */
    mesh_free(&c);
    for (int noisy = 0; noisy < 2; noisy++) { /* a 50 mm square, clean and with 0.2 mm noise */
        mesh_init(&c);
        for (int i = 0; i < 3000; i++)
            add(&c, vec3((float)(0.05 * urand()), (float)(0.05 * urand()), 0), vec3(0, 0, 1),
                noisy ? 0.0002 : 0.0);
        float thick, noise;
        assert_int_equal(octfit_check_points(&c, &thick, &noise), OCTFIT_CLOUD_FLAT);
        assert_true(thick <= 3.0f * noise + 1e-7f);
        assert_int_equal(normals_estimate(&c, NULL, NULL), ARGIL_OK);
        assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG);
        mesh_free(&c);
    }
    mesh_init(&c);
    for (int i = 0; i < 1000; i++)
        add(&c, vec3((float)(0.05 * urand()), 0.01f, 0.02f), vec3(0, 0, 1), 0.0);
    assert_int_equal(octfit_check_points(&c, NULL, NULL), OCTFIT_CLOUD_FLAT);
    mesh_free(&c);
    sphere_cloud(&c, 1500, 0.0, 2.0);
    mesh_t d;
    mesh_init(&d);
    for (size_t i = 0; i < c.n_vert; i++)
        for (int k = 0; k < 3; k++)
            add(&d, vec3(c.pos[3 * i], c.pos[3 * i + 1], c.pos[3 * i + 2]),
                vec3(c.normal[3 * i], c.normal[3 * i + 1], c.normal[3 * i + 2]), 0.0);
    assert_int_equal(octfit_check_points(&d, NULL, NULL), OCTFIT_CLOUD_OK);
    const float half[3] = {0.03f, 0.03f, 0.03f};
    const dist_t r = fit_and_measure("sphere, every point x3", &d, sd_sphere, half, 0.06f, 0.0005f, 5, NULL);
    assert_true(r.max <= 0.02 && r.components == 1 && r.euler == 2);
    d.pos[7] = NAN;
    assert_int_equal(octfit_check_points(&d, NULL, NULL), OCTFIT_CLOUD_NONFINITE);
    mesh_free(&d);
    mesh_free(&c);
}

static volatile int g_stop = 1;

static void test_limits_and_errors(void **state)
{
    (void)state;
    mesh_t c;
    sphere_cloud(&c, 800, 0.0, 2.0);
    octfit_opts_t o;
    octfit_opts_default(&o);
    octfit_model_t m;
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG); /* no tolerance */
    o.tolerance = 1e-9f;
    o.max_depth = OCTFIT_DEPTH_MAX + 1;
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG);
    o.max_depth = 0; /* one node however tight the bound */
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_OK);
    assert_int_equal(m.n_nodes, 1);
    octfit_free(&m);
    o.max_depth = 2; /* a tight bound splits down to the limit, never beyond */
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_OK);
    assert_int_equal(m.depth, 2);
    assert_true(m.n_nodes > 9);
    assert_true(octfit_eval(&m, vec3(0, 0, 0)) > 0.0f && octfit_eval(&m, vec3(0.05f, 0, 0)) < 0.0f);
    assert_true(octfit_eval(&m, vec3(1.0f, 0, 0)) < -0.9f); /* beyond the root: minus the distance */
    octfit_free(&m);
    o.stop = &g_stop;
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_STATE);
    assert_int_equal(m.n_nodes, 0);
    o.stop = NULL;
    c.normal[5] = NAN;
    assert_int_equal(octfit_points(&c, &o, &m), ARGIL_ERR_ARG);
    mesh_free(&c);
    /* child links that are no octree */
    const float org[3] = {0, 0, 0};
    uint32_t links[17] = {0};
    assert_int_equal(octfit_alloc(&m, 1, links, org, 1.0f), ARGIL_OK);
    octfit_free(&m);
    links[0] = 1;
    assert_int_equal(octfit_alloc(&m, 9, links, org, 1.0f), ARGIL_OK);
    assert_int_equal(m.n_leaves, 8);
    octfit_free(&m);
    assert_int_equal(octfit_alloc(&m, 8, links, org, 1.0f), ARGIL_ERR_ARG);  /* children missing */
    assert_int_equal(octfit_alloc(&m, 10, links, org, 1.0f), ARGIL_ERR_ARG); /* an orphan */
    links[1] = 1;
    assert_int_equal(octfit_alloc(&m, 17, links, org, 1.0f), ARGIL_ERR_ARG); /* a loop back */
    links[1] = 9;
    assert_int_equal(octfit_alloc(&m, 17, links, org, 1.0f), ARGIL_OK);
    octfit_free(&m);
    links[0] = 0;
    assert_int_equal(octfit_alloc(&m, 17, links, org, 1.0f), ARGIL_ERR_ARG); /* node 1 orphaned */
    links[0] = 1;
    assert_int_equal(octfit_alloc(&m, 17, links, org, 0.0f), ARGIL_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_torus),
        cmocka_unit_test(test_box),
        cmocka_unit_test(test_torus_estimated_normals),
        {"test_scan_holed_box", test_scan, NULL, NULL, &g_scans[0]},
        {"test_scan_holed_box_pca", test_scan, NULL, NULL, &g_scans[1]},
        {"test_scan_plate", test_scan, NULL, NULL, &g_scans[2]},
        {"test_scan_plate_pca", test_scan, NULL, NULL, &g_scans[3]},
        cmocka_unit_test(test_volume),
        cmocka_unit_test(test_limits_and_errors),
        cmocka_unit_test(test_bad_clouds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
