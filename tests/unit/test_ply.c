/* Binary PLY export and the strict reader: round trip, exact header, and one test per way a
 * file can be wrong (each error names the file and where). */
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

#include "host/io/ply.h"
#include "host/mesh/mc.h"

static const char header_fmt[] =
    "ply\n"
    "format binary_little_endian 1.0\n"
    "comment argil mesh, model space, metres\n"
    "element vertex %zu\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property float nx\n"
    "property float ny\n"
    "property float nz\n"
    "element face %zu\n"
    "property list uchar int vertex_indices\n"
    "end_header\n";

typedef struct {
    char dir[64];
    char path[128];
    mesh_t mesh;
} fixture_t;

static int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof(*f));
    if (f == NULL)
        return -1;
    strcpy(f->dir, "/tmp/argil_test_ply_XXXXXX");
    if (mkdtemp(f->dir) == NULL)
        return -1;
    snprintf(f->path, sizeof(f->path), "%s/m.ply", f->dir);
    /* A small closed mesh: a sphere on an 8³ block. */
    float d[512];
    const int32_t dims[3] = {8, 8, 8};
    for (int z = 0, i = 0; z < 8; z++)
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 8; x++, i++) {
                const float r = sqrtf((float)((x - 3.5) * (x - 3.5) + (y - 3.5) * (y - 3.5) +
                                              (z - 3.5) * (z - 3.5)));
                const float v = 0.5f + 0.5f * (2.5f - r) / 2.0f;
                d[i] = v < 0 ? 0 : (v > 1 ? 1 : v);
            }
    mesh_init(&f->mesh);
    if (mc_extract(d, dims, 1.0e-3f, vec3(-0.0035f, -0.0035f, -0.0035f), 0.5f, &f->mesh) !=
        ARGIL_OK)
        return -1;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture_t *f = *state;
    char cmd[160];
    snprintf(cmd, sizeof(cmd), "rm -rf '%s'", f->dir);
    if (system(cmd) != 0)
        return -1;
    mesh_free(&f->mesh);
    free(f);
    return 0;
}

/* Reads a whole file into a fresh buffer. */
static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    assert_int_equal(fseek(fp, 0, SEEK_END), 0);
    const long n = ftell(fp);
    assert_true(n >= 0);
    rewind(fp);
    unsigned char *buf = malloc((size_t)n + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    *len = (size_t)n;
    return buf;
}

static void spit(const char *path, const void *data, size_t len)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(data, 1, len, fp), len);
    assert_int_equal(fclose(fp), 0);
}

/* Writes data as a file, reads it, expects the rule err_code and every needle in the message. */
static void expect_read_error(fixture_t *f, const void *data, size_t len, ply_err_t err_code,
                              const char *needle1, const char *needle2)
{
    spit(f->path, data, len);
    mesh_t m;
    mesh_init(&m);
    char err[512] = "";
    assert_int_equal(ply_read_mesh(f->path, &m, err, sizeof(err)), err_code);
    assert_int_equal(m.n_vert, 0);
    assert_int_equal(m.n_tri, 0);
    if (strstr(err, f->path) == NULL || strstr(err, needle1) == NULL ||
        (needle2 != NULL && strstr(err, needle2) == NULL))
        fail_msg("error text '%s' lacks '%s' / '%s'", err, needle1, needle2 ? needle2 : "");
    mesh_free(&m);
}

static char *header_for(size_t nv, size_t nf)
{
    char *h = malloc(1024);
    assert_non_null(h);
    snprintf(h, 1024, header_fmt, nv, nf);
    return h;
}

static void test_round_trip(void **state)
{
    fixture_t *f = *state;
    assert_true(f->mesh.n_tri > 50);
    char err[256] = "";
    assert_int_equal(ply_write(f->path, &f->mesh, err, sizeof(err)), ARGIL_OK);
    mesh_t back;
    mesh_init(&back);
    assert_int_equal(ply_read_mesh(f->path, &back, err, sizeof(err)), PLY_OK);
    assert_int_equal(back.n_vert, f->mesh.n_vert);
    assert_int_equal(back.n_tri, f->mesh.n_tri);
    assert_memory_equal(back.pos, f->mesh.pos, 3 * sizeof(float) * back.n_vert);
    assert_memory_equal(back.normal, f->mesh.normal, 3 * sizeof(float) * back.n_vert);
    assert_memory_equal(back.tri, f->mesh.tri, 3 * sizeof(uint32_t) * back.n_tri);
    /* No temporary file is left behind. */
    char tmp[160];
    snprintf(tmp, sizeof(tmp), "%s.tmp", f->path);
    assert_int_equal(access(tmp, F_OK), -1);
    mesh_free(&back);

    /* An empty mesh round-trips too. */
    mesh_t empty;
    mesh_init(&empty);
    assert_int_equal(ply_write(f->path, &empty, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(ply_read_mesh(f->path, &empty, err, sizeof(err)), PLY_OK);
    assert_int_equal(empty.n_vert + empty.n_tri, 0);
    mesh_free(&empty);
}

static void test_round_trip_large(void **state)
{
    fixture_t *f = *state;
    /* Tens of thousands of records: the body spans many write and read chunks. */
    enum { n = 40 };
    float *d = malloc(n * n * n * sizeof(float));
    assert_non_null(d);
    const int32_t dims[3] = {n, n, n};
    for (int z = 0, i = 0; z < n; z++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++, i++)
                d[i] = 0.5f + 0.5f * sinf(0.4f * (float)x) * cosf(0.3f * (float)y) *
                                  sinf(0.5f * (float)z + 0.2f);
    mesh_t m, back;
    mesh_init(&m);
    mesh_init(&back);
    assert_int_equal(mc_extract(d, dims, 1.0e-3f, vec3(0, 0, 0), 0.5f, &m), ARGIL_OK);
    assert_true(24 * m.n_vert > 4 * 65536 && 13 * m.n_tri > 4 * 65536);
    char err[256] = "";
    assert_int_equal(ply_write(f->path, &m, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(ply_read_mesh(f->path, &back, err, sizeof(err)), PLY_OK);
    assert_int_equal(back.n_vert, m.n_vert);
    assert_int_equal(back.n_tri, m.n_tri);
    assert_memory_equal(back.pos, m.pos, 3 * sizeof(float) * m.n_vert);
    assert_memory_equal(back.normal, m.normal, 3 * sizeof(float) * m.n_vert);
    assert_memory_equal(back.tri, m.tri, 3 * sizeof(uint32_t) * m.n_tri);
    mesh_free(&m);
    mesh_free(&back);
    free(d);
}

static void test_header_and_layout_exact(void **state)
{
    fixture_t *f = *state;
    assert_int_equal(ply_write(f->path, &f->mesh, NULL, 0), ARGIL_OK);
    size_t len;
    unsigned char *buf = slurp(f->path, &len);
    char *h = header_for(f->mesh.n_vert, f->mesh.n_tri);
    const size_t hl = strlen(h);
    assert_true(len > hl);
    assert_memory_equal(buf, h, hl);
    assert_int_equal(len, hl + 24 * f->mesh.n_vert + 13 * f->mesh.n_tri);
    /* First vertex x, little-endian float; first face: count 3 then three int32. */
    uint32_t bits = (uint32_t)buf[hl] | (uint32_t)buf[hl + 1] << 8 |
                    (uint32_t)buf[hl + 2] << 16 | (uint32_t)buf[hl + 3] << 24;
    float x;
    memcpy(&x, &bits, sizeof(x));
    assert_memory_equal(&x, &f->mesh.pos[0], sizeof(float));
    const size_t face0 = hl + 24 * f->mesh.n_vert;
    assert_int_equal(buf[face0], 3);
    assert_int_equal(buf[face0 + 1] | buf[face0 + 2] << 8, f->mesh.tri[0]);
    free(h);
    free(buf);
}

/* A valid file's bytes, for corrupting. */
static unsigned char *valid_file(fixture_t *f, size_t *len, size_t *header_len)
{
    assert_int_equal(ply_write(f->path, &f->mesh, NULL, 0), ARGIL_OK);
    char *h = header_for(f->mesh.n_vert, f->mesh.n_tri);
    *header_len = strlen(h);
    free(h);
    return slurp(f->path, len);
}

static void test_truncated_and_trailing(void **state)
{
    fixture_t *f = *state;
    size_t len, hl;
    unsigned char *buf = valid_file(f, &len, &hl);
    expect_read_error(f, buf, len - 5, PLY_ERR_SIZE, "file too short", "byte");
    expect_read_error(f, buf, hl + 10, PLY_ERR_SIZE, "file too short", NULL);
    expect_read_error(f, buf, hl - 4, PLY_ERR_LINE_END, "no end of line", "header line 13");
    expect_read_error(f, buf, 0, PLY_ERR_LINE_END, "header line 1", NULL);
    unsigned char *longer = malloc(len + 3);
    assert_non_null(longer);
    memcpy(longer, buf, len);
    memset(longer + len, 0, 3);
    expect_read_error(f, longer, len + 3, PLY_ERR_SIZE, "trailing bytes", NULL);
    free(longer);
    free(buf);
}

static void test_bad_header_lines(void **state)
{
    fixture_t *f = *state;
    char *h = header_for(0, 0);
    char text[1200];

    snprintf(text, sizeof(text), "plx\n%s", h + 4);
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 1", "'ply'");

    snprintf(text, sizeof(text), "ply\nformat ascii 1.0\n%s", strstr(h, "comment"));
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 2",
                      "binary_little_endian");
    snprintf(text, sizeof(text), "ply\nformat binary_big_endian 1.0\n%s", strstr(h, "comment"));
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 2", NULL);

    snprintf(text, sizeof(text), "ply\nformat binary_little_endian 1.0\nelement vertex abc\n");
    expect_read_error(f, text, strlen(text), PLY_ERR_COUNT, "header line 3", "'abc'");
    snprintf(text, sizeof(text), "ply\nformat binary_little_endian 1.0\nelement vertex -1\n");
    expect_read_error(f, text, strlen(text), PLY_ERR_COUNT, "header line 3", "'-1'");

    /* A property out of order, a missing face list, an unknown element. */
    char *p = strstr(h, "property float y");
    memcpy(p, "property float q", 16);
    expect_read_error(f, h, strlen(h), PLY_ERR_HEADER, "header line 6", "property float y");
    free(h);
    snprintf(text, sizeof(text), "%s", "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
             "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
             "property float ny\nproperty float nz\nelement face 0\n"
             "property list uchar uint vertex_indices\nend_header\n");
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 11", "list uchar int");
    snprintf(text, sizeof(text), "ply\nformat binary_little_endian 1.0\nelement edge 3\n");
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 3", NULL);

    /* Over-long line, NUL byte, no header end within the limit. */
    memset(text, 'a', sizeof(text));
    memcpy(text, "ply\ncomment ", 12);
    text[600] = '\n';
    expect_read_error(f, text, 601, PLY_ERR_LINE_LONG, "header line 2", "longer than");
    const char nul[] = "ply\nform\0at binary_little_endian 1.0\n";
    expect_read_error(f, nul, sizeof(nul) - 1, PLY_ERR_LINE_NUL, "header line 2", "NUL");
    char *big = malloc(PLY_HEADER_MAX_BYTES + 200);
    assert_non_null(big);
    size_t n = 0;
    n += (size_t)sprintf(big, "ply\nformat binary_little_endian 1.0\n");
    while (n < PLY_HEADER_MAX_BYTES + 100)
        n += (size_t)sprintf(big + n, "comment padding padding\n");
    expect_read_error(f, big, n, PLY_ERR_LINE_END, "no end of line", NULL);
    free(big);
}

static void test_huge_declared_counts(void **state)
{
    fixture_t *f = *state;
    char text[512];
    /* Above the format's int indices: refused at the header line. */
    memset(text, 'x', 100);
    const char *h4 = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n";
    memcpy(text, h4, strlen(h4));
    expect_read_error(f, text, 100, PLY_ERR_COUNT, "header line 3", "4000000000");
    /* Within the format, but far beyond what the file holds: refused before any allocation. */
    snprintf(text, sizeof(text), header_fmt, (size_t)2000000000u, (size_t)0);
    expect_read_error(f, text, strlen(text), PLY_ERR_SIZE, "file too short", "2000000000");
    snprintf(text, sizeof(text), header_fmt, (size_t)0, (size_t)18446744073709551615u);
    expect_read_error(f, text, strlen(text), PLY_ERR_COUNT, "header line 11", NULL);
    snprintf(text, sizeof(text), header_fmt, (size_t)0, (size_t)999999999999u);
    expect_read_error(f, text, strlen(text), PLY_ERR_SIZE, "file too short", NULL);
}

static void test_bad_records(void **state)
{
    fixture_t *f = *state;
    size_t len, hl;
    unsigned char *buf = valid_file(f, &len, &hl);
    unsigned char *c = malloc(len);
    assert_non_null(c);
    const size_t face0 = hl + 24 * f->mesh.n_vert;
    char where[64];

    memcpy(c, buf, len);
    c[face0 + 13] = 4; /* face 1 claims four vertices */
    snprintf(where, sizeof(where), "byte %zu", face0 + 13);
    expect_read_error(f, c, len, PLY_ERR_FACE_SIZE, where, "4 vertices");

    memcpy(c, buf, len);
    c[face0 + 1] = 0xFF; /* index 255 + ... out of range */
    c[face0 + 2] = 0xFF;
    c[face0 + 3] = 0x00;
    c[face0 + 4] = 0x00;
    snprintf(where, sizeof(where), "byte %zu", face0 + 1);
    expect_read_error(f, c, len, PLY_ERR_INDEX, where, "names vertex 65535");

    memcpy(c, buf, len);
    c[face0 + 8] = 0xFF; /* second index negative */
    snprintf(where, sizeof(where), "byte %zu", face0 + 5);
    expect_read_error(f, c, len, PLY_ERR_INDEX, where, "names vertex -");

    memcpy(c, buf, len);
    const unsigned char nan_le[4] = {0x00, 0x00, 0xC0, 0x7F};
    memcpy(c + hl + 24 + 16, nan_le, 4); /* vertex 1, ny */
    snprintf(where, sizeof(where), "byte %zu", hl + 24 + 16);
    expect_read_error(f, c, len, PLY_ERR_NONFINITE, where, "non-finite ny");
    free(c);
    free(buf);
}

static void test_header_variants_accepted(void **state)
{
    fixture_t *f = *state;
    /* CRLF line ends, extra comments and spaces, type synonyms. */
    const char text[] = "ply\r\nformat  binary_little_endian 1.0\r\ncomment hi\r\n"
                        "element vertex 3\nobj_info x\nproperty float32 x\nproperty float y\n"
                        "property float z\nproperty float nx\nproperty float ny\n"
                        "property float nz\nelement face 1\n"
                        "property list uint8 int32 vertex_indices\nend_header\n";
    unsigned char file[sizeof(text) - 1 + 3 * 24 + 13] = {0};
    memcpy(file, text, sizeof(text) - 1);
    unsigned char *face = file + sizeof(text) - 1 + 72;
    face[0] = 3;
    face[5] = 1;
    face[9] = 2;
    spit(f->path, file, sizeof(file));
    mesh_t m;
    mesh_init(&m);
    char err[256] = "";
    if (ply_read_mesh(f->path, &m, err, sizeof(err)) != PLY_OK)
        fail_msg("%s", err);
    assert_int_equal(m.n_vert, 3);
    assert_int_equal(m.n_tri, 1);
    assert_int_equal(m.tri[2], 2);
    mesh_free(&m);
}

/* A mesh with colours: red green blue uchar after the normal (27-byte vertices), read back
 * exactly; a header whose colour is incomplete names the line; a coloured read leaves no colour
 * behind in the next, uncoloured one. */
static void test_colour_round_trip(void **state)
{
    fixture_t *f = *state;
    mesh_t m, back;
    mesh_init(&m);
    mesh_init(&back);
    assert_int_equal(mesh_enable_rgb(&m), ARGIL_OK);
    for (size_t v = 0; v < f->mesh.n_vert; v++) {
        const float *p = &f->mesh.pos[3 * v], *n = &f->mesh.normal[3 * v];
        const uint8_t rgb[3] = {(uint8_t)(v * 7), (uint8_t)(255 - v), (uint8_t)(v * 13 + 1)};
        assert_int_equal(mesh_add_vertex_rgb(&m, vec3(p[0], p[1], p[2]), vec3(n[0], n[1], n[2]),
                                             rgb, NULL),
                         ARGIL_OK);
    }
    for (size_t t = 0; t < f->mesh.n_tri; t++)
        assert_int_equal(mesh_add_triangle(&m, f->mesh.tri[3 * t], f->mesh.tri[3 * t + 1],
                                           f->mesh.tri[3 * t + 2]),
                         ARGIL_OK);
    char err[256] = "";
    assert_int_equal(ply_write(f->path, &m, err, sizeof(err)), ARGIL_OK);
    size_t len;
    unsigned char *buf = slurp(f->path, &len);
    const char *rgb_props = "property float nz\nproperty uchar red\nproperty uchar green\n"
                            "property uchar blue\nelement face";
    assert_non_null(strstr((const char *)buf, rgb_props));
    const size_t hl = (size_t)(strstr((const char *)buf, "end_header\n") - (char *)buf) + 11;
    assert_int_equal(len, hl + 27 * m.n_vert + 13 * m.n_tri);
    assert_int_equal(ply_read_mesh(f->path, &back, err, sizeof(err)), PLY_OK);
    assert_true(back.has_rgb);
    assert_int_equal(back.n_vert, m.n_vert);
    assert_memory_equal(back.pos, m.pos, 3 * sizeof(float) * m.n_vert);
    assert_memory_equal(back.normal, m.normal, 3 * sizeof(float) * m.n_vert);
    assert_memory_equal(back.rgb, m.rgb, 3 * m.n_vert);
    assert_memory_equal(back.tri, m.tri, 3 * sizeof(uint32_t) * m.n_tri);
    /* the same mesh without colours into the same out: no colour array stays */
    assert_int_equal(ply_write(f->path, &f->mesh, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(ply_read_mesh(f->path, &back, err, sizeof(err)), PLY_OK);
    assert_false(back.has_rgb);
    assert_null(back.rgb);
    assert_int_equal(back.n_vert, f->mesh.n_vert);
    mesh_free(&back);

    /* red without green and blue, a wrong colour type, colour cut short by the file's end */
    char *h = header_for(0, 0), text[1200];
    char *nz = strstr(h, "property float nz\n") + strlen("property float nz\n");
    snprintf(text, sizeof(text), "%.*sproperty uchar red\n%s", (int)(nz - h), h, nz);
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 12",
                      "property uchar green");
    snprintf(text, sizeof(text), "%.*sproperty float red\n%s", (int)(nz - h), h, nz);
    expect_read_error(f, text, strlen(text), PLY_ERR_HEADER, "header line 11",
                      "'property uchar red' or 'element face <count>'");
    free(h);
    expect_read_error(f, buf, hl + 27 * m.n_vert - 1, PLY_ERR_SIZE, "file too short", NULL);
    free(buf);
    mesh_free(&m);
}

static void test_io_errors(void **state)
{
    fixture_t *f = *state;
    char err[512] = "";
    mesh_t m;
    mesh_init(&m);

    char missing[160];
    snprintf(missing, sizeof(missing), "%s/nope/m.ply", f->dir);
    assert_int_equal(ply_read_mesh(missing, &m, err, sizeof(err)), PLY_ERR_IO);
    assert_non_null(strstr(err, missing));
    assert_non_null(strstr(err, "fopen"));
    assert_int_equal(ply_write(missing, &f->mesh, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "nope/m.ply.tmp"));
    assert_non_null(strstr(err, "fopen"));
    assert_int_equal(ply_read_mesh(f->dir, &m, err, sizeof(err)), PLY_ERR_IO);
    assert_non_null(strstr(err, "not a regular file"));

    /* Renaming onto a directory fails: the error names rename, no .tmp stays behind. */
    char as_dir[160], tmp[170];
    snprintf(as_dir, sizeof(as_dir), "%s/dir.ply", f->dir);
    snprintf(tmp, sizeof(tmp), "%s.tmp", as_dir);
    assert_int_equal(mkdir(as_dir, 0700), 0);
    assert_int_equal(ply_write(as_dir, &f->mesh, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "rename"));
    assert_non_null(strstr(err, as_dir));
    assert_int_equal(access(tmp, F_OK), -1);

    /* A mesh that cannot be written leaves the previous file untouched. */
    assert_int_equal(ply_write(f->path, &f->mesh, NULL, 0), ARGIL_OK);
    size_t len0, len1;
    unsigned char *before = slurp(f->path, &len0);
    f->mesh.tri[4] = (uint32_t)f->mesh.n_vert;
    assert_int_equal(ply_write(f->path, &f->mesh, err, sizeof(err)), ARGIL_ERR_ARG);
    assert_non_null(strstr(err, "triangle 1"));
    f->mesh.tri[4] = 0;
    const float keep = f->mesh.pos[7];
    f->mesh.pos[7] = NAN;
    assert_int_equal(ply_write(f->path, &f->mesh, err, sizeof(err)), ARGIL_ERR_NONFINITE);
    assert_non_null(strstr(err, "vertex 2"));
    f->mesh.pos[7] = keep;
    unsigned char *after = slurp(f->path, &len1);
    assert_int_equal(len0, len1);
    assert_memory_equal(before, after, len0);
    free(before);
    free(after);

    assert_int_equal(ply_write(NULL, &f->mesh, err, sizeof(err)), ARGIL_ERR_ARG);
    assert_int_equal(ply_read_mesh(f->path, NULL, NULL, 0), PLY_ERR_ARG);
    mesh_free(&m);
}

/* The argil_err_t a command reports for each ply_err_t. */
static void test_err_argil(void **state)
{
    (void)state;
    static const ply_err_t outside[] = {PLY_OK, PLY_ERR_ARG, PLY_ERR_IO, PLY_ERR_NOMEM};
    static const argil_err_t as[] = {ARGIL_OK, ARGIL_ERR_ARG, ARGIL_ERR_IO, ARGIL_ERR_NOMEM};
    for (size_t i = 0; i < sizeof(outside) / sizeof(outside[0]); i++)
        assert_int_equal(ply_err_argil(outside[i]), as[i]);
    for (int rule = PLY_ERR_HEADER; rule >= PLY_ERR_INDEX; rule--)
        assert_int_equal(ply_err_argil((ply_err_t)rule), ARGIL_ERR_PARSE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_round_trip_large, setup, teardown),
        cmocka_unit_test_setup_teardown(test_header_and_layout_exact, setup, teardown),
        cmocka_unit_test_setup_teardown(test_truncated_and_trailing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_header_lines, setup, teardown),
        cmocka_unit_test_setup_teardown(test_huge_declared_counts, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_records, setup, teardown),
        cmocka_unit_test_setup_teardown(test_header_variants_accepted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_colour_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_io_errors, setup, teardown),
        cmocka_unit_test(test_err_argil),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
