/* The SIL rig shared by the scenario tests: the simulated arm and drives, the board core and a
 * host on one virtual clock. Either the host is argil's own peer over a clay sphere (full
 * system), or the test plays the host itself and hands the board windows it built (to set up
 * walls, stiffness maps and broken input exactly). Header-only: each scenario is one binary. */
#ifndef ARGIL_SIL_RIG_H
#define ARGIL_SIL_RIG_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/peer.h"
#include "host/model/grid.h"
#include "shared/gpio_lines.h"
#include "sim/rig/rig.h"

typedef struct {
    sim_rig_t rig;            /* the simulated arm, the sim HAL and the board */
    uint32_t can_burst_ticks; /* > 1: the device's frames reach the board in bursts this far apart */
    can_batch_t can_held;     /* the frames of the burst being gathered */
    grid_t grid;
    bool rep_given;           /* the peer sculpts the caller's representation, not grid */
    peer_t peer;
    bool manual_host;         /* the test plays the host (rig_send_window, heartbeats here) */
    msg_tool_t tool;
    vec3_t offset_m;          /* model = device + offset */
    vec3_t hand_model_m;
    bool hand_released;
    bool btn1;
    bool host_alive;          /* the host ticks and answers */
    uint32_t host_seq;
    uint32_t window_version;
    bool armed_sent;
    uint8_t rx[SIM_RIG_LINK_BYTES];
    uint32_t ms;              /* host milliseconds so far: the host acts once per millisecond */
    uint32_t tick_us;         /* the board's loop period the rig steps (rig_set_tick_us) */
    uint32_t tick_us_in_ms;   /* of the current host millisecond, the microseconds stepped */
    /* Optional: every frame the host's peer sends goes here instead of straight to the link
     * (tests/sil/test_faults.c loses, delays, duplicates and reorders them). NULL: direct. */
    bool (*link_hook)(void *hook_ctx, const uint8_t *f, size_t len);
    void *link_hook_ctx;
} rig_t;

static inline bool rig_send(void *ctx, const uint8_t *f, size_t len)
{
    rig_t *r = ctx;
    if (r->link_hook)
        return r->link_hook(r->link_hook_ctx, f, len);
    return sim_rig_host_send(&r->rig, f, len) == ARGIL_OK;
}

/* A sensible tool of the given kind, as the host would send it. */
static inline msg_tool_t rig_tool(const rig_t *r, tool_kind_t kind, float stiffness_n_per_mm)
{
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.kind = (uint8_t)kind;
    t.shape = TOOL_SHAPE_POINT;
    t.filter = BETA_GAUSSIAN;
    t.flags = 0;
    t.radius_m = 0.004f;
    t.length_m = 0.0f;
    t.axis[2] = 1.0f;
    t.alpha = 30000.0f;
    t.contact_stiffness_n_per_m = stiffness_n_per_mm * 1000.0f;
    t.max_force_n = 3.3f;
    t.iso = 0.5f;
    t.yield_force_n = 0.5f;
    t.friction = 0.0f;
    t.probe_gain = 0.02f;
    t.rope_stiffness_n_per_m = 200.0f;
    t.model_scale = 1.0f;
    t.model_offset_m[0] = r->offset_m.x;
    t.model_offset_m[1] = r->offset_m.y;
    t.model_offset_m[2] = r->offset_m.z;
    return t;
}

static inline void rig_tick(rig_t *r);

/* Sends one frame to the board; when the link is full (a 32³ window is larger than the link's
 * buffer), lets the system run a tick at a time until there is room. */
static inline void rig_send_msg(rig_t *r, proto_msg_t *m)
{
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(m, r->host_seq++, buf, sizeof(buf), &len), PROTO_OK);
    int tries = 0;
    while (sim_rig_host_send(&r->rig, buf, len) == ARGIL_ERR_FULL && tries++ < 1000)
        rig_tick(r);
    assert_int_equal(tries <= 1000, 1);
}

/* Builds the rig. manual_host: the test provides windows; otherwise argil's peer over rep, or
 * (rep NULL) over a 30 mm clay sphere at the model origin. The stylus starts at model
 * (0, 0, 60 mm). */
static rig_t *rig_new_host(float stiffness_n_per_mm, bool manual_host, const rep_t *rep)
{
    rig_t *r = calloc(1, sizeof(*r));
    assert_non_null(r);
    sim_rig_cfg_t rc;
    sim_rig_cfg_default(&rc);
    /* Scenarios run on a virtual clock and test behaviour, not this machine's speed: a
     * sanitizer build on a busy machine must not trip the overrun streak (tested on its own in
     * test_safety and test_safety_table). */
    rc.board.safety.overrun_streak = 0;
    assert_int_equal(sim_rig_init(&r->rig, &rc), ARGIL_OK);
    r->manual_host = manual_host;
    r->tick_us = 1000u;
    r->offset_m = vec3_sub(vec3(0, 0, 0.060f), sim_rig_tip_m(&r->rig));
    r->hand_model_m = vec3(0, 0, 0.060f);
    r->host_alive = true;
    r->tool = rig_tool(r, TOOL_TOUCH, stiffness_n_per_mm);
    if (!manual_host && rep) {
        r->rep_given = true;
        peer_cfg_t pc;
        peer_cfg_default(&pc);
        assert_int_equal(peer_init_rep(&r->peer, &pc, *rep, rig_send, NULL, r), ARGIL_OK);
        peer_set_tool(&r->peer, &r->tool);
        peer_request_arm(&r->peer);
        assert_true(peer_send_hello(&r->peer, "sil rig"));
    } else if (!manual_host) {
        const int32_t dims[3] = {72, 72, 72};
        const float half = 0.5f * 71 * 0.00125f;
        assert_int_equal(grid_init(&r->grid, dims, 0.00125f, vec3(-half, -half, -half)),
                         ARGIL_OK);
        grid_fill_sphere(&r->grid, vec3(0, 0, 0), 0.030f);
        peer_cfg_t pc;
        peer_cfg_default(&pc);
        assert_int_equal(peer_init(&r->peer, &pc, &r->grid, rig_send, NULL, r), ARGIL_OK);
        peer_set_tool(&r->peer, &r->tool);
        peer_request_arm(&r->peer);
        assert_true(peer_send_hello(&r->peer, "sil rig"));
    } else {
        proto_msg_t m;
        memset(&m, 0, sizeof(m));
        m.type = MSG_HELLO; /* the board serves the host that says HELLO */
        m.u.hello.role = PROTO_ROLE_HOST;
        rig_send_msg(r, &m);
        memset(&m, 0, sizeof(m));
        m.type = MSG_TOOL;
        m.u.tool = r->tool;
        rig_send_msg(r, &m);
    }
    return r;
}

static inline rig_t *rig_new_mode(float stiffness_n_per_mm, bool manual_host)
{
    return rig_new_host(stiffness_n_per_mm, manual_host, NULL);
}

static inline rig_t *rig_new(float stiffness_n_per_mm)
{
    return rig_new_mode(stiffness_n_per_mm, false);
}

static inline void rig_free(rig_t *r)
{
    if (!r->manual_host) {
        peer_free(&r->peer);
        if (!r->rep_given)
            grid_free(&r->grid);
    }
    free(r);
}

/* Changes the tool (both modes). */
static inline void rig_set_tool(rig_t *r, const msg_tool_t *t)
{
    r->tool = *t;
    if (!r->manual_host) {
        peer_set_tool(&r->peer, t);
        return;
    }
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_TOOL;
    m.u.tool = *t;
    rig_send_msg(r, &m);
}

/* Manual host: sends a whole window (density, and stiffness when not NULL) as one version. */
static inline void rig_send_window(rig_t *r, const float *density, const float *stiffness,
                            const int32_t dims[3], vec3_t origin_m, float spacing_m,
                            const spring_material_t *mat)
{
    static proto_msg_t m;
    static float all[PROTO_WINDOW_CHANNELS_MAX * ARGIL_WINDOW_SAMPLES_MAX];
    const int32_t n = dims[0] * dims[1] * dims[2];
    memcpy(all, density, (size_t)n * sizeof(float));
    if (stiffness)
        memcpy(all + n, stiffness, (size_t)n * sizeof(float));
    msg_window_t head;
    memset(&head, 0, sizeof(head));
    head.version = ++r->window_version;
    for (int a = 0; a < 3; a++)
        head.dims[a] = (uint8_t)dims[a];
    head.channels = stiffness ? 2 : 1;
    head.origin_m[0] = origin_m.x;
    head.origin_m[1] = origin_m.y;
    head.origin_m[2] = origin_m.z;
    head.spacing_m = spacing_m;
    head.iso = 0.5f;
    head.node_mass = mat->node_mass;
    head.stiffness = mat->stiffness;
    head.damping = mat->damping;
    head.plastic_rate_hz = mat->plastic_rate_hz;
    head.chunk_count = window_chunk_count(head.dims, head.channels);
    for (uint16_t i = 0; i < head.chunk_count; i++) {
        memset(&m, 0, sizeof(m));
        m.type = MSG_WINDOW;
        assert_int_equal(window_chunk_fill(&head, all, i, &m.u.window), PROTO_OK);
        rig_send_msg(r, &m);
    }
}

/* Runs the board and the simulated device at tick_us (the board's loop period: 1000 at 1 kHz,
 * 250 at 4 kHz); call before the first tick. The host still acts once per millisecond: the
 * manual host's heartbeat every 5 ms, the peer's tick, r->ms. */
static inline void rig_set_tick_us(rig_t *r, uint32_t tick_us)
{
    r->tick_us = tick_us;
    r->rig.board.cfg.tick_us = tick_us;
    hal_sim_set_tick_us(&r->rig.hal, tick_us);
}

/* One board tick of the whole system (one millisecond unless rig_set_tick_us said otherwise). */
static inline void rig_tick(rig_t *r)
{
    if (r->hand_released)
        sim_rig_release_hand(&r->rig);
    else
        sim_rig_set_hand(&r->rig, vec3_sub(r->hand_model_m, r->offset_m), vec3(0, 0, 0),
                         r->btn1, false);
    if (r->can_burst_ticks > 1) {
        /* A late bus: the device's frames reach the board only every can_burst_ticks ticks,
         * all at once (as argil-sim under emulation answers several SYNCs in one read). */
        can_batch_t to_board;
        sim_rig_step_device_frames(&r->rig, r->tick_us, &to_board);
        for (uint8_t i = 0; i < to_board.n; i++)
            (void)can_batch_push(&r->can_held, &to_board.f[i]);
        if (r->ms % r->can_burst_ticks == 0) {
            hal_sim_put_to_board(&r->rig.hal, &r->can_held);
            r->can_held.n = 0;
        }
        (void)sim_rig_step_board(&r->rig);
    } else {
        (void)sim_rig_step_ns(&r->rig, r->tick_us);
    }
    const size_t n = sim_rig_host_receive(&r->rig, r->rx, sizeof(r->rx));
    if (r->host_alive && !r->manual_host)
        peer_receive(&r->peer, r->rx, n);
    r->tick_us_in_ms += r->tick_us;
    if (r->tick_us_in_ms < 1000u)
        return;
    r->tick_us_in_ms -= 1000u;
    if (r->host_alive && !r->manual_host) {
        peer_tick(&r->peer, 1000);
    } else if (r->host_alive && r->ms % 5u == 0) {
        proto_msg_t m;
        memset(&m, 0, sizeof(m));
        m.type = MSG_HEARTBEAT;
        m.u.heartbeat.time_us = (uint64_t)r->ms * 1000u;
        m.u.heartbeat.window_version = r->window_version;
        m.u.heartbeat.impulse_seq = r->rig.board.impulse_seq;
        if (!r->armed_sent && r->rig.board.safety.state == SAFETY_IDLE && r->window_version > 0) {
            m.u.heartbeat.command = PROTO_CMD_ARM;
            r->armed_sent = true;
        }
        rig_send_msg(r, &m);
    }
    r->ms++;
}

/* The board ticks in ms milliseconds. */
static inline int rig_ticks_in_ms(const rig_t *r, int ms)
{
    return (int)((int64_t)ms * 1000 / (int64_t)r->tick_us);
}

/* Runs until the board is ACTIVE; returns the milliseconds it took, rounded up (or -1). */
static inline int rig_until_active(rig_t *r, int max_ms)
{
    const int ticks = rig_ticks_in_ms(r, max_ms);
    for (int i = 0; i < ticks; i++) {
        rig_tick(r);
        if (r->rig.board.safety.state == SAFETY_ACTIVE)
            return (int)(((int64_t)(i + 1) * r->tick_us + 999) / 1000);
    }
    return -1;
}

/* Moves the hand in a straight line over ms milliseconds, a step each board tick. */
static inline void rig_move(rig_t *r, vec3_t to_m, int ms)
{
    const vec3_t from = r->hand_model_m;
    const int ticks = rig_ticks_in_ms(r, ms);
    for (int i = 1; i <= ticks; i++) {
        r->hand_model_m = vec3_add(from, vec3_scale(vec3_sub(to_m, from), (float)i / (float)ticks));
        rig_tick(r);
    }
}

/* The stylus tip in model space (the truth, from the simulator). */
static inline vec3_t rig_tip_model(const rig_t *r)
{
    return vec3_add(sim_rig_tip_m(&r->rig), r->offset_m);
}

/* Where the host's clay surface crosses the +z axis through (x, y), in metres (-1 if none). */
static inline float rig_surface_z(const rig_t *r, float x, float y)
{
    float prev = grid_density_at(&r->grid, vec3(x, y, 0.045f));
    for (int k = 1; k <= 4500; k++) {
        const float z = 0.045f - 1e-5f * (float)k;
        const float d = grid_density_at(&r->grid, vec3(x, y, z));
        if (prev < r->grid.iso && d >= r->grid.iso)
            return z + 1e-5f * (d - r->grid.iso) / (d - prev);
        prev = d;
    }
    return -1.0f;
}

#endif
