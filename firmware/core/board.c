/* The board tick pipeline. */
#include "board.h"

#include <math.h>
#include <string.h>

#include "shared/gpio_lines.h"
#include "shared/wire.h"

/* Empties the box of nodes with pending impulses. */
static void impulse_box_clear(board_t *b)
{
    for (int a = 0; a < 3; a++) {
        b->impulse_lo[a] = INT32_MAX;
        b->impulse_hi[a] = -1;
    }
}

void board_cfg_default(board_cfg_t *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->tick_us = 1000u;
    cfg->max_force_n = 3.3f;
    cfg->impulse_period_us = 5000u;
    cfg->heartbeat_period_us = 10000u;
    cfg->rt_stats_period_us = 1000000u;
    cfg->swap_fade_ticks = 20u;
    cfg->contact_damping_n_s_per_m = 0.5f;
    cfg->contact_damping_s = 0.0025f;
    cfg->io_delay_ticks = 2u;
    cfg->slew_n_per_s = 1000.0f;
    cfg->passivity = true;
    cfg->pc_max_damping_n_s_per_m = 10.0f;
    cfg->pc_deadband_j = 0.2e-3f;
    cfg->joint_margin_rad = 0.1f;
    cfg->joint_limit_stiffness_nm_per_rad = 0.5f;
    cfg->accel_limit = 1e5f;
    cfg->velocity_filter = 0.5f;
    cfg->velocity_tolerance_m = 30e-6f; /* one count at the tip, worst joint at home: 0.027 mm */
    safety_cfg_default(&cfg->safety);
    drives_cfg_default(&cfg->drives);
    arm_desc_default(&cfg->arm);
    memcpy(cfg->name, "argil-board v1", 14);
}

argil_err_t board_init(board_t *b, const board_cfg_t *cfg)
{
    if (cfg->tick_us < 100u || cfg->tick_us > 10000u || !(cfg->max_force_n > 0.0f) ||
        !isfinite(cfg->max_force_n) || cfg->impulse_period_us == 0 ||
        cfg->heartbeat_period_us == 0 || cfg->rt_stats_period_us == 0 ||
        !(cfg->velocity_filter > 0.0f) || !(cfg->velocity_tolerance_m >= 0.0f) ||
        !isfinite(cfg->velocity_tolerance_m) ||
        cfg->velocity_filter > 1.0f || cfg->swap_fade_ticks > 10000u || !(cfg->contact_damping_n_s_per_m >= 0.0f) || !(cfg->contact_damping_s >= 0.0f) ||
        cfg->io_delay_ticks < 1u || cfg->io_delay_ticks > PASSIVITY_DELAY_MAX ||
        !(cfg->slew_n_per_s > 0.0f) || !(cfg->pc_max_damping_n_s_per_m >= 0.0f) || !(cfg->pc_deadband_j >= 0.0f) ||
        !(cfg->joint_margin_rad >= 0.0f) || !(cfg->joint_limit_stiffness_nm_per_rad >= 0.0f) ||
        !(cfg->accel_limit > 0.0f) || !isfinite(cfg->slew_n_per_s) || !isfinite(cfg->accel_limit))
        return ARGIL_ERR_ARG;
    b->cfg = *cfg;
    safety_init(&b->safety);
    drives_init(&b->drives);
    window_init(&b->window);
    haptics_init(&b->haptics);
    host_session_init(&b->session);
    memset(&b->tool, 0, sizeof(b->tool));
    b->tool_valid = false;
    memset(b->impulse_ns, 0, sizeof(b->impulse_ns));
    b->impulse_pending = false;
    impulse_box_clear(b);
    b->impulse_seq = 0;
    b->tx_seq = 0;
    b->time_us = 0;
    b->since_impulse_us = 0;
    b->since_heartbeat_us = 0;
    b->since_rt_stats_us = 0;
    rt_stats_init(&b->rt);
    b->hello_due = false; /* the board speaks HELLO in answer to a host's */
    b->fault_reported = false;
    b->arm_pending_us = 0;
    b->wdog_level = false;
    b->host_window_version = 0;
    b->host_impulse_ack = 0;
    b->have_tip = false;
    b->tip_device_m = vec3(0, 0, 0);
    memset(b->tpdos_seen, 0, sizeof(b->tpdos_seen));
    b->stale_ticks = 0;
    velocity_window_reset(&b->vel_window);
    b->sense_ticks = 0;
    b->pos_m = vec3(0, 0, 0);
    b->vel_m_s = vec3(0, 0, 0);
    b->force_n = vec3(0, 0, 0);
    b->swap_offset_n = vec3(0, 0, 0);
    b->swapped = false;
    passivity_init(&b->passivity, cfg->io_delay_ticks);
    b->spring_max_accel = 0.0f;
    b->log_head = 0;
    b->log_count = 0;
    b->settle_left = 0;
    b->work_m = vec3(0, 0, 0);
    b->work_radius_m = 0.0f;
    b->contact = false;
    b->sculpting = false;
    memset(&b->stats, 0, sizeof(b->stats));
    return ARGIL_OK;
}

void board_rt_stats_msg(const board_t *b, proto_msg_t *m)
{
    memset(m, 0, sizeof(*m));
    m->type = MSG_RT_STATS;
    rt_stats_to_msg(&b->rt, b->cfg.tick_us * 1000u, b->time_us, &m->u.rt_stats);
    board_link_counts(b, &m->u.rt_stats.link);
}

void board_link_counts(const board_t *b, proto_link_counts_t *c)
{
    c->decode_errors = b->stats.link_errors;
    c->wrong_source = b->stats.transport_refused_source;
    c->no_session = b->stats.refused_no_session + b->stats.transport_refused_no_session;
    c->duplicate = b->stats.refused_duplicate;
    c->stale = b->stats.refused_stale;
    c->sessions = b->session.epoch;
    c->bad_mac = b->stats.transport_refused_bad_mac;
    c->bad_nonce = b->stats.transport_refused_bad_nonce;
    c->arm_refused = b->stats.refused_arm;
}

vec3_t board_device_to_model(const board_t *b, vec3_t device_m)
{
    return vec3(b->tool.model_scale * device_m.x + b->tool.model_offset_m[0],
                b->tool.model_scale * device_m.y + b->tool.model_offset_m[1],
                b->tool.model_scale * device_m.z + b->tool.model_offset_m[2]);
}

/* Encodes msg into the tick's output; counts a drop when it does not fit. */
static void send(board_t *b, board_out_t *out, const proto_msg_t *msg)
{
    size_t len = 0;
    const proto_err_t e = proto_encode(msg, b->tx_seq, out->link_tx + out->link_tx_len,
                                       BOARD_LINK_TX_MAX - out->link_tx_len, &len);
    if (e != PROTO_OK) {
        b->stats.link_tx_dropped++;
        return;
    }
    b->tx_seq++;
    out->link_tx_len += len;
}

typedef struct {
    bool heartbeat;
    bool arm;
    bool disarm;
    bool nonfinite;
} host_events_t;

/* True when the host session admits m (counted by reason when not): nothing in a refused
 * frame acts. */
static bool session_admits(board_t *b, const proto_msg_t *m)
{
    const bool hello = m->type == MSG_HELLO && m->u.hello.role == PROTO_ROLE_HOST;
    switch (host_session_admit(&b->session, hello, hello || m->type == MSG_HEARTBEAT, m->seq)) {
    case HOST_FRAME_NO_SESSION: b->stats.refused_no_session++; return false;
    case HOST_FRAME_DUPLICATE: b->stats.refused_duplicate++; return false;
    case HOST_FRAME_STALE: b->stats.refused_stale++; return false;
    default: return true;
    }
}

/* Acts on one decoded frame from the host. */
static void handle_frame(board_t *b, const proto_msg_t *m, host_events_t *ev)
{
    if (!session_admits(b, m))
        return;
    b->stats.link_frames_rx++;
    switch (m->type) {
    case MSG_HELLO:
        if (m->u.hello.role == PROTO_ROLE_HOST) {
            b->hello_due = true;
            b->fault_reported = false; /* a (re)connected host learns a latched fault too */
        }
        break;
    case MSG_HEARTBEAT:
        ev->heartbeat = true;
        b->host_window_version = m->u.heartbeat.window_version;
        b->host_impulse_ack = m->u.heartbeat.impulse_seq;
        if (m->u.heartbeat.command == PROTO_CMD_ARM && b->cfg.refuse_arm) {
            b->stats.refused_arm++; /* the person's host is not known to have sent it */
        } else if (m->u.heartbeat.command == PROTO_CMD_ARM) {
            ev->arm = true;
        } else if (m->u.heartbeat.command == PROTO_CMD_DISARM) {
            ev->disarm = true;
        } else if (m->u.heartbeat.command == PROTO_CMD_END) {
            ev->disarm = true;
            host_session_end(&b->session);
        }
        break;
    case MSG_WINDOW: {
        const proto_err_t we = window_feed_decoded(&b->window, &m->u.window);
        if (we == PROTO_ERR_VALUE)
            ev->nonfinite = true;
        if (we != PROTO_OK) {
            b->stats.link_errors++;
            b->stats.last_link_error = we;
        }
        break;
    }
    case MSG_TOOL:
        b->tool = m->u.tool; /* the decoder has checked every field */
        b->tool_valid = true;
        break;
    default:
        break; /* TELEMETRY, IMPULSE, FAULT are board → host only */
    }
}

/* Decodes the frames in buf[0, len) and acts on them; a refused frame is skipped byte by byte
 * until the next frame boundary is found, so one bad frame costs only itself. With defer, up
 * to BOARD_DEFER_FRAMES whole WINDOW frames (magic, type and declared length checked only)
 * are copied aside undecoded for the next tick. */
static void decode_frames(board_t *b, const uint8_t *buf, size_t len, bool defer,
                          host_events_t *ev)
{
    proto_msg_t *const m = &b->scratch;
    size_t at = 0;
    while (at < len) {
        if (defer && b->deferred_n < BOARD_DEFER_FRAMES && len - at >= PROTO_HEADER_SIZE &&
            buf[at] == 'A' && buf[at + 1u] == 'R' && buf[at + 2u] == 'G' && buf[at + 3u] == 'L' &&
            buf[at + 5u] == MSG_WINDOW) {
            const size_t flen =
                PROTO_HEADER_SIZE + PROTO_CRC_SIZE + (size_t)le_get_u16(buf + at + 6u);
            if (flen <= PROTO_FRAME_MAX && flen <= len - at) {
                memcpy(b->deferred[b->deferred_n], buf + at, flen);
                b->deferred_len[b->deferred_n++] = (uint16_t)flen;
                b->stats.window_frames_deferred++;
                at += flen;
                continue;
            }
        }
        size_t flen = 0;
        const proto_err_t e = proto_decode(buf + at, len - at, m, &flen);
        if (e != PROTO_OK) {
            b->stats.link_errors++;
            b->stats.last_link_error = e;
            /* A window or tool with NaN, Inf or an out-of-range value: the host is broken, and
             * the safe state is a fault, not a guess. */
            if (e == PROTO_ERR_VALUE && len - at > 5u &&
                (buf[at + 5u] == MSG_WINDOW || buf[at + 5u] == MSG_TOOL))
                ev->nonfinite = true;
            if (e == PROTO_ERR_TRUNCATED)
                break; /* frames arrive whole; the rest of this buffer is a torn frame */
            at++;
            continue;
        }
        at += flen;
        handle_frame(b, m, ev);
    }
}

/* Decodes the WINDOW frames the last tick put off, then every frame the host sent this tick.
 * A tick that will send impulses (the flush: ~63k instructions of gathering, encoding and
 * CRC) puts its WINDOW frames off by one tick (~11.5k each), so the two never add up. */
static void receive_link(board_t *b, const board_in_t *in, host_events_t *ev, bool flush_due)
{
    const uint32_t n = b->deferred_n;
    b->deferred_n = 0;
    for (uint32_t k = 0; k < n; k++)
        decode_frames(b, b->deferred[k], b->deferred_len[k], false, ev);
    decode_frames(b, in->link_rx, in->link_rx ? in->link_rx_len : 0, flush_due, ev);
}

/* Kinematics: joint angles from the encoders, tip in device and model space, velocity. */
static bool sense_tool(board_t *b)
{
    if (!drives_positions_valid(&b->drives))
        return true;
    float q[ARGIL_DRIVES];
    for (int j = 0; j < ARGIL_DRIVES; j++)
        q[j] = arm_counts_to_rad(&b->cfg.arm, j, b->drives.d[j].position_counts);
    const vec3_t tip = arm_fk(&b->cfg.arm, q);
    if (!vec3_isfinite(tip))
        return false;
    /* The velocity is the motion since the last new position over the ticks it took: a TPDO
     * lost, or several arriving in one tick (a late bus), must not read as a standstill and
     * then a jump of several ticks' motion in one. Stale for longer than
     * BOARD_STALE_POSITION_TICKS, the arm is taken to be still. */
    bool fresh = false;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        if (b->drives.d[j].tpdos != b->tpdos_seen[j])
            fresh = true;
        b->tpdos_seen[j] = b->drives.d[j].tpdos;
    }
    const float dt_s = (float)b->cfg.tick_us * 1e-6f;
    b->sense_ticks++;
    if (b->have_tip && !fresh && b->stale_ticks < BOARD_STALE_POSITION_TICKS) {
        b->stale_ticks++;
    } else {
        const vec3_t fitted = b->cfg.velocity_tolerance_m > 0.0f
                                  ? velocity_window_add(&b->vel_window, tip, b->sense_ticks, dt_s,
                                                        b->cfg.velocity_tolerance_m)
                                  : vec3(0, 0, 0);
        if (b->have_tip) {
            const float span_s = dt_s * (float)(b->stale_ticks + 1u);
            const vec3_t v = b->cfg.velocity_tolerance_m > 0.0f
                                 ? fitted
                                 : vec3_scale(vec3_sub(tip, b->tip_device_m), 1.0f / span_s);
            const float a = b->cfg.velocity_filter;
            b->vel_m_s = vec3_add(vec3_scale(b->vel_m_s, 1.0f - a), vec3_scale(v, a));
        }
        b->stale_ticks = 0;
        b->tip_device_m = tip;
        b->have_tip = true;
    }
    if (b->tool_valid) {
        b->pos_m = board_device_to_model(b, tip);
    }
    return vec3_isfinite(b->pos_m) && vec3_isfinite(b->vel_m_s);
}

/* Remembers a sent impulse until a window from the host includes it. */
static void log_impulse(board_t *b, uint32_t seq, vec3_t pos_m, float impulse_ns)
{
    const uint32_t slot = b->log_head;
    if (b->log_count == BOARD_IMPULSE_LOG && (int32_t)(b->log_seq[slot] - b->host_impulse_ack) > 0)
        b->stats.impulse_log_overflow++;
    b->log_seq[slot] = seq;
    b->log_pos_m[slot] = pos_m;
    b->log_impulse_ns[slot] = impulse_ns;
    b->log_head = (slot + 1u) % BOARD_IMPULSE_LOG;
    if (b->log_count < BOARD_IMPULSE_LOG)
        b->log_count++;
}

/* Re-applies to a freshly swapped-in window the impulses its host had not yet applied when it
 * extracted it, as the velocity kicks the host will give them (Δv = J / m). */
static void reapply_impulses(board_t *b, window_buf_t *w)
{
    const float inv_h = 1.0f / w->spacing_m;
    /* The log is in sending order: walk back from the newest until the host has them all. */
    for (uint32_t n = 0; n < b->log_count; n++) {
        const uint32_t k = (b->log_head + BOARD_IMPULSE_LOG - 1u - n) % BOARD_IMPULSE_LOG;
        if ((int32_t)(b->log_seq[k] - w->impulse_seq) <= 0)
            break;
        const vec3_t d = vec3_sub(b->log_pos_m[k], w->origin_m);
        const int32_t i = window_index(w, (int32_t)lrintf(d.x * inv_h), (int32_t)lrintf(d.y * inv_h),
                                       (int32_t)lrintf(d.z * inv_h));
        if (i < 0)
            continue;
        w->velocity[i] += b->log_impulse_ns[k] / w->material.node_mass;
        b->stats.impulses_reapplied++;
    }
}

/* Lists, in node order, up to cap nodes of the box [lo, hi] with a nonzero impulse; *more
 * tells whether the box holds further ones. */
static uint32_t gather_impulses(const board_t *b, const window_buf_t *w, const int32_t lo[3],
                                const int32_t hi[3], uint32_t *nodes, uint32_t cap, bool *more)
{
    uint32_t n = 0;
    *more = false;
    for (int32_t z = lo[2]; z <= hi[2]; z++) {
        for (int32_t y = lo[1]; y <= hi[1]; y++) {
            const int32_t base = w->dims[0] * (y + w->dims[1] * z);
            const float *row = b->impulse_ns + base;
            for (int32_t x = lo[0]; x <= hi[0]; x++) {
                if (row[x] == 0.0f)
                    continue;
                if (n == cap) {
                    *more = true;
                    return n;
                }
                nodes[n++] = (uint32_t)(base + x);
            }
        }
    }
    return n;
}

/* Sends the accumulated impulses of the active window in node order, at most
 * BOARD_IMPULSE_FRAMES_MAX frames; only the box that received impulses is scanned. */
static void flush_impulses(board_t *b, board_out_t *out)
{
    const window_buf_t *w = window_active(&b->window);
    if (!w || !b->impulse_pending)
        return;
    proto_msg_t *const m = &b->scratch;
    int32_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = b->impulse_lo[a] < 0 ? 0 : b->impulse_lo[a];
        hi[a] = b->impulse_hi[a] > w->dims[a] - 1 ? w->dims[a] - 1 : b->impulse_hi[a];
    }
    uint32_t nodes[BOARD_IMPULSE_FRAMES_MAX * PROTO_IMPULSE_MAX];
    bool left = false;
    const uint32_t count = gather_impulses(b, w, lo, hi, nodes,
                                           BOARD_IMPULSE_FRAMES_MAX * PROTO_IMPULSE_MAX, &left);
    const int32_t nx = w->dims[0], nxy = w->dims[0] * w->dims[1];
    for (uint32_t at = 0; at < count;) {
        m->type = MSG_IMPULSE;
        m->u.impulse.window_version = w->version;
        m->u.impulse.impulse_seq = b->impulse_seq + 1u;
        m->u.impulse.count = 0;
        for (uint32_t k = at; k < count && m->u.impulse.count < PROTO_IMPULSE_MAX; k++) {
            proto_impulse_t *e = &m->u.impulse.entries[m->u.impulse.count++];
            e->node = nodes[k];
            e->impulse_ns = b->impulse_ns[nodes[k]];
        }
        const size_t before = out->link_tx_len;
        send(b, out, m);
        if (out->link_tx_len == before) {
            /* No room this tick: keep these impulses for the next flush. */
            left = true;
            break;
        }
        b->impulse_seq++;
        for (uint16_t k = 0; k < m->u.impulse.count; k++) {
            const int32_t node = (int32_t)m->u.impulse.entries[k].node;
            const int32_t z = node / nxy, y = (node - z * nxy) / nx;
            log_impulse(b, b->impulse_seq, window_node_pos(w, node - y * nx - z * nxy, y, z),
                        b->impulse_ns[node]);
            b->impulse_ns[node] = 0.0f;
        }
        at += m->u.impulse.count;
    }
    b->impulse_pending = left;
    if (!left)
        impulse_box_clear(b);
}

/* LED pattern per state: off idle, slow blink armed, on active, fast blink fault/e-stop. */
static bool status_led(const board_t *b)
{
    const uint32_t ms = (uint32_t)(b->time_us / 1000u);
    switch (b->safety.state) {
    case SAFETY_ARMED: return (ms / 500u) % 2u == 0;
    case SAFETY_ACTIVE: return true;
    case SAFETY_FAULT:
    case SAFETY_ESTOP: return (ms / 100u) % 2u == 0;
    default: return false;
    }
}

/* From the mapped force to the one the hand gets: contact damping, the passivity controller,
 * the window-swap smoothing, the force limit, the slew limit and the safety scale. */
static vec3_t shape_force(board_t *b, const haptics_out_t *h, float scale, float dt_s)
{
    vec3_t f = h->force_n;
    if (h->contact) {
        /* Contact damping b = b0 + K·τ. A delay τ makes a wall of stiffness K act like a
         * negative damper of about K·τ during a contact, and this pays it back: on the Z-width
         * bench (docs/haptics.md) it keeps the bounces passive up to 4 N/mm where b0 alone
         * gains energy from 2 N/mm. It is not what Colgate & Schenkel's condition asks for
         * (b > K·T/2 + |B| counts a virtual damper B against the device's own damping b, at
         * every frequency); on a one-tick backward difference of quantised positions it also
         * turned each encoder count into a force kick, which the adaptive-window velocity
         * (velocity.h) no longer does. */
        const float damping = b->cfg.contact_damping_n_s_per_m +
                              b->tool.contact_stiffness_n_per_m * b->cfg.contact_damping_s;
        f = vec3_sub(f, vec3_scale(b->vel_m_s, damping));
    }
    const window_buf_t *w = window_active(&b->window);
    /* The environment whose stored energy the observer follows: the window, the tool and
     * whether its button holds the clay (a pull's or rope's spring to the grab point, a push's
     * clamped contact) or not (the plain contact). Letting go of a pull inside the bump it
     * raised swaps one spring for another; counting that jump in stored energy as generated
     * made the controller drag and buzz in free space for half a second afterwards. */
    const bool holding = b->haptics.grabbing || b->haptics.pushing;
    const uint32_t env = ((w ? w->version : 0u) * TOOL_KIND_COUNT +
                          (b->tool_valid ? b->tool.kind : 0u)) * 2u + (holding ? 1u : 0u);
    const vec3_t device_m = b->tip_device_m;
    f = vec3_add(f, passivity_process(&b->passivity, device_m, b->vel_m_s, h->potential_j, env,
                                      dt_s, b->cfg.passivity && scale > 0.0f,
                                      b->cfg.pc_deadband_j, b->cfg.pc_max_damping_n_s_per_m));
    /* A force step the board makes on its own is brought in by Guo et al.'s exponential
     * weighted average: the difference from the force felt before decays by α each tick. Two
     * make one: a window swap, and a button going down or up with a tool whose force law it
     * changes (push: the contact slides freely while the clay may flow; pull and rope: the
     * spring to the grab point; letting go of a pull inside the bump it raised met the clay
     * 3 mm deep and threw the stylus out at the 3.3 N limit). */
    if (b->swapped || h->hold_edge) {
        /* the offset that makes this tick feel like the last (which already held the old
         * offset: adding to it counted that twice, a step each swap during a fade) */
        b->swap_offset_n = vec3_sub(b->force_n, f);
        b->swapped = false;
    }
    f = vec3_add(f, b->swap_offset_n);
    const float alpha = b->cfg.swap_fade_ticks > 0u ? 1.0f - 1.0f / (float)b->cfg.swap_fade_ticks : 0.0f;
    b->swap_offset_n = vec3_scale(b->swap_offset_n, alpha);
    const float limit = b->tool_valid && b->tool.max_force_n < b->cfg.max_force_n
                            ? b->tool.max_force_n
                            : b->cfg.max_force_n;
    f = vec3_clamp_len(f, limit);
    /* Slew limit: the force changes by at most slew · dt per tick. */
    const vec3_t step = vec3_clamp_len(vec3_sub(f, b->force_n), b->cfg.slew_n_per_s * dt_s);
    f = vec3_add(b->force_n, step);
    f = vec3_clamp_len(vec3_scale(f, scale), limit);
    if (!vec3_isfinite(f))
        f = vec3(0, 0, 0);
    passivity_applied(&b->passivity, f);
    return f;
}

/* Counts one more tick and keeps its number among the first BOARD_PREEMPTED_KEPT. */
static void keep_tick(uint32_t kept[BOARD_PREEMPTED_KEPT], uint32_t *count, uint32_t tick)
{
    if (*count < BOARD_PREEMPTED_KEPT)
        kept[*count] = tick;
    (*count)++;
}

void board_tick(board_t *b, const board_in_t *in, board_out_t *out)
{
    const uint32_t dt_us = b->cfg.tick_us;
    const float dt_s = (float)dt_us * 1e-6f;
    out->can_tx.n = 0;
    out->link_tx_len = 0;
    b->stats.ticks++;
    b->time_us += dt_us;

    /* Deadline accounting for the previous tick: late wake-up plus compute past the period. A
     * tick the platform could not time (preempted on a CPU-time clock) is counted apart: its
     * figure holds time that was not its own. */
    const uint64_t prev_used_ns = (uint64_t)in->prev_wake_ns + in->prev_compute_ns;
    const bool timed = !in->prev_compute_preempted;
    const bool overrun = timed && prev_used_ns > dt_us * 1000u;
    if (!timed) {
        b->stats.preempted_ticks++;
        if (prev_used_ns > dt_us * 1000u) {
            keep_tick(b->stats.preempted_over_tick, &b->stats.preempted_over_period,
                      b->stats.ticks - 1u);
        }
    }
    if (b->stats.ticks > 1u && timed)
        (void)rt_stats_add(&b->rt, in->prev_wake_ns, in->prev_compute_ns, dt_us * 1000u);
    if (overrun)
        keep_tick(b->stats.deadline_miss_tick, &b->stats.deadline_misses, b->stats.ticks - 1u);
    if (timed && in->prev_compute_ns > b->stats.worst_compute_ns)
        b->stats.worst_compute_ns = in->prev_compute_ns;

    /* 1. Sense. */
    host_events_t ev = {false, false, false, false};
    if (in->can_rx)
        drives_receive(&b->drives, in->can_rx);
    b->stats.transport_refused_source = in->link_refused_source;
    b->stats.transport_refused_no_session = in->link_refused_no_session;
    b->stats.transport_refused_bad_mac = in->link_refused_bad_mac;
    b->stats.transport_refused_bad_nonce = in->link_refused_bad_nonce;
    receive_link(b, in, &ev,
                 b->impulse_pending && (b->since_impulse_us + dt_us >= b->cfg.impulse_period_us ||
                                        window_pending(&b->window)));
    (void)host_session_process(&b->session, dt_us, b->cfg.safety.host_timeout_us);
    if (ev.arm) {
        drives_clear_emcy(&b->drives);
        /* Re-arm after a drive trip: reset the drives' faults (power stays off) and let the
         * ARM wait, bounded, for DRIVE_FAULT_N to come back; never while the e-stop is down. */
        const bool latched = b->safety.state == SAFETY_FAULT || b->safety.state == SAFETY_IDLE;
        if (latched && (in->gpio_in & GPIO_IN_ESTOP_N) != 0) {
            drives_request_fault_reset(&b->drives, BOARD_REARM_WAIT_US);
            b->arm_pending_us = BOARD_REARM_WAIT_US;
        }
    }

    /* Swap a complete window in at this tick boundary, once its predecessor's impulses are out. */
    if (window_pending(&b->window) && !b->impulse_pending) {
        /* impulse_ns is all zero here: every entry went out before the swap. */
        window_swap(&b->window);
        reapply_impulses(b, window_active_mut(&b->window));
        if (b->settle_left > 0)
            b->settle_left = BOARD_SETTLE_TICKS;
        haptics_reset_path(&b->haptics);
        b->swapped = true;
        b->stats.windows_swapped++;
    }

    /* 2. Kinematics. */
    bool nonfinite = ev.nonfinite || !sense_tool(b);

    /* 3-4. Force mapping and the local window step. */
    window_buf_t *w = window_active_mut(&b->window);
    const bool btn1 = (in->gpio_in & GPIO_IN_STYLUS_BTN1) != 0;
    haptics_out_t h = {vec3(0, 0, 0), 0.0f, false, false, false, vec3(0, 0, 0), 0.0f,
                       {INT32_MAX, INT32_MAX, INT32_MAX}, {-1, -1, -1}, false};
    if (w && b->tool_valid && b->have_tip && !nonfinite) {
        haptics_process(&b->haptics, &b->tool, w, b->pos_m, b->vel_m_s, btn1,
                        safety_may_sculpt(&b->safety), dt_s, b->impulse_ns, &h);
        if (h.sculpting) {
            b->impulse_pending = true;
            b->settle_left = BOARD_SETTLE_TICKS;
        }
        for (int a = 0; a < 3; a++) {
            if (h.touched_lo[a] < b->impulse_lo[a])
                b->impulse_lo[a] = h.touched_lo[a];
            if (h.touched_hi[a] > b->impulse_hi[a])
                b->impulse_hi[a] = h.touched_hi[a];
        }
        /* Step the springs only in a box around where the tool works the clay — the nodes
         * its forces reach — the board's own physical window (Hua & Qin §6.3). */
        if (h.sculpting) {
            b->work_m = h.work_m;
            b->work_radius_m = h.work_radius_m;
        }
        const float reach = 0.75f * b->work_radius_m;
        int32_t lo[3], hi[3];
        const float p[3] = {b->work_m.x - w->origin_m.x, b->work_m.y - w->origin_m.y,
                            b->work_m.z - w->origin_m.z};
        for (int a = 0; a < 3; a++) {
            lo[a] = (int32_t)floorf((p[a] - reach) / w->spacing_m);
            hi[a] = (int32_t)ceilf((p[a] + reach) / w->spacing_m) + 1;
        }
        /* The window's springs move only while the tool works the clay and shortly after (or
         * after re-applied impulses); a window at rest is left alone — the host is
         * authoritative and sends the settled shape. */
        spring_field_t f = {{w->dims[0], w->dims[1], w->dims[2]},
                            w->density, w->rest, w->velocity, w->force, w->node_stiffness};
        /* Adaptive step (Hua & Qin §7): halve while the step is beyond the explicit stability
         * bound or the last step's acceleration exceeded the limit; at most 3 halvings. */
        spring_material_t worst = w->material;
        worst.stiffness = w->max_stiffness;
        uint32_t sub = b->settle_left > 0 ? 1u : 0u;
        if (b->settle_left > 0)
            b->settle_left--;
        while (sub > 0 && sub < BOARD_SUBSTEPS_MAX &&
               (dt_s / (float)sub > springs_stable_dt_s(&worst) ||
                b->spring_max_accel * (dt_s / (float)sub) > b->cfg.accel_limit * 1e-3f))
            sub *= 2u;
        if (sub > b->stats.max_substeps)
            b->stats.max_substeps = sub;
        b->spring_max_accel = 0.0f;
        for (uint32_t k = 0; k < sub; k++) {
            /* External forces act over the whole tick: springs_step consumes them in the
             * first sub-step, so scale them to keep the impulse. */
            if (k == 0 && sub > 1u)
                for (int32_t z = lo[2] < 0 ? 0 : lo[2]; z < hi[2] && z < w->dims[2]; z++)
                    for (int32_t y = lo[1] < 0 ? 0 : lo[1]; y < hi[1] && y < w->dims[1]; y++)
                        for (int32_t x = lo[0] < 0 ? 0 : lo[0]; x < hi[0] && x < w->dims[0]; x++)
                            w->force[window_index(w, x, y, z)] *= (float)sub;
            const float acc = springs_step(&f, &w->material, lo, hi, dt_s / (float)sub);
            if (acc > b->spring_max_accel)
                b->spring_max_accel = acc;
        }
    } else {
        haptics_reset_path(&b->haptics);
    }
    if (!vec3_isfinite(h.force_n))
        nonfinite = true;

    /* 5. Safety. */
    safety_inputs_t si;
    si.estop_pressed = (in->gpio_in & GPIO_IN_ESTOP_N) == 0;
    si.drive_fault_line = (in->gpio_in & GPIO_IN_DRIVE_FAULT_N) == 0;
    si.drives_enabled = drives_all_enabled(&b->drives);
    si.drive_heartbeat_lost = drives_heartbeat_lost(&b->drives, &b->cfg.drives);
    si.drive_emcy = drives_any_emcy(&b->drives);
    si.window_ready = w != 0 && b->tool_valid && b->have_tip;
    si.host_heartbeat = ev.heartbeat;
    si.arm_request = ev.arm || b->arm_pending_us > 0;
    si.disarm_request = ev.disarm;
    si.nonfinite = nonfinite;
    si.force_limit_exceeded = false;
    si.deadline_overrun = overrun;
    si.bus_error = drives_bus_error(&b->drives, &b->cfg.drives);
    si.velocity_limit_exceeded =
        b->cfg.max_velocity_m_s > 0.0f && vec3_norm(b->vel_m_s) > b->cfg.max_velocity_m_s;
    const float scale = safety_process(&b->safety, &b->cfg.safety, &si, dt_us);
    const bool waiting = b->safety.state == SAFETY_FAULT || b->safety.state == SAFETY_IDLE;
    b->arm_pending_us = (waiting && !ev.disarm && b->arm_pending_us > dt_us)
                            ? b->arm_pending_us - dt_us : 0;

    const vec3_t f = nonfinite ? vec3(0, 0, 0) : shape_force(b, &h, scale, dt_s);
    b->force_n = f;
    b->contact = h.contact;
    b->sculpting = h.sculpting && scale > 0.0f;
    const float fn = vec3_norm(f);
    if (fn > b->stats.peak_force_n)
        b->stats.peak_force_n = fn;

    /* 6. Actuate: tau = Jᵀ F, motor torque in per-mille of rated. */
    int16_t permille[ARGIL_DRIVES] = {0};
    if (b->have_tip && !nonfinite && scale > 0.0f) {
        float q[ARGIL_DRIVES], jac[3][ARGIL_DRIVES], tau[ARGIL_DRIVES];
        for (int j = 0; j < ARGIL_DRIVES; j++)
            q[j] = arm_counts_to_rad(&b->cfg.arm, j, b->drives.d[j].position_counts);
        arm_jacobian(&b->cfg.arm, q, jac);
        arm_jt_force(jac, f, tau);
        /* Soft workspace limits: within the margin of a joint limit, a joint-space spring
         * pushes back before the hard stop. */
        const float m = b->cfg.joint_margin_rad, k = b->cfg.joint_limit_stiffness_nm_per_rad;
        for (int j = 0; j < ARGIL_DRIVES; j++) {
            const float over_hi = q[j] - (b->cfg.arm.q_max_rad[j] - m);
            const float over_lo = (b->cfg.arm.q_min_rad[j] + m) - q[j];
            if (over_hi > 0.0f)
                tau[j] -= k * over_hi * scale;
            else if (over_lo > 0.0f)
                tau[j] += k * over_lo * scale;
        }
        for (int j = 0; j < ARGIL_DRIVES; j++) {
            float pm = tau[j] / b->cfg.arm.gear_ratio[j] / b->cfg.arm.rated_torque_nm[j] * 1000.0f;
            if (!isfinite(pm))
                pm = 0.0f;
            if (pm > 32767.0f) pm = 32767.0f;
            if (pm < -32767.0f) pm = -32767.0f;
            permille[j] = (int16_t)lrintf(pm);
        }
    }
    const bool drives_on = safety_drives_on(&b->safety);
    drives_process(&b->drives, &b->cfg.drives, drives_on, permille, dt_us, &out->can_tx);
    const bool healthy = b->safety.state != SAFETY_FAULT && b->safety.state != SAFETY_ESTOP;
    if (healthy)
        b->wdog_level = !b->wdog_level;
    out->gpio_out = (drives_on ? GPIO_OUT_DRIVE_ENABLE : 0u) |
                    (status_led(b) ? GPIO_OUT_STATUS_LED : 0u) |
                    (b->wdog_level ? GPIO_OUT_WDOG_KICK : 0u);

    /* 7. Telemetry, heartbeats, impulses, faults. */
    proto_msg_t *const m = &b->scratch;
    if (b->hello_due) {
        memset(m, 0, sizeof(*m));
        m->type = MSG_HELLO;
        m->u.hello.role = PROTO_ROLE_BOARD;
        m->u.hello.drives = ARGIL_DRIVES;
        m->u.hello.window_max = ARGIL_WINDOW_MAX;
        m->u.hello.tick_hz = (uint16_t)(1000000u / dt_us);
        memcpy(m->u.hello.name, b->cfg.name, PROTO_NAME_LEN);
        send(b, out, m);
        b->hello_due = false;
    }
    const bool bad = b->safety.state == SAFETY_FAULT || b->safety.state == SAFETY_ESTOP;
    if (bad && !b->fault_reported) {
        m->type = MSG_FAULT;
        m->u.fault.time_us = b->time_us;
        m->u.fault.code = (uint16_t)b->safety.fault;
        m->u.fault.state = (uint8_t)b->safety.state;
        m->u.fault.detail = b->stats.last_link_error < 0 ? (uint32_t)(-b->stats.last_link_error) : 0u;
        send(b, out, m);
        b->fault_reported = true;
    } else if (!bad) {
        b->fault_reported = false;
    }
    b->since_impulse_us += dt_us;
    if (b->since_impulse_us >= b->cfg.impulse_period_us || window_pending(&b->window)) {
        flush_impulses(b, out);
        b->since_impulse_us = 0;
    }
    b->since_heartbeat_us += dt_us;
    if (b->since_heartbeat_us >= b->cfg.heartbeat_period_us) {
        const window_buf_t *aw = window_active(&b->window);
        m->type = MSG_HEARTBEAT;
        m->u.heartbeat.time_us = b->time_us;
        m->u.heartbeat.window_version = aw ? aw->version : 0u;
        m->u.heartbeat.impulse_seq = b->impulse_seq;
        m->u.heartbeat.command = PROTO_CMD_NONE;
        send(b, out, m);
        b->since_heartbeat_us = 0;
    }
    b->since_rt_stats_us += dt_us;
    if (b->since_rt_stats_us >= b->cfg.rt_stats_period_us) {
        board_rt_stats_msg(b, m);
        send(b, out, m);
        b->stats.rt_stats_sent++;
        b->since_rt_stats_us = 0;
    }
    const window_buf_t *aw = window_active(&b->window);
    m->type = MSG_TELEMETRY;
    msg_telemetry_t *t = &m->u.telemetry;
    t->time_us = b->time_us;
    t->tick = b->stats.ticks;
    t->state = (uint8_t)b->safety.state;
    t->tool_kind = b->tool_valid ? b->tool.kind : (uint8_t)TOOL_TOUCH;
    t->buttons = (uint8_t)((btn1 ? 1u : 0u) | ((in->gpio_in & GPIO_IN_STYLUS_BTN2) ? 2u : 0u));
    t->flags = (uint8_t)((b->contact ? 1u : 0u) | (b->sculpting ? 2u : 0u));
    const vec3_t pos = vec3_isfinite(b->pos_m) ? b->pos_m : vec3(0, 0, 0);
    const vec3_t vel = vec3_isfinite(b->vel_m_s) ? b->vel_m_s : vec3(0, 0, 0);
    t->pos_m[0] = pos.x; t->pos_m[1] = pos.y; t->pos_m[2] = pos.z;
    t->vel_m_s[0] = vel.x; t->vel_m_s[1] = vel.y; t->vel_m_s[2] = vel.z;
    t->force_n[0] = f.x; t->force_n[1] = f.y; t->force_n[2] = f.z;
    t->window_version = aw ? aw->version : 0u;
    t->compute_ns = in->prev_compute_ns;
    t->deadline_misses = b->stats.deadline_misses;
    send(b, out, m);
}
