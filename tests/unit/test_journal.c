/* The autosave journal: edits recovered bit for bit, a record torn at any byte ignored, a bad
 * record in the middle stops replay there, a foreign base refused, rotation, the autosave
 * interval, and one crafted journal per rule the reader enforces. */
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
#include "host/io/journal.h"
#include "shared/crc32c.h"
#include "shared/wire.h"

#include "tests/unit/test_files.h"
#include "tests/unit/grid_view.h"

#define EDGE_X 10
#define EDGE_Y 9
#define EDGE_Z 8
#define N_SAMPLES (EDGE_X * EDGE_Y * EDGE_Z)
#define MAX_STEPS 40

static int setup_dir(void **state)
{
    (void)state;
    return test_dir_make("argil_test_journal");
}

static long file_size(const char *name)
{
    char p[128];
    test_path(p, sizeof(p), name);
    struct stat st;
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

static uint32_t rng_next(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

/* A session under test: the grid, its journal and the density after every record. */
typedef struct {
    grid_t grid;
    journal_t j;
    uint32_t rng;
    uint32_t records;
    float after[MAX_STEPS + 1][N_SAMPLES]; /* [k]: density after record k (0: the base) */
    spring_material_t mat_after[MAX_STEPS + 1];
} sess_t;

static sess_t *sess_new(const journal_cfg_t *cfg)
{
    sess_t *s = calloc(1, sizeof(*s));
    assert_non_null(s);
    const int32_t dims[3] = {EDGE_X, EDGE_Y, EDGE_Z};
    assert_int_equal(grid_init(&s->grid, dims, 0.002f, vec3(-0.009f, -0.008f, -0.007f)),
                     ARGIL_OK);
    grid_fill_sphere(&s->grid, vec3(0, 0, 0), 0.006f);
    s->rng = 0x2545F491u;
    journal_cfg_t c;
    journal_cfg_default(&c);
    if (cfg)
        c = *cfg;
    char err[512] = "";
    assert_int_equal(journal_open(&s->j, g_test_dir, &s->grid, &c, 0.0, 0.0, err, sizeof(err)),
                     ARGIL_OK);
    gv_copy(&s->grid, GRID_DENSITY, s->after[0]);
    s->mat_after[0] = s->grid.material;
    return s;
}

static void sess_free(sess_t *s)
{
    journal_close(&s->j);
    grid_free(&s->grid);
    free(s);
}

/* One edit step k: a cluster of changed samples with gaps, scattered singles, odd bit patterns
 * (-0, a subnormal, 1); every 5th step changes nothing, every 7th only the material. Returns
 * whether a record was appended, after checking the journal agrees. */
static bool sess_step(sess_t *s, uint32_t k, double sim_s, double real_s)
{
    grid_t *g = &s->grid;
    const bool material_only = k % 7 == 6, nothing = k % 5 == 4 && !material_only;
    if (material_only) {
        s->grid.material.stiffness += 0.25f;
    } else if (!nothing) {
        const uint32_t start = rng_next(&s->rng) % (N_SAMPLES - 40);
        for (uint32_t i = 0; i < 30; i++)
            if (i % 4 != 3) /* gaps of one unchanged sample: bridged into one run */
                gv_set(g, GRID_DENSITY, start + i, (float)(rng_next(&s->rng) % 100001u) * 1e-5f);
        for (uint32_t i = 0; i < 5; i++)
            gv_set(g, GRID_DENSITY, rng_next(&s->rng) % N_SAMPLES,
                   (float)(rng_next(&s->rng) % 1000u) * 1e-3f);
        gv_set(g, GRID_DENSITY, rng_next(&s->rng) % N_SAMPLES, -0.0f);
        gv_set(g, GRID_DENSITY, rng_next(&s->rng) % N_SAMPLES, 1e-40f);
        gv_set(g, GRID_DENSITY, rng_next(&s->rng) % N_SAMPLES, 1.0f);
    }
    bool appended = false;
    char err[512] = "";
    assert_int_equal(journal_record(&s->j, &s->grid, NULL, s->records + 1u, sim_s, real_s,
                                    1700000000000ull + k, &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_int_equal(appended, !nothing);
    if (appended) {
        s->records++;
        assert_true(s->records <= MAX_STEPS);
        gv_copy(g, GRID_DENSITY, s->after[s->records]);
        s->mat_after[s->records] = s->grid.material;
    }
    assert_int_equal(journal_tick(&s->j, sim_s, real_s, err, sizeof(err)), ARGIL_OK);
    return appended;
}

static void sess_steps(sess_t *s, uint32_t n)
{
    for (uint32_t k = 0; k < n; k++)
        (void)sess_step(s, k, 0.1 * (double)k, 0.05 * (double)k);
    char err[512] = "";
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);
}

static void test_round_trip(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    sess_steps(s, 30);
    assert_int_equal(s->records, 24); /* 30 steps, 6 of them without a change */
    assert_int_equal(s->j.stats.records, 24);
    assert_true(s->j.stats.syncs >= 2); /* 3 s simulated with autosave 1 s */

    argil_doc_t doc;
    journal_info_t info;
    char err[512] = "";
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_true(gv_same(&doc.grid, GRID_DENSITY, &s->grid, GRID_DENSITY));
    assert_true(gv_same(&doc.grid, GRID_REST, &s->grid, GRID_DENSITY));
    assert_int_equal(info.records, 24);
    assert_int_equal(info.first_seq, 1);
    assert_int_equal(info.last_seq, 24);
    assert_int_equal(info.edits, 24);
    assert_int_equal(doc.state.edits, 24);
    assert_int_equal(info.torn_bytes, 0);
    assert_memory_equal(&doc.grid.material, &s->grid.material, sizeof(spring_material_t));
    assert_true(fabs(info.last_sim_s - 2.8) < 1e-6); /* step 29 changed nothing */
    assert_int_equal(info.last_wall_ms, 1700000000000ull + 28);

    /* The writer's own model file and the recovery's are the same bytes. */
    char a[128], b[128];
    test_path(a, sizeof(a), "writer.argil");
    test_path(b, sizeof(b), "recovered.argil");
    assert_int_equal(journal_write_model(&s->j, &s->grid, 24, a, err, sizeof(err)),
                     ARGIL_OK);
    assert_int_equal(argil_file_write(b, &doc, err, sizeof(err)), ARGIL_OK);
    size_t la, lb;
    uint8_t *ba = test_slurp(a, &la), *bb = test_slurp(b, &lb);
    assert_int_equal(la, lb);
    assert_memory_equal(ba, bb, la);
    free(ba);
    free(bb);
    argil_doc_free(&doc);

    /* Probe (no base needed) sees the same. */
    journal_info_t p;
    assert_int_equal(journal_probe(g_test_dir, &p, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(p.records, 24);

    /* A clean end removes the journal and its base. */
    assert_true(journal_exists(g_test_dir));
    assert_int_equal(journal_finish(&s->j, err, sizeof(err)), ARGIL_OK);
    assert_false(journal_exists(g_test_dir));
    assert_int_equal(file_size("journal-base-0.argil"), -1);
    sess_free(s);
}

static void test_no_records_gives_the_base(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    argil_doc_t doc;
    journal_info_t info;
    char err[512] = "";
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 0);
    assert_true(gv_equal(&doc.grid, GRID_DENSITY, s->after[0]));
    argil_doc_free(&doc);
    sess_free(s);
}

/* Every cut inside the last record: that record is ignored, the rest recovered exactly. */
static void test_torn_tail_every_byte(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    sess_steps(s, 4); /* steps 0..3: four records */
    assert_int_equal(s->records, 4);
    char jp[128];
    test_path(jp, sizeof(jp), JOURNAL_FILE);
    size_t len;
    uint8_t *full = test_slurp(jp, &len);
    /* Find where the last record starts by walking the length fields. */
    size_t at = JOURNAL_HEADER_BYTES, last = 0;
    while (at < len) {
        last = at;
        at += 8 + le_get_u32(full + at);
    }
    assert_int_equal(at, len);
    assert_true(len - last > 100);
    for (size_t cut = last; cut < len; cut++) {
        test_spit(jp, full, cut);
        argil_doc_t doc;
        journal_info_t info;
        char err[512] = "";
        assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
        assert_int_equal(info.records, 3);
        assert_int_equal(info.torn_bytes, cut - last);
        assert_true(gv_equal(&doc.grid, GRID_DENSITY, s->after[3]));
        argil_doc_free(&doc);
    }
    /* A cut inside the header is a clear refusal, not a crash. */
    test_spit(jp, full, JOURNAL_HEADER_BYTES - 1);
    argil_doc_t doc;
    journal_info_t info;
    char err[512] = "";
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), JOURNAL_ERR_SHORT);
    assert_non_null(strstr(err, "shorter than the journal header"));
    assert_int_equal(grid_count(&doc.grid), 0);
    free(full);
    sess_free(s);
}

static void test_bad_crc_in_the_middle_stops_there(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    sess_steps(s, 4);
    char jp[128];
    test_path(jp, sizeof(jp), JOURNAL_FILE);
    size_t len;
    uint8_t *full = test_slurp(jp, &len);
    const size_t r1 = JOURNAL_HEADER_BYTES, r2 = r1 + 8 + le_get_u32(full + r1);
    const size_t r3 = r2 + 8 + le_get_u32(full + r2);
    const size_t r4 = r3 + 8 + le_get_u32(full + r3);
    /* A flipped bit inside record 2's values. */
    full[r2 + 70] ^= 0x10;
    test_spit(jp, full, len);
    argil_doc_t doc;
    journal_info_t info;
    char err[512] = "";
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)),
                     JOURNAL_ERR_RECORD_CRC);
    assert_non_null(strstr(err, "record 2: checksum mismatch"));
    char want[64];
    snprintf(want, sizeof(want), "byte %zu:", r2);
    assert_non_null(strstr(err, want));
    assert_int_equal(info.records, 1);
    assert_true(grid_count(&doc.grid) > 0);
    assert_true(gv_equal(&doc.grid, GRID_DENSITY, s->after[1]));
    argil_doc_free(&doc);
    full[r2 + 70] ^= 0x10;

    /* The same flip in the last record, which ends the file, reads as a torn write. */
    full[r4 + 70] ^= 0x10;
    test_spit(jp, full, len);
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 3);
    assert_int_equal(info.torn_bytes, len - r4);
    assert_true(gv_equal(&doc.grid, GRID_DENSITY, s->after[3]));
    argil_doc_free(&doc);
    free(full);
    sess_free(s);
}

static void test_wrong_base_refused(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    sess_steps(s, 3);
    char err[512] = "", bp[128];
    test_path(bp, sizeof(bp), "journal-base-0.argil");
    /* Another model under the base's name. */
    grid_fill_sphere(&s->grid, vec3(0, 0, 0), 0.004f);
    assert_int_equal(journal_write_model(&s->j, &s->grid, 0, bp, err, sizeof(err)),
                     ARGIL_OK);
    argil_doc_t doc;
    journal_info_t info;
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)),
                     JOURNAL_ERR_BASE_MISMATCH);
    assert_non_null(strstr(err, "is not the one this journal continues"));
    assert_int_equal(grid_count(&doc.grid), 0);
    /* A base that is not a valid .argil file. */
    test_spit(bp, "ARGIL", 5);
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)),
                     JOURNAL_ERR_BASE_FILE);
    assert_non_null(strstr(err, "shorter than the 32-byte header"));
    assert_int_equal(grid_count(&doc.grid), 0);
    /* No base at all. */
    assert_int_equal(unlink(bp), 0);
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), JOURNAL_ERR_IO);
    assert_non_null(strstr(err, "journal-base-0.argil"));
    assert_int_equal(grid_count(&doc.grid), 0);
    sess_free(s);
}

static void test_checkpoint_rotation(void **state)
{
    (void)state;
    journal_cfg_t c;
    journal_cfg_default(&c);
    c.checkpoint_s = 1.0f;
    sess_t *s = sess_new(&c);
    sess_steps(s, 16); /* 1.5 s simulated: one rotation at 1.0 s */
    assert_int_equal(s->j.stats.checkpoints, 1);
    assert_int_equal(file_size("journal-base-0.argil"), -1);
    assert_true(file_size("journal-base-1.argil") > 0);
    assert_int_equal(file_size(JOURNAL_FILE ".tmp"), -1);
    argil_doc_t doc;
    journal_info_t info;
    char err[512] = "";
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.checkpoint, 1);
    assert_true(info.first_seq > 1);
    assert_int_equal(info.last_seq, s->records);
    assert_int_equal(info.edits, s->records);
    assert_true(gv_same(&doc.grid, GRID_DENSITY, &s->grid, GRID_DENSITY));
    assert_memory_equal(&doc.grid.material, &s->grid.material, sizeof(spring_material_t));
    argil_doc_free(&doc);
    sess_free(s);
}

/* Records stay in memory until the oldest is autosave_s old, in simulated or in real time. */
static void test_autosave_interval(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    char err[512] = "";
    const long header = JOURNAL_HEADER_BYTES;
    assert_true(sess_step(s, 0, 0.0, 0.0));
    assert_int_equal(file_size(JOURNAL_FILE), header);
    assert_int_equal(journal_tick(&s->j, 0.5, 0.4, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(file_size(JOURNAL_FILE), header);
    assert_int_equal(s->j.stats.syncs, 0);
    assert_int_equal(journal_tick(&s->j, 1.0, 0.6, err, sizeof(err)), ARGIL_OK); /* sim 1 s */
    assert_int_equal(s->j.stats.syncs, 1);
    const long one = file_size(JOURNAL_FILE);
    assert_true(one > header);
    assert_true(sess_step(s, 1, 1.1, 0.5));
    assert_int_equal(journal_tick(&s->j, 1.2, 1.49, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(file_size(JOURNAL_FILE), one);
    assert_int_equal(journal_tick(&s->j, 1.2, 1.5, err, sizeof(err)), ARGIL_OK); /* real 1 s */
    assert_int_equal(s->j.stats.syncs, 2);
    assert_true(file_size(JOURNAL_FILE) > one);
    sess_free(s);
}

/* A journal with one record; rewrite fields and fix the record's CRC. */
static uint8_t *one_record(size_t *len)
{
    sess_t *s = sess_new(NULL);
    assert_true(sess_step(s, 0, 0.0, 0.0));
    char err[512] = "", jp[128];
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);
    sess_free(s);
    test_path(jp, sizeof(jp), JOURNAL_FILE);
    return test_slurp(jp, len);
}

static void fix_record_crc(uint8_t *b, size_t len)
{
    const size_t r = JOURNAL_HEADER_BYTES, payload = le_get_u32(b + r);
    if (r + 8 + payload <= len)
        le_put_u32(b + r + 4 + payload, crc32c(0, b + r, 4 + payload));
}

/* Replaying b is refused with code, err naming the byte and rule, and no record counted. */
static void expect_refusal(const uint8_t *b, size_t len, journal_err_t code, const char *rule)
{
    journal_info_t info;
    char err[512] = "";
    static float density[N_SAMPLES];
    const journal_err_t e =
        journal_replay(b, len, "j.log", density, N_SAMPLES, &info, err, sizeof(err));
    if (e != code || journal_err_argil(e) != ARGIL_ERR_PARSE || strstr(err, rule) == NULL ||
        strstr(err, "j.log: byte ") != err)
        fail_msg("wanted %d '%s', got %d '%s'", code, rule, e, err);
    assert_int_equal(info.records, 0);
}

static void test_each_rule(void **state)
{
    (void)state;
    size_t len;
    uint8_t *good = one_record(&len);
    uint8_t *b = malloc(len + 64);
    assert_non_null(b);
    const size_t h = JOURNAL_HEADER_BYTES, p = h + 4; /* record payload */
    journal_info_t info;
    char err[512];
    static float density[N_SAMPLES];
    assert_int_equal(journal_replay(good, len, "j.log", density, N_SAMPLES, &info, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_int_equal(info.records, 1);
    assert_int_equal(
        journal_replay(good, len, "j.log", density, N_SAMPLES - 1, &info, err, sizeof(err)),
        JOURNAL_ERR_ARG);

#define FRESH() memcpy(b, good, len)
    /* Header rules. */
    FRESH();
    b[0] = 'X';
    expect_refusal(b, len, JOURNAL_ERR_MAGIC, "not an argil journal");
    FRESH();
    b[20] ^= 1;
    expect_refusal(b, len, JOURNAL_ERR_HEADER_CRC, "header checksum mismatch");
#define HDR_FIX() le_put_u32(b + h - 4, crc32c(0, b, h - 4))
    FRESH();
    le_put_u32(b + 8, 3);
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_VERSION, "journal version (this argil reads 1..2)");
    FRESH();
    le_put_u32(b + 12, 100);
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_HEADER_SIZE, "header size");
    FRESH();
    le_put_u32(b + 16, 0);
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_DIMS, "grid dimension");
    FRESH();
    le_put_f32(b + 28, -1.0f);
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_GEOMETRY, "spacing");
    FRESH();
    le_put_f32(b + 52, 0.0f); /* node mass */
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_MATERIAL, "material out of range");
    FRESH();
    le_put_u32(b + 76, 0);
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_FIRST_SEQ, "first record number 0");
    FRESH();
    b[96] = '/';
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_BASE_NAME, "plain file name");
    FRESH();
    b[96 + 50] = 'x';
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_BASE_PADDING, "NUL-padded");
    FRESH();
    b[97] = 0x01;
    HDR_FIX();
    expect_refusal(b, len, JOURNAL_ERR_BASE_ASCII, "printable");

    /* Record rules, each with a good CRC. */
    FRESH();
    le_put_u32(b + p, 7);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RECORD_TYPE, "unknown record type 7");
    FRESH();
    le_put_u32(b + 8, 1); /* a version-1 journal has no painted-material records */
    HDR_FIX();
    le_put_u32(b + p, 2);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RECORD_TYPE, "unknown record type 2");
    FRESH();
    le_put_u32(b + p, 2); /* type 2 without its material blocks */
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_MAT_COUNT_HEAD, "material block count runs past the record");
    FRESH();
    le_put_u32(b + p + 4, 5);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RECORD_SEQ, "record 1: number 5, expected 1");
    FRESH();
    le_put_f32(b + p + 28, -1.0f);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RECORD_MATERIAL, "record 1: material out of range");
    FRESH();
    le_put_u32(b + p + 52, N_SAMPLES); /* first run's start: past the last sample */
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RUN_RANGE, "beyond the grid");
    FRESH();
    le_put_u32(b + p + 56, 0); /* first run's count */
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RUN_RANGE, "empty");
    FRESH();
    le_put_f32(b + p + 60, 1.5f);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_DENSITY, "density not a finite number in [0, 1]");
    FRESH();
    le_put_f32(b + p + 60, NAN);
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_DENSITY, "density not a finite number in [0, 1]");
    FRESH();
    le_put_u32(b + p + 48, le_get_u32(b + p + 48) + 1u); /* one run more than there is */
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_RUN_HEAD, "head runs past the record");
    FRESH();
    le_put_u32(b + p + 48, le_get_u32(b + p + 48) - 1u); /* one run less */
    fix_record_crc(b, len);
    expect_refusal(b, len, JOURNAL_ERR_TRAILING, "bytes after the last run");
    /* A record shorter than its head: length 8, its CRC fixed, and a second copy after it so
     * it is not the last. */
    {
        uint8_t small[JOURNAL_HEADER_BYTES + 32];
        memcpy(small, good, h);
        le_put_u32(small + h, 8);
        memset(small + h + 4, 0, 8);
        le_put_u32(small + h + 12, crc32c(0, small + h, 12));
        memcpy(small + h + 16, small + h, 16);
        expect_refusal(small, sizeof(small), JOURNAL_ERR_RECORD_HEAD, "shorter than a record head");
    }
    /* Scanning without a model gives the same verdicts. */
    FRESH();
    assert_int_equal(journal_replay(b, len, "j.log", NULL, 0, &info, err, sizeof(err)),
                     ARGIL_OK);
    assert_int_equal(info.records, 1);
#undef FRESH
#undef HDR_FIX
    free(b);
    free(good);
}

/* A box limits what is compared: changes inside it (clipped to the grid) are recorded, one
 * outside it waits for the next whole-grid record, and replay still ends bit-exact. */
static void test_box_hint(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    grid_t *g = &s->grid;
    char err[512] = "";
    bool appended = false;
    const size_t inside = 1 + EDGE_X * (2 + EDGE_Y * 3);     /* (1, 2, 3) */
    const size_t outside = 9 + EDGE_X * (8 + EDGE_Y * 7);    /* (9, 8, 7) */
    gv_set(g, GRID_DENSITY, inside, 0.123f);
    gv_set(g, GRID_DENSITY, outside, 0.456f);
    const journal_box_t box = {{-5, 0, 1}, {4, 3, 4}};       /* x clipped to [0, 4) */
    assert_int_equal(journal_record(&s->j, &s->grid, &box, 1, 0.01, 0.0, 0, &appended, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_int_equal(s->j.stats.samples, 1);
    const journal_box_t empty = {{3, 3, 3}, {3, 9, 9}};
    assert_int_equal(journal_record(&s->j, &s->grid, &empty, 2, 0.02, 0.0, 0, &appended, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_false(appended);
    const journal_box_t huge = {{-100, -100, -100}, {100, 100, 100}};
    assert_int_equal(journal_record(&s->j, &s->grid, &huge, 2, 0.03, 0.0, 0, &appended, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_int_equal(s->j.stats.samples, 2);
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);
    argil_doc_t doc;
    journal_info_t info;
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 2);
    assert_true(gv_same(&doc.grid, GRID_DENSITY, g, GRID_DENSITY));
    argil_doc_free(&doc);
    sess_free(s);
}


/* Paints (what gsolve_material_to_grid does): channel ch of samples [at, at + n) set to v. */
static void paint(grid_t *g, grid_mat_t ch, size_t at, size_t n, float v)
{
    for (size_t i = 0; i < n; i++)
        gv_mat_set(g, ch, at + i, v);
    assert_true(grid_mat_painted(g, ch));
    g->mat_writes++;
}

static void record(sess_t *s, const journal_box_t *box, double sim_s, bool want)
{
    bool appended = false;
    char err[512] = "";
    assert_int_equal(journal_record(&s->j, &s->grid, box, s->records + 1u, sim_s, sim_s, 0,
                                    &appended, err, sizeof(err)),
                     ARGIL_OK);
    assert_int_equal(appended, want);
    s->records += appended;
    assert_int_equal(journal_tick(&s->j, sim_s, sim_s, err, sizeof(err)), ARGIL_OK);
}

static void assert_mat(const grid_t *got, const grid_t *want)
{
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        if (!grid_mat_equal(got, want, (grid_mat_t)ch))
            fail_msg("painted channel %d differs", ch);
}

/* Painted material is journaled (record type 2) and recovered bit for bit: through a box that
 * does not hold it (mat_writes tells the journal to look), across a rotation onto a painted
 * base, and with a torn last record ignored. */
static void test_painted_material(void **state)
{
    (void)state;
    journal_cfg_t c;
    journal_cfg_default(&c);
    c.checkpoint_s = 1.0f;
    sess_t *s = sess_new(&c);
    const journal_box_t corner = {{0, 0, 0}, {8, 1, 1}}; /* densities compared: 8 samples */
    char err[512] = "";
    paint(&s->grid, GRID_MAT_STIFFNESS, 100, 40, 4.0f);
    paint(&s->grid, GRID_MAT_MASS, 130, 20, 0.5f);
    record(s, &corner, 0.1, true);
    assert_int_equal(s->j.stats.mat_samples, 60);
    /* Unchanged paint, another mat_writes: nothing to record. */
    s->grid.mat_writes++;
    record(s, &corner, 0.2, false);
    /* A change that skips mat_writes waits for the whole-grid comparison. */
    gv_mat_set(&s->grid, GRID_MAT_STIFFNESS, 5, 2.0f);
    record(s, &corner, 0.3, false);
    record(s, NULL, 0.4, true);
    assert_int_equal(s->j.stats.mat_samples, 61);
    /* Rotation at 1 s: the new base holds the paint. */
    record(s, NULL, 1.1, false);
    assert_int_equal(s->j.stats.checkpoints, 1);
    paint(&s->grid, GRID_MAT_STIFFNESS, 100, 10, 3.0f);
    paint(&s->grid, GRID_MAT_RESTLEN, 0, 1, -0.0f);
    gv_set(&s->grid, GRID_DENSITY, 7, 0.75f);
    record(s, &corner, 1.2, true);
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);

    argil_doc_t doc;
    journal_info_t info;
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.checkpoint, 1);
    assert_int_equal(info.records, 1);
    assert_int_equal(info.mat_samples, 11);
    assert_true(gv_same(&doc.grid, GRID_DENSITY, &s->grid, GRID_DENSITY));
    assert_mat(&doc.grid, &s->grid);
    assert_float_equal(gv_mat(&doc.grid, GRID_MAT_STIFFNESS, 105), 3.0f, 0);
    assert_float_equal(gv_mat(&doc.grid, GRID_MAT_STIFFNESS, 139), 4.0f, 0);
    assert_float_equal(gv_mat(&doc.grid, GRID_MAT_MASS, 149), 0.5f, 0);
    assert_true(signbit(gv_mat(&doc.grid, GRID_MAT_RESTLEN, 0)));
    /* The writer's model and the recovered one are the same bytes, painted (version 2). */
    char a[128], b[128];
    test_path(a, sizeof(a), "writer.argil");
    test_path(b, sizeof(b), "recovered.argil");
    assert_int_equal(journal_write_model(&s->j, &s->grid, s->records, a, err, sizeof(err)),
                     ARGIL_OK);
    doc.state.edits = s->records;
    assert_int_equal(argil_file_write(b, &doc, err, sizeof(err)), ARGIL_OK);
    size_t la, lb;
    uint8_t *ba = test_slurp(a, &la), *bb = test_slurp(b, &lb);
    assert_int_equal(la, lb);
    assert_memory_equal(ba, bb, la);
    assert_int_equal(le_get_u32(ba + 8), 2);
    free(ba);
    free(bb);
    argil_doc_free(&doc);

    /* The last record torn: the paint as of the base (stiffness 4 at sample 105). */
    char jp[128];
    test_path(jp, sizeof(jp), JOURNAL_FILE);
    size_t len;
    uint8_t *full = test_slurp(jp, &len);
    test_spit(jp, full, len - 5);
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 0);
    assert_true(info.torn_bytes > 0);
    assert_float_equal(gv_mat(&doc.grid, GRID_MAT_STIFFNESS, 105), 4.0f, 0);
    assert_float_equal(gv_mat(&doc.grid, GRID_MAT_STIFFNESS, 5), 2.0f, 0);
    assert_false(grid_mat_painted(&doc.grid, GRID_MAT_RESTLEN));
    argil_doc_free(&doc);
    test_spit(jp, full, len);

    /* A base whose paint differs from the journal's is refused (the CRC covers the paint). */
    char bp[128];
    test_path(bp, sizeof(bp), "journal-base-1.argil");
    argil_doc_t base;
    assert_int_equal(argil_file_read(bp, &base, err, sizeof(err)), ARGIL_OK);
    gv_mat_set(&base.grid, GRID_MAT_MASS, 130, 0.25f);
    assert_int_equal(argil_file_write(bp, &base, err, sizeof(err)), ARGIL_OK);
    argil_doc_free(&base);
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)),
                     JOURNAL_ERR_BASE_MISMATCH);
    assert_non_null(strstr(err, "is not the one this journal continues"));
    assert_int_equal(grid_count(&doc.grid), 0);

    /* Record rules for the material blocks (the last record's, its CRC fixed). */
    size_t r = JOURNAL_HEADER_BYTES;
    const size_t payload = le_get_u32(full + r);
    const size_t blocks = r + 4 + JOURNAL_RECORD_HEAD_BYTES + 8 + 4; /* one density run of 1 */
    assert_int_equal(le_get_u32(full + r + 4), 2);                 /* type 2 */
    assert_int_equal(le_get_u32(full + blocks), 2);                /* stiffness, rest length */
    journal_info_t ji;
    static float density[N_SAMPLES];
#define MAT_CASE(off, val, code, rule)                                                             \
    do {                                                                                           \
        uint8_t *m = malloc(len);                                                                  \
        assert_non_null(m);                                                                        \
        memcpy(m, full, len);                                                                      \
        le_put_u32(m + (off), (val));                                                              \
        le_put_u32(m + r + 4 + payload, crc32c(0, m + r, 4 + payload));                            \
        const journal_err_t e =                                                                    \
            journal_replay(m, len, "j.log", density, N_SAMPLES, &ji, err, sizeof(err));            \
        if (e != (code) || strstr(err, rule) == NULL)                                              \
            fail_msg("wanted %d '%s', got %d '%s'", (code), rule, e, err);                         \
        free(m);                                                                                   \
    } while (0)
    MAT_CASE(blocks, 0, JOURNAL_ERR_MAT_COUNT, "material block count 0 not in 1..4");
    MAT_CASE(blocks, 5, JOURNAL_ERR_MAT_COUNT, "material block count 5 not in 1..4");
    MAT_CASE(blocks + 4, 9, JOURNAL_ERR_MAT_CHANNEL, "channel 9 not 0..3");
    MAT_CASE(blocks + 8, 0, JOURNAL_ERR_MAT_CHANNEL,
             "channel 0 not 0..3 in increasing order, or no runs");
    MAT_CASE(blocks + 12, N_SAMPLES, JOURNAL_ERR_MAT_RUN_RANGE, "material run 0");
    MAT_CASE(blocks + 16, 0, JOURNAL_ERR_MAT_RUN_RANGE,
             "empty, beyond the grid or past the record");
    MAT_CASE(blocks + 20, 0xff800000u, JOURNAL_ERR_MAT_VALUE,
             "painted material value out of range");
    MAT_CASE(blocks, 3, JOURNAL_ERR_MAT_BLOCK_HEAD, "material block 2 head runs past the record");
    MAT_CASE(blocks, 1, JOURNAL_ERR_TRAILING, "bytes after the last run");
#undef MAT_CASE
    free(full);
    sess_free(s);
}

/* The clay grows past the journal's box (the sparse grid holds any index): the journal rebases
 * onto a new checkpoint over a box that holds it, and recovery rebuilds the grown model bit for
 * bit, in the new box's indices. */
static void test_growth_rebases(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    grid_t *g = &s->grid;
    char err[512] = "";
    bool appended = false;
    assert_int_equal(grid_set(g, GRID_DENSITY, EDGE_X + 5, 2, 3, 0.625f), ARGIL_OK);
    assert_int_equal(grid_set(g, GRID_DENSITY, 1, -3, 2, 1e-40f), ARGIL_OK);
    const journal_box_t box = {{0, -3, 2}, {EDGE_X + 6, 3, 4}};
    assert_int_equal(journal_record(&s->j, g, &box, 1, 0.01, 0.0, 0, &appended, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_int_equal(s->j.stats.rebases, 1);
    assert_int_equal(s->j.stats.checkpoints, 1);
    /* The new box: the old one, grown by JOURNAL_GROW_SAMPLES past each side the clay crossed. */
    assert_int_equal(s->j.lo[0], 0);
    assert_int_equal(s->j.lo[1], -3 - JOURNAL_GROW_SAMPLES);
    assert_int_equal(s->j.dims[0], EDGE_X + 6 + JOURNAL_GROW_SAMPLES);
    /* A change inside the new box is an ordinary record again. */
    assert_int_equal(grid_set(g, GRID_DENSITY, EDGE_X + 2, 0, 0, 0.25f), ARGIL_OK);
    const journal_box_t box2 = {{EDGE_X + 2, 0, 0}, {EDGE_X + 3, 1, 1}};
    assert_int_equal(journal_record(&s->j, g, &box2, 2, 0.02, 0.0, 0, &appended, err,
                                    sizeof(err)),
                     ARGIL_OK);
    assert_true(appended);
    assert_int_equal(s->j.stats.rebases, 1);
    assert_int_equal(journal_sync(&s->j, err, sizeof(err)), ARGIL_OK);
    argil_doc_t doc;
    journal_info_t info;
    assert_int_equal(journal_recover(g_test_dir, &doc, &info, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(info.records, 1);
    assert_int_equal(doc.grid.dims[0], s->j.dims[0]);
    int32_t lo[3], hi[3];
    grid_bounds(g, lo, hi);
    size_t differ = 0, n = 0;
    for (int32_t z = lo[2]; z < hi[2]; z++)
        for (int32_t y = lo[1]; y < hi[1]; y++)
            for (int32_t x = lo[0]; x < hi[0]; x++, n++)
                differ += !gv_bits(grid_get(&doc.grid, GRID_DENSITY, x - s->j.lo[0],
                                            y - s->j.lo[1], z - s->j.lo[2]),
                                   grid_get(g, GRID_DENSITY, x, y, z));
    assert_int_equal(differ, 0);
    assert_true(n > N_SAMPLES);
    assert_float_equal(grid_get(&doc.grid, GRID_DENSITY, EDGE_X + 5, 2 + 3 + JOURNAL_GROW_SAMPLES,
                                3),
                       0.625f, 0.0f);
    argil_doc_free(&doc);
    sess_free(s);
}

static void test_discard_and_bad_config(void **state)
{
    (void)state;
    sess_t *s = sess_new(NULL);
    sess_steps(s, 3);
    char err[512] = "";
    assert_true(journal_exists(g_test_dir));
    assert_int_equal(journal_discard(g_test_dir, err, sizeof(err)), ARGIL_OK);
    assert_false(journal_exists(g_test_dir));
    assert_int_equal(file_size("journal-base-0.argil"), -1);
    journal_info_t info;
    assert_int_equal(journal_probe(g_test_dir, &info, err, sizeof(err)), JOURNAL_ERR_IO);
    sess_free(s);

    journal_t j;
    grid_t g;
    const int32_t dims[3] = {4, 4, 4};
    assert_int_equal(grid_init(&g, dims, 0.01f, vec3(0, 0, 0)), ARGIL_OK);
    journal_cfg_t c;
    journal_cfg_default(&c);
    c.autosave_s = 0.0f;
    assert_int_equal(journal_open(&j, g_test_dir, &g, &c, 0.0, 0.0, err, sizeof(err)), ARGIL_ERR_ARG);
    journal_cfg_default(&c);
    assert_int_equal(journal_open(&j, "/nonexistent/argil", &g, &c, 0.0, 0.0, err, sizeof(err)),
                     ARGIL_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/argil"));
    /* A journal already there is never overwritten. */
    assert_int_equal(journal_open(&j, g_test_dir, &g, &c, 0.0, 0.0, err, sizeof(err)), ARGIL_OK);
    journal_close(&j);
    assert_int_equal(journal_open(&j, g_test_dir, &g, &c, 0.0, 0.0, err, sizeof(err)),
                     ARGIL_ERR_STATE);
    assert_non_null(strstr(err, "unfinished session"));
    grid_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_round_trip, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_no_records_gives_the_base, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_torn_tail_every_byte, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_bad_crc_in_the_middle_stops_there, setup_dir,
                                        test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_wrong_base_refused, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_rotation, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_autosave_interval, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_each_rule, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_box_hint, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_painted_material, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_growth_rebases, setup_dir, test_dir_teardown),
        cmocka_unit_test_setup_teardown(test_discard_and_bad_config, setup_dir, test_dir_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
