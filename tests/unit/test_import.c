/* Importers (PLY, STL, OBJ, XYZ, raw, NRRD): round trips of what the exporters write, and one
 * case per error branch, each asserting the message names the file, the line or byte, and the
 * rule broken. */
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

#include "host/io/io_util.h"
#include "host/io/mesh_export.h"
#include "host/io/mesh_import.h"
#include "host/io/volume.h"
#include "host/mesh/mc_blocks.h"
#include "host/mesh/mesh_check.h"
#include "host/model/grid.h"
#include "tests/unit/grid_view.h"

#include "tests/unit/test_files.h"

static int setup_dir(void **state)
{
    (void)state;
    return test_dir_make("argil_test_import");
}

/* A painted sphere mesh (closed). */
static void sphere_mesh(mesh_t *m, bool colours)
{
    grid_t g;
    const int32_t dims[3] = {20, 20, 20};
    assert_int_equal(grid_init(&g, dims, 1e-3f, vec3(-0.0095f, -0.0095f, -0.0095f)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0, 0, 0), 0.006f);
    uint8_t *rgb = malloc(3 * 8000);
    assert_non_null(rgb);
    for (size_t i = 0; i < 8000; i++) {
        rgb[3 * i] = (uint8_t)(i % 20 * 12);
        rgb[3 * i + 1] = 100;
        rgb[3 * i + 2] = 7;
    }
    mesh_init(m);
    assert_int_equal(mc_extract_region(gv_dense(&g), colours ? rgb : NULL, g.dims, g.spacing_m,
                                       g.origin_m, 0.5f, NULL, NULL, m),
                     ARGIL_OK);
    free(rgb);
    grid_free(&g);
}

static void assert_same_geometry(const mesh_t *a, const mesh_t *b, float tol)
{
    assert_int_equal(a->n_vert, b->n_vert);
    assert_int_equal(a->n_tri, b->n_tri);
    for (size_t i = 0; i < 3 * a->n_vert; i++)
        assert_float_equal(a->pos[i], b->pos[i], tol);
    assert_memory_equal(a->tri, b->tri, 3 * sizeof(uint32_t) * a->n_tri);
}

static void test_round_trips(void **state)
{
    (void)state;
    mesh_t m, r;
    sphere_mesh(&m, true);
    mesh_init(&r);
    char p[128], err[256];
    bool nrm;
    const struct {
        const char *name;
        export_format_t fmt;
    } cases[] = {{"a.ply", EXPORT_PLY_BINARY}, {"b.ply", EXPORT_PLY_ASCII}, {"c.obj", EXPORT_OBJ}};
    for (size_t k = 0; k < 3; k++) {
        test_path(p, sizeof(p), cases[k].name);
        assert_int_equal(mesh_export(p, &m, cases[k].fmt, err, sizeof(err)), ARGIL_OK);
        assert_int_equal(mesh_import(p, &r, &nrm, err, sizeof(err)), IMPORT_OK);
        assert_true(nrm);
        assert_same_geometry(&m, &r, 1e-7f);
        assert_true(r.has_rgb);
        for (size_t i = 0; i < 3 * m.n_vert; i++)
            assert_int_equal(r.rgb[i], m.rgb[i]);
        for (size_t i = 0; i < 3 * m.n_vert; i++)
            assert_float_equal(r.normal[i], m.normal[i], 1e-5f);
    }
    /* STL: welded back to the same closed surface with the same volume. */
    test_path(p, sizeof(p), "d.stl");
    assert_int_equal(mesh_export(p, &m, EXPORT_STL, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(stl_read(p, &r, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_vert, m.n_vert);
    assert_int_equal(r.n_tri, m.n_tri);
    assert_true(mesh_watertight(&r, NULL, NULL));
    assert_float_equal(mesh_volume_m3(&r), mesh_volume_m3(&m), 1e-12);
    /* ASCII STL of one facet, and a binary STL whose header starts with "solid". */
    test_path(p, sizeof(p), "e.stl");
    const char *a = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                    "   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
    test_spit(p, a, strlen(a));
    assert_int_equal(stl_read(p, &r, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_tri, 1);
    assert_float_equal(r.normal[2], 1.0f, 1e-6f);
    uint8_t bin[134] = "solid but binary";
    bin[80] = 1;
    for (int k = 0; k < 3; k++)
        memcpy(bin + 96 + 12 * k + 4 * k, &(float){1.0f}, 4);
    test_spit(p, bin, sizeof(bin));
    assert_int_equal(stl_read(p, &r, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_vert, 3);
    /* XYZ with and without normals, comments and blank lines. */
    test_path(p, sizeof(p), "f.xyz");
    const char *x6 = "# cloud\n0 0 1 0 0 1\n\n1 0 0 1 0 0\r\n0 1 0 0 1 0\n";
    test_spit(p, x6, strlen(x6));
    assert_int_equal(mesh_import(p, &r, &nrm, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_vert, 3);
    assert_true(nrm);
    assert_float_equal(r.normal[3], 1.0f, 0);
    const char *x3 = "0 0 1\n1.5e-3 -2 0\n";
    test_spit(p, x3, strlen(x3));
    assert_int_equal(xyz_read(p, &r, &nrm, err, sizeof(err)), IMPORT_OK);
    assert_false(nrm);
    assert_float_equal(r.pos[3], 1.5e-3f, 0);
    /* PLY variants: big-endian doubles with an extra element and a quad face; OBJ forms. */
    test_path(p, sizeof(p), "g.ply");
    const char *ph = "ply\nformat binary_big_endian 1.0\nelement camera 1\nproperty uchar k\n"
                     "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                     "element face 1\nproperty list uchar uint vertex_index\nend_header\n";
    uint8_t body[1 + 96 + 1 + 16];
    size_t o = 0;
    body[o++] = 9;
    const double vv[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (int i = 0; i < 12; i++) {
        uint64_t u;
        memcpy(&u, &vv[i], 8);
        for (int k = 7; k >= 0; k--)
            body[o++] = (uint8_t)(u >> (8 * k));
    }
    body[o++] = 4;
    for (uint32_t i = 0; i < 4; i++) {
        body[o++] = 0;
        body[o++] = 0;
        body[o++] = 0;
        body[o++] = (uint8_t)i;
    }
    uint8_t file[512];
    memcpy(file, ph, strlen(ph));
    memcpy(file + strlen(ph), body, o);
    test_spit(p, file, strlen(ph) + o);
    assert_int_equal(ply_load(p, &r, &nrm, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_vert, 4);
    assert_int_equal(r.n_tri, 2);
    assert_false(nrm);
    assert_float_equal(r.pos[6], 1.0f, 0);
    test_path(p, sizeof(p), "h.obj");
    const char *ob = "mtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
                     "vn 0 0 1\ng g\ns off\nusemtl m\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4 -2 -1 # tri\n";
    test_spit(p, ob, strlen(ob));
    assert_int_equal(obj_read(p, &r, &nrm, err, sizeof(err)), IMPORT_OK);
    assert_int_equal(r.n_tri, 3);
    assert_true(nrm); /* every vertex got vn 1 through the quad */
    mesh_free(&m);
    mesh_free(&r);
}

typedef import_err_t (*reader_fn)(const char *, mesh_t *, bool *, char *, size_t);

static import_err_t rd_stl(const char *p, mesh_t *m, bool *n, char *e, size_t l)
{
    (void)n;
    return stl_read(p, m, e, l);
}

/* Writes data, reads it with fn, expects the rule want and needles in the one-line message. */
static void expect_err(reader_fn fn, const char *name, const void *data, size_t len,
                       import_err_t want, const char *where, const char *rule)
{
    char p[128], err[512] = "";
    test_path(p, sizeof(p), name);
    test_spit(p, data, len);
    mesh_t m;
    mesh_init(&m);
    const import_err_t got = fn(p, &m, NULL, err, sizeof(err));
    if (got != want || strstr(err, p) == NULL || strstr(err, where) == NULL ||
        strstr(err, rule) == NULL || strchr(err, '\n') != NULL)
        fail_msg("%s: got %d '%s', want %d with '%s' and '%s'", name, got, err, want, where, rule);
    assert_int_equal(m.n_vert, 0);
    assert_int_equal(m.n_tri, 0);
    mesh_free(&m);
}

#define EXPECT_TXT(fn, name, text, want, where, rule) \
    expect_err(fn, name, text, strlen(text), want, where, rule)

#define PH "ply\nformat ascii 1.0\n"

static void test_ply_errors(void **state)
{
    (void)state;
    char buf[8192];
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex 0\n",
               IMPORT_ERR_PLY_HEADER_END, "line 3",
               "no end_header");
    size_t o = (size_t)sprintf(buf, "%s", PH);
    for (int i = 0; i < 600; i++)
        o += (size_t)sprintf(buf + o, "comment x\n");
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_PLY_HEADER_END, "line 513", "within 512 lines");
    memset(buf, 'a', 2000);
    memcpy(buf, "ply\ncomment ", 12);
    buf[2000] = '\n';
    expect_err(ply_load, "e.ply", buf, 2001, IMPORT_ERR_LINE_LONG, "line 2", "longer than 1023");
    expect_err(ply_load, "e.ply", "ply\nfor\0mat\n", 12, IMPORT_ERR_LINE_NUL, "line 2", "NUL byte");
    EXPECT_TXT(ply_load, "e.ply", "PLY\n", IMPORT_ERR_PLY_MAGIC, "line 1", "not a PLY file");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat binary 1.0\n", IMPORT_ERR_PLY_FORMAT,
               "line 2", "expected 'format");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex\n", IMPORT_ERR_PLY_ELEMENT,
               "line 3",
               "expected 'element");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex -3\n",
               IMPORT_ERR_PLY_ELEMENT, "line 3",
               "not a whole number");
    o = (size_t)sprintf(buf, "%s", PH);
    for (int i = 0; i < 17; i++)
        o += (size_t)sprintf(buf + o, "element e%d 0\n", i);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_PLY_LIMIT, "line 19", "more than 16 elements");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nproperty float x\n",
               IMPORT_ERR_PLY_PROPERTY, "line 3",
               "property before any element");
    o = (size_t)sprintf(buf, "%selement vertex 0\n", PH);
    for (int i = 0; i < 33; i++)
        o += (size_t)sprintf(buf + o, "property float p%d\n", i);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_PLY_LIMIT, "line 36", "more than 32 properties");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n",
               IMPORT_ERR_PLY_PROPERTY,
               "line 4", "expected 'property");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\n",
               IMPORT_ERR_PLY_PROPERTY,
               "line 4", "unknown or unusable property type");
    EXPECT_TXT(ply_load, "e.ply",
               "ply\nformat ascii 1.0\nelement f 1\nproperty list float int v\n",
               IMPORT_ERR_PLY_PROPERTY, "line 4",
               "unknown or unusable property type");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nbogus\n", IMPORT_ERR_PLY_KEYWORD,
               "line 3",
               "unknown header keyword 'bogus'");
#define VH "ply\nformat binary_little_endian 1.0\nelement vertex %s\nproperty float x\n" \
           "property float y\nproperty float z\n%send_header\n"
    sprintf(buf, VH, "1099511627776", "");
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_PLY_COUNTS,
               "byte 127", "declares 1099511627776 records but only 0");
    sprintf(buf, VH, "1", "element face 1\nproperty list uchar int vertex_indices\n");
    o = strlen(buf);
    memset(buf + o, 0, 12);
    expect_err(ply_load, "e.ply", buf, o + 12, IMPORT_ERR_PLY_COUNTS,
               "byte", "elements declare more");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
               "end_header\n1\n", IMPORT_ERR_PLY_NO_VERTEX,
               "header", "no 'vertex' element with scalar x, y and z");
    const char *ah = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                     "property float z\nproperty uchar red\nproperty uchar green\n"
                     "property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n"
                     "end_header\n";
    sprintf(buf, "%s0 0 0 1 2 3\n1 1 1 4 5 6\n3 0 1\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_TRUNCATED, "line 15", "file ends inside face 0");
    sprintf(buf, "%s0 0 0 1 2 3\n1 1 11111111111111111111111111111111111111111111111111111111111111111111 4 5 6\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_NUMBER,
               "line 14", "vertex 1: value is not a number");
    sprintf(buf, "%s0 0 0 1 2 3\n1 nan 1 4 5 6\n3 0 1 1\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_NUMBER,
               "line 14", "'nan' is not a finite number");
    sprintf(buf, "%s0 0 0 1 2.5 3\n1 1 1 4 5 6\n3 0 1 1\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_PLY_WHOLE,
               "line 13", "'2.5' must be a whole number");
    sprintf(buf, "%s0 0 0 1 2 3\n1 1 1 4 5 6\n2 0 1\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_FACE_SIZE,
               "line 15", "face 0 has 2 vertices (at least 3)");
    sprintf(buf, "%s0 0 0 1 2 3\n1 1 1 4 5 6\n3 0 1 2\n", ah);
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_INDEX, "line 15", "face 0 names vertex 2 of 2");
    sprintf(buf, "%s1e300 0 0 1 2 3\n1 1 1 4 5 6\n3 0 1 1\n", PH "element vertex 2\nproperty double x\n"
            "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n");
    EXPECT_TXT(ply_load, "e.ply", buf, IMPORT_ERR_NUMBER,
               "vertex 0", "coordinates overflow a float");
    EXPECT_TXT(ply_load, "e.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int "
               "vertex_indices\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
               "z\nend_header\n3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n", IMPORT_ERR_PLY_FACE_ORDER,
               "line 10", "faces come before vertices");
    /* binary: truncated, NaN, bad list length, trailing bytes */
    sprintf(buf, VH, "2", "");
    o = strlen(buf);
    memset(buf + o, 0, 20);
    expect_err(ply_load, "e.ply", buf, o + 20, IMPORT_ERR_PLY_COUNTS,
               "byte", "declares 2 records but only 20");
    sprintf(buf, VH, "1", "");
    o = strlen(buf);
    memset(buf + o, 0, 12);
    buf[o + 7] = 0x7f;
    buf[o + 6] = (char)0xc0; /* y = NaN */
    char where[32];
    sprintf(where, "byte %zu", o + 4);
    expect_err(ply_load, "e.ply", buf, o + 12, IMPORT_ERR_NUMBER, where, "not finite (NaN or Inf)");
    memset(buf + o, 0, 16);
    sprintf(where, "byte %zu", o + 12);
    expect_err(ply_load, "e.ply", buf, o + 16, IMPORT_ERR_PLY_TRAILING,
               where, "4 bytes after the last");
    sprintf(buf, VH, "1", "element face 1\nproperty list int int vertex_indices\n");
    o = strlen(buf);
    memset(buf + o, 0, 12);
    memset(buf + o + 12, 0xff, 4); /* count -1 */
    expect_err(ply_load, "e.ply", buf, o + 16, IMPORT_ERR_PLY_LIST_LENGTH,
               "byte", "list length -1 out of");
    memset(buf + o + 12, 0, 4);
    buf[o + 12] = 3;
    expect_err(ply_load, "e.ply", buf, o + 16, IMPORT_ERR_TRUNCATED,
               "byte", "file ends inside face 0");
    char p[128], err[256];
    test_path(p, sizeof(p), "missing.ply");
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(ply_load(p, &m, NULL, err, sizeof(err)), IMPORT_ERR_IO);
    assert_non_null(strstr(err, "cannot open"));
    assert_int_equal(ply_load(g_test_dir, &m, NULL, err, sizeof(err)), IMPORT_ERR_IO);
    assert_non_null(strstr(err, "not a regular file"));
    assert_int_equal(mesh_import("x.foo", &m, NULL, err, sizeof(err)), IMPORT_ERR_ARG);
    assert_non_null(strstr(err, "unknown extension"));
    mesh_free(&m);
}

static void test_stl_errors(void **state)
{
    (void)state;
    uint8_t b[200] = {0};
    expect_err(rd_stl, "e.stl", b, 50, IMPORT_ERR_STL_SIZE, "byte 50", "too short for binary STL");
    b[80] = 3;
    expect_err(rd_stl, "e.stl", b, 134, IMPORT_ERR_STL_SIZE, "byte 80", "declares 3 facets");
    b[80] = 1;
    b[96 + 3] = 0x7f;
    b[96 + 2] = 0x80; /* +Inf */
    expect_err(rd_stl, "e.stl", b, 134, IMPORT_ERR_NUMBER, "byte 96", "facet 0 has a non-finite");
    char big[1500];
    memset(big, 'x', sizeof(big));
    memcpy(big, "solid a\n", 8);
    expect_err(rd_stl, "e.stl", big, sizeof(big), IMPORT_ERR_LINE_LONG,
               "line 2", "longer than 1023");
    expect_err(rd_stl, "e.stl", "solid a\nfa\0cet\n", 15, IMPORT_ERR_LINE_NUL,
               "line 2", "NUL byte");
    EXPECT_TXT(rd_stl, "e.stl", "solidx\n", IMPORT_ERR_STL_SYNTAX,
               "line 1", "expects 'solid <name>'");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 x\n", IMPORT_ERR_STL_SYNTAX,
               "line 2", "expects 'facet normal");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 1\nouter loo\n", IMPORT_ERR_STL_SYNTAX,
               "line 3",
               "expects 'outer loop'");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nan\n",
               IMPORT_ERR_STL_SYNTAX,
               "line 4", "expects 'vertex x y z'");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
               "vertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0\n", IMPORT_ERR_STL_SYNTAX,
               "line 7", "expects 'endloop'");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
               "vertex 0 0 0\nvertex 0 0 0\nendloop\nendloop\n", IMPORT_ERR_STL_SYNTAX,
               "line 8", "expects 'endfacet'");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nendsolid a\nsolid b\n", IMPORT_ERR_STL_SYNTAX,
               "line 3", "nothing after endsolid");
    EXPECT_TXT(rd_stl, "e.stl", "solid a\nfacet normal 0 0 1\n", IMPORT_ERR_TRUNCATED,
               "line 2", "before 'endsolid'");
}

static void test_obj_xyz_errors(void **state)
{
    (void)state;
    char big[1500];
    memset(big, '1', sizeof(big));
    big[0] = 'v';
    big[1] = ' ';
    expect_err(obj_read, "e.obj", big, sizeof(big), IMPORT_ERR_LINE_LONG,
               "line 1", "longer than 1023");
    expect_err(obj_read, "e.obj", "v 0 0\0 0\n", 9, IMPORT_ERR_LINE_NUL, "line 1", "NUL byte");
    EXPECT_TXT(obj_read, "e.obj", "# c\nv 0 0\n", IMPORT_ERR_OBJ_VERTEX,
               "line 2", "'v' needs 3 (x y z)");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 inf\n", IMPORT_ERR_OBJ_VERTEX, "line 1", "'v' needs 3");
    EXPECT_TXT(obj_read, "e.obj", "vn 0 0\n", IMPORT_ERR_OBJ_VERTEX,
               "line 1", "'vn' needs 3 finite numbers");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", IMPORT_ERR_FACE_SIZE,
               "line 3", "'f' needs 3 to 64");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n", IMPORT_ERR_INDEX, "line 3",
               "face corner 3 names a vertex or normal that does not exist");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 2 -4\n", IMPORT_ERR_INDEX,
               "line 4",
               "face corner 3 names");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 0\nv 1 0 0\nv 1 1 1\nvn 0 0 1\nf 1//1 2//2 3//1\n",
               IMPORT_ERR_INDEX,
               "line 5", "face corner 2 names");
    EXPECT_TXT(obj_read, "e.obj", "v 0 0 0\nbevel on\n", IMPORT_ERR_OBJ_STATEMENT,
               "line 2", "unknown OBJ statement 'bevel'");

    memset(big, '1', sizeof(big));
    expect_err(xyz_read, "e.xyz", big, sizeof(big), IMPORT_ERR_LINE_LONG,
               "line 1", "longer than 1023");
    expect_err(xyz_read, "e.xyz", "0 0\0 0\n", 7, IMPORT_ERR_LINE_NUL, "line 1", "NUL byte");
    EXPECT_TXT(xyz_read, "e.xyz", "0 0 0\n1 2 3 4\n", IMPORT_ERR_XYZ_COLUMNS,
               "line 2", "4 values; each point needs 3");
    EXPECT_TXT(xyz_read, "e.xyz", "0 0 0\n1 2 3 0 0 1\n", IMPORT_ERR_XYZ_COLUMNS, "line 2",
               "6 values but line 1 had 3 (every line must have the same count)");
    EXPECT_TXT(xyz_read, "e.xyz", "0 0 0\n1 2 1e999\n", IMPORT_ERR_NUMBER,
               "line 2", "value 3 '1e999' is not a finite");
    EXPECT_TXT(xyz_read, "e.xyz", "# only a comment\n\n", IMPORT_ERR_XYZ_EMPTY,
               "line 2", "no points");
}

/* How a volume case is read: raw with dims, type and byte order, or NRRD. */
typedef struct {
    int32_t dims[3];
    vol_type_t t;
    bool big;
    bool raw;
} vol_case_t;

/* Writes data as name, reads it as c says, and expects the rule want, no samples, and where and
 * rule in the one-line message that names the file. */
static void expect_vol(const vol_case_t *c, const char *name, const void *data, size_t len,
                       volume_err_t want, const char *where, const char *rule)
{
    char p[128], err[512] = "";
    test_path(p, sizeof(p), name);
    test_spit(p, data, len);
    volume_t v;
    const volume_err_t got = c->raw
                                 ? volume_read_raw(p, c->dims, c->t, c->big, &v, err, sizeof(err))
                                 : volume_read_nrrd(p, &v, err, sizeof(err));
    if (got != want || strstr(err, p) == NULL || strstr(err, where) == NULL ||
        strstr(err, rule) == NULL || strchr(err, '\n') != NULL)
        fail_msg("%s: got %d '%s', want %d with '%s' and '%s'", name, got, err, want, where, rule);
    assert_null(v.value);
}

#define EXPECT_VOL(c, name, text, want, where, rule) \
    expect_vol(c, name, text, strlen(text), want, where, rule)

static void test_volumes(void **state)
{
    (void)state;
    char p[128], err[256];
    /* raw: 2x3x4 big-endian u16 */
    uint8_t raw[48];
    for (int i = 0; i < 24; i++) {
        raw[2 * i] = (uint8_t)(i >> 8);
        raw[2 * i + 1] = (uint8_t)(i * 10);
    }
    test_path(p, sizeof(p), "v.raw");
    test_spit(p, raw, sizeof(raw));
    volume_t v;
    const int32_t dims[3] = {2, 3, 4};
    vol_type_t t;
    assert_true(vol_type_parse("u16", &t));
    assert_false(vol_type_parse("u17", &t));
    assert_int_equal(volume_read_raw(p, dims, t, true, &v, err, sizeof(err)), VOLUME_OK);
    assert_float_equal(v.value[23], 230.0f, 0);
    assert_float_equal(v.spacing_m[1], 1.0f, 0);
    volume_free(&v);
    /* NRRD, attached and detached */
    char hdr[512];
    int n = sprintf(hdr, "NRRD0004\n# made by a test\ntype: unsigned short\ndimension: 3\n"
                         "sizes: 2 3 4\nencoding: raw\nendian: big\nspace: RAS\n"
                         "space directions: (0.5,0,0) (0,0.5,0) (0,0,2)\n"
                         "space origin: (1,2,3)\nkey:=value\n\n");
    memcpy(hdr + n, raw, sizeof(raw));
    test_path(p, sizeof(p), "v.nrrd");
    test_spit(p, hdr, (size_t)n + sizeof(raw));
    assert_int_equal(volume_read_nrrd(p, &v, err, sizeof(err)), VOLUME_OK);
    assert_float_equal(v.value[5], 50.0f, 0);
    assert_float_equal(v.spacing_m[2], 2.0f, 1e-6f);
    assert_float_equal(v.origin_m.z, 3.0f, 0);
    volume_free(&v);
    n = sprintf(hdr, "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n"
                     "endian: big\nspacings: 1 1 1\ndata file: v.raw\n\n");
    test_path(p, sizeof(p), "d.nhdr");
    test_spit(p, hdr, (size_t)n);
    assert_int_equal(volume_read_nrrd(p, &v, err, sizeof(err)), VOLUME_OK);
    assert_float_equal(v.value[1], 10.0f, 0);
    volume_free(&v);
}

/* Every type name of NRRD and of argil's raw options names its type. */
static void test_volume_type_names(void **state)
{
    (void)state;
    static const char *const spellings[VOL_F64 + 1] = {
        [VOL_U8] = "u8|uchar|unsigned char|uint8|uint8_t",
        [VOL_I8] = "i8|signed char|int8|int8_t",
        [VOL_U16] = "u16|ushort|unsigned short|unsigned short int|uint16|uint16_t",
        [VOL_I16] = "i16|short|short int|signed short|signed short int|int16|int16_t",
        [VOL_U32] = "u32|uint|unsigned int|uint32|uint32_t",
        [VOL_I32] = "i32|int|signed int|int32|int32_t",
        [VOL_F32] = "f32|float",
        [VOL_F64] = "f64|double",
    };
    int count = 0;
    for (int want = VOL_U8; want <= VOL_F64; want++) {
        char list[96];
        snprintf(list, sizeof(list), "%s", spellings[want]);
        for (char *name = strtok(list, "|"); name != NULL; name = strtok(NULL, "|"), count++) {
            vol_type_t t = want == VOL_U8 ? VOL_F64 : VOL_U8;
            if (!vol_type_parse(name, &t) || (int)t != want)
                fail_msg("'%s' gave %d, want %d", name, t, want);
        }
    }
    assert_int_equal(count, 36);
    vol_type_t t = VOL_I16;
    assert_false(vol_type_parse("Float", &t));
    assert_false(vol_type_parse("", &t));
    assert_false(vol_type_parse(NULL, &t));
    assert_int_equal(t, VOL_I16);
}

/* A NRRD header line refused at line 2 with a rule's code and words that say why. */
typedef struct { const char *line; volume_err_t want; const char *says; } nrrd_refusal_t;

static const nrrd_refusal_t nrrd_field_refusals[] = {
    {"type float", VOLUME_ERR_FIELD, "expected '<field>: <value>'"},
    {"type: quaternion", VOLUME_ERR_TYPE, "unknown type"},
    {"dimension: 2", VOLUME_ERR_DIMENSION, "dimension must be 3"},
    {"sizes: 2 0 2", VOLUME_ERR_SIZES, "sizes must be three"},
    {"sizes: 2 2 2 2", VOLUME_ERR_SIZES, "sizes must be three"},
    {"sizes: 2 2.5 2", VOLUME_ERR_SIZES, "sizes must be three"},
    {"encoding: gzip", VOLUME_ERR_ENCODING, "'gzip' is not supported"},
    {"endian: middle", VOLUME_ERR_ENDIAN, "endian must be"},
    {"spacings: 1 -1 1", VOLUME_ERR_SPACINGS, "spacings must be"},
    {"space directions: (1,0,0) (0,1,0)", VOLUME_ERR_DIRECTIONS, "space directions must be three"},
    {"space directions: (1,0,0) (0,0,0) (0,0,1)", VOLUME_ERR_DIRECTIONS, "zero length"},
    {"space origin: (1,2)", VOLUME_ERR_ORIGIN, "space origin must"},
    {"data file: ../../etc/passwd", VOLUME_ERR_DATA_FILE, "one plain file name"},
};

/* Each malformed raw file or NRRD header is refused with the code of the rule it broke. */
static void test_volume_rules(void **state)
{
    (void)state;
    uint8_t raw[48] = {0};
    vol_case_t c = {{2, 3, 4}, VOL_U16, true, true};
    expect_vol(&c, "r.raw", raw, 47, VOLUME_ERR_DATA_LENGTH, "byte 0",
               "need 48 data bytes, the file has 47");
    c.t = VOL_F32;
    c.dims[2] = 2;
    uint8_t nanraw[48] = {0};
    nanraw[44] = 0x7f;
    nanraw[45] = 0xc0;
    expect_vol(&c, "r.raw", nanraw, 48, VOLUME_ERR_SAMPLE, "byte 44", "sample 11 is not a finite");
    c.dims[0] = 0;
    expect_vol(&c, "r.raw", raw, 48, VOLUME_ERR_ARG, "dimension 0", "must be 1..2^30");
    c.dims[0] = 65536;
    c.dims[1] = 65536;
    expect_vol(&c, "r.raw", raw, 48, VOLUME_ERR_ARG, "65536 x 65536", "exceed the limit");

    c.raw = false;
    const char *H = "NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\nencoding: raw\nendian: little\n";
    char buf[1024];
    EXPECT_VOL(&c, "e.nrrd", "NRRD0009\n", VOLUME_ERR_MAGIC, "line 1", "not a NRRD file");
    memset(buf, 'a', 400);
    memcpy(buf, "NRRD0004\n", 9);
    expect_vol(&c, "e.nrrd", buf, 400, VOLUME_ERR_LINE_LONG, "line 2", "longer than 255");
    expect_vol(&c, "e.nrrd", "NRRD0004\nty\0pe: float\n", 22, VOLUME_ERR_LINE_NUL, "line 2", "NUL");
    EXPECT_VOL(&c, "e.nrrd", "NRRD0004\ntype: float\n", VOLUME_ERR_HEADER_END, "line 2",
               "does not end with a blank");
    for (size_t i = 0; i < sizeof(nrrd_field_refusals) / sizeof(nrrd_field_refusals[0]); i++) {
        snprintf(buf, sizeof(buf), "NRRD0004\n%s\n\n", nrrd_field_refusals[i].line);
        EXPECT_VOL(&c, "e.nrrd", buf, nrrd_field_refusals[i].want, "line 2",
                   nrrd_field_refusals[i].says);
    }
    EXPECT_VOL(&c, "e.nrrd", "NRRD0004\ntype: float\ndimension: 3\nencoding: raw\n\n",
               VOLUME_ERR_MISSING, "line 5", "lacks the required field 'sizes'");
    EXPECT_VOL(&c, "e.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 1 1 1\n"
               "encoding: raw\n\n", VOLUME_ERR_MISSING, "line 6",
               "lacks 'endian' for a 4-byte type");
    char at[32];
    sprintf(at, "byte %zu", strlen(H) + 1);
    sprintf(buf, "%s\n", H);
    EXPECT_VOL(&c, "e.nrrd", buf, VOLUME_ERR_DATA_LENGTH, at, "need 4 data bytes, the file has 0");
    sprintf(buf, "%s\n\xff\xff\xff\xff", H);
    EXPECT_VOL(&c, "e.nrrd", buf, VOLUME_ERR_SAMPLE, at, "sample 0 is not a finite");
    EXPECT_VOL(&c, "e.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 1073741824 1073741824 "
               "1073741824\nencoding: raw\nendian: little\n\n", VOLUME_ERR_SAMPLES_MAX, "line 4",
               "more than 2^30 samples");
    sprintf(buf, "%sdata file: nothere.raw\n\n", H);
    EXPECT_VOL(&c, "e.nrrd", buf, VOLUME_ERR_IO, "nothere.raw", "cannot open");
    /* a detached data file's own rule comes back through the header's reader */
    char p[128];
    test_path(p, sizeof(p), "short.raw");
    test_spit(p, "\0\0\0", 3);
    sprintf(buf, "%sdata file: short.raw\n\n", H);
    EXPECT_VOL(&c, "e.nrrd", buf, VOLUME_ERR_DATA_LENGTH, "data file: ", "the file has 3");
}

/* Failures outside the file's rules: arguments, the file system, a file over the size limit;
 * and each code's argil_err_t. */
static void test_volume_failures(void **state)
{
    (void)state;
    char p[128], err[256] = "";
    volume_t v;
    const int32_t dims[3] = {1, 1, 1};
    assert_int_equal(volume_read_nrrd(NULL, &v, err, sizeof(err)), VOLUME_ERR_ARG);
    assert_string_equal(err, "volume_read_nrrd: missing argument");
    assert_int_equal(volume_read_raw(NULL, dims, VOL_U8, false, &v, err, sizeof(err)),
                     VOLUME_ERR_ARG);
    assert_string_equal(err, "volume_read_raw: missing argument");
    test_path(p, sizeof(p), "");
    assert_int_equal(volume_read_nrrd(p, &v, err, sizeof(err)), VOLUME_ERR_IO);
    assert_non_null(strstr(err, "not a regular file"));
    /* a sparse file one byte over the limit: refused before any byte is read */
    test_path(p, sizeof(p), "huge.raw");
    test_spit(p, "", 0);
    assert_int_equal(truncate(p, (off_t)IO_FILE_MAX_BYTES + 1), 0);
    assert_int_equal(volume_read_raw(p, dims, VOL_U8, false, &v, err, sizeof(err)),
                     VOLUME_ERR_FILE_SIZE);
    assert_non_null(strstr(err, "more than the 4294967296 this reader takes"));
    assert_null(v.value);
    assert_int_equal(unlink(p), 0);

    assert_int_equal(volume_err_argil(VOLUME_OK), ARGIL_OK);
    assert_int_equal(volume_err_argil(VOLUME_ERR_ARG), ARGIL_ERR_ARG);
    assert_int_equal(volume_err_argil(VOLUME_ERR_IO), ARGIL_ERR_IO);
    assert_int_equal(volume_err_argil(VOLUME_ERR_NOMEM), ARGIL_ERR_NOMEM);
    for (int e = VOLUME_ERR_FILE_SIZE; e >= VOLUME_ERR_MISSING; e--)
        assert_int_equal(volume_err_argil((volume_err_t)e), ARGIL_ERR_PARSE);
}

/* The import readers' failures outside the file, and the argil_err_t a command reports for each. */
static void test_import_failures(void **state)
{
    (void)state;
    char p[128], err[256] = "";
    mesh_t m;
    mesh_init(&m);
    assert_int_equal(ply_load(NULL, &m, NULL, err, sizeof(err)), IMPORT_ERR_ARG);
    assert_string_equal(err, "ply_load: no path or no mesh");
    assert_int_equal(stl_read("a.stl", NULL, err, sizeof(err)), IMPORT_ERR_ARG);
    assert_string_equal(err, "stl_read: no path or no mesh");
    assert_int_equal(obj_read(NULL, &m, NULL, err, sizeof(err)), IMPORT_ERR_ARG);
    assert_string_equal(err, "obj_read: no path or no mesh");
    assert_int_equal(xyz_read(NULL, &m, NULL, err, sizeof(err)), IMPORT_ERR_ARG);
    assert_string_equal(err, "xyz_read: no path or no mesh");
    /* a sparse file one byte over the limit: refused before any byte is read */
    test_path(p, sizeof(p), "huge.xyz");
    test_spit(p, "", 0);
    assert_int_equal(truncate(p, (off_t)IO_FILE_MAX_BYTES + 1), 0);
    assert_int_equal(mesh_import(p, &m, NULL, err, sizeof(err)), IMPORT_ERR_FILE_SIZE);
    assert_non_null(strstr(err, "more than the 4294967296 this reader takes"));
    assert_int_equal(unlink(p), 0);
    mesh_free(&m);

    const argil_err_t got[] = {import_err_argil(IMPORT_OK), import_err_argil(IMPORT_ERR_ARG),
                               import_err_argil(IMPORT_ERR_IO), import_err_argil(IMPORT_ERR_NOMEM)};
    const argil_err_t want[] = {ARGIL_OK, ARGIL_ERR_ARG, ARGIL_ERR_IO, ARGIL_ERR_NOMEM};
    assert_memory_equal(got, want, sizeof(want));
    for (int e = IMPORT_ERR_FILE_SIZE; e >= IMPORT_ERR_XYZ_EMPTY; e--) /* every rule of a file */
        assert_int_equal(import_err_argil((import_err_t)e), ARGIL_ERR_PARSE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trips),   cmocka_unit_test(test_ply_errors),
        cmocka_unit_test(test_stl_errors),    cmocka_unit_test(test_obj_xyz_errors),
        cmocka_unit_test(test_import_failures),
        cmocka_unit_test(test_volumes),       cmocka_unit_test(test_volume_type_names),
        cmocka_unit_test(test_volume_rules),  cmocka_unit_test(test_volume_failures),
    };
    return cmocka_run_group_tests(tests, setup_dir, test_dir_teardown);
}
