/* Session script parser and player: every error branch names its line. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "host/app/script.h"
#include "shared/proto.h"

static script_err_t parse(script_t *s, const char *text, char *err)
{
    return script_parse(s, text, strlen(text), err, 256);
}

static void test_parses_every_command(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256];
    const char *text = "# comment\n\ntool push   # trailing comment\nset radius_mm 5.5\r\n"
                       "move 1 2 -3 0.5\npress 1\nwait 0.25\nrelease 1\npress 2\n";
    assert_int_equal(parse(&s, text, err), ARGIL_OK);
    assert_int_equal(s.count, 7);
    assert_int_equal(s.cmds[0].op, SCRIPT_TOOL);
    assert_int_equal(s.cmds[0].arg_int, TOOL_PUSH);
    assert_int_equal(s.cmds[0].line, 3);
    assert_int_equal(s.cmds[1].arg_int, PARAM_RADIUS_MM);
    assert_float_equal(s.cmds[1].value, 5.5f, 1e-6f);
    assert_float_equal(s.cmds[2].target_m.z, -0.003f, 1e-7f);
    assert_int_equal(s.cmds[3].op, SCRIPT_PRESS);
    assert_float_equal(script_duration_s(&s), 0.75f, 1e-6f);
    script_free(&s);
}

static void test_errors_name_the_line_and_rule(void **st)
{
    (void)st;
    const struct {
        const char *text, *expect;
        script_err_t code;
    } cases[] = {
        {"wait 1\nmvoe 1 2 3 4\n", "line 2: unknown command 'mvoe'", SCRIPT_ERR_COMMAND},
        {"tool pinch\n", "line 1: unknown tool 'pinch'", SCRIPT_ERR_NAME},
        {"tool\n", "line 1: 'tool' takes one name", SCRIPT_ERR_ARGS},
        {"set radius_mm\n", "line 1: 'set' takes a name and a value", SCRIPT_ERR_ARGS},
        {"set colour 3\n", "line 1: unknown parameter 'colour'", SCRIPT_ERR_NAME},
        {"set alpha abc\n", "line 1: 'abc' is not a number", SCRIPT_ERR_NUMBER},
        {"set radius_mm 100\n", "line 1: radius_mm must be within", SCRIPT_ERR_RANGE},
        {"set radius_mm nan\n", "line 1: 'nan' is not a number", SCRIPT_ERR_NUMBER},
        {"move 1 2 3\n", "line 1: 'move' takes X Y Z", SCRIPT_ERR_ARGS},
        {"move 1 2 x 1\n", "line 1: 'move' arguments must be numbers", SCRIPT_ERR_NUMBER},
        {"move 1 2 9000 1\n", "line 1: move target beyond", SCRIPT_ERR_RANGE},
        {"move 1 2 3 0\n", "line 1: move duration must be within", SCRIPT_ERR_RANGE},
        {"press 3\n", "line 1: 'press' takes a button number", SCRIPT_ERR_ARGS},
        {"release\n", "line 1: 'release' takes a button number", SCRIPT_ERR_ARGS},
        {"wait\n", "line 1: 'wait' takes SECONDS", SCRIPT_ERR_ARGS},
        {"wait -1\n", "line 1: wait must be within", SCRIPT_ERR_RANGE},
        {"move 1 2 3 4 5 6\n", "line 1: too many words", SCRIPT_ERR_WORDS},
        {"wait 3000\nwait 3000\n", "line 2: the script runs longer than", SCRIPT_ERR_DURATION},
    };
    for (unsigned i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        script_t s;
        script_init(&s);
        char err[256] = "";
        const script_err_t e = parse(&s, cases[i].text, err);
        if (e != cases[i].code || strncmp(err, cases[i].expect, strlen(cases[i].expect)) != 0)
            fail_msg("case %u: got %d '%s', want %d '%s…'", i, e, err, cases[i].code,
                     cases[i].expect);
        script_free(&s);
    }
    /* A line too long and an embedded NUL. */
    char big[700];
    memset(big, 'a', sizeof(big));
    script_t s;
    script_init(&s);
    char err[256];
    assert_int_equal(script_parse(&s, big, sizeof(big), err, sizeof(err)), SCRIPT_ERR_LINE_LONG);
    assert_non_null(strstr(err, "longer than"));
    const char nul[] = "wait 1\nwa\0it 1\n";
    assert_int_equal(script_parse(&s, nul, sizeof(nul) - 1, err, sizeof(err)), SCRIPT_ERR_LINE_NUL);
    assert_non_null(strstr(err, "line 2"));
    script_free(&s);
}

static void test_missing_file_names_the_path(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256];
    assert_int_equal(script_load(&s, "/nonexistent/x.scn", err, sizeof(err)), SCRIPT_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/x.scn: cannot open"));
}

static void test_player_moves_at_constant_speed(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256];
    assert_int_equal(parse(&s, "press 1\nmove 10 0 0 1\nrelease 1\nwait 0.5\n", err), ARGIL_OK);
    script_player_t p;
    script_player_init(&p, &s, vec3(0, 0, 0));
    int ticks = 0, done = 0;
    float x_at_half = -1.0f;
    while (!done && ticks < 5000) {
        done = script_player_step(&p, 0.001f);
        ticks++;
        if (ticks == 500)
            x_at_half = p.pos_m.x;
        if (ticks == 100) {
            assert_int_equal(p.buttons & 1, 1);
            assert_float_equal(p.vel_m_s.x, 0.010f, 1e-4f); /* 10 mm in 1 s */
        }
    }
    assert_float_equal(x_at_half, 0.005f, 2e-5f);
    assert_float_equal(p.pos_m.x, 0.010f, 1e-6f);
    assert_int_equal(p.buttons, 0);
    assert_in_range(ticks, 1499, 1502);
    script_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parses_every_command),
        cmocka_unit_test(test_errors_name_the_line_and_rule),
        cmocka_unit_test(test_missing_file_names_the_path),
        cmocka_unit_test(test_player_moves_at_constant_speed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
