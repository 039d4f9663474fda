/* The UDP link's key file (shared/link_key_text.c, read by the board's firmware/hal/link_key.c
 * and the host's host/link/link_key_file.c): a good file in every allowed form, and every rule
 * that refuses one (mode, not a file, bad hex, short, long, two keys, too large), each with a
 * line that names the fix, the same from both readers; argil keygen's writer (0600, never over
 * a file). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "firmware/hal/link_key.h"
#include "host/link/link_key_file.h"

#define HEX64 "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f"

static char g_dir[64];

static int setup(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof(g_dir), "/tmp/argil-key-XXXXXX");
    return mkdtemp(g_dir) ? 0 : -1;
}

static int teardown(void **st)
{
    (void)st;
    char cmd[128];
    snprintf(cmd, sizeof(cmd), "rm -rf %s", g_dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Writes text into g_dir/name with mode; returns the path (static). */
static const char *put(const char *name, const char *text, mode_t mode)
{
    static char path[128];
    snprintf(path, sizeof(path), "%s/%s", g_dir, name);
    unlink(path);
    const int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
    close(fd);
    assert_int_equal(chmod(path, mode), 0);
    return path;
}

typedef link_key_err_t (*key_loader_fn)(const char *path, link_key_t *key, char *err,
                                        size_t err_len);

/* The board's reader and the host's. */
static const key_loader_fn LOADERS[] = {link_key_load, link_key_file_load};

/* Loads path with both readers and asserts the verdict, that the message says what, and that
 * both say the same. */
static void expect(const char *path, link_key_err_t want, const char *says)
{
    link_key_t k;
    char err[400] = "", host_err[400] = "";
    const link_key_err_t e = link_key_load(path, &k, err, sizeof(err));
    const link_key_err_t host_e = link_key_file_load(path, &k, host_err, sizeof(host_err));
    if (host_e != e || strcmp(host_err, err) != 0)
        fail_msg("%s: the board says %s (%s), the host %s (%s)", path, link_key_err_text(e), err,
                 link_key_err_text(host_e), host_err);
    if (e != want)
        fail_msg("%s: got %s (%s), wanted %s", path, link_key_err_text(e), err,
                 link_key_err_text(want));
    if (says && strstr(err, says) == NULL)
        fail_msg("'%s' does not say '%s'", err, says);
    if (want != LINK_KEY_OK && strchr(err, '\n'))
        fail_msg("'%s' is more than one line", err);
}

static void test_a_good_key_file_in_every_allowed_form(void **st)
{
    (void)st;
    static const char *const good[] = {
        HEX64 "\n",
        HEX64,                                                 /* no newline at the end */
        "# argil link key\n\n  " HEX64 "  # the key\n# end\n", /* comments, blanks */
        "\r\n" HEX64 "\r\n",                                   /* CRLF */
        "000102030405060708090A0B0C0D0E0F101112131415161718191A1B1C1D1E1F\n", /* upper case */
    };
    for (size_t i = 0; i < sizeof(good) / sizeof(good[0]); i++)
        for (size_t r = 0; r < sizeof(LOADERS) / sizeof(LOADERS[0]); r++) {
            link_key_t k;
            char err[400];
            memset(&k, 0xee, sizeof(k));
            assert_int_equal(LOADERS[r](put("good", good[i], 0600), &k, err, sizeof(err)),
                             LINK_KEY_OK);
            for (unsigned b = 0; b < LINK_KEY_BYTES; b++)
                assert_int_equal(k.k[b], b);
        }
    expect(put("ro", HEX64 "\n", 0400), LINK_KEY_OK, NULL);
}

static void test_a_file_others_may_read_or_write_is_refused(void **st)
{
    (void)st;
    static const mode_t modes[] = {0644, 0640, 0604, 0620, 0602, 0660, 0666, 0700 | 0001};
    for (size_t i = 0; i < sizeof(modes) / sizeof(modes[0]); i++) {
        const char *p = put("open", HEX64 "\n", modes[i]);
        char fix[160];
        snprintf(fix, sizeof(fix), "chmod 600 %s", p);
        expect(p, LINK_KEY_ERR_MODE, fix);
    }
}

static void test_malformed_keys_are_refused_with_their_line(void **st)
{
    (void)st;
    static const struct {
        const char *text;
        link_key_err_t err;
        const char *says;
    } bad[] = {
        {"", LINK_KEY_ERR_NO_KEY, "no key line"},
        {"# only a comment\n\n", LINK_KEY_ERR_NO_KEY, "no key line"},
        {"# k\n" "g00102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n",
         LINK_KEY_ERR_HEX, ":2: a character that is not a hex digit"},
        {"0001 0203\n", LINK_KEY_ERR_HEX, ":1:"},
        {"0x0102\n", LINK_KEY_ERR_HEX, "hex digit"},
        {"000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1\n",
         LINK_KEY_ERR_SHORT, "fewer than 64 hex digits"},                    /* 63 digits */
        {"00010203\n", LINK_KEY_ERR_SHORT, "truncated"},
        {HEX64 "20\n", LINK_KEY_ERR_LONG, "more than 64 hex digits"},
        {HEX64 "0\n", LINK_KEY_ERR_LONG, "more than 64"},
        {HEX64 "\n" HEX64 "\n", LINK_KEY_ERR_EXTRA, ":2: a second key line"},
    };
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++)
        expect(put("bad", bad[i].text, 0600), bad[i].err, bad[i].says);
    /* the parser alone, as the fuzzer calls it */
    link_key_t k;
    uint32_t line = 0;
    assert_int_equal(link_key_parse("\n\n00\n", 5, &k, &line), LINK_KEY_ERR_SHORT);
    assert_int_equal(line, 3);
    assert_int_equal(link_key_parse(HEX64 "\0", 65, &k, &line), LINK_KEY_ERR_HEX); /* a NUL */
    /* a refused file leaves the caller's key as it was, even after a good first line */
    memset(&k, 0xee, sizeof(k));
    assert_int_equal(link_key_parse(HEX64 "\n" HEX64 "\n", 130, &k, &line), LINK_KEY_ERR_EXTRA);
    for (unsigned b = 0; b < LINK_KEY_BYTES; b++)
        assert_int_equal(k.k[b], 0xee);
}

static void test_what_is_not_a_key_file_is_refused(void **st)
{
    (void)st;
    char p[128];
    snprintf(p, sizeof(p), "%s/dir", g_dir);
    assert_int_equal(mkdir(p, 0700), 0);
    expect(p, LINK_KEY_ERR_NOT_FILE, "not a regular file");
    snprintf(p, sizeof(p), "%s/fifo", g_dir);
    assert_int_equal(mkfifo(p, 0600), 0);
    expect(p, LINK_KEY_ERR_NOT_FILE, "not a regular file"); /* and does not wait for a writer */
    snprintf(p, sizeof(p), "%s/missing", g_dir);
    expect(p, LINK_KEY_ERR_OPEN, "argil keygen");
    char big[LINK_KEY_FILE_MAX + 2];
    memset(big, '#', sizeof(big) - 1u);
    big[sizeof(big) - 1u] = '\0';
    expect(put("big", big, 0600), LINK_KEY_ERR_BIG, "larger than");
}

static void test_keygen_makes_an_owner_only_file_and_never_overwrites(void **st)
{
    (void)st;
    char p[128], q[128], err[400];
    snprintf(p, sizeof(p), "%s/new.key", g_dir);
    snprintf(q, sizeof(q), "%s/other.key", g_dir);
    const mode_t old = umask(0); /* the file must be 0600 whatever the umask */
    assert_int_equal(link_key_file_create(p, err, sizeof(err)), LINK_KEY_OK);
    umask(old);
    struct stat st_;
    assert_int_equal(stat(p, &st_), 0);
    assert_int_equal(st_.st_mode & 07777, 0600);
    expect(p, LINK_KEY_OK, NULL); /* both readers take it */
    link_key_t a, b;
    assert_int_equal(link_key_load(p, &a, err, sizeof(err)), LINK_KEY_OK);
    assert_int_equal(link_key_file_create(p, err, sizeof(err)), LINK_KEY_ERR_EXISTS);
    assert_non_null(strstr(err, "never overwritten"));
    assert_int_equal(link_key_load(p, &b, err, sizeof(err)), LINK_KEY_OK);
    assert_memory_equal(a.k, b.k, LINK_KEY_BYTES); /* unchanged */
    assert_int_equal(link_key_file_create(q, err, sizeof(err)), LINK_KEY_OK);
    assert_int_equal(link_key_load(q, &b, err, sizeof(err)), LINK_KEY_OK);
    assert_memory_not_equal(a.k, b.k, LINK_KEY_BYTES);
    snprintf(q, sizeof(q), "%s/no/such/dir.key", g_dir);
    assert_int_equal(link_key_file_create(q, err, sizeof(err)), LINK_KEY_ERR_WRITE);
}

/* A new file's text: a comment, then the key as 64 lower-case digits, read back the same. */
static void test_a_new_key_files_text_reads_back(void **st)
{
    (void)st;
    link_key_t k, back;
    for (unsigned b = 0; b < LINK_KEY_BYTES; b++)
        k.k[b] = (uint8_t)(0xa5u ^ (7u * b));
    char text[LINK_KEY_TEXT_MAX + 1u];
    const size_t n = link_key_format(&k, text, LINK_KEY_TEXT_MAX);
    assert_true(n > 2u * LINK_KEY_BYTES && text[0] == '#' && text[n - 1u] == '\n');
    text[n] = '\0';
    const char *line = strrchr(text, '\n');
    while (line > text && line[-1] != '\n')
        line--;
    assert_int_equal(strspn(line, "0123456789abcdef"), 2u * LINK_KEY_BYTES);
    uint32_t at = 0;
    assert_int_equal(link_key_parse(text, n, &back, &at), LINK_KEY_OK);
    assert_memory_equal(back.k, k.k, LINK_KEY_BYTES);
    assert_int_equal(link_key_format(&k, text, n - 1u), 0); /* short */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_good_key_file_in_every_allowed_form),
        cmocka_unit_test(test_a_file_others_may_read_or_write_is_refused),
        cmocka_unit_test(test_malformed_keys_are_refused_with_their_line),
        cmocka_unit_test(test_what_is_not_a_key_file_is_refused),
        cmocka_unit_test(test_keygen_makes_an_owner_only_file_and_never_overwrites),
        cmocka_unit_test(test_a_new_key_files_text_reads_back),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
