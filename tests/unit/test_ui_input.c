/* The live window's scripted-input parser: every kind of event parses to what it says, and every
 * malformed line is refused with "line N: why", keeping nothing. */
#define GLFW_INCLUDE_NONE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include <GLFW/glfw3.h>

#include "host/render/ui_input.h"

static void test_accepts_each_event(void **state)
{
    (void)state;
    const char *text = "# a demo\n"
                       "\n"
                       "0.5 key 2   # tool push\n"
                       "1 cursor 320.5 -4\n"
                       "1 left down\n"
                       "1.5 right up\r\n"
                       "2 shift down\n"
                       "3 wheel -2.5\n"
                       "4 key ESC";
    ui_input_t in;
    ui_input_init(&in);
    char err[256] = "";
    assert_int_equal(ui_input_parse(&in, text, strlen(text), err, sizeof(err)), UI_INPUT_OK);
    assert_int_equal(in.count, 7);
    assert_int_equal(in.ev[0].kind, UI_EV_KEY);
    assert_int_equal(in.ev[0].code, GLFW_KEY_2);
    assert_int_equal(in.ev[0].line, 3);
    assert_true(in.ev[0].at_s == 0.5);
    assert_int_equal(in.ev[1].kind, UI_EV_CURSOR);
    assert_true(in.ev[1].x == 320.5 && in.ev[1].y == -4.0);
    assert_int_equal(in.ev[2].kind, UI_EV_LEFT);
    assert_int_equal(in.ev[2].down, 1);
    assert_int_equal(in.ev[3].kind, UI_EV_RIGHT);
    assert_int_equal(in.ev[3].down, 0);
    assert_int_equal(in.ev[4].kind, UI_EV_SHIFT);
    assert_int_equal(in.ev[5].kind, UI_EV_WHEEL);
    assert_true(in.ev[5].x == -2.5);
    assert_int_equal(in.ev[6].code, GLFW_KEY_ESCAPE);
    assert_int_equal(ui_input_key_code("PLUS"), GLFW_KEY_EQUAL);
    assert_int_equal(ui_input_key_code("F"), -1);
    ui_input_free(&in);
}

#define E(rule) UI_INPUT_ERR_##rule /* a rule's code, in the table of refused lines */

/* Parsing text is refused with code and exactly the message want, keeping nothing. */
static void refused(const char *text, size_t len, ui_input_err_t code, const char *want)
{
    ui_input_t in;
    ui_input_init(&in);
    char err[256] = "";
    assert_int_equal(ui_input_parse(&in, text, len, err, sizeof(err)), code);
    if (strcmp(err, want) != 0)
        fail_msg("for '%s': got '%s', want '%s'", text, err, want);
    assert_int_equal(in.count, 0);
    assert_null(in.ev);
}

static void test_refuses_with_line(void **state)
{
    (void)state;
    const struct {
        const char *text, *want;
        ui_input_err_t code;
    } cases[] = {
        {"x key 1", "line 1: time is not a number of seconds 0..1e6: 'x'", E(TIME)},
        {"-1 key 1", "line 1: time is not a number of seconds 0..1e6: '-1'", E(TIME)},
        {"nan key 1", "line 1: time is not a number of seconds 0..1e6: 'nan'", E(TIME)},
        {"1 key 1\n0.5 key 2", "line 2: time goes backwards: '0.5'", E(TIME_BACKWARDS)},
        {"1", "line 1: an event is missing after the time", E(EVENT_MISSING)},
        {"1 key", "line 1: key needs one NAME", E(KEY_ARGS)},
        {"1 key F", "line 1: unknown key 'F'", E(KEY)},
        {"1 left sideways", "line 1: needs down or up: 'left'", E(UP_DOWN)},
        {"1 shift", "line 1: needs down or up: 'shift'", E(UP_DOWN)},
        {"1 cursor 1", "line 1: cursor needs X Y in pixels (within 1e5)", E(CURSOR)},
        {"1 cursor 1 2e6", "line 1: cursor needs X Y in pixels (within 1e5)", E(CURSOR)},
        {"1 wheel 500", "line 1: wheel needs STEPS within -100..100", E(WHEEL)},
        {"1 jump", "line 1: unknown event 'jump'", E(EVENT)},
        {"1 key 1 2 3", "line 1: too many words", E(WORDS)},
        {"1 a b c d e", "line 1: too many words", E(WORDS)},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++)
        refused(cases[i].text, strlen(cases[i].text), cases[i].code, cases[i].want);
    const char nul[] = "1 key 1\n2 k\0y 1\n";
    refused(nul, sizeof(nul) - 1, E(LINE_NUL), "line 2: NUL byte in the line");
    char longline[400];
    memset(longline, ' ', sizeof(longline));
    memcpy(longline, "1 key 1", 7);
    refused(longline, sizeof(longline), E(LINE_LONG), "line 1: line longer than 255 characters");
}

static void test_load_names_the_file(void **state)
{
    (void)state;
    ui_input_t in;
    char err[512] = "";
    assert_int_equal(ui_input_load(&in, "/nonexistent/input.txt", err, sizeof(err)),
                     UI_INPUT_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/input.txt: cannot open"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accepts_each_event),
        cmocka_unit_test(test_refuses_with_line),
        cmocka_unit_test(test_load_names_the_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
