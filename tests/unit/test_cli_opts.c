/* The commands' command-line reader (host/app/cli_opts.h): flags, numbers and words land in the
 * options struct by their tables, -o and the input are taken, and every refusal ends the
 * command with exit status 2 and ARGIL_ERR_ARG; --help ends it with 0. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "host/app/cli_opts.h"

/* What the test command's command line asks for. */
typedef struct {
    const char *in, *out, *name;
    double size, box[3];
    bool loud, quiet;
} test_opts_t;

static int g_usage_calls;

/* The test command's --help text (counted, not printed). */
static void usage_test(FILE *f)
{
    (void)f;
    g_usage_calls++;
}

static const cli_flag_t TEST_FLAGS[] = {
    {"--quiet", offsetof(test_opts_t, quiet), true},
    {"--loud", offsetof(test_opts_t, loud), false},
};
static const cli_number_t TEST_NUMBERS[] = {
    {"--size", 1, 10, offsetof(test_opts_t, size), 1, true},
    {"--box", -1, 1, offsetof(test_opts_t, box), 3, false},
};
static const cli_word_t TEST_WORDS[] = {{"--name", offsetof(test_opts_t, name)}};
static const cli_cmd_t TEST_CLI = {
    .name = "test", .usage = usage_test,
    .flags = TEST_FLAGS, .n_flags = 2, .numbers = TEST_NUMBERS, .n_numbers = 2,
    .words = TEST_WORDS, .n_words = 1,
    .out_needs = "a value", .out = offsetof(test_opts_t, out),
    .inputs = true, .input = offsetof(test_opts_t, in),
};

/* Parses the n words of argv into *o (defaults first); the exit status into *status. */
static argil_err_t parse(int n, const char **argv, test_opts_t *o, bool *done, int *status)
{
    const test_opts_t def = {NULL, NULL, NULL, 5, {0, 0, 0}, true, false};
    *o = def;
    *status = -1;
    return cli_parse(&TEST_CLI, o, n, (char **)argv, done, status);
}

static void test_tables_fill_the_options(void **state)
{
    (void)state;
    const char *argv[] = {"in.ply", "--quiet", "--loud", "--size", "7", "--box", "0.5",
                          "-0.5", "1", "--name", "n", "-o", "out.ply"};
    test_opts_t o;
    bool done;
    int status;
    assert_int_equal(parse(13, argv, &o, &done, &status), ARGIL_OK);
    assert_false(done);
    assert_int_equal(status, -1);
    assert_string_equal(o.in, "in.ply");
    assert_string_equal(o.out, "out.ply");
    assert_string_equal(o.name, "n");
    assert_true(o.quiet);
    assert_false(o.loud);
    assert_true(o.size == 7.0);
    assert_true(o.box[0] == 0.5 && o.box[1] == -0.5 && o.box[2] == 1.0);
}

static void test_help_ends_with_zero(void **state)
{
    (void)state;
    const char *argv[] = {"--size", "3", "-h", "--bogus"};
    test_opts_t o;
    bool done;
    int status;
    g_usage_calls = 0;
    assert_int_equal(parse(4, argv, &o, &done, &status), ARGIL_OK);
    assert_true(done);
    assert_int_equal(status, 0);
    assert_int_equal(g_usage_calls, 1);
}

/* Each command line is refused: done, exit status 2, ARGIL_ERR_ARG. */
static void test_refusals_end_with_two(void **state)
{
    (void)state;
    static const char *const lines[][4] = {
        {"--size", "11", NULL},          /* out of range */
        {"--size", "2.5", NULL},         /* not whole */
        {"--size", NULL},                /* no value */
        {"--box", "0", "0", NULL},       /* too few numbers */
        {"--name", NULL},                /* no word */
        {"-o", NULL},                    /* no file */
        {"--bogus", NULL},               /* unknown */
        {"-", NULL},                     /* a lone dash is no input here */
        {"a", "b", NULL},                /* a second input */
    };
    for (size_t k = 0; k < sizeof(lines) / sizeof(lines[0]); k++) {
        int n = 0;
        while (n < 4 && lines[k][n] != NULL)
            n++;
        test_opts_t o;
        bool done = false;
        int status = -1;
        assert_int_equal(parse(n, (const char **)lines[k], &o, &done, &status), ARGIL_ERR_ARG);
        assert_true(done);
        assert_int_equal(status, 2);
    }
}

static void test_session_options_take_only_their_places(void **state)
{
    (void)state;
    uint32_t undo_mb = 1;
    int knot = 1;
    const cli_session_t s = {NULL, NULL, &knot, NULL, NULL, NULL, &undo_mb};
    const char *ok[] = {"--undo-mb", "64", "--knot-ratio", "4"};
    int i = 0;
    assert_int_equal(cli_session_option("test", &s, 4, (char **)ok, &i), CLI_OPT_TAKEN);
    assert_int_equal(i, 1);
    i = 2;
    assert_int_equal(cli_session_option("test", &s, 4, (char **)ok, &i), CLI_OPT_TAKEN);
    assert_int_equal(undo_mb, 64);
    assert_int_equal(knot, 4);
    const char *bad[] = {"--undo-mb", "70000", "--rate-hz", "1000"};
    i = 0;
    assert_int_equal(cli_session_option("test", &s, 4, (char **)bad, &i), CLI_OPT_BAD);
    assert_int_equal(undo_mb, 64);
    i = 2; /* no place for --rate-hz: not this command's option */
    assert_int_equal(cli_session_option("test", &s, 4, (char **)bad, &i), CLI_OPT_OTHER);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tables_fill_the_options),
        cmocka_unit_test(test_help_ends_with_zero),
        cmocka_unit_test(test_refusals_end_with_two),
        cmocka_unit_test(test_session_options_take_only_their_places),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
