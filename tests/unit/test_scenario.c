/* Scenario parser (sim/scenario.c): the shipped scenarios parse to the numbers they say, and
 * every refusal branch is reached with its code, line and reason. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>

#include "sim/scenario.h"

static scenario_t s;

static scn_err_t parse(const char *text, scn_error_t *err)
{
    return scenario_parse(&s, text, strlen(text), err);
}

static void test_a_full_scenario(void **st)
{
    (void)st;
    static const char text[] =
        "# a comment with UTF-8 → fine\n"
        "name demo   # trailing comment\n"
        "duration 5s\r\n"
        "\n"
        "at 0 hand 0 0 0\n"
        "at 0.25 hand 1.5 -2 -29.125 over 500ms\n"
        "at 1.000 button 1 down\n"
        "at 1.000 button 2 up\n"
        "at 1.5 estop press\n"
        "at 1.6 estop release\n"
        "at 1.7 drive_fault_line low\n"
        "at 1.8 emcy 3\n"
        "at 1.9 heartbeat 2 stop\n"
        "at 2.0 heartbeat 2 resume\n"
        "at 2.1 encoder_jump 1 -250\n"
        "at 2.2 can_drop 0.5% seed 42\n"
        "at 2.3 can_drop 10%\n"
        "at 2.4 can_delay 1.5ms\n"
        "at 2.5 bus_off\n"
        "at 2.6 bus_restart\n"
        "at 2.7 link lost\n"
        "at 2.8 link restore\n"
        "at 2.9 link delay 30ms\n"
        "at 3.0 link duplicate 5\n"
        "at 3.0 link reorder 6\n"
        "at 3.0 link garbage 1024\n"
        "at 3.0 link nan_tool\n"
        "at 3.1 overrun 3\n"
        "at 3.2 rearm\n"
        "at 3.3 hand release\n"
        "expect at 1.5 torque_zero within 1ms\n"
        "expect at 1.5 no_torque_frames until rearm\n"
        "expect at 0.5 running until 1.250\n"
        "expect at 2.0 fault until end\n"
        "expect at 2.0 safe until end\n"
        "expect at 3.2 enabled within 0.3s\n"
        "expect at 1.0 quick_stop within 250us";
    scn_error_t err;
    assert_int_equal(parse(text, &err), SCN_OK);
    assert_string_equal(s.name, "demo");
    assert_int_equal(s.duration_us, 5000000);
    assert_int_equal(s.n_steps, 26);
    assert_int_equal(s.n_expects, 7);
    const scn_step_t *h = &s.step[1];
    assert_int_equal(h->action, SCN_HAND);
    assert_int_equal(h->t_us, 250000);
    assert_float_equal(h->p_mm[0], 1.5f, 1e-6f);
    assert_float_equal(h->p_mm[2], -29.125f, 1e-6f);
    assert_int_equal(h->dur_us, 500000);
    assert_int_equal(h->line, 6);
    assert_string_equal(h->text, "at 0.25 hand 1.5 -2 -29.125 over 500ms");
    assert_int_equal(s.step[2].action, SCN_BUTTON);
    assert_int_equal(s.step[2].b, 1);
    assert_int_equal(s.step[3].a, 2);
    assert_int_equal(s.step[3].b, 0);
    assert_int_equal(s.step[4].a, 1);
    assert_int_equal(s.step[7].action, SCN_EMCY);
    assert_int_equal(s.step[7].a, 3);
    assert_int_equal(s.step[8].b, 0);
    assert_int_equal(s.step[10].b, -250);
    assert_int_equal(s.step[11].ppm, 5000);     /* 0.5 % */
    assert_int_equal(s.step[11].seed, 42);
    assert_int_equal(s.step[12].ppm, 100000);   /* 10 % */
    assert_int_equal(s.step[12].seed, 1);
    assert_int_equal(s.step[13].dur_us, 1500);
    assert_int_equal(s.step[18].dur_us, 30000);
    assert_int_equal(s.step[21].a, 1024);
    assert_int_equal(s.step[22].action, SCN_LINK_NAN);
    assert_int_equal(s.step[23].a, 3);
    assert_int_equal(s.step[25].action, SCN_HAND_RELEASE);
    assert_true(scenario_action_is_host_side(SCN_REARM));
    assert_false(scenario_action_is_host_side(SCN_BUS_OFF));
    assert_string_equal(scenario_action_name(SCN_CAN_DROP), "can_drop");
    assert_string_equal(scenario_expect_name(SCN_EXP_SAFE), "safe");
    assert_int_equal(s.expect[0].within_us, 1000);
    assert_int_equal(scenario_until_us(&s, &s.expect[0]), 3200000); /* hold until the rearm */
    assert_int_equal(s.expect[1].until, SCN_UNTIL_REARM);
    assert_int_equal(scenario_until_us(&s, &s.expect[1]), 3200000);
    assert_int_equal(scenario_until_us(&s, &s.expect[2]), 1250000);
    assert_int_equal(scenario_until_us(&s, &s.expect[3]), 5000000);
    assert_int_equal(s.expect[5].within_us, 300000);
    assert_int_equal(scenario_until_us(&s, &s.expect[5]), 5000000); /* no rearm after 3.2 */
    assert_int_equal(s.expect[6].within_us, 250);
}

/* A hostile sender: three kinds, each for a stated time; anything else names its line. */
static void test_stranger_steps(void **st)
{
    (void)st;
    scn_error_t err;
    assert_int_equal(parse("duration 15s\n"
                           "at 1.0 stranger replay for 800ms\n"
                           "at 2.0 stranger forge for 1s\n"
                           "at 3.0 stranger flood for 10s\n", &err), SCN_OK);
    assert_int_equal(s.n_steps, 3);
    for (int k = 0; k < 3; k++) {
        assert_int_equal(s.step[k].action, SCN_STRANGER);
        assert_int_equal(s.step[k].a, k);
    }
    assert_int_equal(s.step[0].dur_us, 800000);
    assert_int_equal(s.step[2].dur_us, 10000000);
    assert_true(scenario_action_is_host_side(SCN_STRANGER));
    assert_string_equal(scenario_stranger_name(SCN_STRANGER_FLOOD), "flood");
    static const struct {
        const char *line;
        scn_err_t e;
    } bad[] = {
        {"at 1 stranger dance for 1s\n", SCN_ERR_ARG},
        {"at 1 stranger replay\n", SCN_ERR_DURATION},
        {"at 1 stranger replay 1s\n", SCN_ERR_DURATION},
        {"at 1 stranger replay for 11s\n", SCN_ERR_DURATION},
        {"at 1 stranger flood for 1s now\n", SCN_ERR_TRAILING},
    };
    for (size_t k = 0; k < sizeof(bad) / sizeof(bad[0]); k++) {
        char text[128];
        snprintf(text, sizeof(text), "duration 20s\n%s", bad[k].line);
        assert_int_equal(parse(text, &err), bad[k].e);
        assert_int_equal(err.line, 2);
    }
}

static void test_every_shipped_scenario_parses(void **st)
{
    (void)st;
    DIR *d = opendir("hil/scenarios");
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".scn") != 0)
            continue;
        char path[300];
        snprintf(path, sizeof(path), "hil/scenarios/%s", e->d_name);
        scn_error_t err;
        const scn_err_t rc = scenario_load(&s, path, &err);
        if (rc != SCN_OK)
            fail_msg("%s:%u: %s", path, err.line, err.msg);
        assert_true(s.n_expects >= 1);
        n++;
    }
    closedir(d);
    assert_true(n >= 17); /* basic + one per fault class */
}

typedef struct {
    const char *text;
    scn_err_t code;
    uint32_t line;
    const char *says;   /* a piece of the message */
} bad_t;

#define D "duration 5s\n"
static const bad_t bad[] = {
    /* lines and characters */
    {D "at 1 hand 0 0 0 # "
     "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx"
     "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx"
     "xxxxxxxxxxxxxxxxxxxxxxxxxxxxxx\n",
     SCN_ERR_LINE_LONG, 2, "longer than 200"},
    {D "at 1 estop\x01 press\n", SCN_ERR_CHAR, 2, "control"},
    {D "at 1 estop pr\xc3\xa9ss\n", SCN_ERR_CHAR, 2, "non-ASCII"},
    {D "at 1 a b c d e f g h i j k l\n", SCN_ERR_ARG, 2, "too many words"},
    {D "at 1 hand 0 0 0000000000000000000000000000000000000000000\n", SCN_ERR_ARG, 2, "39"},
    {D "bogus 1\n", SCN_ERR_KEYWORD, 2, "unknown keyword 'bogus'"},
    /* name and duration */
    {"name two words\n" D, SCN_ERR_ARG, 1, "name needs one word"},
    {"name abcdefghijabcdefghijabcdefghijab\n" D, SCN_ERR_ARG, 1, "under 32"},
    {D D, SCN_ERR_NO_DURATION, 2, "second 'duration'"},
    {"duration\n", SCN_ERR_DURATION, 1, "duration needs"},
    {"duration 5\n", SCN_ERR_DURATION, 1, "'5'"},
    {"duration 5min\n", SCN_ERR_DURATION, 1, "'5min'"},
    {"duration 0s\n", SCN_ERR_DURATION, 1, "duration needs"},
    {"duration 0.5us\n", SCN_ERR_DURATION, 1, "'0.5us'"},
    {"duration 3601s\n", SCN_ERR_DURATION, 1, "'3601s'"},
    {"duration -1s\n", SCN_ERR_DURATION, 1, "'-1s'"},
    {"duration 5s now\n", SCN_ERR_TRAILING, 1, "'now'"},
    {"at 1 rearm\n", SCN_ERR_NO_DURATION, 1, "no 'duration'"},
    {"", SCN_ERR_NO_DURATION, 1, "no 'duration'"},
    /* at: time, order, action, trailing */
    {D "at\n", SCN_ERR_TIME, 2, "not a time"},
    {D "at -1 rearm\n", SCN_ERR_TIME, 2, "'-1'"},
    {D "at 1.0000001 rearm\n", SCN_ERR_TIME, 2, "'1.0000001'"},
    {D "at 1s rearm\n", SCN_ERR_TIME, 2, "'1s'"},
    {D "at . rearm\n", SCN_ERR_TIME, 2, "'.'"},
    {D "at 9999999999 rearm\n", SCN_ERR_TIME, 2, "9999999999"},
    {D "at 2 rearm\nat 1 rearm\n", SCN_ERR_ORDER, 3, "before the previous"},
    {D "at 1\n", SCN_ERR_ACTION, 2, "missing action"},
    {D "at 1 dance\n", SCN_ERR_ACTION, 2, "unknown action 'dance'"},
    {D "at 1 rearm now\n", SCN_ERR_TRAILING, 2, "'now'"},
    {D "at 6 rearm\n", SCN_ERR_BEYOND, 2, "after the duration"},
    /* hand */
    {D "at 1 hand 0 0\n", SCN_ERR_ARG, 2, "X Y Z"},
    {D "at 1 hand 0 0 x\n", SCN_ERR_ARG, 2, "'x'"},
    {D "at 1 hand 0 0 201\n", SCN_ERR_ARG, 2, "'201'"},
    {D "at 1 hand 0 0 1mm\n", SCN_ERR_ARG, 2, "'1mm'"},
    {D "at 1 hand 0 0 0 over\n", SCN_ERR_DURATION, 2, "'over' needs"},
    {D "at 1 hand 0 0 0 over 5\n", SCN_ERR_DURATION, 2, "'over' needs"},
    /* buttons, e-stop, fault line */
    {D "at 1 button 3 down\n", SCN_ERR_ARG, 2, "1 or 2, got '3'"},
    {D "at 1 button\n", SCN_ERR_ARG, 2, "1 or 2"},
    {D "at 1 button 1 sideways\n", SCN_ERR_ARG, 2, "'sideways'"},
    {D "at 1 estop\n", SCN_ERR_ARG, 2, "missing argument"},
    {D "at 1 drive_fault_line maybe\n", SCN_ERR_ARG, 2, "'maybe'"},
    /* drive nodes */
    {D "at 1 emcy\n", SCN_ERR_ARG, 2, "missing drive node"},
    {D "at 1 emcy two\n", SCN_ERR_ARG, 2, "'two' is not a drive node"},
    {D "at 1 emcy 1.5\n", SCN_ERR_ARG, 2, "'1.5' is not a drive node"},
    {D "at 1 emcy 4\n", SCN_ERR_NODE, 2, "outside 1-3"},
    {D "at 1 heartbeat 0 stop\n", SCN_ERR_NODE, 2, "'0'"},
    {D "at 1 heartbeat 1 pause\n", SCN_ERR_ARG, 2, "'pause'"},
    {D "at 1 encoder_jump 1\n", SCN_ERR_ARG, 2, "encoder_jump needs counts"},
    {D "at 1 encoder_jump 1 0\n", SCN_ERR_ARG, 2, "non-zero"},
    {D "at 1 encoder_jump 1 1000001\n", SCN_ERR_ARG, 2, "1000000"},
    /* CAN faults */
    {D "at 1 can_drop\n", SCN_ERR_ARG, 2, "percentage"},
    {D "at 1 can_drop 10\n", SCN_ERR_ARG, 2, "got '10'"},
    {D "at 1 can_drop 101%\n", SCN_ERR_ARG, 2, "'101%'"},
    {D "at 1 can_drop -1%\n", SCN_ERR_ARG, 2, "'-1%'"},
    {D "at 1 can_drop 1% seed\n", SCN_ERR_ARG, 2, "seed needs"},
    {D "at 1 can_drop 1% seed 0\n", SCN_ERR_ARG, 2, "seed needs"},
    {D "at 1 can_delay\n", SCN_ERR_DURATION, 2, "can_delay needs"},
    {D "at 1 can_delay 2s\n", SCN_ERR_DURATION, 2, "'2s'"},
    /* host side */
    {D "at 1 link\n", SCN_ERR_ACTION, 2, "unknown link fault ''"},
    {D "at 1 link broken\n", SCN_ERR_ACTION, 2, "'broken'"},
    {D "at 1 link delay\n", SCN_ERR_DURATION, 2, "link delay needs"},
    {D "at 1 link delay 2s\n", SCN_ERR_DURATION, 2, "link delay needs"},
    {D "at 1 link garbage 1025\n", SCN_ERR_ARG, 2, "link garbage needs a count"},
    {D "at 1 link duplicate\n", SCN_ERR_ARG, 2, "link duplicate needs"},
    {D "at 1 link reorder 0\n", SCN_ERR_ARG, 2, "link reorder needs"},
    {D "at 1 overrun 0\n", SCN_ERR_ARG, 2, "overrun needs"},
    {D "at 1 overrun\n", SCN_ERR_ARG, 2, "got ''"},
    /* expectations */
    {D "expect torque_zero\n", SCN_ERR_EXPECT, 2, "expect at T"},
    {D "expect at x torque_zero within 1ms\n", SCN_ERR_TIME, 2, "'x'"},
    {D "expect at\n", SCN_ERR_TIME, 2, "not a time"},
    {D "expect at 1\n", SCN_ERR_EXPECT, 2, "missing expectation kind"},
    {D "expect at 1 happiness within 1ms\n", SCN_ERR_EXPECT, 2, "unknown expectation 'happiness'"},
    {D "expect at 1 fault\n", SCN_ERR_EXPECT, 2, "needs 'within D' or 'until X'"},
    {D "expect at 1 running within 1ms\n", SCN_ERR_EXPECT, 2, "takes 'until'"},
    {D "expect at 1 fault within soon\n", SCN_ERR_DURATION, 2, "'soon'"},
    {D "expect at 1 fault until later\n", SCN_ERR_EXPECT, 2, "'until later'"},
    {D "expect at 2 fault until 1.5\n", SCN_ERR_EXPECT, 2, "a later time"},
    {D "expect at 1 quick_stop until end\n", SCN_ERR_EXPECT, 2, "takes 'within'"},
    {D "expect at 1 fault after 1ms\n", SCN_ERR_EXPECT, 2, "got 'after'"},
    {D "expect at 1 fault within 1ms please\n", SCN_ERR_TRAILING, 2, "'please'"},
    {D "expect at 6 fault within 1ms\n", SCN_ERR_BEYOND, 2, "after the duration"},
    {D "expect at 1 running until 5.5\n", SCN_ERR_BEYOND, 2, "after the duration"},
};

static void test_every_refusal_names_its_line(void **st)
{
    (void)st;
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        scn_error_t err;
        const scn_err_t rc = parse(bad[i].text, &err);
        if (rc != bad[i].code || err.line != bad[i].line || strstr(err.msg, bad[i].says) == NULL)
            fail_msg("case %zu: got code %d line %u '%s', want %d line %u '%s'", i, rc,
                     err.line, err.msg, bad[i].code, bad[i].line, bad[i].says);
        assert_int_equal(err.code, rc);
    }
}

static void test_too_many_steps_and_expectations(void **st)
{
    (void)st;
    static char text[8192];
    size_t n = (size_t)snprintf(text, sizeof(text), "duration 100s\n");
    for (unsigned i = 0; i <= SCN_STEPS_MAX; i++)
        n += (size_t)snprintf(text + n, sizeof(text) - n, "at %u rearm\n", i);
    scn_error_t err;
    assert_int_equal(parse(text, &err), SCN_ERR_TOO_MANY);
    assert_int_equal(err.line, 2 + SCN_STEPS_MAX);
    n = (size_t)snprintf(text, sizeof(text), "duration 100s\n");
    for (unsigned i = 0; i <= SCN_EXPECTS_MAX; i++)
        n += (size_t)snprintf(text + n, sizeof(text) - n, "expect at %u fault within 1ms\n", i);
    assert_int_equal(parse(text, &err), SCN_ERR_TOO_MANY);
    assert_int_equal(err.line, 2 + SCN_EXPECTS_MAX);
    assert_non_null(strstr(err.msg, "32 expectations"));
}

static void test_load_refuses_what_it_cannot_read(void **st)
{
    (void)st;
    scn_error_t err;
    assert_int_equal(scenario_load(&s, "hil/scenarios/no-such-file.scn", &err), SCN_ERR_IO);
    assert_int_equal(err.line, 0);
    assert_non_null(strstr(err.msg, "cannot open"));
    assert_int_equal(scenario_load(&s, "hil/scenarios", &err), SCN_ERR_IO); /* a directory */
    assert_non_null(strstr(err.msg, "read error"));
    char path[] = "/tmp/argil-scn-XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "wb");
    assert_non_null(f);
    for (int i = 0; i < 70000; i++)
        fputc('#', f);
    fclose(f);
    assert_int_equal(scenario_load(&s, path, &err), SCN_ERR_IO);
    assert_non_null(strstr(err.msg, "64 KiB"));
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_full_scenario),
        cmocka_unit_test(test_stranger_steps),
        cmocka_unit_test(test_every_shipped_scenario_parses),
        cmocka_unit_test(test_every_refusal_names_its_line),
        cmocka_unit_test(test_too_many_steps_and_expectations),
        cmocka_unit_test(test_load_refuses_what_it_cannot_read),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
