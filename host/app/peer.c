/* Host side of the board protocol. */
#include "peer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/safety.h"

void peer_cfg_default(peer_cfg_t *cfg)
{
    cfg->window_edge = 16;
    cfg->heartbeat_period_us = 5000u;
    cfg->solve_period_us = 10000u;
    cfg->window_min_period_us = 20000u;
}

argil_err_t peer_init(peer_t *p, const peer_cfg_t *cfg, grid_t *grid, peer_send_fn send,
                      peer_telemetry_fn on_telemetry, void *ctx)
{
    if (cfg->window_edge < 4 || cfg->window_edge > ARGIL_WINDOW_MAX)
        return ARGIL_ERR_ARG;
    memset(p, 0, sizeof(*p));
    p->cfg = *cfg;
    p->grid = grid;
    p->send = send;
    p->on_telemetry = on_telemetry;
    p->ctx = ctx;
    p->next_version = 1;
    p->win_samples = malloc((size_t)cfg->window_edge * cfg->window_edge * cfg->window_edge *
                            sizeof(float));
    if (!p->win_samples)
        return ARGIL_ERR_NOMEM;
    for (int a = 0; a < 3; a++) {
        p->dirty_lo[a] = 1;
        p->dirty_hi[a] = 0;
    }
    return ARGIL_OK;
}

void peer_free(peer_t *p)
{
    free(p->win_samples);
    p->win_samples = NULL;
}

static bool send_msg(peer_t *p, const proto_msg_t *m)
{
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    if (proto_encode(m, p->tx_seq, buf, sizeof(buf), &len) != PROTO_OK)
        return false;
    if (!p->send(p->ctx, buf, len))
        return false;
    p->tx_seq++;
    return true;
}

static void mark_dirty(peer_t *p, const int32_t lo[3], const int32_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        if (p->dirty_lo[a] > p->dirty_hi[a]) {
            for (int b = 0; b < 3; b++) {
                p->dirty_lo[b] = lo[b];
                p->dirty_hi[b] = hi[b];
            }
            return;
        }
    }
    for (int a = 0; a < 3; a++) {
        if (lo[a] < p->dirty_lo[a]) p->dirty_lo[a] = lo[a];
        if (hi[a] > p->dirty_hi[a]) p->dirty_hi[a] = hi[a];
    }
}

static const peer_window_ref_t *find_ref(const peer_t *p, uint32_t version)
{
    for (uint32_t i = 0; i < PEER_VERSIONS_KEPT; i++)
        if (p->refs[i].version == version && version != 0)
            return &p->refs[i];
    return NULL;
}

static void apply_impulses(peer_t *p, const msg_impulse_t *im)
{
    const peer_window_ref_t *r = find_ref(p, im->window_version);
    p->stats.impulse_frames++;
    if (!r) {
        p->stats.impulses_unmapped += im->count;
        return;
    }
    const float inv_dt = 1e6f / (float)p->cfg.solve_period_us;
    const uint32_t nx = (uint32_t)r->dims[0], ny = (uint32_t)r->dims[1];
    const uint32_t n = nx * ny * (uint32_t)r->dims[2];
    for (uint16_t k = 0; k < im->count; k++) {
        const proto_impulse_t *e = &im->entries[k];
        if (e->node >= n) {
            p->stats.impulses_unmapped++;
            continue;
        }
        const int32_t x = r->corner[0] + (int32_t)(e->node % nx);
        const int32_t y = r->corner[1] + (int32_t)((e->node / nx) % ny);
        const int32_t z = r->corner[2] + (int32_t)(e->node / (nx * ny));
        /* The impulse acts over the next solve step as a force J/dt. */
        if (grid_add_force(p->grid, x, y, z, e->impulse_ns * inv_dt)) {
            p->stats.impulse_total_ns += fabs((double)e->impulse_ns);
            p->field_dirty = true;
        } else {
            p->stats.impulses_unmapped++;
        }
    }
    if ((int32_t)(im->impulse_seq - p->impulse_seq_received) > 0)
        p->impulse_seq_received = im->impulse_seq;
}

void peer_receive(peer_t *p, const uint8_t *bytes, size_t len)
{
    size_t at = 0;
    proto_msg_t *m = &p->scratch;
    while (at < len) {
        size_t flen = 0;
        const proto_err_t e = proto_decode(bytes + at, len - at, m, &flen);
        if (e != PROTO_OK) {
            p->stats.decode_errors++;
            if (e == PROTO_ERR_TRUNCATED)
                break;
            at++;
            continue;
        }
        at += flen;
        p->stats.frames_rx++;
        switch (m->type) {
        case MSG_HELLO:
            if (m->u.hello.role == PROTO_ROLE_BOARD) {
                /* A (re)started board: resend the tool and a fresh window. */
                p->board_seen = true;
                p->tool_dirty = true;
                p->have_current = false;
                p->sending_active = false;
                p->arm_sent = false;
            }
            break;
        case MSG_TELEMETRY:
            p->last_tm = m->u.telemetry;
            p->have_tm = true;
            if (p->on_telemetry)
                p->on_telemetry(p->ctx, &m->u.telemetry);
            break;
        case MSG_IMPULSE:
            apply_impulses(p, &m->u.impulse);
            break;
        case MSG_FAULT:
            p->stats.faults++;
            p->stats.last_fault_code = m->u.fault.code;
            break;
        case MSG_RT_STATS:
            p->last_rt = m->u.rt_stats;
            p->stats.rt_stats_frames++;
            break;
        default:
            break;
        }
    }
}

void peer_set_tool(peer_t *p, const msg_tool_t *tool)
{
    p->tool = *tool;
    p->tool_dirty = true;
}

void peer_request_arm(peer_t *p)
{
    p->want_armed = true;
    p->arm_sent = false;
}

static vec3_t tool_pos(const peer_t *p)
{
    return vec3(p->last_tm.pos_m[0], p->last_tm.pos_m[1], p->last_tm.pos_m[2]);
}

/* Starts sending a new window version centred on the tool. */
static void start_window(peer_t *p)
{
    const grid_t *g = p->grid;
    const int32_t e = p->cfg.window_edge;
    const int32_t dims[3] = {e, e, e};
    peer_window_ref_t r;
    r.version = p->next_version++;
    grid_window_corner(g, p->have_tm ? tool_pos(p) : vec3(0, 0, 0), dims, r.corner);
    for (int a = 0; a < 3; a++)
        r.dims[a] = e;
    grid_extract(g, r.corner, dims, p->win_samples);
    memset(&p->head, 0, sizeof(p->head));
    p->head.version = r.version;
    for (int a = 0; a < 3; a++)
        p->head.dims[a] = (uint8_t)e;
    p->head.origin_m[0] = g->origin_m.x + (float)r.corner[0] * g->spacing_m;
    p->head.origin_m[1] = g->origin_m.y + (float)r.corner[1] * g->spacing_m;
    p->head.origin_m[2] = g->origin_m.z + (float)r.corner[2] * g->spacing_m;
    p->head.spacing_m = g->spacing_m;
    p->head.iso = g->iso;
    p->head.node_mass = g->material.node_mass;
    p->head.stiffness = g->material.stiffness;
    p->head.damping = g->material.damping;
    p->head.plastic_rate_hz = g->material.plastic_rate_hz;
    p->head.impulse_seq = p->impulse_seq_applied;
    p->head.channels = 1;
    p->head.chunk_count = window_chunk_count(p->head.dims, p->head.channels);
    p->sending = r;
    p->sending_active = true;
    p->next_chunk = 0;
    p->refs[r.version % PEER_VERSIONS_KEPT] = r;
    p->field_dirty = false;
    p->since_window_us = 0;
}

/* True when the tool is near the edge of the board's window, or outside it. */
static bool tool_near_edge(const peer_t *p)
{
    if (!p->have_current || !p->have_tm)
        return !p->have_current;
    const grid_t *g = p->grid;
    const vec3_t t = tool_pos(p);
    const float pos[3] = {t.x, t.y, t.z};
    const float org[3] = {g->origin_m.x, g->origin_m.y, g->origin_m.z};
    const float margin = p->tool.radius_m + 2.0f * g->spacing_m;
    for (int a = 0; a < 3; a++) {
        const float lo = org[a] + (float)p->current.corner[a] * g->spacing_m;
        const float hi = lo + (float)(p->current.dims[a] - 1) * g->spacing_m;
        if (pos[a] - lo < margin || hi - pos[a] < margin)
            return true;
    }
    return false;
}

/* Keeps box simulated until it comes to rest; with no room, merges the two oldest boxes. */
static void remember_settling(peer_t *p, const peer_box_t *box)
{
    if (p->settling_count == PEER_SETTLING_MAX) {
        peer_box_t *a = &p->settling[0];
        const peer_box_t *b = &p->settling[1];
        for (int k = 0; k < 3; k++) {
            if (b->lo[k] < a->lo[k]) a->lo[k] = b->lo[k];
            if (b->hi[k] > a->hi[k]) a->hi[k] = b->hi[k];
        }
        p->settling[1] = p->settling[--p->settling_count];
    }
    p->settling[p->settling_count++] = *box;
}

static void solve(peer_t *p)
{
    grid_t *g = p->grid;
    p->stats.solves++;
    const bool active = p->have_tm && p->last_tm.state == SAFETY_ACTIVE;
    if (active && p->last_tm.tool_kind == TOOL_CARVE && (p->last_tm.buttons & 1u)) {
        int32_t lo[3], hi[3];
        grid_carve_sphere(g, tool_pos(p), p->tool.radius_m, lo, hi);
        if (hi[0] > lo[0]) {
            mark_dirty(p, lo, hi);
            p->field_dirty = true;
        }
    }
    /* The physical window of the global solve: the board's window and a margin around it;
     * plus the regions the tool left that are still moving (elastic clay springing back). */
    if (!p->have_current)
        return;
    peer_box_t box;
    for (int a = 0; a < 3; a++) {
        box.lo[a] = p->current.corner[a] - 4;
        box.hi[a] = p->current.corner[a] + p->current.dims[a] + 4;
    }
    if (p->have_box && memcmp(&box, &p->box, sizeof(box)) != 0)
        remember_settling(p, &p->box);
    p->box = box;
    p->have_box = true;
    /* Impulses received so far act in this step: from now on windows include them. */
    p->impulse_seq_applied = p->impulse_seq_received;
    spring_field_t f = grid_springs(g);
    const float dt_s = (float)p->cfg.solve_period_us * 1e-6f;
    const float acc = springs_step(&f, &g->material, box.lo, box.hi, dt_s);
    if (acc > 0.0f) {
        mark_dirty(p, box.lo, box.hi);
        p->field_dirty = true;
    }
    for (uint32_t k = 0; k < p->settling_count;) {
        const peer_box_t *s = &p->settling[k];
        const float a = springs_step(&f, &g->material, s->lo, s->hi, dt_s);
        if (a > 0.0f)
            mark_dirty(p, s->lo, s->hi);
        if (a < PEER_REST_ACCEL) {
            /* At rest: stop simulating it. */
            p->settling[k] = p->settling[--p->settling_count];
        } else {
            k++;
        }
    }
}

void peer_tick(peer_t *p, uint32_t dt_us)
{
    p->time_us += dt_us;
    p->since_window_us += dt_us;
    p->since_heartbeat_us += dt_us;
    p->since_solve_us += dt_us;
    proto_msg_t *m = &p->scratch;

    if (!p->board_seen)
        return;
    if (p->tool_dirty) {
        m->type = MSG_TOOL;
        m->u.tool = p->tool;
        if (send_msg(p, m))
            p->tool_dirty = false;
    }
    if (p->since_solve_us >= p->cfg.solve_period_us) {
        p->since_solve_us = 0;
        solve(p);
    }
    /* A new window when the tool nears the edge, or when the field under it changed. */
    if (!p->sending_active &&
        (tool_near_edge(p) ||
         (p->field_dirty && p->since_window_us >= p->cfg.window_min_period_us)))
        start_window(p);
    if (p->sending_active) {
        for (uint32_t k = 0; k < PEER_CHUNKS_PER_TICK && p->next_chunk < p->head.chunk_count; k++) {
            m->type = MSG_WINDOW;
            if (window_chunk_fill(&p->head, p->win_samples, p->next_chunk, &m->u.window) !=
                    PROTO_OK ||
                !send_msg(p, m))
                break;
            p->next_chunk++;
            p->stats.chunks_sent++;
        }
        if (p->next_chunk >= p->head.chunk_count) {
            p->sending_active = false;
            p->current = p->sending;
            p->have_current = true;
            p->stats.windows_sent++;
        }
    }
    if (p->since_heartbeat_us >= p->cfg.heartbeat_period_us) {
        m->type = MSG_HEARTBEAT;
        m->u.heartbeat.time_us = p->time_us;
        m->u.heartbeat.window_version = p->have_current ? p->current.version : 0u;
        m->u.heartbeat.impulse_seq = p->impulse_seq_applied;
        m->u.heartbeat.command = PROTO_CMD_NONE;
        /* Arm once, when the board is idle and has a window: never re-arm after a fault
         * without the person asking. */
        if (p->want_armed && !p->arm_sent && p->have_current && p->have_tm &&
            p->last_tm.state == SAFETY_IDLE) {
            m->u.heartbeat.command = PROTO_CMD_ARM;
        }
        if (send_msg(p, m)) {
            p->since_heartbeat_us = 0;
            if (m->u.heartbeat.command == PROTO_CMD_ARM)
                p->arm_sent = true;
        }
    }
}
