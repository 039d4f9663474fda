/* The rim of the dent a push leaves (issue 17 point 6): the sharpest folds of the mesh around it,
 * against those of an analytic dent at the grid's resolution (the sphere minus the balls the tool
 * swept, sampled into the same grid and meshed by the same marching cubes). Runs a short scripted
 * push (the default session's first stroke), reads final.ply and telemetry.csv from disk. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/mesh/grid_mesh.h"
#include "host/mesh/mesh_check.h"
#include "host/model/grid.h"
#include "tests/sil/sil_runs.h"

#define CLAY_R_M 0.030    /* the session's sphere, centred at the origin */
#define TOOL_R_M 0.004    /* the script's radius_mm */
#define BAND_RHO_LO 0.7   /* the rim band: distance from the push's axis (+z), in tool radii */
#define BAND_RHO_HI 1.3
#define BAND_HEIGHT 0.5   /* and within this many tool radii of the original sphere */

static const char PUSH_SCRIPT[] =
    "set radius_mm 4\n"
    "set stiffness_n_per_mm 0.8\n"
    "set max_force_n 3.3\n"
    "set alpha 30000\n"
    "tool touch\n"
    "move 0 0 36 0.6\n"
    "move 0 0 32 0.4\n"
    "wait 0.2\n"
    "tool push\n"
    "press 1\n"
    "move 0 0 22 1.5\n"
    "wait 0.3\n"
    "release 1\n"
    "move 0 0 45 0.5\n";

/* The rim's figures: dihedral angles (between the face normals across a shared edge) of the
 * edges whose midpoint lies in the band, and the angle between each band vertex's normal (the
 * mesher's, from the field's gradient) and the area-weighted normal of its triangles. */
typedef struct {
    size_t edges, verts;
    double dihedral_max_deg, dihedral_p99_deg;
    double normal_max_deg;
} rim_figures_t;

typedef struct {
    uint64_t key;
    uint32_t tri;
} edge_key_t;

static int edge_key_cmp(const void *a, const void *b)
{
    const edge_key_t *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
}

static int double_cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static vec3_t vert(const mesh_t *m, uint32_t i)
{
    return vec3(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]);
}

/* Unit normal of triangle t (zero when degenerate); its area in *area (may be NULL). */
static vec3_t face_normal(const mesh_t *m, size_t t, double *area)
{
    const vec3_t a = vert(m, m->tri[3 * t]), b = vert(m, m->tri[3 * t + 1]);
    const vec3_t c = vert(m, m->tri[3 * t + 2]);
    const vec3_t n = vec3_cross(vec3_sub(b, a), vec3_sub(c, a));
    const float len = vec3_norm(n);
    if (area)
        *area = 0.5 * len;
    return len > 0.0f ? vec3_scale(n, 1.0f / len) : vec3(0, 0, 0);
}

/* True for a point of the rim band round the push's axis (+z through the sphere's centre). */
static bool in_rim_band(vec3_t p)
{
    const double rho = sqrt((double)p.x * p.x + (double)p.y * p.y);
    const double height = sqrt((double)p.x * p.x + (double)p.y * p.y + (double)p.z * p.z) - CLAY_R_M;
    return p.z > 0.0f && rho >= BAND_RHO_LO * TOOL_R_M && rho <= BAND_RHO_HI * TOOL_R_M &&
           fabs(height) <= BAND_HEIGHT * TOOL_R_M;
}

static double angle_deg(vec3_t a, vec3_t b)
{
    double d = vec3_dot(a, b);
    d = d > 1.0 ? 1.0 : (d < -1.0 ? -1.0 : d);
    return acos(d) * 180.0 / M_PI;
}

static rim_figures_t rim_measure(const mesh_t *m)
{
    rim_figures_t f = {0};
    const size_t ne = 3 * m->n_tri;
    edge_key_t *e = malloc(ne * sizeof(*e));
    double *ang = malloc(ne * sizeof(*ang));
    vec3_t *area_n = calloc(m->n_vert, sizeof(*area_n));
    assert_true(e && ang && area_n);
    for (size_t t = 0; t < m->n_tri; t++) {
        double area;
        const vec3_t n = face_normal(m, t, &area);
        for (int k = 0; k < 3; k++) {
            const uint32_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            e[3 * t + k].key = (uint64_t)(a < b ? a : b) << 32 | (a < b ? b : a);
            e[3 * t + k].tri = (uint32_t)t;
            area_n[a] = vec3_add(area_n[a], vec3_scale(n, (float)area));
        }
    }
    qsort(e, ne, sizeof(*e), edge_key_cmp);
    for (size_t i = 0; i + 1 < ne; i++) {
        if (e[i].key != e[i + 1].key)
            continue;
        const uint32_t a = (uint32_t)(e[i].key >> 32), b = (uint32_t)e[i].key;
        if (in_rim_band(vec3_scale(vec3_add(vert(m, a), vert(m, b)), 0.5f)))
            ang[f.edges++] = angle_deg(face_normal(m, e[i].tri, NULL),
                                       face_normal(m, e[i + 1].tri, NULL));
        i++;
    }
    qsort(ang, f.edges, sizeof(*ang), double_cmp);
    if (f.edges > 0) {
        f.dihedral_max_deg = ang[f.edges - 1];
        f.dihedral_p99_deg = ang[(size_t)(0.99 * (double)(f.edges - 1))];
    }
    for (uint32_t v = 0; v < m->n_vert; v++) {
        const float len = vec3_norm(area_n[v]);
        if (!in_rim_band(vert(m, v)) || !(len > 0.0f))
            continue;
        const vec3_t mn = vec3(m->normal[3 * v], m->normal[3 * v + 1], m->normal[3 * v + 2]);
        const double d = angle_deg(vec3_scale(area_n[v], 1.0f / len), mn);
        f.verts++;
        if (d > f.normal_max_deg)
            f.normal_max_deg = d;
    }
    free(e);
    free(ang);
    free(area_n);
    return f;
}

/* The analytic dent into m: the session's sphere in the session's grid (88³ at 1.25 mm, centred
 * on the origin), minus the tool ball at every telemetry row where the push was sculpting. */
static void analytic_dent(const char *telemetry_path, mesh_t *m)
{
    const int32_t dims[3] = {88, 88, 88};
    const float half = 0.5f * 87.0f * 0.00125f;
    grid_t g;
    assert_int_equal(grid_init(&g, dims, 0.00125f, vec3(-half, -half, -half)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0, 0, 0), (float)CLAY_R_M);
    FILE *fp = fopen(telemetry_path, "r");
    assert_non_null(fp);
    char line[512];
    assert_non_null(fgets(line, sizeof(line), fp));
    assert_non_null(strstr(line, "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state,tool,"
                                 "buttons,contact,sculpting"));
    int carved = 0;
    while (fgets(line, sizeof(line), fp)) {
        double t, x, y, z, fx, fy, fz, fn;
        char state[32];
        int tool, buttons, contact, sculpting;
        if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%31[^,],%d,%d,%d,%d", &t, &x, &y, &z,
                   &fx, &fy, &fz, &fn, state, &tool, &buttons, &contact, &sculpting) != 13 ||
            sculpting != 1 || tool != 1)
            continue;
        int32_t lo[3], hi[3];
        grid_carve_sphere(&g, vec3((float)(x * 1e-3), (float)(y * 1e-3), (float)(z * 1e-3)),
                          (float)TOOL_R_M, lo, hi);
        carved++;
    }
    fclose(fp);
    assert_true(carved > 100); /* the push sculpted for a while */
    mesh_init(m);
    assert_int_equal(grid_mesh_extract(&g, g.iso, m), ARGIL_OK);
    grid_free(&g);
}

static void print_rim(const char *what, const rim_figures_t *f)
{
    printf("# %s: %zu rim edges, dihedral max %.1f deg, p99 %.1f deg; %zu rim vertices, "
           "normal off its triangles' by %.1f deg at most\n", what, f->edges,
           f->dihedral_max_deg, f->dihedral_p99_deg, f->verts, f->normal_max_deg);
}

/* The push's rim is no sharper than the analytic dent's at this resolution: its largest and
 * 99th-percentile dihedral angles are at most the analytic dent's, and its shading normals stray
 * from its triangles no more than the analytic dent's do. */
static void test_push_rim_no_sharper_than_analytic_dent(void **state)
{
    (void)state;
    char dir[64], script[128];
    const char *const parts[] = {PUSH_SCRIPT, NULL};
    assert_int_equal(sil_script_dir(dir, "argil-dent-rim", "push.scn", parts, script), 0);
    session_opts_t o;
    sil_opts(&o, script, dir);
    session_summary_t sum;
    sil_run(&o, &sum, "push session");
    sil_assert_clean(&sum);

    mesh_t pushed, analytic;
    sil_read_final(dir, &pushed);
    char telemetry[128];
    snprintf(telemetry, sizeof(telemetry), "%s/telemetry.csv", dir);
    analytic_dent(telemetry, &analytic);
    const rim_figures_t fp = rim_measure(&pushed), fa = rim_measure(&analytic);
    print_rim("pushed dent", &fp);
    print_rim("analytic dent", &fa);

    /* Both rims were found: a band of a tool radius holds ~200 edges at 1.25 mm. */
    assert_true(fp.edges > 100 && fa.edges > 100);
    /* The analytic rim is the crease where the bore meets the sphere; marching cubes cuts it
     * into folds of 40–90 degrees at this resolution. */
    assert_true(fa.dihedral_p99_deg > 30.0 && fa.dihedral_max_deg < 120.0);
    assert_true(fp.dihedral_max_deg <= fa.dihedral_max_deg);
    assert_true(fp.dihedral_p99_deg <= fa.dihedral_p99_deg);
    assert_true(fp.normal_max_deg <= fa.normal_max_deg);

    mesh_free(&pushed);
    mesh_free(&analytic);
    assert_int_equal(sil_remove_dir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_push_rim_no_sharper_than_analytic_dent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
