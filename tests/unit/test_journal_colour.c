/* The autosave journal's painted colour (record type 3, docs/files.md): colour changes are
 * recovered bit for bit, across a checkpoint whose base carries the colour (COLR) and its CRC,
 * an unpainted journal has no type-3 record, and each rule for a crafted type-3 record is
 * refused at its byte. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "host/io/argil_file.h"
#include "host/io/io_util.h"
#include "host/io/journal.h"
#include "shared/crc32c.h"
#include "shared/wire.h"

#include "tests/unit/grid_view.h"
#include "tests/unit/test_files.h"

#define EDGE 10
#define N_SAMPLES (EDGE * EDGE * EDGE)

static int setup_dir(void **state)
{
    (void)state;
    return test_dir_make("argil_test_jcolour");
}

typedef struct {
    grid_t grid;
    journal_t j;
    uint32_t records;
} sess_t;

static void sess_open(sess_t *s, const char *sub)
{
    memset(s, 0, sizeof(*s));
    const int32_t dims[3] = {EDGE, EDGE, EDGE};
    assert_int_equal(grid_init(&s->grid, dims, 0.002f, vec3(-0.009f, -0.009f, -0.009f)),
                     ARGIL_OK);
    grid_fill_sphere(&s->grid, vec3(0, 0, 0), 0.006f);
    char dir[128], err[512] = "";
    test_path(dir, sizeof(dir), sub);
    assert_int_equal(mkdir(dir, 0777), 0);
    journal_cfg_t c;
    journal_cfg_default(&c);
    assert_int_equal(journal_open(&s->j, dir, &s->grid, &c, 0.0, 0.0, err, sizeof(err)),
                     ARGIL_OK);
}

/* Paints samples [start, start + count) with colour c (and says so through rgb_writes), then
 * records an edit step whose density box does not cover them: the colour is compared whole. */
static void sess_paint(sess_t *s, size_t start, size_t count, const uint8_t c[3])
{
    for (size_t i = start; i < start + count; i++) {
        int32_t x, y, z;
        gv_xyz(&s->grid, i, &x, &y, &z);
        assert_int_equal(grid_rgb_set(&s->grid, x, y, z, c), ARGIL_OK);
    }
    s->grid.rgb_writes++;
    const journal_box_t box = {{0, 0, 0}, {0, 0, 0}};
    bool appended = false;
    char err[512] = "";
    assert_int_equal(journal_record(&s->j, &s->grid, &box, s->records + 1u, 0.01 * s->records,
                                    0.0, 1700000000000ull, &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    s->records++;
}

static void sess_recover_equal(sess_t *s, const char *sub, uint32_t want_records,
                               uint64_t want_rgb_samples)
{
    char dir[128], err[512] = "";
    test_path(dir, sizeof(dir), sub);
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);
    argil_doc_t d;
    journal_info_t info;
    if (journal_recover(dir, &d, &info, err, sizeof(err)) != JOURNAL_OK)
        fail_msg("recover: %s", err);
    assert_int_equal(info.records, want_records);
    assert_non_null(d.rgb);
    uint8_t rgb[3 * N_SAMPLES];
    assert_memory_equal(d.rgb, gv_rgb_copy(&s->grid, rgb), 3 * N_SAMPLES);
    float *da = malloc(2 * N_SAMPLES * sizeof(float));
    assert_non_null(da);
    assert_memory_equal(gv_copy(&d.grid, GRID_DENSITY, da),
                        gv_copy(&s->grid, GRID_DENSITY, da + N_SAMPLES), N_SAMPLES * sizeof(float));
    free(da);
    if (want_rgb_samples > 0)
        assert_int_equal(info.rgb_samples, want_rgb_samples);
    argil_doc_free(&d);
}

static void test_colour_round_trip(void **state)
{
    (void)state;
    sess_t s;
    sess_open(&s, "a");
    const uint8_t red[3] = {230, 20, 20}, blue[3] = {10, 40, 250};
    sess_paint(&s, 100, 50, red);
    sess_paint(&s, 120, 10, blue); /* over part of the red */
    sess_paint(&s, 900, 3, blue);
    /* 50 + 10 + 3 samples journaled; the base had none */
    sess_recover_equal(&s, "a", 3, 63);
    assert_int_equal(s.j.stats.rgb_samples, 63);
    /* A checkpoint: the base now carries the colour (COLR) and its CRC covers it. */
    char err[512] = "";
    assert_int_equal(journal_checkpoint(&s.j, 1.0, err, sizeof(err)), ARGIL_OK);
    sess_paint(&s, 0, 1, red);
    sess_recover_equal(&s, "a", 1, 1);
    /* The recovered model, like any .argil, reads back with the same colour. */
    char base[160];
    test_path(base, sizeof(base), "a/journal-base-1.argil");
    argil_doc_t b;
    assert_int_equal(argil_file_read(base, &b, err, sizeof(err)), ARGIL_OK);
    assert_non_null(b.rgb);
    assert_int_equal(b.rgb[3 * 100], 230);
    assert_int_equal(b.rgb[3 * 120 + 2], 250);
    assert_int_equal(b.rgb[0], GRID_RGB_DEFAULT); /* painted after the checkpoint */
    argil_doc_free(&b);
    /* A base whose colour was changed is not the one the journal continues. */
    assert_int_equal(argil_file_read(base, &b, err, sizeof(err)), ARGIL_OK);
    b.rgb[3 * 100] = 229;
    assert_int_equal(argil_file_write(base, &b, err, sizeof(err)), ARGIL_OK);
    argil_doc_free(&b);
    char dir[128];
    test_path(dir, sizeof(dir), "a");
    journal_info_t info;
    assert_int_equal(journal_recover(dir, &b, &info, err, sizeof(err)), JOURNAL_ERR_BASE_MISMATCH);
    assert_non_null(strstr(err, "is not the one this journal continues"));
    argil_doc_free(&b);
    journal_close(&s.j);
    grid_free(&s.grid);
}

static void test_unpainted_has_no_colour_record(void **state)
{
    (void)state;
    sess_t s;
    sess_open(&s, "b");
    gv_set(&s.grid, GRID_DENSITY, 555, 0.25f);
    bool appended = false;
    char err[512] = "";
    assert_int_equal(journal_record(&s.j, &s.grid, NULL, 1, 0.01, 0.0, 1700000000000ull,
                                    &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    /* a colour array that holds only the clay's grey is no paint either */
    const uint8_t red[3] = {230, 20, 20}, grey[3] = {GRID_RGB_DEFAULT, GRID_RGB_DEFAULT,
                                                     GRID_RGB_DEFAULT};
    assert_int_equal(grid_rgb_set(&s.grid, 1, 2, 3, red), ARGIL_OK);
    assert_int_equal(grid_rgb_set(&s.grid, 1, 2, 3, grey), ARGIL_OK);
    assert_true(grid_rgb_any(&s.grid));
    s.grid.rgb_writes++;
    assert_int_equal(journal_record(&s.j, &s.grid, NULL, 2, 0.02, 0.0, 1700000000000ull,
                                    &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_false(appended);
    assert_int_equal(journal_sync(&s.j, err, sizeof(err)), ARGIL_OK);
    char p[160];
    test_path(p, sizeof(p), "b/journal.log");
    size_t len = 0;
    uint8_t *data = test_slurp(p, &len);
    assert_int_equal(le_get_u32(data + JOURNAL_HEADER_BYTES + 4), 1u); /* type 1 */
    assert_int_equal(le_get_u32(data + 8), 2u);                        /* version 2 */
    free(data);
    test_path(p, sizeof(p), "b");
    argil_doc_t d;
    journal_info_t info;
    assert_int_equal(journal_recover(p, &d, &info, err, sizeof(err)), ARGIL_OK);
    assert_null(d.rgb);
    assert_int_equal(info.rgb_samples, 0);
    argil_doc_free(&d);
    journal_close(&s.j);
    grid_free(&s.grid);
}

/* ---- crafted type-3 records ---- */

static uint8_t g_header[JOURNAL_HEADER_BYTES];

/* A header for an EDGE^3 grid (from a real journal). */
static void take_header(void)
{
    sess_t s;
    sess_open(&s, "h");
    char p[160];
    test_path(p, sizeof(p), "h/journal.log");
    size_t len = 0;
    uint8_t *data = test_slurp(p, &len);
    assert_true(len >= JOURNAL_HEADER_BYTES);
    memcpy(g_header, data, JOURNAL_HEADER_BYTES);
    free(data);
    journal_close(&s.j);
    grid_free(&s.grid);
}

typedef struct {
    uint8_t b[512];
    size_t n;
} buf_t;

static void put32(buf_t *b, uint32_t v)
{
    le_put_u32(b->b + b->n, v);
    b->n += 4;
}

/* The header, then one record of type `type` whose payload is the 52-byte head (no density
 * runs) followed by tail[0..tail_n). Returns the file length. */
static size_t craft(uint8_t *out, uint32_t type, const buf_t *tail)
{
    memcpy(out, g_header, JOURNAL_HEADER_BYTES);
    uint8_t *r = out + JOURNAL_HEADER_BYTES;
    const size_t payload = JOURNAL_RECORD_HEAD_BYTES + tail->n;
    le_put_u32(r, (uint32_t)payload);
    uint8_t *h = r + 4;
    memset(h, 0, JOURNAL_RECORD_HEAD_BYTES);
    le_put_u32(h, type);
    le_put_u32(h + 4, le_get_u32(g_header + 76)); /* the first record's number */
    memcpy(h + 28, g_header + 52, 20);                  /* the base's material */
    le_put_u32(h + 48, 0);                            /* no density runs */
    memcpy(h + JOURNAL_RECORD_HEAD_BYTES, tail->b, tail->n);
    le_put_u32(h + payload, crc32c(0, r, 4 + payload));
    return JOURNAL_HEADER_BYTES + 8 + payload;
}

static void test_crafted_colour_records(void **state)
{
    (void)state;
    take_header();
    const size_t tail_at = JOURNAL_HEADER_BYTES + 4 + JOURNAL_RECORD_HEAD_BYTES;
    /* Offsets within the tail: 0 material block count, 4 colour run count, 8 first run head. */
    static const struct {
        int kind;
        size_t byte;            /* offset in the tail the error names */
        journal_err_t code; /* the rule broken */
        const char *why;
    } cases[] = {
        {0, 0, JOURNAL_ERR_MAT_COUNT, "record 1: material block count 5 not in 0..4"},
        {1, 4, JOURNAL_ERR_RGB_COUNT_HEAD, "record 1: colour run count runs past the record"},
        {2, 4, JOURNAL_ERR_RGB_COUNT, "record 1: colour run count 0"},
        {3, 8, JOURNAL_ERR_RGB_RUN_HEAD, "record 1: colour run 0 head runs past the record"},
        {4, 8, JOURNAL_ERR_RGB_RUN_RANGE, "record 1: colour run 0 (0 samples from 3) empty"},
        {5, 8, JOURNAL_ERR_RGB_RUN_RANGE,
         "record 1: colour run 0 (2 samples from 999) empty, out of order, beyond the grid"},
        {6, 8, JOURNAL_ERR_RGB_RUN_RANGE,
         "record 1: colour run 0 (4 samples from 3) empty, out of order, beyond the grid or "
         "past the record"},
        {7, 22, JOURNAL_ERR_RGB_RUN_RANGE,
         "record 1: colour run 1 (1 samples from 3) empty, out of order"},
        {8, 19, JOURNAL_ERR_TRAILING, "record 1: 2 bytes after the last run"},
        {9, 0, JOURNAL_ERR_RECORD_TYPE, "record 1: unknown record type 4"},
    };
    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
        buf_t t = {{0}, 0};
        uint32_t type = 3;
        switch (cases[k].kind) {
        case 0: put32(&t, 5); break;
        case 1: put32(&t, 0); break;
        case 2: put32(&t, 0); put32(&t, 0); break;
        case 3: put32(&t, 0); put32(&t, 1); put32(&t, 3); break;
        case 4: put32(&t, 0); put32(&t, 1); put32(&t, 3); put32(&t, 0); break;
        case 5: put32(&t, 0); put32(&t, 1); put32(&t, 999); put32(&t, 2); t.n += 6; break;
        case 6: put32(&t, 0); put32(&t, 1); put32(&t, 3); put32(&t, 4); t.n += 11; break;
        case 7: /* a second run starting inside the first */
            put32(&t, 0); put32(&t, 2); put32(&t, 3); put32(&t, 2); t.n += 6;
            put32(&t, 3); put32(&t, 1); t.n += 3;
            break;
        case 8: put32(&t, 0); put32(&t, 1); put32(&t, 3); put32(&t, 1); t.n += 3 + 2; break;
        case 9: type = 4; put32(&t, 0); break;
        }
        uint8_t file[JOURNAL_HEADER_BYTES + 600];
        const size_t len = craft(file, type, &t);
        char err[512] = "", want[300];
        journal_info_t info;
        const size_t byte = cases[k].kind == 9 ? JOURNAL_HEADER_BYTES + 4 : tail_at + cases[k].byte;
        snprintf(want, sizeof(want), "j.log: byte %zu: %s", byte, cases[k].why);
        assert_int_equal(journal_replay(file, len, "j.log", NULL, 0, &info, err, sizeof(err)),
                         cases[k].code);
        if (strncmp(err, want, strlen(want)) != 0)
            fail_msg("case %zu: got \"%s\", want \"%s\"", k, err, want);
        assert_null(strchr(err, '\n'));
        assert_int_equal(info.records, 0);
    }
    /* A good one: two runs, applied onto a grid. */
    buf_t t = {{0}, 0};
    put32(&t, 0);
    put32(&t, 2);
    put32(&t, 3);
    put32(&t, 2);
    const uint8_t c6[6] = {1, 2, 3, 4, 5, 6};
    memcpy(t.b + t.n, c6, 6);
    t.n += 6;
    put32(&t, 999);
    put32(&t, 1);
    t.b[t.n++] = 7;
    t.b[t.n++] = 8;
    t.b[t.n++] = 9;
    uint8_t file[JOURNAL_HEADER_BYTES + 600];
    const size_t len = craft(file, 3, &t);
    grid_t g;
    const int32_t dims[3] = {EDGE, EDGE, EDGE};
    assert_int_equal(grid_init(&g, dims, 0.002f, vec3(0, 0, 0)), ARGIL_OK);
    journal_info_t info;
    char err[512] = "";
    if (journal_replay_grid(file, len, "j.log", &g, &info, err, sizeof(err)) != JOURNAL_OK)
        fail_msg("good record: %s", err);
    assert_int_equal(info.records, 1);
    assert_int_equal(info.rgb_samples, 3);
    assert_true(grid_rgb_any(&g));
    uint8_t rgb[3 * N_SAMPLES];
    gv_rgb_copy(&g, rgb);
    assert_memory_equal(rgb + 9, c6, 6);
    assert_int_equal(rgb[3 * 999 + 2], 9);
    assert_int_equal(rgb[0], GRID_RGB_DEFAULT);
    assert_int_equal(rgb[3 * 5], GRID_RGB_DEFAULT);
    grid_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_colour_round_trip),
        cmocka_unit_test(test_unpainted_has_no_colour_record),
        cmocka_unit_test(test_crafted_colour_records),
    };
    return cmocka_run_group_tests(tests, setup_dir, test_dir_teardown);
}
