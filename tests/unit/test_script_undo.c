/* The script verbs undo and redo: parsed (with their line), refused with arguments, found for
 * the springs check, and played as a wait: the hand holds still at the verb until the session
 * clears it, then the script goes on. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "host/app/script.h"

static void test_parse(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256] = "";
    const char *text = "move 0 0 40 0.1\n# c\nundo\nredo\n";
    assert_int_equal(script_parse(&s, text, strlen(text), err, sizeof(err)), ARGIL_OK);
    assert_int_equal(s.count, 3);
    assert_int_equal(s.cmds[1].op, SCRIPT_UNDO);
    assert_int_equal(s.cmds[1].line, 3);
    assert_int_equal(s.cmds[2].op, SCRIPT_REDO);
    assert_int_equal(script_first_history_line(&s), 3);
    const char *bad = "wait 1\nundo 2\n";
    assert_int_equal(script_parse(&s, bad, strlen(bad), err, sizeof(err)), SCRIPT_ERR_ARGS);
    assert_string_equal(err, "line 2: 'undo' takes no arguments");
    const char *none = "wait 1\n";
    assert_int_equal(script_parse(&s, none, strlen(none), err, sizeof(err)), ARGIL_OK);
    assert_int_equal(script_first_history_line(&s), 0);
    script_free(&s);
}

static void test_player_waits_at_the_verb(void **st)
{
    (void)st;
    script_t s;
    script_init(&s);
    char err[256] = "";
    const char *text = "move 0 0 40 0.01\nundo\nmove 0 0 30 0.01\n";
    assert_int_equal(script_parse(&s, text, strlen(text), err, sizeof(err)), ARGIL_OK);
    script_player_t p;
    script_player_init(&p, &s, vec3(0, 0, 0.06f));
    for (int k = 0; k < 12; k++) /* the 10 ms move, then the verb */
        assert_int_equal(script_player_step(&p, 0.001f), 0);
    assert_int_equal(p.history_op, SCRIPT_UNDO);
    assert_int_equal(p.history_line, 2);
    /* held: the hand stays at 40 mm, however long the session takes */
    for (int k = 0; k < 100; k++)
        assert_int_equal(script_player_step(&p, 0.001f), 0);
    assert_float_equal(p.pos_m.z, 0.040f, 1e-6f);
    assert_float_equal(p.vel_m_s.z, 0.0f, 0.0f);
    p.history_op = 0; /* the session did it */
    int done = 0;
    for (int k = 0; k < 30 && !done; k++)
        done = script_player_step(&p, 0.001f);
    assert_true(done);
    assert_float_equal(p.pos_m.z, 0.030f, 1e-6f);
    script_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_player_waits_at_the_verb),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
