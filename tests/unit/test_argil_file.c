/* The .argil session file: round trip of every part, atomic replacement, any flipped bit or cut
 * refused, and one crafted file per rule the reader enforces (each error names file + byte). */
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

#include "host/io/argil_file.h"
#include "host/io/io_util.h"
#include "shared/crc32c.h"
#include "shared/wire.h"

#include "tests/unit/test_files.h"
#include "tests/unit/grid_view.h"

#define E(rule) ARGIL_FILE_ERR_##rule /* the code of a rule, in the tables of crafted files */

static int setup_dir(void **state)
{
    (void)state;
    return test_dir_make("argil_test_argil");
}

static void make_doc(argil_doc_t *d, bool extras)
{
    argil_doc_init(d);
    const int32_t dims[3] = {6, 5, 4};
    assert_int_equal(grid_init(&d->grid, dims, 0.002f, vec3(-0.005f, -0.004f, -0.003f)), ARGIL_OK);
    grid_fill_sphere(&d->grid, vec3(0, 0, 0), 0.004f);
    d->grid.iso = 0.4f;
    d->grid.material.stiffness = 123.0f;
    d->tool.tool_kind = 3;
    d->tool.radius_m = 0.007f;
    d->tool.paint_rgb[1] = 99;
    d->state.device_scale = 2.5f;
    d->state.device_offset_m = vec3(0.1f, 0.2f, 0.3f);
    d->state.edits = 42;
    if (extras) {
        d->rgb = malloc(3 * 120);
        assert_non_null(d->rgb);
        for (int i = 0; i < 360; i++)
            d->rgb[i] = (uint8_t)i;
        assert_int_equal(rbf_alloc(&d->rbf, 3), ARGIL_OK);
        d->has_rbf = true;
        for (int i = 0; i < 9; i++)
            d->rbf.centre_m[i] = (float)i * 0.001f;
        d->rbf.weight[2] = -5.0f;
        d->rbf.poly[3] = 0.25f;
        d->rbf.rms_err_m = 1e-4f;
    }
}

static void test_round_trip(void **state)
{
    (void)state;
    char p[128], err[256];
    snprintf(p, sizeof(p), "%s/a.argil", g_test_dir);
    for (int extras = 0; extras < 2; extras++) {
        argil_doc_t d, r;
        make_doc(&d, extras);
        assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
        assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
        assert_memory_equal(r.grid.dims, d.grid.dims, sizeof(d.grid.dims));
        assert_true(gv_same(&r.grid, GRID_DENSITY, &d.grid, GRID_DENSITY));
        assert_true(gv_same(&r.grid, GRID_REST, &d.grid, GRID_DENSITY));
        assert_float_equal(r.grid.iso, 0.4f, 0);
        assert_float_equal(r.grid.spacing_m, 0.002f, 0);
        assert_float_equal(r.grid.origin_m.y, -0.004f, 0);
        assert_float_equal(r.grid.band_m, d.grid.band_m, 0);
        assert_float_equal(r.grid.material.stiffness, 123.0f, 0);
        assert_int_equal(r.tool.tool_kind, 3);
        assert_float_equal(r.tool.radius_m, 0.007f, 0);
        assert_int_equal(r.tool.paint_rgb[1], 99);
        assert_float_equal(r.state.device_scale, 2.5f, 0);
        assert_float_equal(r.state.device_offset_m.z, 0.3f, 0);
        assert_int_equal(r.state.edits, 42);
        assert_int_equal(r.has_rbf, extras);
        if (extras) {
            assert_memory_equal(r.rgb, d.rgb, 360);
            assert_int_equal(r.rbf.n, 3);
            assert_float_equal(r.rbf.weight[2], -5.0f, 0);
            assert_float_equal(r.rbf.centre_m[8], 0.008f, 0);
            assert_float_equal(r.rbf.poly[3], 0.25f, 0);
            assert_float_equal(r.rbf.rms_err_m, 1e-4f, 0);
        } else {
            assert_null(r.rgb);
        }
        argil_doc_free(&r);
        argil_doc_free(&d);
    }
}

/* A crash mid-save leaves path.tmp behind, never a damaged path; a failed save keeps the old. */
static void test_atomic(void **state)
{
    (void)state;
    char p[128], tmp[160], err[256];
    snprintf(p, sizeof(p), "%s/keep.argil", g_test_dir);
    snprintf(tmp, sizeof(tmp), "%s.tmp", p);
    argil_doc_t d, r;
    make_doc(&d, true);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    size_t len0;
    uint8_t *before = test_slurp(p, &len0);
    /* a half-written temp file from a crash: the saved file still reads */
    test_spit(tmp, before, len0 / 2);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    argil_doc_free(&r);
    /* a save that fails (NaN in the model) leaves the file byte for byte as it was */
    gv_set(&d.grid, GRID_DENSITY, 7, NAN);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_ERR_NONFINITE);
    assert_non_null(strstr(err, "NaN or Inf"));
    /* a save whose temp file cannot be created (it is a directory) fails with IO */
    gv_set(&d.grid, GRID_DENSITY, 7, 0.5f);
    unlink(tmp);
    assert_int_equal(mkdir(tmp, 0700), 0);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "fopen"));
    rmdir(tmp);
    size_t len1;
    uint8_t *after = test_slurp(p, &len1);
    assert_int_equal(len0, len1);
    assert_memory_equal(before, after, len0);
    /* and a successful save replaces it whole, leaving no temp file */
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(access(tmp, F_OK), -1);
    free(before);
    free(after);
    argil_doc_free(&d);
    /* writing the seed for the fuzzer's corpus is not this test's business; an empty doc: */
    argil_doc_init(&d);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_ERR_ARG);
}

/* Every single-bit flip and every truncation of a saved file is refused with a clear error. */
static void test_any_corruption_refused(void **state)
{
    (void)state;
    char p[128], q[160], err[256];
    snprintf(p, sizeof(p), "%s/c.argil", g_test_dir);
    snprintf(q, sizeof(q), "%s/bad.argil", g_test_dir);
    argil_doc_t d, r;
    make_doc(&d, true);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    argil_doc_free(&d);
    size_t len;
    uint8_t *b = test_slurp(p, &len);
    for (size_t i = 0; i < len; i += 3) {
        b[i] ^= (uint8_t)(1u << (i % 8));
        test_spit(q, b, len);
        const argil_file_err_t e = argil_file_read(q, &r, err, sizeof(err));
        if (e >= ARGIL_FILE_ERR_FILE_SIZE || argil_file_err_argil(e) != ARGIL_ERR_PARSE ||
            strstr(err, q) == NULL || strstr(err, "byte ") == NULL)
            fail_msg("flip at byte %zu: %d '%s'", i, e, err);
        assert_int_equal(grid_count(&r.grid), 0);
        b[i] ^= (uint8_t)(1u << (i % 8));
    }
    for (size_t cut = 0; cut < len; cut += 17) {
        test_spit(q, b, cut);
        assert_int_equal(argil_file_err_argil(argil_file_read(q, &r, err, sizeof(err))),
                         ARGIL_ERR_PARSE);
    }
    free(b);
}

/* Builds a file from sections with correct checksums (so the deeper rules are reached). */
typedef struct {
    uint8_t b[4096];
    size_t len;
    uint32_t n_sec;
} build_t;

static void b_begin(build_t *f)
{
    memset(f, 0, sizeof(*f));
    f->len = 32;
}

static void b_sec(build_t *f, const char *tag, const void *payload, size_t n)
{
    uint8_t *s = f->b + f->len;
    memcpy(s, tag, 4);
    le_put_u32(s + 4, (uint32_t)n);
    le_put_u32(s + 8, 0);
    memcpy(s + 12, payload, n);
    le_put_u32(s + 12 + n, crc32c(0, s, 12 + n));
    f->len += 16 + n;
    f->n_sec++;
}

static void b_end(build_t *f, const char *path, uint32_t version)
{
    static const uint8_t magic[8] = {'A', 'R', 'G', 'I', 'L', '\r', '\n', 0x1a};
    memcpy(f->b, magic, 8);
    le_put_u32(f->b + 8, version);
    le_put_u32(f->b + 12, f->n_sec);
    le_put_u32(f->b + 16, (uint32_t)(f->len + 4));
    le_put_u32(f->b + 20, 0);
    le_put_u32(f->b + 24, 0);
    le_put_u32(f->b + 28, crc32c(0, f->b, 28));
    le_put_u32(f->b + f->len, crc32c(0, f->b, f->len));
    test_spit(path, f->b, f->len + 4);
}

/* A 1x1x2 GRID payload with the given density and spacing. */
static size_t grid_payload(uint8_t *p, int32_t nx, float spacing, float density)
{
    le_put_u32(p, (uint32_t)nx);
    le_put_u32(p + 4, 1);
    le_put_u32(p + 8, 2);
    const float f[6] = {spacing, 0, 0, 0, 0.5f, 0.004f};
    for (int k = 0; k < 6; k++)
        le_put_f32(p + 12 + 4 * k, f[k]);
    const size_t n = nx > 0 ? 2u * (size_t)nx : 0;
    for (size_t i = 0; i < n && i < 64; i++)
        le_put_f32(p + 36 + 4 * i, density);
    return 36 + 4 * (n < 64 ? n : 64);
}

/* Reading path is refused with code, err naming the path, where and rule, and no model left. */
static void expect_rule(const char *path, argil_file_err_t code, const char *where,
                        const char *rule)
{
    argil_doc_t r;
    char err[512] = "";
    const argil_file_err_t e = argil_file_read(path, &r, err, sizeof(err));
    if (e != code || argil_file_err_argil(e) != ARGIL_ERR_PARSE || strstr(err, path) == NULL ||
        strstr(err, where) == NULL || strstr(err, rule) == NULL)
        fail_msg("got %d '%s', want %d '%s' and '%s'", e, err, code, where, rule);
    assert_int_equal(grid_count(&r.grid), 0);
}

static void test_each_rule(void **state)
{
    (void)state;
    char p[128];
    snprintf(p, sizeof(p), "%s/r.argil", g_test_dir);
    build_t f;
    uint8_t g[512], x[64] = {0};
    const size_t gl = grid_payload(g, 1, 0.001f, 0.5f);

    test_spit(p, "ARGIL", 5);
    expect_rule(p, ARGIL_FILE_ERR_SHORT, "byte 5", "shorter than the 32-byte header");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    b_end(&f, p, 1);
    argil_doc_t ok;
    char err[256];
    assert_int_equal(argil_file_read(p, &ok, err, sizeof(err)), ARGIL_OK); /* builder is right */
    assert_float_equal(gv_get(&ok.grid, GRID_DENSITY, 1), 0.5f, 0);
    argil_doc_free(&ok);
    f.b[0] = 'X';
    test_spit(p, f.b, f.len + 4);
    expect_rule(p, ARGIL_FILE_ERR_MAGIC, "byte 0", "not an .argil file");
    b_end(&f, p, 1);
    f.b[20] = 1;
    test_spit(p, f.b, f.len + 4);
    expect_rule(p, ARGIL_FILE_ERR_HEADER_CRC, "byte 28", "header checksum mismatch");
    b_end(&f, p, 3);
    expect_rule(p, ARGIL_FILE_ERR_VERSION, "byte 8", "format version 3; this argil reads 1..2");
    f.n_sec = 0;
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_SECTION_COUNT, "byte 12", "section count not in 1..64");
    f.n_sec = 1;
    b_end(&f, p, 1);
    f.b[f.len + 4] = 0; /* one byte more than declared */
    test_spit(p, f.b, f.len + 5);
    expect_rule(p, ARGIL_FILE_ERR_FILE_LENGTH, "byte 16", "declared file length differs");
    b_end(&f, p, 1);
    f.b[40] ^= 1; /* inside the GRID payload: the file checksum catches it first */
    test_spit(p, f.b, f.len + 4);
    char at[32];
    snprintf(at, sizeof(at), "byte %zu", f.len);
    expect_rule(p, ARGIL_FILE_ERR_FILE_CRC, at, "file checksum mismatch");
    /* deeper rules need consistent outer checksums: */
    f.b[40] ^= 1;
    f.n_sec = 2;
    b_end(&f, p, 1);
    snprintf(at, sizeof(at), "byte %zu", f.len);
    expect_rule(p, ARGIL_FILE_ERR_SECTION_HEAD, at, "section head runs past the end");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    le_put_u32(f.b + 36, 100000); /* length beyond the file, crc not even reached */
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_SECTION_LENGTH, "byte 36", "section length runs past the end");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    f.b[32 + 12 + 20] ^= 4;
    b_end(&f, p, 1);
    snprintf(at, sizeof(at), "byte %zu", 32 + 12 + gl);
    expect_rule(p, ARGIL_FILE_ERR_SECTION_CRC, at, "section checksum mismatch");
    const struct {
        const char *tag;
        const void *payload;
        size_t n;
        const char *where, *rule;
        argil_file_err_t code;
    } cases[] = {
        {"GRID", g, 20, "byte 44", "shorter than its 36-byte head", E(GRID_HEAD)},
        {"MATL", x, 19, "byte 32", "MATL section repeated or not 20 bytes", E(MATL_SIZE)},
        {"MATL", x, 20, "byte 44", "MATL values out of range", E(MATL_VALUE)},
        {"TOOL", x, 15, "byte 32", "TOOL section repeated or not 16 bytes", E(TOOL_SIZE)},
        {"STAT", x, 20, "byte 44", "STAT transform not finite (or scale not > 0)", E(STAT_VALUE)},
        {"STAT", x, 21, "byte 32", "STAT section repeated or not 20 bytes", E(STAT_SIZE)},
        {"RBF3", x, 27, "byte 32", "RBF3 section repeated or shorter than 28", E(RBF3_HEAD)},
        {"RBF3", x, 44, "byte 44", "RBF3 centre count out of range", E(RBF3_COUNT)},
        {"XTRA", x, 8, "byte 32", "no GRID section", E(GRID_MISSING)},
    };
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        b_begin(&f);
        b_sec(&f, cases[k].tag, cases[k].payload, cases[k].n);
        b_end(&f, p, 1);
        expect_rule(p, cases[k].code, cases[k].where, cases[k].rule);
    }
    /* values inside sections */
    uint8_t t[64] = {0};
    le_put_f32(t + 4, -1.0f);
    b_begin(&f);
    b_sec(&f, "TOOL", t, 16);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_TOOL_VALUE, "byte 48", "TOOL radius or strength out of range");
    memset(t, 0, sizeof(t));
    le_put_u32(t, 1);
    le_put_f32(t + 8, NAN);
    b_begin(&f);
    b_sec(&f, "RBF3", t, 44);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_RBF3_VALUE, "byte 44", "RBF3 holds NaN or Inf");
    uint8_t g2[512];
    size_t g2l = grid_payload(g2, 0, 0.001f, 0.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g2, g2l);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_DIM, "byte 44", "GRID dimension below 1");
    g2l = grid_payload(g2, 1, 0.001f, 0.5f);
    le_put_u32(g2 + 4, 1u << 20);
    le_put_u32(g2 + 8, 1u << 20);
    b_begin(&f);
    b_sec(&f, "GRID", g2, g2l);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_SAMPLES_MAX, "byte 52", "more than 2^30 samples");
    g2l = grid_payload(g2, 2, 0.001f, 0.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g2, g2l - 4);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_LENGTH, "byte 44",
                "GRID section length does not match its dimensions");
    g2l = grid_payload(g2, 1, -0.001f, 0.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g2, g2l);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_GEOMETRY, "byte 56", "GRID spacing, origin, iso or band");
    g2l = grid_payload(g2, 1, 0.001f, 1.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g2, g2l);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_DENSITY, "byte 80",
                "GRID density not a finite number in [0, 1]");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    b_sec(&f, "GRID", g, gl);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_GRID_REPEATED, "byte 92", "second GRID section");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    b_sec(&f, "COLR", x, 5);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_COLR_LENGTH, "byte 104",
                "COLR section is not 3 bytes per GRID sample");
    b_begin(&f);
    b_sec(&f, "COLR", x, 6);
    b_sec(&f, "COLR", x, 6);
    b_sec(&f, "GRID", g, gl);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_COLR_REPEATED, "byte 54", "second COLR section");
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    f.len += 4; /* 4 stray bytes before the file checksum */
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_TRAILING, "byte 92",
                "bytes between the last section and the file checksum");
    /* an unknown section with a good checksum is skipped; order does not matter */
    uint8_t m[20];
    const float mf[5] = {2.0f, 1.0f, 1.0f, 1.0f, 0.0f};
    for (int k = 0; k < 5; k++)
        le_put_f32(m + 4 * k, mf[k]);
    b_begin(&f);
    b_sec(&f, "MATL", m, 20);
    b_sec(&f, "XTRA", x, 8);
    b_sec(&f, "GRID", g, gl);
    b_end(&f, p, 1);
    assert_int_equal(argil_file_read(p, &ok, err, sizeof(err)), ARGIL_OK);
    assert_float_equal(ok.grid.material.node_mass, 2.0f, 0);
    argil_doc_free(&ok);
    test_spit(p, "", 0);
    expect_rule(p, ARGIL_FILE_ERR_SHORT, "byte 0", "shorter than the 32-byte header");
}

/* The OCTB section (octree B-spline fit): round trip to the same function, and each rule. */
static size_t octb_payload(uint8_t *p, uint32_t n, uint32_t per_axis, uint32_t kind, float size,
                           const uint32_t *links, float coef)
{
    le_put_u32(p, n);
    le_put_u32(p + 4, per_axis);
    le_put_u32(p + 8, kind);
    const float f[7] = {0, 0, 0, size, 1e-4f, 2e-4f, 0.25f};
    for (int k = 0; k < 7; k++)
        le_put_f32(p + 12 + 4 * k, f[k]);
    for (uint32_t i = 0; i < n; i++)
        le_put_u32(p + 40 + 4 * i, links[i]);
    size_t len = 40 + 4 * (size_t)n;
    /* One block of coefficients per leaf (a link of 0), at least one. */
    uint32_t leaves = 0;
    for (uint32_t i = 0; i < n; i++)
        leaves += links[i] == 0;
    if (leaves == 0)
        leaves = 1;
    for (uint32_t i = 0; i < leaves * OCTFIT_NCOEF; i++, len += 4)
        le_put_f32(p + len, coef);
    return len;
}

static void test_octb(void **state)
{
    (void)state;
    char p[128], err[256];
    snprintf(p, sizeof(p), "%s/o.argil", g_test_dir);
    argil_doc_t d, r;
    make_doc(&d, false);
    uint32_t links[9] = {1, 0, 0, 0, 0, 0, 0, 0, 0};
    const float org[3] = {-0.01f, -0.01f, -0.01f};
    assert_int_equal(octfit_alloc(&d.octree, 9, links, org, 0.02f), ARGIL_OK);
    d.has_octree = true;
    for (uint32_t l = 0; l < 8; l++)
        for (uint32_t c = 0; c < OCTFIT_NCOEF; c++)
            d.octree.leaf[l].coef[c] = 0.001f * (float)l - 0.00001f * (float)c;
    d.octree.rms_err = 3e-5f;
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    assert_true(r.has_octree);
    assert_int_equal(r.octree.n_nodes, 9);
    assert_int_equal(r.octree.n_leaves, 8);
    assert_float_equal(r.octree.rms_err, 3e-5f, 0);
    for (int k = 0; k < 50; k++) {
        const vec3_t q = vec3(0.0004f * (float)k - 0.01f, 0.003f, -0.0002f * (float)k);
        assert_float_equal(octfit_eval(&r.octree, q), octfit_eval(&d.octree, q), 0);
    }
    argil_doc_free(&r);
    argil_doc_free(&d);

    build_t f;
    uint8_t g[512], o[2400];
    const size_t gl = grid_payload(g, 1, 0.001f, 0.5f);
    const uint32_t leaf[2] = {0, 0};
    const struct {
        uint32_t n, per_axis, kind;
        float size, coef;
        size_t cut;
        const char *where, *rule;
        argil_file_err_t code;
    } bad[] = {
        {1, 6, 0, 0.02f, 0.0f, 900, "byte 92", "OCTB section repeated or shorter", E(OCTB_HEAD)},
        {0, 6, 0, 0.02f, 0.0f, 0, "byte 104", "OCTB node count not in 1..65537", E(OCTB_NODES)},
        {1, 5, 0, 0.02f, 0.0f, 0, "byte 108", "OCTB coefficients per axis not 6", E(OCTB_PER_AXIS)},
        {1, 6, 2, 0.02f, 0.0f, 0, "byte 112", "OCTB kind not 0", E(OCTB_KIND)},
        {1, 6, 0, 0.0f, 0.0f, 0, "byte 116", "OCTB origin, size, errors or overlap",
         E(OCTB_GEOMETRY)},
        {2, 6, 0, 0.02f, 0.0f, 0, "byte 144", "OCTB child links do not form an octree",
         E(OCTB_LINKS)},
        {1, 6, 0, 0.02f, 0.0f, 4, "byte 104", "OCTB section length does not match", E(OCTB_LENGTH)},
        {1, 6, 0, 0.02f, NAN, 0, "byte 148", "OCTB coefficient NaN or Inf", E(OCTB_COEF)},
    };
    for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
        size_t ol = octb_payload(o, bad[k].n, bad[k].per_axis, bad[k].kind, bad[k].size, leaf,
                                 bad[k].coef);
        if (bad[k].cut == 900)
            ol = 36;
        else
            ol -= bad[k].cut;
        b_begin(&f);
        b_sec(&f, "GRID", g, gl);
        b_sec(&f, "OCTB", o, ol);
        b_end(&f, p, 1);
        expect_rule(p, bad[k].code, bad[k].where, bad[k].rule);
    }
    const size_t ol = octb_payload(o, 1, 6, 0, 0.02f, leaf, 0.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    b_sec(&f, "OCTB", o, ol);
    b_end(&f, p, 1);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    assert_float_equal(octfit_eval(&r.octree, vec3(0.01f, 0.01f, 0.01f)), 0.5f, 1e-5f);
    argil_doc_free(&r);
    b_sec(&f, "OCTB", o, ol);
    b_end(&f, p, 1);
    expect_rule(p, ARGIL_FILE_ERR_OCTB_HEAD, "byte 1016", "OCTB section repeated");
}


/* Paints channels of d's 6x5x4 grid: stiffness 4x and mass 0.5x on a few samples with a gap
 * (bridged into one run) and a far one (a second run), a subnormal, a rest-length -0 (a value
 * whose bits differ from the default 0, so it must be stored). */
static void paint_doc(argil_doc_t *d)
{
    grid_t *g = &d->grid;
    gv_mat_set(g, GRID_MAT_STIFFNESS, 10, 4.0f);
    gv_mat_set(g, GRID_MAT_STIFFNESS, 11, 2.5f);
    gv_mat_set(g, GRID_MAT_STIFFNESS, 13, 1.0000001f); /* gap of 1 at 12: bridged */
    gv_mat_set(g, GRID_MAT_STIFFNESS, 119, 4.0f);      /* far: a second run */
    gv_mat_set(g, GRID_MAT_MASS, 0, 0.5f);
    gv_mat_set(g, GRID_MAT_MASS, 1, 1e-40f); /* subnormal, still > 0 */
    gv_mat_set(g, GRID_MAT_RESTLEN, 50, -0.0f);
    gv_mat_set(g, GRID_MAT_DAMPING, 0, 1.0f); /* present, all default */
    assert_true(grid_mat_painted(g, GRID_MAT_STIFFNESS) && grid_mat_painted(g, GRID_MAT_MASS) &&
                grid_mat_painted(g, GRID_MAT_RESTLEN) && grid_mat_painted(g, GRID_MAT_DAMPING));
}

/* Painted channels come back bit for bit; the file is version 2 and grows only by the painted
 * runs; an unpainted model stays a version-1 file of the old size. */
static void test_painted_round_trip(void **state)
{
    (void)state;
    char p[128], q[128], err[256];
    snprintf(p, sizeof(p), "%s/plain.argil", g_test_dir);
    snprintf(q, sizeof(q), "%s/painted.argil", g_test_dir);
    argil_doc_t d, r;
    make_doc(&d, false);
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    paint_doc(&d);
    assert_int_equal(argil_file_write(q, &d, err, sizeof(err)), ARGIL_OK);
    size_t lp, lq;
    uint8_t *bp = test_slurp(p, &lp), *bq = test_slurp(q, &lq);
    assert_int_equal(le_get_u32(bp + 8), 1);
    assert_int_equal(le_get_u32(bq + 8), 2);
    /* MTLS = 16 overhead + 4 count + stiffness (8 + 2 runs: 8+4*4, 8+4) + mass (8 + 8+2*4) +
     * rest length (8 + 8+4); damping holds no painted value and is left out. */
    assert_int_equal(lq - lp, 16 + 4 + (8 + 24 + 12) + (8 + 16) + (8 + 12));
    free(bp);
    free(bq);
    assert_int_equal(argil_file_read(q, &r, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(r.file_version, 2);
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        assert_true(grid_mat_equal(&r.grid, &d.grid, (grid_mat_t)ch));
    assert_true(grid_mat_painted(&r.grid, GRID_MAT_STIFFNESS));
    assert_false(grid_mat_painted(&r.grid, GRID_MAT_DAMPING));
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_STIFFNESS, 10), 4.0f, 0);
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_STIFFNESS, 12), 1.0f, 0); /* bridged, unpainted */
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_MASS, 0), 0.5f, 0);
    assert_true(signbit(gv_mat(&r.grid, GRID_MAT_RESTLEN, 50)));
    assert_true(gv_same(&r.grid, GRID_DENSITY, &d.grid, GRID_DENSITY));
    argil_doc_free(&r);
    /* A changed painted value is not the same model. */
    gv_mat_set(&d.grid, GRID_MAT_MASS, 0, 0.25f);
    assert_int_equal(argil_file_read(q, &r, err, sizeof(err)), ARGIL_OK);
    assert_false(grid_mat_equal(&r.grid, &d.grid, GRID_MAT_MASS));
    argil_doc_free(&r);
    /* Out-of-range paint is refused at write time, naming the channel and sample. */
    gv_mat_set(&d.grid, GRID_MAT_MASS, 3, 0.0f);
    assert_int_equal(argil_file_write(q, &d, err, sizeof(err)), ARGIL_ERR_NONFINITE);
    assert_non_null(strstr(err, "channel 1 holds 0 at sample 3"));
    gv_mat_set(&d.grid, GRID_MAT_MASS, 3, 1.0f);
    /* Every cut of a painted file is a clear refusal. */
    bq = test_slurp(q, &lq);
    for (size_t cut = 0; cut < lq; cut += 7) {
        test_spit(p, bq, cut);
        assert_true(argil_file_read(p, &r, err, sizeof(err)) < ARGIL_FILE_ERR_FILE_SIZE);
        assert_non_null(strstr(err, p));
        assert_int_equal(grid_count(&r.grid), 0);
    }
    free(bq);
    argil_doc_free(&d);
}

/* A file the version-1 writer made (before painted material existed) still loads, and an
 * unpainted model is still written as exactly those bytes. */
static const uint8_t V1_FILE[] = {
  0x41, 0x52, 0x47, 0x49, 0x4c, 0x0d, 0x0a, 0x1a, 0x01, 0x00, 0x00, 0x00,
  0x04, 0x00, 0x00, 0x00, 0xd8, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0xad, 0xd1, 0xea, 0xb9, 0x47, 0x52, 0x49, 0x44,
  0x3c, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00,
  0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x6f, 0x12, 0x83, 0x3a,
  0x6f, 0x12, 0x83, 0xba, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x3f, 0x6f, 0x12, 0x83, 0x3b, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x3e, 0x00, 0x00, 0x80, 0x3e, 0x00, 0x00, 0xc0, 0x3e,
  0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x20, 0x3f, 0x3b, 0xcf, 0x70, 0xdb,
  0x4d, 0x41, 0x54, 0x4c, 0x14, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0xe0, 0x40, 0x00, 0x00, 0x80, 0x40,
  0x00, 0x00, 0x20, 0x42, 0x00, 0x00, 0xa0, 0x41, 0xd5, 0xe7, 0xed, 0xb5,
  0x54, 0x4f, 0x4f, 0x4c, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x0a, 0xd7, 0xa3, 0x3b, 0x00, 0x00, 0x00, 0x3f,
  0xc8, 0x50, 0x28, 0x00, 0x26, 0xf2, 0x88, 0xa2, 0x53, 0x54, 0x41, 0x54,
  0x14, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f,
  0x05, 0x00, 0x00, 0x00, 0x1a, 0x8f, 0xcd, 0x69, 0x07, 0x92, 0x98, 0x2f
};

static void test_old_version_loads(void **state)
{
    (void)state;
    char p[128], q[128], err[256];
    snprintf(p, sizeof(p), "%s/v1.argil", g_test_dir);
    snprintf(q, sizeof(q), "%s/v1-again.argil", g_test_dir);
    test_spit(p, V1_FILE, sizeof(V1_FILE));
    argil_doc_t r;
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(r.file_version, 1);
    assert_int_equal(r.grid.dims[0], 3);
    assert_int_equal(r.grid.dims[1], 2);
    assert_float_equal(gv_get(&r.grid, GRID_DENSITY, 5), 0.625f, 0);
    assert_float_equal(r.grid.material.stiffness, 7.0f, 0);
    assert_int_equal(r.state.edits, 5);
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        assert_false(grid_mat_painted(&r.grid, ch));
    assert_int_equal(argil_file_write(q, &r, err, sizeof(err)), ARGIL_OK);
    size_t len;
    uint8_t *b = test_slurp(q, &len);
    assert_int_equal(len, sizeof(V1_FILE));
    assert_memory_equal(b, V1_FILE, len);
    free(b);
    argil_doc_free(&r);
}

/* One crafted MTLS section per rule (GRID of 1x1x2 samples). */
static void mtls_case(const char *path, uint32_t version, const uint8_t *m, size_t ml, int copies)
{
    build_t f;
    uint8_t g[512];
    const size_t gl = grid_payload(g, 1, 0.001f, 0.5f);
    b_begin(&f);
    b_sec(&f, "GRID", g, gl);
    for (int i = 0; i < copies; i++)
        b_sec(&f, "MTLS", m, ml);
    b_end(&f, path, version);
}

static size_t mtls_one(uint8_t *m, uint32_t k, uint32_t ch, uint32_t runs, uint32_t start,
                       uint32_t count, float v)
{
    le_put_u32(m, k);
    le_put_u32(m + 4, ch);
    le_put_u32(m + 8, runs);
    le_put_u32(m + 12, start);
    le_put_u32(m + 16, count);
    le_put_f32(m + 20, v);
    return 24;
}

static void test_mtls_rules(void **state)
{
    (void)state;
    char p[128], err[256];
    snprintf(p, sizeof(p), "%s/m.argil", g_test_dir);
    uint8_t m[64];
    size_t ml = mtls_one(m, 1, GRID_MAT_STIFFNESS, 1, 1, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    argil_doc_t r;
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK); /* builder is right */
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_STIFFNESS, 0), 1.0f, 0);
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_STIFFNESS, 1), 4.0f, 0);
    argil_doc_free(&r);
    /* Damping (2) then rest length (3): two channels, increasing ids. */
    uint8_t two[64];
    le_put_u32(two, 2);
    mtls_one(two, 2, GRID_MAT_DAMPING, 1, 0, 1, 0.0f); /* overwrites the count: fix below */
    le_put_u32(two, 2);
    memcpy(two + 24, two + 4, 20);
    le_put_u32(two + 24, GRID_MAT_RESTLEN);
    le_put_f32(two + 40, -0.25f);
    mtls_case(p, 2, two, 44, 1);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_DAMPING, 0), 0.0f, 0);
    assert_float_equal(gv_mat(&r.grid, GRID_MAT_RESTLEN, 0), -0.25f, 0);
    argil_doc_free(&r);
    le_put_u32(two + 24, GRID_MAT_DAMPING);
    mtls_case(p, 2, two, 44, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_CHANNEL, "byte 128", "MTLS channel id not 0..3");

    mtls_case(p, 1, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_VERSION, "byte 92",
                "MTLS section (painted material) in a version-1 file");
    mtls_case(p, 2, m, ml, 2);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_REPEATED, "byte 132", "second MTLS section");
    mtls_case(p, 2, m, 2, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_COUNT, "byte 104", "shorter than its 4-byte channel count");
    mtls_case(p, 2, m, 4, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_CHANNEL, "byte 108",
                "MTLS channel head runs past the section");
    ml = mtls_one(m, 0, 0, 1, 1, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_COUNT, "byte 104", "MTLS channel count not in 1..4");
    ml = mtls_one(m, 5, 0, 1, 1, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_COUNT, "byte 104", "MTLS channel count not in 1..4");
    ml = mtls_one(m, 1, 4, 1, 1, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_CHANNEL, "byte 108", "MTLS channel id not 0..3");
    ml = mtls_one(m, 1, 0, 0, 1, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_CHANNEL, "byte 112", "MTLS channel with no runs");
    ml = mtls_one(m, 1, 0, 1, 1, 0, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_RUN, "byte 116",
                "MTLS run empty, overlapping or out of order");
    ml = mtls_one(m, 1, 0, 1, 2, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_RUN, "byte 116", "beyond the grid's samples");
    ml = mtls_one(m, 1, 0, 1, 0, 2, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_RUN, "byte 116", "MTLS run values run past the section");
    ml = mtls_one(m, 1, 0, 2, 0, 1, 4.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_RUN, "byte 128", "MTLS run head runs past the section");
    /* Two runs, the second starting inside the first. */
    ml = mtls_one(m, 1, 0, 2, 0, 2, 4.0f);
    le_put_f32(m + 24, 3.0f);
    le_put_u32(m + 28, 1);
    le_put_u32(m + 32, 1);
    le_put_f32(m + 36, 2.0f);
    mtls_case(p, 2, m, 40, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_RUN, "byte 132", "overlapping or out of order");
    ml = mtls_one(m, 1, GRID_MAT_MASS, 1, 0, 1, 0.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_VALUE, "byte 124", "MTLS value out of range");
    ml = mtls_one(m, 1, GRID_MAT_STIFFNESS, 1, 0, 1, -1.0f);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_VALUE, "byte 124", "MTLS value out of range");
    ml = mtls_one(m, 1, GRID_MAT_RESTLEN, 1, 0, 1, NAN);
    mtls_case(p, 2, m, ml, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_VALUE, "byte 124", "MTLS value out of range");
    ml = mtls_one(m, 1, 0, 1, 0, 1, 4.0f);
    mtls_case(p, 2, m, ml + 3, 1);
    expect_rule(p, ARGIL_FILE_ERR_MTLS_TRAILING, "byte 128", "bytes after the last MTLS channel");
}

/* The paint settings a session chose (TOOL's paint rgb + section PNTS): they come back; a
 * document without them is written as before (no PNTS, 20 bytes less); each PNTS rule. */
static void test_paint_settings(void **state)
{
    (void)state;
    char p[128], q[128], err[256];
    snprintf(p, sizeof(p), "%s/paint.argil", g_test_dir);
    snprintf(q, sizeof(q), "%s/nopaint.argil", g_test_dir);
    argil_doc_t d, r;
    make_doc(&d, false);
    assert_int_equal(argil_file_write(q, &d, err, sizeof(err)), ARGIL_OK);
    d.tool.paint_chosen = true;
    const uint8_t blue[3] = {40, 60, 220};
    memcpy(d.tool.paint_rgb, blue, 3);
    d.tool.soft_paint_per_s = 37.5f;
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(r.file_version, 1); /* an older argil skips PNTS: the model is whole */
    assert_true(r.tool.paint_chosen);
    assert_memory_equal(r.tool.paint_rgb, blue, 3);
    assert_float_equal(r.tool.soft_paint_per_s, 37.5f, 0);
    argil_doc_free(&r);
    assert_int_equal(argil_file_read(q, &r, err, sizeof(err)), ARGIL_OK);
    assert_false(r.tool.paint_chosen);
    argil_doc_free(&r);
    struct stat sp, sq;
    assert_int_equal(stat(p, &sp), 0);
    assert_int_equal(stat(q, &sq), 0);
    assert_int_equal(sp.st_size - sq.st_size, 16 + 4);
    /* the writer refuses a rate the reader would refuse, and keeps the old file */
    d.tool.soft_paint_per_s = 100.5f;
    assert_int_equal(argil_file_write(p, &d, err, sizeof(err)), ARGIL_ERR_NONFINITE);
    assert_non_null(strstr(err, "soft-paint rate"));
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_OK);
    argil_doc_free(&r);
    argil_doc_free(&d);

    uint8_t g[512], v[8];
    const size_t gl = grid_payload(g, 1, 0.001f, 0.5f);
    char where[32];
    const float rates[3] = {-1.0f, 101.0f, NAN};
    for (int k = 0; k < 3; k++) {
        build_t f;
        b_begin(&f);
        b_sec(&f, "GRID", g, gl);
        le_put_f32(v, rates[k]);
        b_sec(&f, "PNTS", v, 4);
        b_end(&f, p, 1);
        snprintf(where, sizeof(where), "byte %zu", 32 + 16 + gl + 12);
        expect_rule(p, ARGIL_FILE_ERR_PNTS_RATE, where,
                    "PNTS soft-paint rate not in 0..100 per second");
    }
    for (int k = 0; k < 2; k++) {
        build_t f;
        b_begin(&f);
        b_sec(&f, "GRID", g, gl);
        le_put_f32(v, 5.0f);
        b_sec(&f, "PNTS", v, k == 0 ? 8 : 4);
        if (k == 1)
            b_sec(&f, "PNTS", v, 4);
        b_end(&f, p, 1);
        snprintf(where, sizeof(where), "byte %zu", 32 + 16 + gl + (k == 0 ? 0 : 16 + 4));
        expect_rule(p, ARGIL_FILE_ERR_PNTS_SIZE, where, "PNTS section repeated or not 4 bytes");
    }
}

/* Failures outside the file have their own codes, and the boundary maps each code. */
static void test_read_failures(void **state)
{
    (void)state;
    char p[128], err[256];
    argil_doc_t r;
    assert_int_equal(argil_file_read(NULL, &r, err, sizeof(err)), ARGIL_FILE_ERR_ARG);
    assert_string_equal(err, "argil_file_read: no path or no document");
    snprintf(p, sizeof(p), "%s/absent.argil", g_test_dir);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_FILE_ERR_IO);
    assert_non_null(strstr(err, "cannot open"));
    assert_int_equal(argil_file_read(g_test_dir, &r, err, sizeof(err)), ARGIL_FILE_ERR_IO);
    assert_non_null(strstr(err, "not a regular file"));
    /* a sparse file one byte over the limit: refused before any byte is read */
    snprintf(p, sizeof(p), "%s/huge.argil", g_test_dir);
    test_spit(p, "", 0);
    assert_int_equal(truncate(p, (off_t)IO_FILE_MAX_BYTES + 1), 0);
    assert_int_equal(argil_file_read(p, &r, err, sizeof(err)), ARGIL_FILE_ERR_FILE_SIZE);
    assert_non_null(strstr(err, "more than the 4294967296 this reader takes"));
    assert_int_equal(grid_count(&r.grid), 0);
    assert_int_equal(unlink(p), 0);

    /* at the boundary: the failures outside the file as themselves, every rule PARSE */
    const argil_err_t outside[] = {ARGIL_OK, ARGIL_ERR_ARG, ARGIL_ERR_IO, ARGIL_ERR_NOMEM};
    for (int e = ARGIL_FILE_OK; e >= ARGIL_FILE_ERR_OCTB_COEF; e--)
        assert_int_equal(argil_file_err_argil((argil_file_err_t)e),
                         e > ARGIL_FILE_ERR_FILE_SIZE ? outside[-e] : ARGIL_ERR_PARSE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_atomic),
        cmocka_unit_test(test_any_corruption_refused),
        cmocka_unit_test(test_each_rule),
        cmocka_unit_test(test_octb),
        cmocka_unit_test(test_painted_round_trip),
        cmocka_unit_test(test_old_version_loads),
        cmocka_unit_test(test_mtls_rules),
        cmocka_unit_test(test_paint_settings),
        cmocka_unit_test(test_read_failures),
    };
    return cmocka_run_group_tests(tests, setup_dir, test_dir_teardown);
}
