/* The board's host session (firmware/core/host_session.c): a HELLO starts it, sequence numbers
 * must be new and within the newest 64, it lapses after the host timeout and ends on END; and
 * the board core refuses, counts and ignores what the session refuses. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "firmware/core/board.h"
#include "firmware/core/host_session.h"
#include "shared/gpio_lines.h"

#define HELLO true, true
#define BEAT false, true
#define OTHER false, false /* a TOOL or WINDOW frame */

static void test_only_a_hello_starts_a_session(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, BEAT, 5), HOST_FRAME_NO_SESSION);
    assert_int_equal(host_session_admit(&s, OTHER, 6), HOST_FRAME_NO_SESSION);
    assert_int_equal(host_session_admit(&s, HELLO, 1000), HOST_FRAME_NEW_SESSION);
    assert_int_equal(s.state, HOST_SESSION_LIVE);
    assert_int_equal(s.epoch, 1);
    assert_int_equal(host_session_admit(&s, BEAT, 1001), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, OTHER, 1002), HOST_FRAME_ACCEPT);
}

static void test_duplicates_and_old_numbers_are_refused(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, HELLO, 10), HOST_FRAME_NEW_SESSION);
    for (uint32_t q = 11; q <= 100; q++)
        assert_int_equal(host_session_admit(&s, BEAT, q), HOST_FRAME_ACCEPT);
    /* every one of them again: a replay */
    for (uint32_t q = 100 - HOST_SESSION_WINDOW + 1u; q <= 100; q++)
        assert_int_equal(host_session_admit(&s, BEAT, q), HOST_FRAME_DUPLICATE);
    /* older than the window: too late to tell, refused */
    assert_int_equal(host_session_admit(&s, BEAT, 100 - HOST_SESSION_WINDOW), HOST_FRAME_STALE);
    assert_int_equal(host_session_admit(&s, BEAT, 10), HOST_FRAME_STALE);
    assert_int_equal(host_session_admit(&s, HELLO, 100), HOST_FRAME_DUPLICATE);
}

static void test_reordering_within_the_window_is_accepted_once(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, HELLO, 0), HOST_FRAME_NEW_SESSION);
    /* pairs swapped: 2 1 4 3 6 5 … */
    for (uint32_t q = 1; q < 200; q += 2) {
        assert_int_equal(host_session_admit(&s, BEAT, q + 1u), HOST_FRAME_ACCEPT);
        assert_int_equal(host_session_admit(&s, BEAT, q), HOST_FRAME_ACCEPT);
        assert_int_equal(host_session_admit(&s, BEAT, q), HOST_FRAME_DUPLICATE);
    }
    /* a gap, then a late one: 201 is the oldest the window still holds, 200 just out of it */
    assert_int_equal(host_session_admit(&s, OTHER, 200 + HOST_SESSION_WINDOW), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, OTHER, 201), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, OTHER, 200), HOST_FRAME_STALE);
    /* a jump far ahead forgets everything behind it */
    assert_int_equal(host_session_admit(&s, OTHER, 100000), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, OTHER, 99999), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, OTHER, 100000 - 64), HOST_FRAME_STALE);
}

static void test_numbers_may_wrap_around(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, HELLO, 0xFFFFFFF0u), HOST_FRAME_NEW_SESSION);
    assert_int_equal(host_session_admit(&s, BEAT, 0x00000005u), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, BEAT, 0xFFFFFFF8u), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, BEAT, 0xFFFFFFF8u), HOST_FRAME_DUPLICATE);
    assert_int_equal(host_session_admit(&s, BEAT, 0xFFFFFFF0u), HOST_FRAME_DUPLICATE);
    /* half the number space behind: older, not newer */
    assert_int_equal(host_session_admit(&s, BEAT, 0x80000005u), HOST_FRAME_STALE);
}

static void test_a_quiet_host_lapses_and_any_hello_takes_over(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, HELLO, 500), HOST_FRAME_NEW_SESSION);
    for (int ms = 0; ms < 49; ms++)
        assert_false(host_session_process(&s, 1000, 50000));
    assert_int_equal(host_session_admit(&s, OTHER, 501), HOST_FRAME_ACCEPT); /* not a heartbeat */
    assert_true(host_session_process(&s, 1000, 50000));
    assert_int_equal(s.state, HOST_SESSION_LAPSED);
    assert_false(host_session_process(&s, 1000, 50000)); /* once */
    /* its host may carry on, and its numbers are still checked */
    assert_int_equal(host_session_admit(&s, BEAT, 501), HOST_FRAME_DUPLICATE);
    assert_int_equal(s.state, HOST_SESSION_LAPSED);
    assert_int_equal(host_session_admit(&s, BEAT, 502), HOST_FRAME_ACCEPT);
    assert_int_equal(s.state, HOST_SESSION_LIVE);
    assert_int_equal(s.epoch, 1);
    /* lapsed again: a new host's HELLO starts a session whatever its numbers */
    for (int ms = 0; ms < 50; ms++)
        (void)host_session_process(&s, 1000, 50000);
    assert_int_equal(s.state, HOST_SESSION_LAPSED);
    assert_int_equal(host_session_admit(&s, HELLO, 3), HOST_FRAME_NEW_SESSION);
    assert_int_equal(s.epoch, 2);
    assert_int_equal(host_session_admit(&s, BEAT, 4), HOST_FRAME_ACCEPT);
    assert_int_equal(host_session_admit(&s, BEAT, 502), HOST_FRAME_ACCEPT); /* a new window */
}

static void test_end_and_a_second_hello(void **st)
{
    (void)st;
    host_session_t s;
    host_session_init(&s);
    assert_int_equal(host_session_admit(&s, HELLO, 7), HOST_FRAME_NEW_SESSION);
    assert_int_equal(host_session_admit(&s, BEAT, 8), HOST_FRAME_ACCEPT);
    /* the live host says HELLO again (a reconnection): a new session, the numbers go on */
    assert_int_equal(host_session_admit(&s, HELLO, 9), HOST_FRAME_NEW_SESSION);
    assert_int_equal(s.epoch, 2);
    assert_int_equal(host_session_admit(&s, BEAT, 8), HOST_FRAME_DUPLICATE);
    host_session_end(&s);
    assert_int_equal(s.state, HOST_SESSION_NONE);
    assert_int_equal(host_session_admit(&s, BEAT, 10), HOST_FRAME_NO_SESSION);
    assert_false(host_session_process(&s, 100000, 50000));
    assert_int_equal(host_session_admit(&s, HELLO, 0), HOST_FRAME_NEW_SESSION);
    assert_int_equal(s.epoch, 3);
}

/* ---- the board core ---- */

static board_t g_board;
static board_out_t g_out;

static size_t put(uint8_t *buf, size_t at, const proto_msg_t *m, uint32_t seq)
{
    size_t n = 0;
    assert_int_equal(proto_encode(m, seq, buf + at, 4096 - at, &n), PROTO_OK);
    return at + n;
}

static void tick(const uint8_t *rx, size_t len)
{
    board_in_t in;
    memset(&in, 0, sizeof(in));
    in.gpio_in = GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N;
    in.link_rx = rx;
    in.link_rx_len = len;
    board_tick(&g_board, &in, &g_out);
}

/* Whether this tick's output holds a board HELLO. */
static bool sent_hello(void)
{
    for (size_t at = 0; at + PROTO_HEADER_SIZE <= g_out.link_tx_len;) {
        proto_msg_t m;
        size_t n = 0;
        assert_int_equal(proto_decode(g_out.link_tx + at, g_out.link_tx_len - at, &m, &n),
                         PROTO_OK);
        if (m.type == MSG_HELLO)
            return true;
        at += n;
    }
    return false;
}

static void test_the_board_acts_on_its_host_only_and_counts_the_rest(void **st)
{
    (void)st;
    board_cfg_t cfg;
    board_cfg_default(&cfg);
    assert_int_equal(board_init(&g_board, &cfg), ARGIL_OK);
    static uint8_t rx[4096];
    proto_msg_t tool, hello, beat;
    memset(&tool, 0, sizeof(tool));
    tool.type = MSG_TOOL;
    tool.u.tool.radius_m = 0.004f;
    tool.u.tool.axis[2] = 1.0f;
    tool.u.tool.max_force_n = 3.0f;
    tool.u.tool.model_scale = 1.0f;
    memset(&hello, 0, sizeof(hello));
    hello.type = MSG_HELLO;
    hello.u.hello.role = PROTO_ROLE_HOST;
    memset(&beat, 0, sizeof(beat));
    beat.type = MSG_HEARTBEAT;

    /* before any HELLO: a tool and a heartbeat act on nothing, and the board says nothing */
    size_t n = put(rx, 0, &tool, 1);
    n = put(rx, n, &beat, 2);
    tick(rx, n);
    assert_false(g_board.tool_valid);
    assert_false(sent_hello());
    assert_int_equal(g_board.stats.refused_no_session, 2);
    assert_int_equal(g_board.stats.link_frames_rx, 0);

    /* the HELLO starts the session: the board answers; its tool acts; a replayed tool does not */
    n = put(rx, 0, &hello, 40);
    n = put(rx, n, &tool, 41);
    tick(rx, n);
    assert_true(sent_hello());
    assert_true(g_board.tool_valid);
    assert_int_equal(g_board.session.epoch, 1);
    g_board.tool_valid = false;
    n = put(rx, 0, &tool, 41);
    n = put(rx, n, &hello, 40);
    tick(rx, n);
    assert_false(g_board.tool_valid);
    assert_false(sent_hello());
    assert_int_equal(g_board.stats.refused_duplicate, 2);

    /* END: the session is over; what follows is refused until a HELLO */
    beat.u.heartbeat.command = PROTO_CMD_END;
    n = put(rx, 0, &beat, 42);
    beat.u.heartbeat.command = PROTO_CMD_NONE;
    n = put(rx, n, &tool, 43);
    tick(rx, n);
    assert_int_equal(g_board.session.state, HOST_SESSION_NONE);
    assert_false(g_board.tool_valid);
    assert_int_equal(g_board.stats.refused_no_session, 3);

    /* far behind the window after a new session: stale */
    n = put(rx, 0, &hello, 1000);
    n = put(rx, n, &tool, 900);
    tick(rx, n);
    assert_int_equal(g_board.stats.refused_stale, 1);
    assert_false(g_board.tool_valid);

    /* the counts reach RT_STATS, with the transport's own */
    board_in_t in;
    memset(&in, 0, sizeof(in));
    in.gpio_in = GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N;
    in.link_refused_source = 7;
    in.link_refused_no_session = 4;
    in.link_refused_bad_mac = 9;
    in.link_refused_bad_nonce = 5;
    board_tick(&g_board, &in, &g_out);
    proto_msg_t rt;
    board_rt_stats_msg(&g_board, &rt);
    assert_int_equal(rt.u.rt_stats.link.wrong_source, 7);
    assert_int_equal(rt.u.rt_stats.link.no_session, 3 + 4);
    assert_int_equal(rt.u.rt_stats.link.duplicate, 2);
    assert_int_equal(rt.u.rt_stats.link.stale, 1);
    assert_int_equal(rt.u.rt_stats.link.sessions, 2);
    assert_int_equal(rt.u.rt_stats.link.decode_errors, 0);
    assert_int_equal(rt.u.rt_stats.link.bad_mac, 9);
    assert_int_equal(rt.u.rt_stats.link.bad_nonce, 5);
    assert_int_equal(rt.u.rt_stats.link.arm_refused, 0);
}

/* A link that cannot tell who sent a frame (UDP without a key): the host's ARM is refused and
 * counted, while its heartbeats keep the session alive; the same ARM acts when it may. */
static void test_a_board_that_refuses_arm_counts_and_ignores_it(void **st)
{
    (void)st;
    for (int refuse = 1; refuse >= 0; refuse--) {
        board_cfg_t cfg;
        board_cfg_default(&cfg);
        cfg.refuse_arm = refuse != 0;
        assert_int_equal(board_init(&g_board, &cfg), ARGIL_OK);
        g_board.safety.state = SAFETY_IDLE; /* as after boot with the drives ready */
        static uint8_t rx[4096];
        proto_msg_t hello, beat;
        memset(&hello, 0, sizeof(hello));
        hello.type = MSG_HELLO;
        hello.u.hello.role = PROTO_ROLE_HOST;
        memset(&beat, 0, sizeof(beat));
        beat.type = MSG_HEARTBEAT;
        beat.u.heartbeat.command = PROTO_CMD_ARM;
        size_t n = put(rx, 0, &hello, 1);
        n = put(rx, n, &beat, 2);
        tick(rx, n);
        assert_int_equal(g_board.stats.refused_arm, refuse ? 1 : 0);
        assert_int_equal(g_board.session.state, HOST_SESSION_LIVE);
        /* an ARM that acts starts the drives' fault reset (for its bounded wait) */
        if (refuse)
            assert_int_equal(g_board.drives.fault_reset_left_us, 0);
        else
            assert_true(g_board.drives.fault_reset_left_us > 0);
        proto_msg_t rt;
        board_rt_stats_msg(&g_board, &rt);
        assert_int_equal(rt.u.rt_stats.link.arm_refused, refuse ? 1 : 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_only_a_hello_starts_a_session),
        cmocka_unit_test(test_duplicates_and_old_numbers_are_refused),
        cmocka_unit_test(test_reordering_within_the_window_is_accepted_once),
        cmocka_unit_test(test_numbers_may_wrap_around),
        cmocka_unit_test(test_a_quiet_host_lapses_and_any_hello_takes_over),
        cmocka_unit_test(test_end_and_a_second_hello),
        cmocka_unit_test(test_the_board_acts_on_its_host_only_and_counts_the_rest),
        cmocka_unit_test(test_a_board_that_refuses_arm_counts_and_ignores_it),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
