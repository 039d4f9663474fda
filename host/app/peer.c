/* Host side of the board protocol. */
#include "peer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "firmware/core/safety.h"

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

argil_err_t peer_init(peer_t *p, const peer_cfg_t *cfg, grid_t *grid, peer_send_fn send,
                      peer_telemetry_fn on_telemetry, void *ctx)
{
    if (cfg->window_edge < 4 || cfg->window_edge > ARGIL_WINDOW_MAX ||
        (cfg->global_solve != PEER_SOLVE_SPRINGS && cfg->global_solve != PEER_SOLVE_BSPLINE) ||
        (cfg->knot_ratio != 1 && cfg->knot_ratio != 2 && cfg->knot_ratio != 4))
        return ARGIL_ERR_ARG;
    memset(p, 0, sizeof(*p));
    host_tool_default(&p->host_tool);
    p->cfg = *cfg;
    p->grid = grid;
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
        p->force_lo[a] = 1;
        p->force_hi[a] = 0;
    }
    if (cfg->global_solve == PEER_SOLVE_BSPLINE) {
        p->gs = calloc(1, sizeof(*p->gs));
        if (!p->gs) {
            peer_free(p);
            return ARGIL_ERR_NOMEM;
        }
        argil_err_t e = gsolve_init_ratio(p->gs, grid, cfg->knot_ratio);
        /* A loaded model's painted material (.argil MTLS, journal recovery). */
        if (e == ARGIL_OK) {
            e = gsolve_material_from_grid(p->gs, grid);
            if (e == ARGIL_OK) /* and its painted colour (grid rgb, from .argil COLR) */
                e = gsolve_colour_from_grid(p->gs, grid);
            if (e != ARGIL_OK)
                gsolve_free(p->gs);
        }
        if (e != ARGIL_OK) {
            free(p->gs);
            p->gs = NULL;
            peer_free(p);
            return e;
        }
        p->gs_mat = grid->material;
    }
    return ARGIL_OK;
}

void peer_free(peer_t *p)
{
    free(p->win_samples);
    p->win_samples = NULL;
    if (p->gs) {
        gsolve_free(p->gs);
        free(p->gs);
        p->gs = NULL;
    }
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
        if (grid_add_force(p->grid, x, y, z, e->impulse_ns * inv_dt)) {
            p->stats.impulse_total_ns += fabs((double)e->impulse_ns);
            p->field_dirty = true;
            const int32_t at[3] = {x, y, z};
            const bool none = p->force_lo[0] > p->force_hi[0];
            for (int a = 0; a < 3; a++) {
                if (none || at[a] < p->force_lo[a])
                    p->force_lo[a] = at[a];
                if (none || at[a] + 1 > p->force_hi[a])
                    p->force_hi[a] = at[a] + 1;
            }
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
    /* Painted stiffness is felt: when any node of the window has a painted scale, the window
     * carries each node's spring stiffness (base × scale) as a second channel; an unpainted
     * window stays one channel, as cheap as before. Painted mass acts in the global solve only
     * (the wire has one node_mass per window: docs/model.md "In the session"). */
    float *node_k = p->win_samples + (size_t)e * (size_t)e * (size_t)e;
    const bool painted =
        p->gs && gsolve_material_box(p->gs, GSOLVE_MAT_STIFFNESS, r.corner, dims, node_k);
    if (painted)
        for (int32_t i = 0; i < e * e * e; i++)
            node_k[i] *= g->material.stiffness;
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

static void solve_springs(peer_t *p)
{
    grid_t *g = p->grid;
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
        box.lo[a] = p->current.corner[a] - p->sched.margin;
        box.hi[a] = p->current.corner[a] + p->current.dims[a] + p->sched.margin;
    }
    if (p->have_box && memcmp(&box, &p->box, sizeof(box)) != 0)
        remember_settling(p, &p->box);
    p->box = box;
    p->have_box = true;
    /* Impulses received so far act in this step: from now on windows include them. */
    p->impulse_seq_applied = p->impulse_seq_received;
    const float dt_s = (float)p->cfg.solve_period_us * 1e-6f;
    const float acc = grid_springs_step(g, box.lo, box.hi, dt_s);
    if (acc > 0.0f) {
        mark_dirty(p, box.lo, box.hi);
        p->field_dirty = true;
    }
    for (uint32_t k = 0; k < p->settling_count;) {
        const peer_box_t *s = &p->settling[k];
        const float a = grid_springs_step(g, s->lo, s->hi, dt_s);
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

/* Drops the external forces the step did not take (outside its window). */
static void clear_forces(peer_t *p)
{
    grid_t *g = p->grid;
    if (p->force_lo[0] > p->force_hi[0])
        return;
    for (int32_t z = p->force_lo[2]; z < p->force_hi[2]; z++)
        for (int32_t y = p->force_lo[1]; y < p->force_hi[1]; y++)
            for (int32_t x = p->force_lo[0]; x < p->force_hi[0]; x++)
                if (grid_get(g, GRID_FORCE, x, y, z) != 0.0f)
                    (void)grid_set(g, GRID_FORCE, x, y, z, 0.0f);
    for (int a = 0; a < 3; a++) {
        p->force_lo[a] = 1;
        p->force_hi[a] = 0;
    }
}

static void solve_error(peer_t *p, argil_err_t e)
{
    p->stats.solve_errors++;
    p->stats.last_solve_error = e;
}

/* The host tool at the stylus (peer_set_host_tool), once this solve period. A stylus that
 * moved more than band / 2 (2.5 mm) since the last application (faster than 0.25 m/s at
 * 10 ms) gets the poses in between too, so a fast stroke leaves no gaps; a slower one is one
 * pose, exactly the eraser the session always applied. */
static argil_err_t apply_host_tool(peer_t *p, int32_t lo[3], int32_t hi[3])
{
    const vec3_t at = tool_pos(p);
    vec3_t pts[2] = {at, at};
    size_t n = 1;
    const float step_m = 0.5f * p->grid->band_m;
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
    return gsolve_apply_tool(p->gs, p->grid, &p->host_tool, p->tool.radius_m,
                             vec3_norm(axis) > 1e-6f ? axis : vec3(0, 0, 1), pts, n,
                             (float)p->cfg.solve_period_us * 1e-6f, lo, hi);
}

argil_err_t peer_set_host_tool(peer_t *p, const host_tool_t *t)
{
    if (!host_tool_valid(t))
        return ARGIL_ERR_ARG;
    if (!p->gs && !host_tool_is_default(t))
        return ARGIL_ERR_STATE;
    p->host_tool = *t;
    return ARGIL_OK;
}

/* The global solve on the B-spline model: carving through host/model/tools.c, then one
 * implicit step in the physical window (the board's window and a margin). */
static void solve_bspline(peer_t *p)
{
    grid_t *g = p->grid;
    if (memcmp(&p->gs_mat, &g->material, sizeof(p->gs_mat)) != 0) {
        gsolve_set_material(p->gs, &g->material);
        p->gs_mat = g->material;
    }
    const bool active = p->have_tm && p->last_tm.state == SAFETY_ACTIVE;
    if (active && p->last_tm.tool_kind == TOOL_CARVE && (p->last_tm.buttons & 1u)) {
        int32_t lo[3], hi[3];
        const argil_err_t e = apply_host_tool(p, lo, hi);
        if (e != ARGIL_OK) {
            solve_error(p, e);
        } else if (hi[0] > lo[0]) {
            /* Re-meshed (and journaled) either way; a paint leaves the board's densities be. */
            p->stats.host_tool_edits++;
            mark_dirty(p, lo, hi);
            p->field_dirty = p->field_dirty || !host_action_paints(p->host_tool.action);
        }
    } else {
        p->host_prev_valid = false;
    }
    if (p->have_current) {
        peer_box_t box;
        for (int a = 0; a < 3; a++) {
            box.lo[a] = p->current.corner[a] - p->sched.margin;
            box.hi[a] = p->current.corner[a] + p->current.dims[a] + p->sched.margin;
        }
        p->box = box;
        p->have_box = true;
        p->impulse_seq_applied = p->impulse_seq_received;
        int32_t lo[3], hi[3];
        float change = 0.0f;
        const argil_err_t e = gsolve_step(p->gs, g, box.lo, box.hi,
                                          (float)p->cfg.solve_period_us * 1e-6f, lo, hi, &change);
        if (e != ARGIL_OK) {
            solve_error(p, e);
        } else if (hi[0] > lo[0]) {
            mark_dirty(p, lo, hi);
            p->field_dirty = true;
        }
    }
    clear_forces(p);
}

static void solve(peer_t *p)
{
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    p->stats.solves++;
    if (p->gs)
        solve_bspline(p);
    else
        solve_springs(p);
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

float peer_material_at(const peer_t *p, peer_material_t ch, vec3_t x_m)
{
    if (!p->gs)
        return 1.0f; /* the springs solve's material is uniform */
    return gsolve_material_at(p->gs, ch == PEER_MAT_MASS ? GSOLVE_MAT_MASS : GSOLVE_MAT_STIFFNESS,
                              x_m);
}

argil_err_t peer_paint_material(peer_t *p, peer_material_t ch, vec3_t centre_m, float radius_m,
                                float scale)
{
    if (!p->gs)
        return ARGIL_ERR_STATE;
    const argil_err_t e = gsolve_paint(p->gs, ch == PEER_MAT_MASS ? GSOLVE_MAT_MASS
                                                                   : GSOLVE_MAT_STIFFNESS,
                                       centre_m, radius_m, scale);
    if (e == ARGIL_OK) {
        /* The densities did not change, but the surface there must be re-meshed to show the
         * new material (colour maps): the painted ball's sample box becomes dirty. */
        const grid_t *g = p->grid;
        int32_t lo[3], hi[3], b0[3], b1[3];
        grid_bounds(g, b0, b1);
        const float c[3] = {centre_m.x - g->origin_m.x, centre_m.y - g->origin_m.y,
                            centre_m.z - g->origin_m.z};
        for (int a = 0; a < 3; a++) {
            const float l = floorf((c[a] - radius_m) / g->spacing_m);
            const float h = ceilf((c[a] + radius_m) / g->spacing_m) + 1.0f;
            const float fl = (float)b0[a], fh = (float)b1[a];
            lo[a] = l < fl ? b0[a] : l > fh ? b1[a] : (int32_t)l;
            hi[a] = h < fl ? b0[a] : h > fh ? b1[a] : (int32_t)h;
        }
        if (lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2]) {
            /* The grid's painted channels follow (what .argil files and the journal keep). */
            const argil_err_t me = gsolve_material_to_grid(p->gs, p->grid, lo, hi);
            if (me != ARGIL_OK)
                return me;
            mark_dirty(p, lo, hi);
            /* A paint that reaches the board's window changes what the hand feels there: the
             * window is sent again (with its per-node stiffness) like an edited one. */
            const peer_window_ref_t *w = p->sending_active ? &p->sending : &p->current;
            bool overlaps = p->sending_active || p->have_current;
            for (int a = 0; a < 3; a++)
                overlaps = overlaps && lo[a] < w->corner[a] + w->dims[a] && hi[a] > w->corner[a];
            if (overlaps)
                p->field_dirty = true;
        }
    }
    return e;
}

argil_err_t peer_refine(peer_t *p, float *max_dd)
{
    if (max_dd)
        *max_dd = 0.0f;
    if (!p->gs)
        return ARGIL_ERR_STATE;
    int32_t lo[3], hi[3];
    float dd = 0.0f;
    const argil_err_t e = gsolve_refine(p->gs, p->grid, &dd, lo, hi);
    if (max_dd)
        *max_dd = dd;
    if (e == ARGIL_OK) {
        p->stats.refines++;
        if (dd > p->stats.refine_max_dd)
            p->stats.refine_max_dd = dd;
    }
    if (e == ARGIL_OK && hi[0] > lo[0]) {
        /* Only where rounding moved a density past the view's threshold (none measured). */
        mark_dirty(p, lo, hi);
        p->field_dirty = true;
    }
    return e;
}

int32_t peer_knot_ratio(const peer_t *p)
{
    return p->gs ? gsolve_ratio(p->gs) : 0;
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
