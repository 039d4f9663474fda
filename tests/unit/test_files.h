/* Temporary-directory and whole-file helpers shared by the cmocka tests that write files
 * (include after <cmocka.h>). Each test binary gets one directory, made by test_dir_setup as a
 * group setup and removed with everything in it by test_dir_teardown. */
#ifndef ARGIL_TEST_FILES_H
#define ARGIL_TEST_FILES_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char g_test_dir[64];

/* mkdtemp under /tmp with the given name prefix (e.g. "argil_test_journal"). */
static inline int test_dir_make(const char *prefix)
{
    snprintf(g_test_dir, sizeof(g_test_dir), "/tmp/%s_XXXXXX", prefix);
    return mkdtemp(g_test_dir) != NULL ? 0 : -1;
}

static inline int test_dir_teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof(cmd), "rm -rf '%s'", g_test_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* out = "<test dir>/name". */
static inline void test_path(char *out, size_t cap, const char *name)
{
    snprintf(out, cap, "%s/%s", g_test_dir, name);
}

/* The whole file (one spare byte allocated after it); fails the test if it cannot be read. */
static inline uint8_t *test_slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    const long n = ftell(fp);
    assert_true(n >= 0);
    rewind(fp);
    uint8_t *b = malloc((size_t)n + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    *len = (size_t)n;
    return b;
}

/* Writes len bytes to path (replacing it); fails the test on any error. */
static inline void test_spit(const char *path, const void *data, size_t len)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(data, 1, len, fp), len);
    assert_int_equal(fclose(fp), 0);
}

#endif
