/* Unit tests for shared/tokens: the one line splitter of the text readers (words, blanks,
 * comments, overflow and the buffer bound). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <string.h>

#include "shared/tokens.h"

#define CASE_WORDS_MAX 6

/* One line, how it is split, and what a reader gets back. */
typedef struct {
    const char *text;
    const char *blanks;
    char comment;
    size_t max_words;
    size_t want_n;                      /* the count returned (max_words + 1: more words) */
    const char *want[CASE_WORDS_MAX];   /* the words stored, NULL after the last */
} split_case_t;

static const split_case_t CASES[] = {
    /* runs of spaces and tabs, around and between words */
    {"  vertex\t1.5  -2 \t 3e1\t", TOKENS_SPACE_TAB, '\0', 4, 4, {"vertex", "1.5", "-2", "3e1"}},
    {"", TOKENS_SPACE_TAB, '\0', 2, 0, {NULL}},
    {" \t \t", TOKENS_SPACE_TAB, '\0', 2, 0, {NULL}},
    /* exactly max_words, trailing blanks included, is not an overflow; one more is */
    {"a b c", TOKENS_SPACE_TAB, '\0', 3, 3, {"a", "b", "c"}},
    {"a b c   ", TOKENS_SPACE_TAB, '\0', 3, 3, {"a", "b", "c"}},
    {"a b c d", TOKENS_SPACE_TAB, '\0', 3, 4, {"a", "b", "c"}},
    {"a b c d e f", TOKENS_SPACE_TAB, '\0', 3, 4, {"a", "b", "c"}},
    {"a", TOKENS_SPACE_TAB, '\0', 0, 1, {NULL}},
    /* only the given blanks separate: a CR is text unless it is one */
    {"up\r down", TOKENS_SPACE_TAB, '\0', 4, 2, {"up\r", "down"}},
    {"up\r down", " \t\r", '\0', 4, 2, {"up", "down"}},
    {"a\vb\fc\rd", TOKENS_C_SPACE, '\0', 4, 4, {"a", "b", "c", "d"}},
    {"a\vb\fc\rd\ne", TOKENS_C_SPACE, '\0', 4, 5, {"a", "b", "c", "d"}},
    /* a word that starts with the comment character ends the line, before any overflow */
    {"press 0.5 # a b c d", TOKENS_C_SPACE, '#', 3, 2, {"press", "0.5"}},
    {"   #only a comment", TOKENS_C_SPACE, '#', 3, 0, {NULL}},
    {"a b c #d", TOKENS_C_SPACE, '#', 3, 3, {"a", "b", "c"}},
    /* inside a word it is text, and with no comment character it is a word */
    {"tool#2 x", TOKENS_C_SPACE, '#', 3, 2, {"tool#2", "x"}},
    {"a # b", TOKENS_SPACE_TAB, '\0', 3, 3, {"a", "#", "b"}},
};

static void test_lines_split_into_the_words_a_reader_expects(void **st)
{
    (void)st;
    for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
        const split_case_t *k = &CASES[c];
        char buf[64];
        char *words[CASE_WORDS_MAX];
        const size_t len = strlen(k->text);
        assert_true(len < sizeof buf && k->max_words <= CASE_WORDS_MAX);
        memcpy(buf, k->text, len + 1u);
        const size_t n = tokens_split(buf, sizeof buf, k->blanks, k->comment, words, k->max_words);
        if (n != k->want_n)
            fail_msg("case %zu \"%s\": %zu words, want %zu", c, k->text, n, k->want_n);
        for (size_t i = 0; i < CASE_WORDS_MAX && k->want[i] != NULL; i++)
            assert_string_equal(words[i], k->want[i]);
    }
}

static void test_the_scan_stops_at_cap(void **st)
{
    (void)st;
    char buf[8] = {'a', 'b', ' ', 'c', 'd', '\0', 'x', '\0'};
    char *w[4];
    assert_int_equal(tokens_split(buf, 3, TOKENS_SPACE_TAB, '\0', w, 4), 1);
    assert_string_equal(w[0], "ab");
    assert_int_equal(buf[3], 'c'); /* nothing past cap is read or written */
    assert_int_equal(tokens_split(buf, 0, TOKENS_SPACE_TAB, '\0', w, 4), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lines_split_into_the_words_a_reader_expects),
        cmocka_unit_test(test_the_scan_stops_at_cap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
