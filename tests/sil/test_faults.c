/* SIL fault matrix: every scenario of hil/scenarios/ runs in-process on the virtual clock (the
 * scenario's device side through sim_runner_tick, the same per-tick function argil-sim runs;
 * the board core; argil's host peer over a clay sphere; the scenario's host-side faults on the
 * link and the tick). The run is recorded the way a HIL rig records it — a candump -l log of
 * every CAN frame and argil-sim's event log — and each expectation is decided by the log
 * checker of argil-hil-check from those logs alone. The board's own state (telemetry) is
 * asserted on top: the fault code each fault class must latch. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/board_hal.h"
#include "firmware/hal/hal_sim.h"
#include "host/app/peer.h"
#include "shared/crc32c.h"
#include "shared/gpio_lines.h"
#include "sim/hil_check.h"
#include "sim/scenario.h"
#include "sim/sim_runner.h"
#include "tests/sil/rig.h"
#include "tests/unit/dbc_parser.h"

#define LOG_BASE_US 1700000000000000LL /* the logs' CLOCK_REALTIME stand-in for t = 0 */
#define LINK_HELD_MAX 512u
#define OVERRUN_NS 1500000u            /* an overrunning tick took 1.5 ms of its 1 ms */

typedef struct {
    int64_t due_us;
    size_t len;
    uint8_t bytes[PROTO_FRAME_MAX];
} held_frame_t;

typedef struct {
    rig_t *r;
    scenario_t scn;
    sim_runner_t run;
    uint32_t next_host;
    /* host link faults */
    bool lost;
    int64_t delay_us;
    uint32_t dup_left, reorder_left;
    uint32_t dup_sent;                 /* second copies delivered */
    bool have_reorder;
    held_frame_t reorder;
    held_frame_t *held;
    uint32_t n_held;
    uint32_t overrun_left;
    uint32_t link_errors_before;
    /* recording */
    char *can_text, *ev_text;
    size_t can_len, ev_len;
    FILE *can_log, *ev_log;
    int64_t first_bad_us;              /* first tick in FAULT/ESTOP, −1 */
    fault_code_t fault;
    /* what the hand feels: the board's force every tick */
    vec3_t *force;
    uint32_t n_force;
    bool was_active, left_active;      /* ACTIVE once; left it afterwards */
    bool no_link_faults;               /* the twin run: the scenario's link faults not applied */
    /* a stranger on the network between these times (`stranger KIND for D`, or set by a
     * test): forge = CRC-valid commands from another sender every 5 ms; replay = the host's
     * captured frames again, every 1 ms from another sender and from the host's own; flood =
     * 20 junk datagrams a millisecond from another sender */
    int stranger_kind;
    int64_t stranger_from_us, stranger_until_us;
    uint32_t stranger_sent;            /* forged commands */
    uint32_t replayed_other, replayed_own, flooded;
    held_frame_t *captured;            /* the host's last CAPTURED_MAX frames, as sent */
    uint32_t n_captured, replay_next;
} fx_t;

#define CAPTURED_MAX 64u
#define HAL_SIM_STRANGER 2u            /* another sender on the host's network */

#define FORCE_TICKS_MAX 10000u

static void log_event(void *ctx, int64_t t_us, const char *event)
{
    fx_t *x = ctx;
    const int64_t t = LOG_BASE_US + t_us;
    fprintf(x->ev_log, "(%" PRId64 ".%06" PRId64 ") %s t=%" PRId64 ".%06" PRId64 "\n",
            t / 1000000, t % 1000000, event, t_us / 1000000, t_us % 1000000);
}

static void log_frames(fx_t *x, int64_t t_us, const can_batch_t *b)
{
    const int64_t t = LOG_BASE_US + t_us;
    for (uint8_t i = 0; i < b->n; i++) {
        const can_frame_t *f = &b->f[i];
        fprintf(x->can_log, "(%" PRId64 ".%06" PRId64 ") vcan0 ", t / 1000000, t % 1000000);
        if (f->id & ARGIL_CAN_ERR_FLAG)
            fprintf(x->can_log, "%08X#", (unsigned)f->id);
        else
            fprintf(x->can_log, "%03X#", (unsigned)f->id);
        for (uint8_t k = 0; k < f->len; k++)
            fprintf(x->can_log, "%02X", f->data[k]);
        fputc('\n', x->can_log);
    }
}

/* Straight to the board's link queue. */
static void to_board(fx_t *x, const uint8_t *f, size_t len)
{
    (void)hal_sim_host_send(&x->r->rig.hal, f, len);
}

static void hold(fx_t *x, const uint8_t *f, size_t len, int64_t due_us)
{
    if (x->n_held == LINK_HELD_MAX || len > PROTO_FRAME_MAX)
        return; /* a link that delays this much loses frames */
    held_frame_t *h = &x->held[x->n_held++];
    h->due_us = due_us;
    h->len = len;
    memcpy(h->bytes, f, len);
}

/* The host's frames on their way to the board, through the scenario's link faults. */
static bool link_hook(void *ctx, const uint8_t *f, size_t len)
{
    fx_t *x = ctx;
    if (len <= PROTO_FRAME_MAX) { /* what a stranger on the network captures */
        held_frame_t *c = &x->captured[x->n_captured++ % CAPTURED_MAX];
        c->len = len;
        memcpy(c->bytes, f, len);
    }
    if (x->lost)
        return true; /* sent, and lost on the way */
    if (x->delay_us > 0) {
        hold(x, f, len, x->run.now_us + x->delay_us);
        return true;
    }
    if (x->reorder_left > 0 && len <= PROTO_FRAME_MAX) {
        if (!x->have_reorder) {
            memcpy(x->reorder.bytes, f, len);
            x->reorder.len = len;
            x->have_reorder = true;
            return true;
        }
        to_board(x, f, len);
        to_board(x, x->reorder.bytes, x->reorder.len);
        x->have_reorder = false;
        x->reorder_left--;
        return true;
    }
    to_board(x, f, len);
    if (x->dup_left > 0) {
        to_board(x, f, len);
        x->dup_left--;
        x->dup_sent++;
    }
    return true;
}

static void release_held(fx_t *x)
{
    uint32_t k = 0;
    while (k < x->n_held && (x->held[k].due_us <= x->run.now_us || x->delay_us == 0)) {
        to_board(x, x->held[k].bytes, x->held[k].len);
        k++;
    }
    memmove(x->held, x->held + k, (x->n_held - k) * sizeof(x->held[0]));
    x->n_held -= k;
}

/* A TOOL frame whose radius is NaN, with a valid CRC: what a broken host would send. */
static void send_nan_tool(fx_t *x)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_TOOL;
    m.u.tool = x->r->tool;
    m.u.tool.radius_m = 0.00123f; /* a marker to find in the payload */
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, x->r->peer.tx_seq++, buf, sizeof(buf), &len), PROTO_OK);
    uint8_t mark[4];
    memcpy(mark, &m.u.tool.radius_m, 4); /* little-endian host, as the wire */
    size_t at = 0;
    while (at + 4 <= len - 4u && memcmp(buf + at, mark, 4) != 0)
        at++;
    assert_true(at + 4 <= len - 4u);
    const float nan = NAN;
    memcpy(buf + at, &nan, 4);
    const uint32_t crc = crc32c(0u, buf, len - 4u);
    for (int k = 0; k < 4; k++)
        buf[len - 4u + (size_t)k] = (uint8_t)(crc >> (8 * k));
    to_board(x, buf, len);
}

/* The host's re-arm: a heartbeat with ARM, as argil sends when the person presses "arm". */
static void send_rearm(fx_t *x)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HEARTBEAT;
    m.u.heartbeat.time_us = (uint64_t)x->run.now_us;
    m.u.heartbeat.window_version = x->r->peer.have_current ? x->r->peer.current.version : 0u;
    m.u.heartbeat.impulse_seq = x->r->rig.board.impulse_seq;
    m.u.heartbeat.command = PROTO_CMD_ARM;
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, x->r->peer.tx_seq++, buf, sizeof(buf), &len), PROTO_OK);
    to_board(x, buf, len);
}

static void send_garbage(fx_t *x, int32_t n)
{
    uint8_t junk[4096];
    uint32_t s = 0x9E3779B9u ^ (uint32_t)x->run.now_us;
    for (int32_t i = 0; i < n; i++) {
        s = s * 1103515245u + 12345u;
        junk[i] = (uint8_t)(s >> 16);
    }
    if (n >= 4)
        memcpy(junk, "ARGL", 4); /* starts like a frame */
    to_board(x, junk, (size_t)n);
}

static void host_step(fx_t *x, const scn_step_t *st)
{
    switch (st->action) {
    case SCN_LINK_LOST: x->lost = true; break;
    case SCN_LINK_RESTORE:
        x->lost = false;
        x->delay_us = 0;
        x->dup_left = 0;
        x->reorder_left = 0;
        break;
    case SCN_LINK_DELAY: x->delay_us = st->dur_us; break;
    case SCN_LINK_DUPLICATE: x->dup_left = x->no_link_faults ? 0u : (uint32_t)st->a; break;
    case SCN_LINK_REORDER: x->reorder_left = x->no_link_faults ? 0u : (uint32_t)st->a; break;
    case SCN_LINK_GARBAGE: send_garbage(x, st->a); break;
    case SCN_LINK_NAN: send_nan_tool(x); break;
    case SCN_OVERRUN: x->overrun_left = (uint32_t)st->a; break;
    case SCN_REARM: send_rearm(x); break;
    case SCN_STRANGER:
        if (!x->no_link_faults) {
            x->stranger_kind = st->a;
            x->stranger_from_us = x->run.now_us;
            x->stranger_until_us = x->run.now_us + st->dur_us;
        }
        break;
    default: return;
    }
    char text[SCN_TEXT_LEN + 24];
    snprintf(text, sizeof(text), "inject line=%u %s", (unsigned)st->line, st->text);
    log_event(x, x->run.now_us, text);
}

/* A stranger's CRC-valid frames from another sender: what a third process on the network
 * sends to take the arm (a HELLO, DISARM and END heartbeats, a stiffer tool), numbered ahead
 * of the host so that no sequence check alone could tell them apart. */
static void stranger_send(fx_t *x)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    const uint32_t k = x->stranger_sent % 4u;
    if (k == 0) {
        m.type = MSG_HELLO;
        m.u.hello.role = PROTO_ROLE_HOST;
    } else if (k == 3) {
        m.type = MSG_TOOL;
        m.u.tool = x->r->tool;
        m.u.tool.contact_stiffness_n_per_m *= 4.0f;
    } else {
        m.type = MSG_HEARTBEAT;
        m.u.heartbeat.command = k == 1 ? PROTO_CMD_DISARM : PROTO_CMD_END;
    }
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, x->r->peer.tx_seq + 1000u + x->stranger_sent, buf,
                                  sizeof(buf), &len), PROTO_OK);
    assert_int_equal(hal_sim_host_send_from(&x->r->rig.hal, HAL_SIM_STRANGER, buf, len), ARGIL_OK);
    x->stranger_sent++;
}

/* One millisecond of the stranger's kind. */
static void stranger_tick(fx_t *x, int64_t now)
{
    switch (x->stranger_kind) {
    case SCN_STRANGER_FORGE:
        if (now % 5000 == 0)
            stranger_send(x);
        break;
    case SCN_STRANGER_REPLAY: {
        const uint32_t n = x->n_captured < CAPTURED_MAX ? x->n_captured : CAPTURED_MAX;
        if (n == 0)
            break;
        const held_frame_t *c = &x->captured[x->replay_next++ % n];
        assert_int_equal(hal_sim_host_send_from(&x->r->rig.hal, HAL_SIM_STRANGER, c->bytes, c->len),
                         ARGIL_OK);
        x->replayed_other++;
        (void)hal_sim_host_send(&x->r->rig.hal, c->bytes, c->len); /* the host's own address */
        x->replayed_own++;
        break;
    }
    case SCN_STRANGER_FLOOD: {
        uint32_t v = 0x9E3779B9u ^ (uint32_t)now;
        for (int k = 0; k < 20; k++) {
            uint8_t junk[1024];
            v = v * 1103515245u + 12345u;
            const size_t n = 1u + (v >> 8) % sizeof(junk);
            for (size_t i = 0; i < n; i++) {
                v = v * 1103515245u + 12345u;
                junk[i] = (uint8_t)(v >> 16);
            }
            if (k % 2 == 0 && n >= 4)
                memcpy(junk, "ARGL", 4); /* starts like a frame */
            assert_int_equal(hal_sim_host_send_from(&x->r->rig.hal, HAL_SIM_STRANGER, junk, n),
                             ARGIL_OK);
            x->flooded++;
        }
        break;
    }
    default: break;
    }
}

/* One millisecond: device side (scenario + faults), board tick, host side. */
static void fx_tick(fx_t *x)
{
    rig_t *r = x->r;
    const int64_t now = x->run.now_us;
    while (x->next_host < x->scn.n_steps && x->scn.step[x->next_host].t_us <= now) {
        const scn_step_t *st = &x->scn.step[x->next_host++];
        if (scenario_action_is_host_side(st->action))
            host_step(x, st);
    }
    release_held(x);
    if (now >= x->stranger_from_us && now < x->stranger_until_us)
        stranger_tick(x, now);
    can_batch_t from_board, to_b;
    hal_sim_take_from_board(&r->rig.hal, &from_board);
    sim_runner_tick(&x->run, &from_board, hal_sim_gpio_out(&r->rig.hal), &to_b, 1000);
    log_frames(x, now, &to_b);
    hal_sim_put_to_board(&r->rig.hal, &to_b);
    hal_sim_set_gpio_in(&r->rig.hal, sim_runner_gpio_in(&x->run));
    (void)board_run_tick(&r->rig.board, &r->rig.io, &r->rig.hal);
    /* The tick's compute as the board's next tick sees it: the scenario's, not this machine's.
     * This VM charges stolen time to the running thread (/proc/stat steal stays 0; a fixed
     * 150 us loop read up to 1.6 ms of thread CPU time), and with the daemon's streak of 3 the
     * measured time of this sanitizer build was the one thing in the run not on the virtual
     * clock: a loaded run of basic.scn once sent 0 RPDOs with torque where it sends 3,510. */
    r->rig.io.prev_compute_ns = x->overrun_left > 0 ? OVERRUN_NS : 0u; /* the injected load */
    r->rig.io.prev_compute_preempted = false; /* … timed, whatever the machine did meanwhile */
    if (x->overrun_left > 0)
        x->overrun_left--;
    log_frames(x, now + 500, &r->rig.io.out.can_tx); /* the board's frames, half a tick later */
    const size_t n = hal_sim_host_receive(&r->rig.hal, r->rx, sizeof(r->rx));
    if (!x->lost)
        peer_receive(&r->peer, r->rx, n);
    peer_tick(&r->peer, 1000);
    const safety_state_t s = r->rig.board.safety.state;
    if (x->n_force < FORCE_TICKS_MAX)
        x->force[x->n_force++] = r->rig.board.force_n;
    if (s == SAFETY_ACTIVE)
        x->was_active = true;
    else if (x->was_active)
        x->left_active = true;
    if ((s == SAFETY_FAULT || s == SAFETY_ESTOP) && x->first_bad_us < 0) {
        x->first_bad_us = now;
        x->fault = r->rig.board.safety.fault;
    }
    r->ms++;
}

static fx_t *fx_new(const char *path)
{
    fx_t *x = calloc(1, sizeof(*x));
    assert_non_null(x);
    scn_error_t err;
    const scn_err_t e = scenario_load(&x->scn, path, &err);
    if (e != SCN_OK)
        fail_msg("%s:%u: %s", path, err.line, err.msg);
    x->r = rig_new(0.8f);
    /* The daemon's limits (firmware/board/board_config.c): 3 overruns in a row are a fault,
     * and a tool faster than 1.5 m/s is one (how an encoder jump shows). */
    x->r->rig.board.cfg.safety.overrun_streak = 3u;
    x->r->rig.board.cfg.max_velocity_m_s = 1.5f;
    x->r->link_hook = link_hook;
    x->r->link_hook_ctx = x;
    x->held = calloc(LINK_HELD_MAX, sizeof(*x->held));
    assert_non_null(x->held);
    x->force = calloc(FORCE_TICKS_MAX, sizeof(*x->force));
    assert_non_null(x->force);
    x->stranger_from_us = x->stranger_until_us = -1;
    x->stranger_kind = SCN_STRANGER_FORGE;
    x->captured = calloc(CAPTURED_MAX, sizeof(*x->captured));
    assert_non_null(x->captured);
    x->can_log = open_memstream(&x->can_text, &x->can_len);
    x->ev_log = open_memstream(&x->ev_text, &x->ev_len);
    assert_non_null(x->can_log);
    assert_non_null(x->ev_log);
    x->first_bad_us = -1;
    sim_runner_init(&x->run, &x->r->rig.sim_params, &x->scn, true, log_event, x);
    char text[64];
    snprintf(text, sizeof(text), "start scenario %s", x->scn.name);
    log_event(x, 0, text);
    return x;
}

/* With ARGIL_FAULT_LOG_DIR set, keeps the run's logs as DIR/NAME.candump and DIR/NAME.events
 * (inputs for argil-hil-check, and samples for a HIL rig). */
static void fx_keep_logs(const fx_t *x)
{
    const char *dir = getenv("ARGIL_FAULT_LOG_DIR");
    if (dir == NULL || dir[0] == '\0')
        return;
    const char *ext[2] = {"candump", "events"};
    const char *text[2] = {x->can_text, x->ev_text};
    const size_t len[2] = {x->can_len, x->ev_len};
    for (int k = 0; k < 2; k++) {
        char path[512];
        snprintf(path, sizeof(path), "%s/%s.%s", dir, x->scn.name, ext[k]);
        FILE *f = fopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(text[k], 1, len[k], f), len[k]);
        fclose(f);
    }
}

static void fx_run(fx_t *x)
{
    while (!sim_runner_done(&x->run))
        fx_tick(x);
    log_event(x, x->run.now_us, "end");
    fflush(x->can_log);
    fflush(x->ev_log);
    fx_keep_logs(x);
}

static void fx_free(fx_t *x)
{
    fclose(x->can_log);
    fclose(x->ev_log);
    free(x->can_text);
    free(x->ev_text);
    free(x->held);
    free(x->captured);
    free(x->force);
    rig_free(x->r);
    free(x);
}

/* Checks every expectation of x's scenario (or of scn when not NULL) from x's logs; returns
 * the number that failed and prints one line each. */
static int check_logs(const fx_t *x, const scenario_t *scn, bool quiet, uint32_t *hb_ridden)
{
    const scenario_t *s = scn ? scn : &x->scn;
    hil_obs_t o;
    hil_obs_init(&o);
    uint32_t line = 0;
    assert_int_equal(hil_obs_add_candump(&o, x->can_text, x->can_len, &line), HIL_OK);
    assert_int_equal(hil_obs_add_events(&o, s, x->ev_text, x->ev_len, &line), HIL_OK);
    int failed = 0;
    for (uint32_t i = 0; i < s->n_expects; i++) {
        hil_result_t res;
        hil_check_expect(s, &o, i, &res);
        if (!res.pass)
            failed++;
        if (hb_ridden && s->expect[i].kind == SCN_EXP_HEARTBEAT_SUPERVISED)
            *hb_ridden = res.tolerated;
        if (!quiet || !res.pass)
            printf("  %s %s line %u: %s — %s\n", res.pass ? "PASS" : "FAIL", s->name,
                   (unsigned)s->expect[i].line, s->expect[i].text, res.msg);
    }
    hil_obs_free(&o);
    return failed;
}

typedef struct {
    const char *file;
    int fault;              /* the fault code the board must latch; -1: must stay healthy,
                               -2: may fault, but only with alt_fault */
    uint32_t min_link_errors;
    fault_code_t alt_fault; /* a second acceptable code (0: none) */
    uint32_t min_hb_ridden; /* lost drive heartbeats the board must have ridden through */
} matrix_row_t;

static const matrix_row_t matrix[] = {
    {"basic.scn", -1, 0, FAULT_NONE, 0},
    {"estop.scn", FAULT_ESTOP, 0, FAULT_NONE, 0},
    {"bus_off.scn", FAULT_BUS, 0, FAULT_NONE, 0},
    {"heartbeat_lost.scn", FAULT_DRIVE_HEARTBEAT, 0, FAULT_NONE, 0},
    {"emcy.scn", FAULT_DRIVE_LINE, 0, FAULT_DRIVE_EMCY, 0},
    {"drive_fault_line.scn", FAULT_DRIVE_LINE, 0, FAULT_NONE, 0},
    {"encoder_jump.scn", FAULT_VELOCITY_LIMIT, 0, FAULT_NONE, 0},
    {"can_drop_1pct.scn", -1, 0, FAULT_NONE, 1},
    {"can_drop_10pct.scn", FAULT_DRIVE_HEARTBEAT, 0, FAULT_NONE, 2},
    {"can_delay.scn", -1, 0, FAULT_NONE, 0},
    {"host_lost.scn", FAULT_HOST_LOST, 0, FAULT_NONE, 0},
    {"link_delay.scn", -1, 0, FAULT_NONE, 0},
    {"link_duplicate.scn", -1, 0, FAULT_NONE, 0},
    {"link_reorder.scn", -1, 0, FAULT_NONE, 0},
    {"link_garbage.scn", -1, 5, FAULT_NONE, 0},
    {"link_nan.scn", FAULT_NONFINITE, 1, FAULT_NONE, 0},
    {"overrun.scn", FAULT_DEADLINE, 0, FAULT_NONE, 0},
    {"hostile_network.scn", -1, 0, FAULT_NONE, 0},
};

/* Runs a row and checks it; returns the run for more checks (fx_free it). */
static fx_t *run_row_keep(const matrix_row_t *row)
{
    char path[128];
    snprintf(path, sizeof(path), "hil/scenarios/%s", row->file);
    fx_t *x = fx_new(path);
    assert_true(x->scn.n_expects >= 1);
    fx_run(x);
    uint32_t ridden = 0;
    const int failed = check_logs(x, NULL, false, &ridden);
    printf("  %s: first FAULT/ESTOP at %.3f s (%s), link errors %u, CAN dropped %u/%u\n",
           x->scn.name, x->first_bad_us < 0 ? -1.0 : (double)x->first_bad_us * 1e-6,
           x->first_bad_us < 0 ? "none" : safety_fault_name(x->fault),
           x->r->rig.board.stats.link_errors, x->run.faults.dropped_to_board,
           x->run.faults.dropped_from_board);
    assert_int_equal(failed, 0);
    if (row->fault == -1) {
        assert_true(x->first_bad_us < 0);
    } else if (row->fault == -2) {
        assert_true(x->first_bad_us < 0 || x->fault == row->alt_fault);
    } else {
        assert_true(x->first_bad_us >= 0);
        assert_true(x->fault == (fault_code_t)row->fault ||
                    (row->alt_fault != FAULT_NONE && x->fault == row->alt_fault));
    }
    assert_true(x->r->rig.board.stats.link_errors >= row->min_link_errors);
    assert_true(ridden >= row->min_hb_ridden);
    return x;
}

static void run_row(const matrix_row_t *row)
{
    fx_free(run_row_keep(row));
}

/* The largest difference between two runs' forces, tick by tick (N), and the largest force. */
static float force_diff_n(const fx_t *a, const fx_t *b, float *peak_n)
{
    assert_int_equal(a->n_force, b->n_force);
    float worst = 0.0f, peak = 0.0f;
    for (uint32_t i = 0; i < a->n_force; i++) {
        const float d = vec3_norm(vec3_sub(a->force[i], b->force[i]));
        worst = d > worst ? d : worst;
        const float f = vec3_norm(a->force[i]);
        peak = f > peak ? f : peak;
    }
    *peak_n = peak;
    return worst;
}

/* The same scenario without its link faults, as the twin to compare forces with. */
static fx_t *twin_run(const char *file)
{
    char path[128];
    snprintf(path, sizeof(path), "hil/scenarios/%s", file);
    fx_t *t = fx_new(path);
    t->no_link_faults = true;
    fx_run(t);
    return t;
}

/* Runs a matrix row and its twin without the link faults; the largest difference between
 * their forces tick by tick goes to *diff_n, the largest force to *peak_n. */
static fx_t *run_with_twin(const matrix_row_t *row, fx_t **twin, float *diff_n, float *peak_n)
{
    fx_t *x = run_row_keep(row);
    *twin = twin_run(row->file);
    *diff_n = force_diff_n(x, *twin, peak_n);
    return x;
}

/* The host's frames twice (up to 300; as many as it sends by the end): every second copy is
 * refused and counted, none acts, and the hand feels exactly what it feels without them. */
static void test_link_duplicate(void **st)
{
    (void)st;
    fx_t *t;
    float diff, peak;
    fx_t *x = run_with_twin(&matrix[12], &t, &diff, &peak);
    const board_stats_t *bs = &x->r->rig.board.stats;
    printf("  link_duplicate: %u copies, refused duplicate %u, stale %u, no session %u; force "
           "differs from the run without duplicates by %.6f N (peak %.3f N)\n", x->dup_sent,
           bs->refused_duplicate, bs->refused_stale, bs->refused_no_session, (double)diff,
           (double)peak);
    assert_true(x->dup_sent >= 150);
    /* all but the copies of the run's last host tick, which no board tick takes in */
    assert_true(bs->refused_duplicate <= x->dup_sent && bs->refused_duplicate + 2u >= x->dup_sent);
    assert_int_equal(bs->refused_stale, 0);
    assert_int_equal(t->r->rig.board.stats.refused_duplicate, 0);
    assert_true(peak > 0.5f); /* the hand presses into the clay meanwhile */
    assert_true(diff == 0.0f);
    fx_free(t);
    fx_free(x);
}

/* 200 pairs of host frames swapped: within the window, so all are accepted once, none
 * refused, and the force is that of the run in order (to within 1 mN). */
static void test_link_reorder(void **st)
{
    (void)st;
    fx_t *t;
    float diff, peak;
    fx_t *x = run_with_twin(&matrix[13], &t, &diff, &peak);
    const board_stats_t *bs = &x->r->rig.board.stats;
    printf("  link_reorder: refused duplicate %u, stale %u; force differs from the run in "
           "order by %.6f N (peak %.3f N)\n", bs->refused_duplicate, bs->refused_stale,
           (double)diff, (double)peak);
    assert_int_equal(bs->refused_duplicate, 0);
    assert_int_equal(bs->refused_stale, 0);
    assert_true(peak > 0.5f);
    assert_true(diff <= 0.001f);
    fx_free(t);
    fx_free(x);
}

/* A stranger on the network sends CRC-valid HELLO, DISARM, END and TOOL frames from another
 * sender, numbered ahead of the host, for 1 s while the hand presses and strokes the clay:
 * every one is refused and counted, the board stays ACTIVE, and the hand feels exactly what it
 * feels with no stranger. */
static void test_stranger_cannot_command_the_arm(void **st)
{
    (void)st;
    fx_t *x = fx_new("hil/scenarios/basic.scn");
    x->stranger_from_us = 1000000;
    x->stranger_until_us = 2000000;
    fx_run(x);
    assert_int_equal(check_logs(x, NULL, false, NULL), 0);
    fx_t *t = twin_run("basic.scn");
    float peak = 0.0f;
    const float diff = force_diff_n(x, t, &peak);
    const board_stats_t *bs = &x->r->rig.board.stats;
    printf("  stranger: %u frames sent, refused for their sender %u; board %s, left ACTIVE %s; "
           "force differs from the run without the stranger by %.6f N (peak %.3f N)\n",
           x->stranger_sent, bs->transport_refused_source,
           safety_state_name(x->r->rig.board.safety.state), x->left_active ? "yes" : "no",
           (double)diff, (double)peak);
    assert_int_equal(x->stranger_sent, 200);
    assert_int_equal(bs->transport_refused_source, x->stranger_sent);
    assert_int_equal(x->r->rig.board.session.epoch, 1); /* no HELLO but the host's acted */
    assert_true(x->first_bad_us < 0);
    assert_true(x->was_active);
    assert_false(x->left_active);
    assert_true(peak > 0.5f);
    assert_true(diff == 0.0f);
    fx_free(t);
    fx_free(x);
}

/* hostile_network.scn: while the hand presses and strokes the clay a stranger replays the
 * host's captured frames (from another sender and from the host's own), sends CRC-valid
 * commands from another sender, and floods junk. Each frame is refused and counted by its
 * reason, the board stays ACTIVE with its one session, and the hand feels exactly what it
 * feels with no stranger. (The forged authentication tag over UDP, where a stranger can spoof
 * the host's own address, is the HIL's and test_link_auth's: this link carries no tag.) */
static void test_hostile_network(void **st)
{
    (void)st;
    fx_t *t;
    float diff, peak;
    fx_t *x = run_with_twin(&matrix[17], &t, &diff, &peak);
    const board_stats_t *bs = &x->r->rig.board.stats;
    printf("  hostile_network: replayed %u from another sender + %u from the host's, forged %u, "
           "flooded %u; refused: sender %u, duplicate %u, stale %u; board %s, left ACTIVE %s, "
           "sessions %u; force differs from the run without the stranger by %.6f N (peak "
           "%.3f N)\n", x->replayed_other, x->replayed_own, x->stranger_sent, x->flooded,
           bs->transport_refused_source, bs->refused_duplicate, bs->refused_stale,
           safety_state_name(x->r->rig.board.safety.state), x->left_active ? "yes" : "no",
           x->r->rig.board.session.epoch, (double)diff, (double)peak);
    assert_true(x->replayed_own >= 500u && x->stranger_sent >= 100u && x->flooded >= 10000u);
    assert_int_equal(bs->transport_refused_source,
                     x->replayed_other + x->stranger_sent + x->flooded);
    assert_int_equal(bs->refused_duplicate + bs->refused_stale, x->replayed_own);
    assert_int_equal(x->r->rig.board.session.epoch, 1);
    assert_true(x->first_bad_us < 0);
    assert_true(x->was_active);
    assert_false(x->left_active);
    assert_true(peak > 0.5f);
    assert_true(diff == 0.0f);
    fx_free(t);
    fx_free(x);
}

#define ROW_TEST(name, i)                  \
    static void name(void **st)            \
    {                                      \
        (void)st;                          \
        run_row(&matrix[i]);               \
    }
ROW_TEST(test_basic, 0)
ROW_TEST(test_estop, 1)
ROW_TEST(test_bus_off, 2)
ROW_TEST(test_heartbeat_lost, 3)
ROW_TEST(test_emcy, 4)
ROW_TEST(test_drive_fault_line, 5)
ROW_TEST(test_encoder_jump, 6)
ROW_TEST(test_can_drop_1pct, 7)
ROW_TEST(test_can_drop_10pct, 8)
ROW_TEST(test_can_delay, 9)
ROW_TEST(test_host_lost, 10)
ROW_TEST(test_link_delay, 11)
ROW_TEST(test_link_garbage, 14)
ROW_TEST(test_link_nan, 15)
ROW_TEST(test_overrun, 16)

/* The checker is not a rubber stamp: the host-lost run against bounds tighter than what the
 * board does (the force needs 50 ms + 20 ms) must fail, and so must a claim of torque during
 * the e-stop. */
static void test_checker_fails_a_violated_bound(void **st)
{
    (void)st;
    fx_t *x = fx_new("hil/scenarios/host_lost.scn");
    fx_run(x);
    assert_int_equal(check_logs(x, NULL, true, NULL), 0);
    /* The same file with three bounds the board cannot meet (same line numbers, so the
     * event log's injections still match its steps). */
    static char text[8192];
    FILE *f = fopen("hil/scenarios/host_lost.scn", "rb");
    assert_non_null(f);
    const size_t n = fread(text, 1, sizeof(text) - 1, f);
    fclose(f);
    text[n] = '\0';
    static const char *const swap[][2] = {
        {"force_zero within 75ms", "force_zero within 20ms"}, /* the board needs 70 ms */
        {"fault within 77ms", "fault within 40ms"},
        {"at 1.580 no_torque_frames", "at 1.400 no_torque_frames"}, /* torque until 1.57 s */
    };
    for (size_t k = 0; k < 3; k++) {
        char *at = strstr(text, swap[k][0]);
        assert_non_null(at);
        assert_int_equal(strlen(swap[k][0]), strlen(swap[k][1]));
        memcpy(at, swap[k][1], strlen(swap[k][1]));
    }
    scenario_t s;
    scn_error_t err;
    assert_int_equal(scenario_parse(&s, text, n, &err), SCN_OK);
    assert_int_equal(check_logs(x, &s, false, NULL), 3);
    fx_free(x);
}

/* The CAN log of a normal session decodes with the DBC file: every frame's id is a message
 * of firmware/argil.dbc, and the RPDO torque decodes to the value canopen.c encoded. */
static void test_basic_log_decodes_with_the_dbc(void **st)
{
    (void)st;
    static char dbc_text[65536];
    FILE *f = fopen("firmware/argil.dbc", "rb");
    assert_non_null(f);
    const size_t n = fread(dbc_text, 1, sizeof(dbc_text), f);
    fclose(f);
    static dbc_t d;
    uint32_t err_line = 0;
    assert_int_equal(dbc_parse(&d, dbc_text, n, &err_line), DBC_OK);
    fx_t *x = fx_new("hil/scenarios/basic.scn");
    fx_run(x);
    size_t pos = 0, frames = 0, rpdo_nonzero = 0;
    while (pos < x->can_len) {
        size_t end = pos;
        while (end < x->can_len && x->can_text[end] != '\n')
            end++;
        can_frame_t cf;
        assert_int_equal(dbc_candump_line(x->can_text + pos, end - pos, &cf), DBC_OK);
        const dbc_message_t *m = dbc_find(&d, cf.id);
        assert_non_null(m);
        assert_int_equal(m->dlc, cf.len);
        uint8_t node;
        uint16_t cw;
        int16_t tq;
        if (canopen_rpdo_decode(&cf, &node, &cw, &tq)) {
            char sig[32];
            snprintf(sig, sizeof(sig), "RPDO1_%u_TargetTorque", (unsigned)node);
            const dbc_signal_t *s = dbc_signal(m, sig);
            assert_non_null(s);
            assert_int_equal((int)dbc_raw(s, cf.data), tq);
            rpdo_nonzero += tq != 0;
        }
        frames++;
        pos = end + 1;
    }
    printf("  basic: %zu frames decoded with the DBC, %zu RPDOs with torque\n", frames,
           rpdo_nonzero);
    assert_true(frames > 4 * 4000); /* RPDO x3 + SYNC every tick for 4 s, TPDOs on top */
    assert_true(rpdo_nonzero > 1000);
    fx_free(x);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_basic),
        cmocka_unit_test(test_estop),
        cmocka_unit_test(test_bus_off),
        cmocka_unit_test(test_heartbeat_lost),
        cmocka_unit_test(test_emcy),
        cmocka_unit_test(test_drive_fault_line),
        cmocka_unit_test(test_encoder_jump),
        cmocka_unit_test(test_can_drop_1pct),
        cmocka_unit_test(test_can_drop_10pct),
        cmocka_unit_test(test_can_delay),
        cmocka_unit_test(test_host_lost),
        cmocka_unit_test(test_link_delay),
        cmocka_unit_test(test_link_duplicate),
        cmocka_unit_test(test_link_reorder),
        cmocka_unit_test(test_stranger_cannot_command_the_arm),
        cmocka_unit_test(test_hostile_network),
        cmocka_unit_test(test_link_garbage),
        cmocka_unit_test(test_link_nan),
        cmocka_unit_test(test_overrun),
        cmocka_unit_test(test_checker_fails_a_violated_bound),
        cmocka_unit_test(test_basic_log_decodes_with_the_dbc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
