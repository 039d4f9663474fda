/* The script verbs for the host tool (action, action_shape, mirror): parsed, played into the
 * player's setting, and every bad line refused with its line number; `shape` still names the
 * board tool's path sampling. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "host/app/script.h"
#include "shared/proto.h"

#define E(rule) SCRIPT_ERR_##rule /* a rule's code, in the list of the bad lines' rules */

static script_err_t parse(script_t *s, const char *text, char *err)
{
    return script_parse(s, text, strlen(text), err, 256);
}

static void test_verbs_parse_and_play(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256] = "";
    const char *text = "tool carve\nshape curve\naction add\naction_shape box\nmirror xz\n"
                       "action toothpaste strength 12.5\nwait 0.1\naction chisel\n"
                       "action_shape torus\nmirror none\naction interior-carve\nwait 0.1\n";
    assert_int_equal(parse(&s, text, err), ARGIL_OK);
    assert_int_equal(s.count, 12);
    assert_int_equal(s.cmds[1].op, SCRIPT_SHAPE); /* the board's path sampling, as before */
    assert_int_equal(s.cmds[1].arg_int, TOOL_SHAPE_CURVE);
    assert_int_equal(s.cmds[2].op, SCRIPT_ACTION);
    assert_int_equal(s.cmds[2].arg_int, HOST_ACT_ADD);
    assert_int_equal(s.cmds[3].op, SCRIPT_ACTION_SHAPE);
    assert_int_equal(s.cmds[3].arg_int, HOST_SHAPE_BOX);
    assert_int_equal(s.cmds[4].op, SCRIPT_MIRROR);
    assert_int_equal(s.cmds[4].arg_int, HOST_MIRROR_X | HOST_MIRROR_Z);
    assert_float_equal(s.cmds[5].value, 12.5f, 0.0f);
    assert_int_equal(script_first_host_tool_line(&s), 3);

    script_player_t p;
    script_player_init(&p, &s, vec3(0, 0, 0.06f));
    assert_true(host_tool_is_default(&p.host_tool));
    p.params_changed = 0;
    assert_int_equal(script_player_step(&p, 0.01f), 0); /* up to the first wait */
    assert_int_equal(p.shape, TOOL_SHAPE_CURVE);
    assert_int_equal(p.host_tool.action, HOST_ACT_TOOTHPASTE);
    assert_float_equal(p.host_tool.strength, 12.5f, 0.0f);
    assert_int_equal(p.host_tool.shape, HOST_SHAPE_BOX);
    assert_int_equal(p.host_tool.mirror, HOST_MIRROR_X | HOST_MIRROR_Z);
    assert_int_equal(p.params_changed, 1);
    for (int k = 0; k < 10; k++)
        (void)script_player_step(&p, 0.01f); /* the wait ends, the next commands start */
    assert_int_equal(p.host_tool.action, HOST_ACT_INTERIOR_CARVE);
    assert_int_equal(p.host_tool.shape, HOST_SHAPE_TORUS);
    assert_int_equal(p.host_tool.mirror, 0u);
    assert_true(host_tool_valid(&p.host_tool));
    script_free(&s);

    /* no strength given: the action's default (chisel 2 mm/s), none for carve */
    assert_int_equal(parse(&s, "action chisel\naction carve\n", err), ARGIL_OK);
    assert_float_equal(s.cmds[0].value, 2.0f, 0.0f);
    assert_float_equal(s.cmds[1].value, 0.0f, 0.0f);
    assert_int_equal(parse(&s, "wait 1\n", err), ARGIL_OK);
    assert_int_equal(script_first_host_tool_line(&s), 0);
    script_free(&s);
}

static void test_bad_lines_name_the_line_and_rule(void **st)
{
    (void)st;
    const struct {
        const char *text, *expect;
    } cases[] = {
        {"wait 1\naction\n", "line 2: 'action' takes a name (carve, add, toothpaste, soft-erase, "
                             "smooth, stamp, chisel, squirt, interior-carve, paint, soft-paint) "
                             "and optionally strength S (paint and soft-paint: rgb R G B)"},
        {"action pinch\n", "line 1: unknown action 'pinch' (carve, add,"},
        {"action paint rgb 1 2\n", "line 1: 'rgb' takes three whole numbers 0 … 255 (R G B)"},
        {"action paint rgb 1 2 256\n", "line 1: 'rgb' takes three whole numbers 0 … 255, got '256'"},
        {"action paint rgb 1 -2 3\n", "line 1: 'rgb' takes three whole numbers 0 … 255, got '-2'"},
        {"action paint rgb 1 2 3.5\n", "line 1: 'rgb' takes three whole numbers 0 … 255, got '3.5'"},
        {"action paint rgb 1 2 3 rgb 4 5 6\n", "line 1: too many words"},
        {"action soft-paint rgb 1 2 3 rgb 4\n", "line 1: 'rgb' given twice"},
        {"action paint strength 3\n", "line 1: 'action paint' takes no strength"},
        {"action paint colour 3\n", "line 1: 'action paint' takes NAME [rgb R G B], not 'colour'"},
        {"action soft-paint rgb 1 2 3 strength 2 strength 3\n", "line 1: too many words"},
        {"action soft-paint strength 2 strength 3\n", "line 1: 'strength' given twice"},
        {"action smooth rgb 1 2 3\n", "line 1: 'action smooth' takes no colour"},
        {"action add strength 3\n", "line 1: 'action add' takes no strength"},
        {"action smooth strength\n", "line 1: 'action' takes a name"},
        {"action smooth power 3\n", "line 1: 'action' takes NAME [strength S], not 'power'"},
        {"action smooth strength x\n", "line 1: 'x' is not a number"},
        {"action smooth strength 101\n", "line 1: strength must be within 0 … 100, got 101"},
        {"action smooth strength -1\n", "line 1: strength must be within 0 … 100, got -1"},
        {"action_shape\n", "line 1: 'action_shape' takes one name (sphere, box, cylinder, torus)"},
        {"action_shape point\n", "line 1: unknown action_shape 'point' (sphere, box, cylinder, "
                                 "torus)"},
        {"shape box\n", "line 1: unknown shape 'box' (point, curve, area)"},
        {"mirror\n", "line 1: 'mirror' takes one word: none, or the axes x, y, z"},
        {"mirror x y\n", "line 1: 'mirror' takes one word"},
        {"mirror xx\n", "line 1: unknown mirror 'xx'"},
        {"mirror w\n", "line 1: unknown mirror 'w'"},
        {"mirror xyzx\n", "line 1: unknown mirror 'xyzx'"},
        {"actoin add\n", "line 1: unknown command 'actoin' (tool, shape, filter, axis, set, move, "
                         "press, release, wait, paint, refine, action, action_shape, mirror, undo, "
                         "redo)"},
    };
    /* the rule each case breaks, in the order of cases */
    static const script_err_t codes[] = {
        E(ARGS), E(NAME), E(ARGS), E(NUMBER), E(NUMBER), E(NUMBER), E(WORDS), E(REPEATED),
        E(OPTION), E(OPTION), E(WORDS), E(REPEATED), E(OPTION), E(OPTION), E(ARGS), E(OPTION),
        E(NUMBER), E(RANGE), E(RANGE), E(ARGS), E(NAME), E(NAME), E(ARGS), E(ARGS), E(NAME),
        E(NAME), E(NAME), E(COMMAND)
    };
    assert_int_equal(sizeof(codes) / sizeof(codes[0]), sizeof(cases) / sizeof(cases[0]));
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        script_t s;
        script_init(&s);
        char err[256] = "";
        const script_err_t e = parse(&s, cases[i].text, err);
        if (e != codes[i] || strncmp(err, cases[i].expect, strlen(cases[i].expect)) != 0)
            fail_msg("case %zu: got %d \"%s\", want %d \"%s\"", i, e, err, codes[i],
                     cases[i].expect);
        assert_null(strchr(err, '\n')); /* one line */
        script_free(&s);
    }
}

/* `action paint [rgb R G B]`, `action soft-paint [rgb R G B] [strength S]`: the colour and
 * strength reach the player's host tool (terracotta 200 60 40 when no rgb is given). */
static void test_paint_verbs(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256] = "";
    assert_int_equal(parse(&s, "action paint\nwait 0.1\naction soft-paint strength 7 rgb 10 20 30\n"
                               "wait 0.1\naction paint rgb 0 255 1\n", err),
                     ARGIL_OK);
    assert_int_equal(s.cmds[0].arg_int, HOST_ACT_PAINT);
    assert_int_equal(s.cmds[2].arg_int, HOST_ACT_SOFT_PAINT);
    script_player_t p;
    script_player_init(&p, &s, vec3(0, 0, 0.06f));
    const uint8_t terracotta[3] = {200, 60, 40}, c1[3] = {10, 20, 30}, c2[3] = {0, 255, 1};
    (void)script_player_step(&p, 0.01f);
    assert_int_equal(p.host_tool.action, HOST_ACT_PAINT);
    assert_memory_equal(p.host_tool.rgb, terracotta, 3);
    assert_true(host_action_paints(p.host_tool.action));
    for (int k = 0; k < 11; k++)
        (void)script_player_step(&p, 0.01f);
    assert_int_equal(p.host_tool.action, HOST_ACT_SOFT_PAINT);
    assert_float_equal(p.host_tool.strength, 7.0f, 0.0f);
    assert_memory_equal(p.host_tool.rgb, c1, 3);
    for (int k = 0; k < 11; k++)
        (void)script_player_step(&p, 0.01f);
    assert_int_equal(p.host_tool.action, HOST_ACT_PAINT);
    assert_memory_equal(p.host_tool.rgb, c2, 3);
    assert_true(host_tool_valid(&p.host_tool));
    assert_false(host_action_paints(HOST_ACT_CARVE));
    assert_float_equal(host_action_default_strength(HOST_ACT_SOFT_PAINT), 20.0f, 0.0f);
    assert_false(host_action_has_strength(HOST_ACT_PAINT));
    script_free(&s);
}

static void test_names_round_trip(void **st)
{
    (void)st;
    for (int a = 0; a < HOST_ACT_COUNT; a++)
        assert_int_equal(host_action_from_name(host_action_name((host_action_t)a)), a);
    for (int k = 0; k < HOST_SHAPE_COUNT; k++)
        assert_int_equal(host_shape_from_name(host_shape_name((host_shape_t)k)), k);
    char name[8];
    for (uint32_t m = 0; m <= HOST_MIRROR_ALL; m++) {
        host_mirror_name(m, name);
        assert_int_equal(host_mirror_from_name(name), (int)m);
    }
    assert_int_equal(host_mirror_from_name("zyx"), (int)HOST_MIRROR_ALL);
    assert_int_equal(host_mirror_from_name(""), -1);
    assert_string_equal(host_action_name(HOST_ACT_COUNT), "?");
    assert_false(host_action_has_strength(HOST_ACT_CARVE));
    assert_true(host_action_has_strength(HOST_ACT_SMOOTH));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_verbs_parse_and_play),
        cmocka_unit_test(test_bad_lines_name_the_line_and_rule),
        cmocka_unit_test(test_names_round_trip),
        cmocka_unit_test(test_paint_verbs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
