/* Host side of the board protocol. */
#include "peer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "shared/safety_codes.h"

void peer_cfg_default(peer_cfg_t *cfg)
{
    cfg->window_edge = 16;
    cfg->global_solve = PEER_SOLVE_SPRINGS;
    cfg->knot_ratio = GSOLVE_RATIO_DEFAULT;
    cfg->heartbeat_period_us = 5000u;
    cfg->solve_period_us = 10000u;
    cfg->window_min_period_us = 20000u;
    cfg->adaptive_region = false;
}

argil_err_t peer_init_rep(peer_t *p, const peer_cfg_t *cfg, rep_t rep, peer_send_fn send,
                          peer_telemetry_fn on_telemetry, void *ctx)
{
    if (cfg->window_edge < 4 || cfg->window_edge > ARGIL_WINDOW_MAX)
        return ARGIL_ERR_ARG;
    memset(p, 0, sizeof(*p));
    host_tool_default(&p->host_tool);
    p->cfg = *cfg;
    p->rep = rep;
    p->grid = rep.ops->samples(rep.st);
    p->send = send;
    p->on_telemetry = on_telemetry;
    p->ctx = ctx;
    p->next_version = 1;
    solve_sched_init(&p->sched, cfg->adaptive_region);
    /* Densities, then room for the per-node stiffness of a painted window (channels 2). */
    p->win_samples = malloc((size_t)PROTO_WINDOW_CHANNELS_MAX * (size_t)cfg->window_edge *
                            (size_t)cfg->window_edge * (size_t)cfg->window_edge * sizeof(float));
    if (!p->win_samples)
        return ARGIL_ERR_NOMEM;
    for (int a = 0; a < 3; a++) {
        p->dirty_lo[a] = 1;
        p->dirty_hi[a] = 0;
    }
    return ARGIL_OK;
}

argil_err_t peer_init(peer_t *p, const peer_cfg_t *cfg, grid_t *grid, peer_send_fn send,
                      peer_telemetry_fn on_telemetry, void *ctx)
{
    if (cfg->global_solve != PEER_SOLVE_SPRINGS && cfg->global_solve != PEER_SOLVE_BSPLINE)
        return ARGIL_ERR_ARG;
    rep_bspline_t own;
    argil_err_t e = rep_bspline_init(&own, grid, cfg->global_solve == PEER_SOLVE_BSPLINE,
                                     cfg->knot_ratio);
    if (e != ARGIL_OK)
        return e;
    e = peer_init_rep(p, cfg, rep_bspline(&own), send, on_telemetry, ctx);
    if (e != ARGIL_OK) {
        rep_bspline(&own).ops->free(&own);
        return e;
    }
    p->own = own;
    p->rep = rep_bspline(&p->own);
    p->owns_rep = true;
    p->gs = own.gs;
    return ARGIL_OK;
}

void peer_free(peer_t *p)
{
    free(p->win_samples);
    p->win_samples = NULL;
    if (p->owns_rep)
        p->rep.ops->free(p->rep.st);
    p->owns_rep = false;
    p->gs = NULL;
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

bool peer_send_hello(peer_t *p, const char *name)
{
    proto_msg_t *m = &p->scratch;
    memset(m, 0, sizeof(*m));
    m->type = MSG_HELLO;
    m->u.hello.role = PROTO_ROLE_HOST;
    m->u.hello.window_max = (uint16_t)p->cfg.window_edge;
    const size_t n = strlen(name);
    memcpy(m->u.hello.name, name, n < PROTO_NAME_LEN ? n : PROTO_NAME_LEN);
    return send_msg(p, m);
}

/* A heartbeat with the host's window version and impulse acknowledgement. */
static void fill_heartbeat(const peer_t *p, proto_msg_t *m, uint8_t command)
{
    m->type = MSG_HEARTBEAT;
    m->u.heartbeat.time_us = p->time_us;
    m->u.heartbeat.window_version = p->have_current ? p->current.version : 0u;
    m->u.heartbeat.impulse_seq = p->impulse_seq_applied;
    m->u.heartbeat.command = command;
}

bool peer_send_command(peer_t *p, uint8_t command)
{
    proto_msg_t *m = &p->scratch;
    memset(m, 0, sizeof(*m));
    fill_heartbeat(p, m, command);
    return send_msg(p, m);
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
        const int32_t at[3] = {x, y, z};
        if (p->rep.ops->add_node_force(p->rep.st, at, e->impulse_ns * inv_dt) == ARGIL_OK) {
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
                p->board_tick_hz = m->u.hello.tick_hz;
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
    rep_lattice_t lat;
    p->rep.ops->lattice(p->rep.st, &lat);
    const int32_t e = p->cfg.window_edge;
    const int32_t dims[3] = {e, e, e};
    peer_window_ref_t r;
    r.version = p->next_version++;
    p->rep.ops->window_corner(p->rep.st, p->have_tm ? tool_pos(p) : vec3(0, 0, 0), dims,
                              r.corner);
    for (int a = 0; a < 3; a++)
        r.dims[a] = e;
    /* Painted stiffness is felt: a painted window carries each node's spring stiffness as a
     * second channel; an unpainted window stays one channel, as cheap as before. */
    float *node_k = p->win_samples + (size_t)e * (size_t)e * (size_t)e;
    const bool painted =
        p->rep.ops->window_samples(p->rep.st, r.corner, dims, p->win_samples, node_k);
    memset(&p->head, 0, sizeof(p->head));
    p->head.version = r.version;
    for (int a = 0; a < 3; a++)
        p->head.dims[a] = (uint8_t)e;
    p->head.origin_m[0] = lat.origin_m.x + (float)r.corner[0] * lat.spacing_m;
    p->head.origin_m[1] = lat.origin_m.y + (float)r.corner[1] * lat.spacing_m;
    p->head.origin_m[2] = lat.origin_m.z + (float)r.corner[2] * lat.spacing_m;
    p->head.spacing_m = lat.spacing_m;
    p->head.iso = lat.iso;
    p->head.node_mass = lat.material.node_mass;
    p->head.stiffness = lat.material.stiffness;
    p->head.damping = lat.material.damping;
    p->head.plastic_rate_hz = lat.material.plastic_rate_hz;
    p->head.impulse_seq = p->impulse_seq_applied;
    p->head.channels = painted ? 2 : 1;
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
    rep_lattice_t lat;
    p->rep.ops->lattice(p->rep.st, &lat);
    const vec3_t t = tool_pos(p);
    const float pos[3] = {t.x, t.y, t.z};
    const float org[3] = {lat.origin_m.x, lat.origin_m.y, lat.origin_m.z};
    const float margin = p->tool.radius_m + 2.0f * lat.spacing_m;
    for (int a = 0; a < 3; a++) {
        const float lo = org[a] + (float)p->current.corner[a] * lat.spacing_m;
        const float hi = lo + (float)(p->current.dims[a] - 1) * lat.spacing_m;
        if (pos[a] - lo < margin || hi - pos[a] < margin)
            return true;
    }
    return false;
}

static void solve_error(peer_t *p, argil_err_t e)
{
    p->stats.solve_errors++;
    p->stats.last_solve_error = e;
}

/* Re-meshes (and journals) what a model call changed; a change the board feels makes its
 * window stale. */
static void take_change(peer_t *p, const rep_change_t *c)
{
    if (c->box.hi[0] > c->box.lo[0])
        mark_dirty(p, c->box.lo, c->box.hi);
    p->field_dirty = p->field_dirty || c->felt;
}

/* The host tool at the stylus (peer_set_host_tool), once this solve period. A stylus that
 * moved more than band / 2 (2.5 mm) since the last application (faster than 0.25 m/s at
 * 10 ms) gets the poses in between too, so a fast stroke leaves no gaps; a slower one is one
 * pose, exactly the eraser the session always applied. */
static argil_err_t apply_host_tool(peer_t *p, rep_change_t *changed)
{
    rep_lattice_t lat;
    p->rep.ops->lattice(p->rep.st, &lat);
    const vec3_t at = tool_pos(p);
    vec3_t pts[2] = {at, at};
    size_t n = 1;
    const float step_m = 0.5f * lat.band_m;
    if (p->host_prev_valid) {
        const vec3_t d = vec3_sub(at, p->host_prev_m);
        const float len = vec3_norm(d);
        /* Longer than 10 cm in one period is a jump (a new window, a glitch), not a stroke. */
        if (len > step_m && len < 0.1f) {
            pts[0] = vec3_add(p->host_prev_m, vec3_scale(d, step_m / len));
            pts[1] = at;
            n = 2;
        }
    }
    p->host_prev_m = at;
    p->host_prev_valid = true;
    const vec3_t axis = vec3(p->tool.axis[0], p->tool.axis[1], p->tool.axis[2]);
    return p->rep.ops->apply_tool(p->rep.st, &p->host_tool, p->tool.radius_m,
                                  vec3_norm(axis) > 1e-6f ? axis : vec3(0, 0, 1), pts, n,
                                  (float)p->cfg.solve_period_us * 1e-6f, changed);
}

argil_err_t peer_set_host_tool(peer_t *p, const host_tool_t *t)
{
    if (!host_tool_valid(t))
        return ARGIL_ERR_ARG;
    if (!p->rep.ops->tool_supported(p->rep.st, t))
        return ARGIL_ERR_STATE;
    p->host_tool = *t;
    return ARGIL_OK;
}

/* The global solve period: the host tool while carve's button 1 is held, then one step of the
 * model in the physical window (the board's window and the schedule's margin). */
static void solve_model(peer_t *p)
{
    rep_change_t c;
    const bool active = p->have_tm && p->last_tm.state == SAFETY_ACTIVE;
    if (active && p->last_tm.tool_kind == TOOL_CARVE && (p->last_tm.buttons & 1u)) {
        const argil_err_t e = apply_host_tool(p, &c);
        if (e != ARGIL_OK) {
            solve_error(p, e);
        } else if (c.box.hi[0] > c.box.lo[0]) {
            p->stats.host_tool_edits++;
            take_change(p, &c);
        }
    } else {
        p->host_prev_valid = false;
    }
    rep_box_t box;
    if (p->have_current) {
        for (int a = 0; a < 3; a++) {
            box.lo[a] = p->current.corner[a] - p->sched.margin;
            box.hi[a] = p->current.corner[a] + p->current.dims[a] + p->sched.margin;
        }
        memcpy(p->box.lo, box.lo, sizeof(box.lo));
        memcpy(p->box.hi, box.hi, sizeof(box.hi));
        p->have_box = true;
        /* Impulses received so far act in this step: from now on windows include them. */
        p->impulse_seq_applied = p->impulse_seq_received;
    }
    const argil_err_t e = p->rep.ops->step(p->rep.st, p->have_current ? &box : NULL,
                                           (float)p->cfg.solve_period_us * 1e-6f, &c);
    if (e != ARGIL_OK)
        solve_error(p, e);
    else
        take_change(p, &c);
}

static void solve(peer_t *p)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    p->stats.solves++;
    solve_model(p);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    const double ms = (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6;
    solve_sched_record(&p->sched, p->cfg.solve_period_us, ms);
}

bool peer_solve_due(const peer_t *p, uint32_t dt_us)
{
    return p->board_seen && solve_sched_due(&p->sched, p->cfg.solve_period_us, dt_us);
}

void peer_tick(peer_t *p, uint32_t dt_us)
{
    p->time_us += dt_us;
    p->since_window_us += dt_us;
    p->since_heartbeat_us += dt_us;
    solve_sched_advance(&p->sched, dt_us);
    proto_msg_t *m = &p->scratch;

    if (!p->board_seen)
        return;
    if (p->tool_dirty) {
        m->type = MSG_TOOL;
        m->u.tool = p->tool;
        if (send_msg(p, m))
            p->tool_dirty = false;
    }
    if (solve_sched_take(&p->sched, p->cfg.solve_period_us))
        solve(p);
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
        fill_heartbeat(p, m, PROTO_CMD_NONE);
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

static rep_material_t rep_channel(peer_material_t ch)
{
    return ch == PEER_MAT_MASS ? REP_MAT_MASS : REP_MAT_STIFFNESS;
}

float peer_material_at(const peer_t *p, peer_material_t ch, vec3_t x_m)
{
    return p->rep.ops->material_at(p->rep.st, rep_channel(ch), x_m);
}

argil_err_t peer_paint_material(peer_t *p, peer_material_t ch, vec3_t centre_m, float radius_m,
                                float scale)
{
    rep_change_t c;
    const argil_err_t e =
        p->rep.ops->paint(p->rep.st, rep_channel(ch), centre_m, radius_m, scale, &c);
    if (e != ARGIL_OK || c.box.hi[0] <= c.box.lo[0])
        return e;
    mark_dirty(p, c.box.lo, c.box.hi);
    /* A paint that reaches the board's window changes what the hand feels there: the window is
     * sent again (with its per-node stiffness) like an edited one. */
    const peer_window_ref_t *w = p->sending_active ? &p->sending : &p->current;
    bool overlaps = c.felt && (p->sending_active || p->have_current);
    for (int a = 0; a < 3; a++)
        overlaps = overlaps && c.box.lo[a] < w->corner[a] + w->dims[a] &&
                   c.box.hi[a] > w->corner[a];
    if (overlaps)
        p->field_dirty = true;
    return e;
}

argil_err_t peer_refine(peer_t *p, float *max_dd)
{
    rep_change_t c;
    float dd = 0.0f;
    const argil_err_t e = p->rep.ops->refine(p->rep.st, &dd, &c);
    if (max_dd)
        *max_dd = dd;
    if (e != ARGIL_OK)
        return e;
    p->stats.refines++;
    if (dd > p->stats.refine_max_dd)
        p->stats.refine_max_dd = dd;
    /* Only where rounding moved a density past the view's threshold (none measured). */
    take_change(p, &c);
    return e;
}

int32_t peer_knot_ratio(const peer_t *p)
{
    return p->rep.ops->samples_per_dof(p->rep.st);
}

void peer_solve_times_ms(const peer_t *p, double *median, double *p99, double *max)
{
    solve_sched_times_ms(&p->sched, median, p99, max);
}

void peer_set_solve_period_us(peer_t *p, uint32_t us)
{
    p->cfg.solve_period_us = solve_period_clamp_us(us);
}

void peer_model_restored(peer_t *p, const int32_t lo[3], const int32_t hi[3])
{
    if (hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2])
        mark_dirty(p, lo, hi);
    /* A window being sent was cut before the change: the one after it carries the new state. */
    p->field_dirty = true;
    p->since_window_us = p->cfg.window_min_period_us;
    p->host_prev_valid = false;
}
