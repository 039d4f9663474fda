/* The live sculpting window (see sculpt_window.h). Two threads: the session thread runs
 * session_run with a per-tick hook (commands in, paced clock, incremental re-mesh and a
 * snapshot every 1/60 s of simulated time out); the main thread owns GLFW and GL and draws. */
#define _POSIX_C_SOURCE 200809L
#define GLFW_INCLUDE_NONE
#include "host/app/sculpt_window.h"

#include <GLFW/glfw3.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "host/app/live_hand.h"
#include "host/mesh/grid_mesh.h"
#include "host/mesh/mc_blocks.h"
#include "host/render/backend_glfw.h"
#include "host/render/camera.h"
#include "host/render/colour_map.h"
#include "host/render/frame_pacer.h"
#include "host/render/hud.h"
#include "host/render/png_write.h"
#include "host/render/renderer.h"
#include "host/render/triple_buffer.h"
#include "host/render/ui_input.h"
#include "host/render/ui_queue.h"
#include "shared/safety_codes.h"

#define FRAME_PERIOD_S (1.0 / 60.0)   /* simulated time between snapshots */
#define EARLY_PUBLISH_S 0.008        /* least simulated time between snapshots of other changes */
#define SOLVED_PUBLISH_S 0.002       /* ... and after a solve step took in an impulse */
#define STATS_WINDOW_S 1.0            /* loop rate and worst tick over this much time */
#define LATENCY_SAMPLES 4096u
#define INTERACTIVE_NS 300000000u     /* frames skip multisampling this long after a change */
#define ISO2_STEP 0.1f                /* the second iso-surface's level moves by this per key */
#define ISO2_MIN 0.05f
#define ISO2_MAX 0.95f

/* The stages of a change's way to the screen, timed on the wall clock (--report). */
enum {
    STAGE_SOLVE,    /* impulse taken in by the host → the solve step that integrated it */
    STAGE_MESH,     /* → its blocks re-meshed and the snapshot filled */
    STAGE_HANDOVER, /* → snapshot published → taken by the render thread */
    STAGE_UPLOAD,   /* → changed geometry uploaded */
    STAGE_DRAW,     /* → draw calls issued (scene and HUD) */
    STAGE_SWAP,     /* → swap returned: the frame is shown */
    STAGE_COUNT
};
static const char *const STAGE_NAMES[STAGE_COUNT] = {"solve", "mesh", "hand-over",
                                                     "upload", "draw", "swap"};

/* What the sleeping render thread wants to be woken for (live_t.render_waiting). */
enum { WAIT_NONE = 0, WAIT_ANY, WAIT_NEWS };

static const char *const TOOL_NAMES[TOOL_KIND_COUNT] = {"touch", "push", "pull",
                                                        "carve", "probe", "rope"};
static const char *const FILTER_NAMES[BETA_FILTER_COUNT] = {"constant", "gaussian", "spherical",
                                                           "cylindrical", "conical"};

#define PANEL_SOLVE_STEP (-1)         /* panel row that is no PARAM_*: the solve period */
/* Rows for the host tool (what carve does on the host, host/model/host_tool.h): -/+ cycle the
 * action, shape and mirror planes, scale the strength; the keys A, S, X, Y, Z reach them too. */
#define PANEL_HOST_ACTION (-2)
#define PANEL_HOST_SHAPE (-3)
#define PANEL_HOST_MIRROR (-4)
#define PANEL_HOST_STRENGTH (-5)
#define PANEL_HOST_COLOUR (-6)        /* -/+ (or key P) step through PAINT_PALETTE */
#define HOST_MIRROR_TOGGLE_X 2.0f     /* UI_CMD_PARAM value on the mirror row: toggle x (+1 y, +2 z) */

/* The panel's parameters: ranges as scripts accept them (host/app/script.c), a step factor,
 * and the first value above zero for those that may be 0. */
static const struct {
    int param;
    const char *label;
    float lo, hi, factor, first;
} PANEL[] = {
    {PARAM_RADIUS_MM, "radius mm", 0.5f, 50.0f, 1.25f, 0.5f},
    {PARAM_STIFFNESS_N_PER_MM, "tool stiffness N/mm", 0.01f, 10.0f, 1.25f, 0.01f},
    {PARAM_CLAY_STIFFNESS, "clay stiffness", 0.0f, 5000.0f, 1.5f, 0.1f},
    {PARAM_PLASTIC_RATE_HZ, "plastic rate Hz", 0.0f, 1000.0f, 1.25f, 0.5f},
    {PARAM_CLAY_DAMPING, "damping", 0.1f, 1000.0f, 1.25f, 0.1f},
    {PARAM_ALPHA, "alpha", 0.0f, 1e7f, 1.5f, 100.0f},
    {PARAM_YIELD_FORCE_N, "yield N", 0.0f, 10.0f, 1.25f, 0.05f},
    {PARAM_MAX_FORCE_N, "max force N", 0.1f, 10.0f, 1.1f, 0.1f},
    /* The host's global solve step: a peer setting, not a script parameter. */
    {PANEL_SOLVE_STEP, "solve step ms", SOLVE_PERIOD_MIN_US * 1e-3f,
     SOLVE_PERIOD_MAX_US * 1e-3f, 1.25f, SOLVE_PERIOD_MIN_US * 1e-3f},
    {PANEL_HOST_ACTION, "carve does", 0.0f, 0.0f, 1.0f, 0.0f},
    {PANEL_HOST_SHAPE, "host shape", 0.0f, 0.0f, 1.0f, 0.0f},
    {PANEL_HOST_MIRROR, "mirror", 0.0f, 0.0f, 1.0f, 0.0f},
    {PANEL_HOST_STRENGTH, "host strength /s", 0.0f, HOST_STRENGTH_MAX, 1.25f, 0.1f},
    {PANEL_HOST_COLOUR, "paint colour", 0.0f, 0.0f, 1.0f, 0.0f},
};

/* The colours the window's paint and soft paint pick from (key P, or the panel row); the first
 * is the session's default (HOST_PAINT_R/G/B); the last is the unpainted clay's own colour, so
 * painting with it takes paint off again. Scripts may paint any colour (docs/script.md). */
static const struct {
    const char *name;
    uint8_t rgb[3];
} PAINT_PALETTE[] = {
    {"terracotta", {HOST_PAINT_R, HOST_PAINT_G, HOST_PAINT_B}},
    {"ochre", {215, 160, 40}},
    {"olive", {90, 140, 60}},
    {"blue", {50, 90, 190}},
    {"charcoal", {50, 50, 55}},
    {"white", {240, 240, 235}},
    {"clay (no paint)", {GRID_RGB_DEFAULT, GRID_RGB_DEFAULT, GRID_RGB_DEFAULT}},
};
#define PAINT_PALETTE_N ((int)(sizeof(PAINT_PALETTE) / sizeof(PAINT_PALETTE[0])))

/* The palette entry holding rgb, or -1. */
static int palette_index(const uint8_t rgb[3])
{
    for (int k = 0; k < PAINT_PALETTE_N; k++)
        if (memcmp(PAINT_PALETTE[k].rgb, rgb, 3) == 0)
            return k;
    return -1;
}
#define PANEL_N ((int)(sizeof(PANEL) / sizeof(PANEL[0])))

/* One snapshot from the session to the window. */
typedef struct {
    mesh_t mesh;
    uint64_t mesh_serial;         /* the re-mesh this slot's mesh is (0: none yet) */
    double t_s;
    bool active, script_done;
    bool have_tm;
    msg_telemetry_t tm;
    float tool_radius_m;
    bool have_box;
    vec3_t box_lo_m, box_hi_m;
    float loop_hz;
    uint32_t worst_tick_ns;       /* over the last STATS_WINDOW_S */
    float link_latency_ms;
    int tool, filter;
    float params[PARAM_COUNT];
    float solve_step_ms;          /* the host's global solve period */
    bool inverted;
    uint64_t pub_seq;             /* snapshots published before this one, plus one */
    /* The oldest change this snapshot shows that no swapped frame has shown yet (also when it
     * was first published in a snapshot the window skipped): its publication and, on the
     * monotonic wall clock, the impulse taken in by the host, the solve step that integrated it
     * and the end of its re-mesh. */
    bool has_change;
    uint64_t change_pub, arrival_ns, solved_ns, meshed_ns;
    uint64_t published_ns;        /* monotonic wall clock at publication */
    float iso;                    /* the clay's level */
    bool iso2_on;                 /* the second iso-surface: mesh2 at iso2_level */
    float iso2_level;
    mesh_t mesh2;
    uint64_t mesh2_serial;
    int colour;                   /* colour_map_t the mesh's vertex colours show */
    float colour_lo, colour_hi;   /* the ramp's range, relative to the default material */
    int knot_ratio;               /* B-spline samples per knot span (0: springs solve) */
    char knot_note[64];           /* what the last K (refine) did */
    host_tool_t host_tool;        /* what carve does on the host */
    bool undo_on;                 /* undo / redo (off: springs solve, --undo-mb 0) */
    uint32_t undo_n, redo_n;      /* steps that can be undone / redone */
    char undo_note[96];           /* what the last Ctrl+Z / redo did, or why undo is off */
} live_frame_t;

typedef struct {
    /* Shared between the threads. */
    triple_buffer_t tb;
    live_frame_t slot[3];
    _Atomic uint64_t shown_pub;   /* pub_seq of the newest snapshot a swapped frame showed */
    ui_queue_t q;
    atomic_int want_stop, session_done;
    atomic_int render_waiting;    /* WAIT_*: the render thread sleeps until a publish wakes it */
    atomic_int inflight;          /* an impulse is taken in but no snapshot shows it yet */
    glfw_window_t *win;           /* woken by publish (glfw_window_wake is thread-safe) */
    /* Session thread only. */
    const sculpt_window_opts_t *wo;
    volatile sig_atomic_t *stop;
    mc_blocks_t mcb;
    grid_mesh_view_t mcb_view;    /* the grid's bounds mcb was set up over */
    bool mcb_ready, mcb_failed;
    uint64_t serial;
    uint64_t news_serial, news_serial2; /* the serials the last snapshot published */
    mc_blocks_t mcb2;             /* the second iso-surface's mesher (only while shown) */
    grid_mesh_view_t mcb2_view;
    bool mcb2_ready, iso2_on;
    float iso2_level;
    uint64_t serial2;
    int colour;                   /* colour_map_t */
    char knot_note[64];           /* what the last UI_CMD_REFINE did */
    double next_frame_s, last_t_s, last_publish_s;
    uint64_t wall0_ns;
    bool wall0_set;
    double stats_start_s;
    uint32_t worst_ns_now, worst_ns_shown, rate_tick0;
    uint64_t rate_us0;
    float loop_hz;
    bool inverted;
    int invert_from, invert_to;
    bool mouse_down, have_ray;
    vec3_t ray_o, ray_d;
    live_hand_t hand;
    live_hand_cfg_t hand_cfg;
    bool mouse_started;
    bool stopping, final_published;
    uint32_t pending_seq;
    double pending_since_s;       /* < 0: no impulse waiting to be shown */
    uint64_t pending_arrival_ns, pending_solved_ns; /* wall clock: taken in, integrated (0: not yet) */
    uint64_t pub_seq;
    bool carry;                   /* a change published but not yet shown (carry_*) */
    uint64_t carry_pub, carry_arrival_ns, carry_solved_ns, carry_meshed_ns;
    /* The session's own results. */
    session_opts_t so;
    session_hook_t hook;
    session_summary_t sum;
    char err[1024];
    argil_err_t rc;
} live_t;

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

void sculpt_window_opts_default(sculpt_window_opts_t *o)
{
    memset(o, 0, sizeof(*o));
    o->width = 1024;
    o->height = 768;
    o->linger_s = 2.0;
}

/* ---- session thread ---- */

/* A host tool row changed (PANEL_HOST_*): the player's setting, so the session hands it to the
 * peer like a script's `action` (the springs solve keeps carve: the HUD says so). */
static void host_panel(session_frame_t *f, int row, float value)
{
    script_player_t *pl = f->player;
    host_tool_t t = pl->host_tool;
    const int step = value > 0.0f ? 1 : -1;
    if (row == PANEL_HOST_ACTION) {
        t.action = (host_action_t)(((int)t.action + step + HOST_ACT_COUNT) % HOST_ACT_COUNT);
        t.strength = host_action_default_strength(t.action);
    } else if (row == PANEL_HOST_SHAPE) {
        t.shape = (host_shape_t)(((int)t.shape + step + HOST_SHAPE_COUNT) % HOST_SHAPE_COUNT);
    } else if (row == PANEL_HOST_MIRROR) {
        const int bit = (int)lroundf(value - HOST_MIRROR_TOGGLE_X);
        t.mirror = bit >= 0 && bit < 3 ? t.mirror ^ (1u << bit)
                                       : (t.mirror + (uint32_t)(step + 8)) % 8u;
    } else if (row == PANEL_HOST_COLOUR) {
        const int k = palette_index(t.rgb);
        const int next = k < 0 ? 0 : (k + step + PAINT_PALETTE_N) % PAINT_PALETTE_N;
        memcpy(t.rgb, PAINT_PALETTE[next].rgb, 3);
    } else if (host_action_has_strength(t.action)) {
        const float v = step > 0 ? (t.strength > 0.0f ? t.strength * 1.25f : 0.1f)
                                 : (t.strength / 1.25f < 0.1f ? 0.0f : t.strength / 1.25f);
        t.strength = v > HOST_STRENGTH_MAX ? HOST_STRENGTH_MAX : v;
    }
    if (!f->peer->rep.ops->tool_supported(f->peer->rep.st, &t))
        return; /* springs: refused by peer_set_host_tool too */
    pl->host_tool = t;
    pl->params_changed = 1;
}

static void apply_cmd(live_t *L, session_frame_t *f, const ui_cmd_t *c)
{
    script_player_t *pl = f->player;
    switch ((ui_cmd_kind_t)c->kind) {
    case UI_CMD_TOOL:
        if (c->arg >= 0 && c->arg < TOOL_KIND_COUNT) {
            pl->tool = c->arg;
            pl->params_changed = 1;
            L->inverted = false;
        }
        break;
    case UI_CMD_FILTER:
        if (c->arg >= 0 && c->arg < BETA_FILTER_COUNT) {
            pl->filter = c->arg;
            pl->params_changed = 1;
        }
        break;
    case UI_CMD_PARAM:
        if (c->arg >= 0 && c->arg < PANEL_N && PANEL[c->arg].param <= PANEL_HOST_ACTION) {
            host_panel(f, PANEL[c->arg].param, c->value);
        } else if (c->arg >= 0 && c->arg < PANEL_N) {
            const int k = PANEL[c->arg].param;
            float v = k == PANEL_SOLVE_STEP ? (float)f->peer->cfg.solve_period_us * 1e-3f
                                            : pl->params[k];
            if (c->value > 0.0f)
                v = v > 0.0f ? v * PANEL[c->arg].factor : PANEL[c->arg].first;
            else
                v = v / PANEL[c->arg].factor;
            if (c->value < 0.0f && PANEL[c->arg].lo == 0.0f && v < PANEL[c->arg].first)
                v = 0.0f;
            v = v < PANEL[c->arg].lo ? PANEL[c->arg].lo : (v > PANEL[c->arg].hi ? PANEL[c->arg].hi : v);
            if (k == PANEL_SOLVE_STEP) {
                peer_set_solve_period_us(f->peer, (uint32_t)lroundf(v * 1e3f));
            } else {
                pl->params[k] = v;
                pl->params_changed = 1;
            }
        }
        break;
    case UI_CMD_INVERT:
        /* Add ↔ remove while the key is held: push and carve become pull, pull becomes push. */
        if (c->arg && !L->inverted) {
            const int t = pl->tool;
            const int to = (t == TOOL_PUSH || t == TOOL_CARVE) ? TOOL_PULL
                           : t == TOOL_PULL                    ? TOOL_PUSH
                                                               : t;
            if (to != t) {
                L->inverted = true;
                L->invert_from = t;
                L->invert_to = to;
                pl->tool = to;
                pl->params_changed = 1;
            }
        } else if (!c->arg && L->inverted) {
            L->inverted = false;
            if (pl->tool == L->invert_to) {
                pl->tool = L->invert_from;
                pl->params_changed = 1;
            }
        }
        break;
    case UI_CMD_MOUSE:
        L->mouse_down = c->arg != 0;
        L->ray_o = vec3(c->origin_m[0], c->origin_m[1], c->origin_m[2]);
        L->ray_d = vec3(c->dir[0], c->dir[1], c->dir[2]);
        L->have_ray = true;
        break;
    case UI_CMD_STOP:
        *L->stop = 1;
        L->stopping = true;
        break;
    case UI_CMD_ISO2:
        L->iso2_on = c->arg != 0 && c->value >= ISO2_MIN && c->value <= ISO2_MAX;
        if (L->iso2_on)
            L->iso2_level = c->value;
        break;
    case UI_CMD_COLOUR:
        if (c->arg >= 0 && c->arg < COLOUR_MAP_COUNT && c->arg != L->colour) {
            L->colour = c->arg;
            if (L->serial != 0)
                L->serial++; /* every slot's mesh is coloured again */
        }
        break;
    case UI_CMD_UNDO:
        /* Done by the session after its next solve step (refused while button 1 is held);
         * the HUD shows the note. */
        if (f->undo)
            (void)session_undo_request(f->undo, c->arg == 2 ? SESSION_UNDO_OP_REDO
                                                            : SESSION_UNDO_OP_UNDO, 0);
        break;
    case UI_CMD_REFINE: {
        /* Knot insertion: the shape stays, so nothing is re-meshed; the HUD says what it did. */
        const int r0 = (int)peer_knot_ratio(f->peer);
        float dd = 0.0f;
        if (f->undo) /* the open stroke becomes a step first: undo then says the history is cut */
            session_undo_peer_edit_start(f->undo, f->peer);
        const argil_err_t e = peer_refine(f->peer, &dd);
        if (e == ARGIL_OK)
            snprintf(L->knot_note, sizeof(L->knot_note), "refined %d -> %d, |dd| %.0e",
                     r0, (int)peer_knot_ratio(f->peer), (double)dd);
        else
            snprintf(L->knot_note, sizeof(L->knot_note), "%s",
                     r0 == 0                ? "no knots: springs solve"
                     : e == ARGIL_ERR_STATE ? "already at one coefficient per sample"
                                            : "refine failed: out of memory");
        break;
    }
    }
}

typedef struct {
    const peer_t *peer;
    peer_material_t ch;
} material_sampler_t;

static float sample_material(const void *ctx, vec3_t x_m)
{
    const material_sampler_t *s = ctx;
    return peer_material_at(s->peer, s->ch, x_m);
}

/* Keeps the second iso-surface's mesher at its level and meshes what changed. */
static void update_iso2(live_t *L, const grid_t *g, bool empty, const int32_t lo[3],
                        const int32_t hi[3])
{
    if (L->mcb2_ready && (!L->iso2_on || L->mcb2.iso != L->iso2_level ||
                          (grid_mesh_view_stale(&L->mcb2_view, g) &&
                           grid_mesh_grow(&L->mcb2, &L->mcb2_view, g) != ARGIL_OK))) {
        mc_blocks_free(&L->mcb2);
        L->mcb2_ready = false;
    }
    if (!L->iso2_on)
        return;
    if (!L->mcb2_ready) {
        if (grid_mesh_blocks_init(&L->mcb2, &L->mcb2_view, g, L->iso2_level) !=
            ARGIL_OK) {
            L->iso2_on = false; /* no memory for it: the window shows it off */
            return;
        }
        L->mcb2_ready = true;
        L->serial2++;
    } else if (!empty) {
        grid_mesh_mark(&L->mcb2, &L->mcb2_view, lo, hi);
    }
    if (mc_blocks_update_read(&L->mcb2, grid_mesh_read, &L->mcb2_view) == ARGIL_OK &&
        L->mcb2.blocks_meshed > 0)
        L->serial2++;
}

/* Colours within this many levels (largest channel difference) of the model's unpainted grey
 * are drawn shifted toward the window's clay colour (fully at the grey itself). */
#define CLAY_BLEND_LEVELS 64

/* A painted mesh's unpainted vertices (the model's base grey, GRID_RGB_DEFAULT) take the
 * window's clay colour, so the clay looks as it did before the first paint; colours near the
 * grey (a soft stroke's fading rim) are shifted part of the way, so the rim fades into the clay
 * rather than into grey. */
static void unpainted_as_clay(mesh_t *m)
{
    if (!m->has_rgb || m->rgb == NULL)
        return;
    render_scene_t sc;
    render_scene_default(&sc);
    const float shift[3] = {sc.clay_rgb.x * 255.0f - (float)GRID_RGB_DEFAULT,
                            sc.clay_rgb.y * 255.0f - (float)GRID_RGB_DEFAULT,
                            sc.clay_rgb.z * 255.0f - (float)GRID_RGB_DEFAULT};
    for (size_t v = 0; v < m->n_vert; v++) {
        uint8_t *c = &m->rgb[3 * v];
        int far = 0;
        for (int k = 0; k < 3; k++) {
            const int d = abs((int)c[k] - (int)GRID_RGB_DEFAULT);
            far = d > far ? d : far;
        }
        if (far >= CLAY_BLEND_LEVELS)
            continue;
        const float w = 1.0f - (float)far / (float)CLAY_BLEND_LEVELS;
        for (int k = 0; k < 3; k++) {
            const float x = (float)c[k] + shift[k] * w;
            c[k] = (uint8_t)lrintf(x < 0.0f ? 0.0f : (x > 255.0f ? 255.0f : x));
        }
    }
}

/* Re-meshes what changed and publishes a snapshot. */
static void publish(live_t *L, session_frame_t *f)
{
    peer_t *p = f->peer;
    const grid_t *g = p->grid;
    if (L->mcb_ready && grid_mesh_view_stale(&L->mcb_view, g) &&
        grid_mesh_grow(&L->mcb, &L->mcb_view, g) != ARGIL_OK) {
        /* The clay grew past what the mesher can span: set it up again over the new bounds
         * (growth itself re-meshes nothing: the written samples are in the dirty box). */
        mc_blocks_free(&L->mcb);
        L->mcb_ready = false;
    }
    if (!L->mcb_ready && !L->mcb_failed) {
        if (grid_mesh_blocks_init(&L->mcb, &L->mcb_view, g, g->iso) == ARGIL_OK)
            L->mcb_ready = true;
        else
            L->mcb_failed = true;
    }
    bool empty = false;
    for (int a = 0; a < 3; a++)
        empty |= p->dirty_lo[a] >= p->dirty_hi[a];
    if (L->mcb_ready) {
        if (!empty)
            grid_mesh_mark(&L->mcb, &L->mcb_view, p->dirty_lo, p->dirty_hi);
        /* Painted colour once anything was painted (the first paint re-meshes everything). */
        if (mc_blocks_update_read_rgb(&L->mcb, grid_mesh_read,
                                      grid_rgb_any(g) ? grid_mesh_read_rgb : NULL,
                                      &L->mcb_view) == ARGIL_OK &&
            L->mcb.blocks_meshed > 0)
            L->serial++;
    }
    update_iso2(L, g, empty, p->dirty_lo, p->dirty_hi);
    for (int a = 0; a < 3; a++) {
        p->dirty_lo[a] = 1;
        p->dirty_hi[a] = 0;
    }
    live_frame_t *fr = &L->slot[triple_buffer_back(&L->tb)];
    if (L->serial != 0 && fr->mesh_serial != L->serial) {
        if (mc_blocks_assemble(&L->mcb, &fr->mesh) == ARGIL_OK) {
            fr->mesh_serial = L->serial;
            fr->colour = L->colour;
            fr->colour_lo = fr->colour_hi = 1.0f;
            unpainted_as_clay(&fr->mesh);
            if (L->colour != COLOUR_MAP_NONE) {
                const material_sampler_t ms = {
                    p, L->colour == COLOUR_MAP_MASS ? PEER_MAT_MASS : PEER_MAT_STIFFNESS};
                if (colour_map_mesh(&fr->mesh, sample_material, &ms, &fr->colour_lo,
                                    &fr->colour_hi) != ARGIL_OK)
                    fr->colour = COLOUR_MAP_NONE;
            }
        }
    }
    fr->iso = g->iso;
    fr->iso2_on = L->iso2_on && L->mcb2_ready;
    fr->iso2_level = L->iso2_level;
    if (fr->iso2_on && fr->mesh2_serial != L->serial2) {
        if (mc_blocks_assemble(&L->mcb2, &fr->mesh2) == ARGIL_OK)
            fr->mesh2_serial = L->serial2;
        else
            fr->iso2_on = false;
    }
    const uint64_t meshed_ns = now_ns();
    bool news = L->serial != L->news_serial || L->serial2 != L->news_serial2 || L->stopping;
    L->news_serial = L->serial;
    L->news_serial2 = L->serial2;
    fr->pub_seq = ++L->pub_seq;
    if (L->carry && atomic_load(&L->shown_pub) >= L->carry_pub)
        L->carry = false; /* a swapped frame has shown it */
    if (L->pending_since_s >= 0.0 && (int32_t)(p->impulse_seq_applied - L->pending_seq) >= 0 &&
        fr->mesh_serial == L->serial) {
        /* Measured: the oldest change not yet shown (a newer one waits behind it unmeasured,
         * so the figure errs long, never short). */
        if (!L->carry) {
            L->carry = true;
            L->carry_pub = fr->pub_seq;
            L->carry_arrival_ns = L->pending_arrival_ns;
            L->carry_solved_ns = L->pending_solved_ns != 0 ? L->pending_solved_ns : meshed_ns;
            L->carry_meshed_ns = meshed_ns;
        }
        L->pending_since_s = -1.0;
        atomic_store(&L->inflight, 0);
        news = true;
    }
    fr->has_change = L->carry;
    fr->change_pub = L->carry_pub;
    fr->arrival_ns = L->carry_arrival_ns;
    fr->solved_ns = L->carry_solved_ns;
    fr->meshed_ns = L->carry_meshed_ns;
    fr->t_s = f->t_s;
    fr->active = f->active;
    fr->script_done = f->script_done;
    fr->have_tm = p->have_tm;
    fr->tm = p->last_tm;
    fr->tool_radius_m = p->tool.radius_m;
    fr->have_box = p->have_current;
    if (p->have_current) {
        const float s = g->spacing_m;
        fr->box_lo_m = vec3(g->origin_m.x + (float)p->current.corner[0] * s,
                            g->origin_m.y + (float)p->current.corner[1] * s,
                            g->origin_m.z + (float)p->current.corner[2] * s);
        fr->box_hi_m = vec3_add(fr->box_lo_m, vec3((float)(p->current.dims[0] - 1) * s,
                                                   (float)(p->current.dims[1] - 1) * s,
                                                   (float)(p->current.dims[2] - 1) * s));
    }
    fr->loop_hz = L->loop_hz;
    fr->worst_tick_ns = L->worst_ns_shown > L->worst_ns_now ? L->worst_ns_shown : L->worst_ns_now;
    fr->link_latency_ms =
        p->have_tm ? (float)((double)(p->time_us - p->last_tm.time_us) * 1e-3) : 0.0f;
    fr->tool = f->player->tool;
    fr->filter = f->player->filter;
    memcpy(fr->params, f->player->params, sizeof(fr->params));
    fr->solve_step_ms = (float)p->cfg.solve_period_us * 1e-3f;
    fr->knot_ratio = (int)peer_knot_ratio(p);
    memcpy(fr->knot_note, L->knot_note, sizeof(fr->knot_note));
    fr->host_tool = f->player->host_tool;
    fr->undo_on = f->undo && f->undo->on;
    fr->undo_n = f->undo ? (uint32_t)session_undo_undo_count(f->undo) : 0u;
    fr->redo_n = f->undo ? (uint32_t)session_undo_redo_count(f->undo) : 0u;
    snprintf(fr->undo_note, sizeof(fr->undo_note), "%s", f->undo ? f->undo->note : "");
    fr->inverted = L->inverted;
    fr->published_ns = now_ns();
    triple_buffer_publish(&L->tb);
    /* Wake a sleeping render thread: for any snapshot, or only for one with a new mesh. */
    const int waiting = atomic_load(&L->render_waiting);
    if ((waiting == WAIT_ANY || (waiting == WAIT_NEWS && news)) &&
        atomic_exchange(&L->render_waiting, WAIT_NONE) != WAIT_NONE)
        glfw_window_wake(L->win);
}

static void on_tick(void *ctx, session_frame_t *f)
{
    live_t *L = ctx;
    peer_t *p = f->peer;
    const float dt_s = (float)(f->t_s - L->last_t_s);
    L->last_t_s = f->t_s;
    ui_cmd_t c;
    while (ui_queue_pop(&L->q, &c))
        apply_cmd(L, f, &c);
    if (atomic_load_explicit(&L->want_stop, memory_order_relaxed)) {
        *L->stop = 1;
        L->stopping = true;
    }
    if (L->stopping && !L->final_published) {
        /* The last snapshot shows every command taken before the stop. */
        L->final_published = true;
        publish(L, f);
        return;
    }

    /* Status: loop rate and worst tick over the last second of simulated time. */
    if (p->have_tm) {
        if (p->last_tm.compute_ns > L->worst_ns_now)
            L->worst_ns_now = p->last_tm.compute_ns;
        if (f->t_s - L->stats_start_s >= STATS_WINDOW_S) {
            const uint64_t dus = p->last_tm.time_us - L->rate_us0;
            if (L->rate_us0 != 0 && dus > 0)
                L->loop_hz = (float)((double)(p->last_tm.tick - L->rate_tick0) * 1e6 / (double)dus);
            L->rate_tick0 = p->last_tm.tick;
            L->rate_us0 = p->last_tm.time_us;
            L->worst_ns_shown = L->worst_ns_now;
            L->worst_ns_now = 0;
            L->stats_start_s = f->t_s;
        }
    }
    if (L->pending_since_s < 0.0 && p->impulse_seq_received != L->pending_seq) {
        L->pending_seq = p->impulse_seq_received;
        L->pending_since_s = f->t_s;
        atomic_store(&L->inflight, 1);
        L->pending_arrival_ns = now_ns();
        L->pending_solved_ns = 0;
    }
    if (L->pending_since_s >= 0.0 && L->pending_solved_ns == 0 &&
        (int32_t)(p->impulse_seq_applied - L->pending_seq) >= 0)
        L->pending_solved_ns = now_ns();

    /* Mouse sculpting: once the board is ACTIVE and there is no script left, the hand is ours. */
    if (L->wo->mouse && f->active && f->script_done) {
        script_player_t *pl = f->player;
        if (!L->mouse_started) {
            L->mouse_started = true;
            pl->tool = TOOL_PUSH;
            pl->params_changed = 1;
        }
        if (L->have_ray) {
            const bool outward = pl->tool == TOOL_PULL || pl->tool == TOOL_ROPE;
            live_hand_step(&L->hand, &L->hand_cfg, p->grid, L->ray_o, L->ray_d, L->mouse_down,
                           outward, p->tool.radius_m, dt_s, &pl->pos_m, &pl->vel_m_s,
                           &pl->buttons);
        }
    }

    /* A snapshot every frame period; at once (at most every 2 ms) when a solve step has taken
     * in the board's impulse, and early (at most every 8 ms) for any other field change, so a
     * stroke reaches the screen without waiting for the period. */
    bool changed = true;
    for (int a = 0; a < 3; a++)
        changed &= p->dirty_lo[a] < p->dirty_hi[a];
    const double since_s = f->t_s - L->last_publish_s;
    const bool solved = L->pending_since_s >= 0.0 && L->pending_solved_ns != 0;
    if (f->t_s + 1e-9 >= L->next_frame_s || (changed && since_s >= EARLY_PUBLISH_S) ||
        (solved && since_s >= SOLVED_PUBLISH_S)) {
        L->last_publish_s = f->t_s;
        publish(L, f);
        L->next_frame_s += FRAME_PERIOD_S;
        if (L->next_frame_s < f->t_s)
            L->next_frame_s = f->t_s + FRAME_PERIOD_S;
    }

    /* Real-time pacing: never ahead of the wall clock by more than a millisecond. */
    if (!L->wo->fast) {
        const uint64_t now = now_ns();
        if (!L->wall0_set) {
            L->wall0_ns = now - (uint64_t)(f->t_s * 1e9);
            L->wall0_set = true;
        }
        const double ahead_s = f->t_s - (double)(now - L->wall0_ns) * 1e-9;
        if (ahead_s > 1e-3) {
            const struct timespec ts = {0, (long)(ahead_s * 1e9)};
            nanosleep(&ts, NULL);
        }
    }
}

static void *session_main(void *arg)
{
    live_t *L = arg;
    L->rc = session_run(&L->so, &L->sum, L->err, sizeof(L->err));
    atomic_store(&L->session_done, 1);
    return NULL;
}

/* ---- render thread ---- */

typedef struct {
    glfw_window_t win;
    gl_api_t gl;
    renderer_t r;
    hud_t hud;
    render_target_t shot;
    bool shot_ready;
    render_target_t aa;           /* 4x multisampled frame for still frames */
    bool aa_ready, aa_failed;
    uint64_t last_upload_ns;      /* the newest mesh change uploaded (wall clock) */
    uint8_t *shot_rgb;
    camera_t cam;
    render_scene_t scene;
    uint64_t uploaded_serial, uploaded2_serial;
    uint64_t counted_pub;         /* the newest change whose latency is counted */
    int panel_sel;
    bool iso2_on;                 /* asked for by the keys (the session confirms in the frame) */
    float iso2_level;
    int colour;
    bool quit;                    /* Esc: no lingering after the session */
    /* Input state (from GLFW, or from the input file when one is given). */
    double cx, cy;
    bool left, right, shift, ctrl;
    double prev_cx, prev_cy;
    bool prev_right, prev_shift, prev_left;
    ui_input_t script;
    size_t next_ev;
    /* Figures. */
    double frame_ms[LATENCY_SAMPLES];
    size_t n_frame;
    double latency_ms[LATENCY_SAMPLES];
    size_t n_latency;
    double stage_ms[STAGE_COUNT][LATENCY_SAMPLES]; /* each measured change's path, per stage */
    double upload_ms[LATENCY_SAMPLES], draw_ms[LATENCY_SAMPLES], swap_ms[LATENCY_SAMPLES];
    size_t n_upload;              /* frames that uploaded something */
    double cost_ms[LATENCY_SAMPLES]; /* per frame: start of the frame → swap returned */
    size_t n_drawn_mesh, n_drawn_snapshot, n_drawn_other; /* frames: new mesh, other news, none */
    uint64_t drawn_serial, drawn2_serial; /* the meshes the last frame drawn showed */
    render_scene_t drawn;         /* the scene of the last frame drawn (drawn_any) */
    bool drawn_any;
    double fps;
} view_t;

static void ui_send(live_t *L, uint8_t kind, int32_t arg, float value)
{
    ui_cmd_t c;
    memset(&c, 0, sizeof(c));
    c.kind = kind;
    c.arg = arg;
    c.value = value;
    ui_queue_push(&L->q, &c);
}

/* The panel row of a PARAM_* or PANEL_* code. */
static int panel_row(int param)
{
    for (int k = 0; k < PANEL_N; k++)
        if (PANEL[k].param == param)
            return k;
    return 0;
}

static void on_key(live_t *L, view_t *v, int key)
{
    if (v->ctrl && (key == GLFW_KEY_Z || key == GLFW_KEY_Y)) {
        /* Ctrl+Z undo; Ctrl+Shift+Z and Ctrl+Y redo (not the mirror keys Y, Z). */
        ui_send(L, UI_CMD_UNDO, key == GLFW_KEY_Y || v->shift ? 2 : 1, 0.0f);
    } else if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + TOOL_KIND_COUNT) {
        ui_send(L, UI_CMD_TOOL, key - GLFW_KEY_1, 0);
    } else if (key == GLFW_KEY_B) {
        const live_frame_t *fr = &L->slot[L->tb.front];
        ui_send(L, UI_CMD_FILTER, (fr->filter + 1) % BETA_FILTER_COUNT, 0);
    } else if (key == GLFW_KEY_C) {
        v->scene.mode = v->scene.mode == RENDER_MODE_PLAIN ? RENDER_MODE_CLEARCOAT
                                                           : RENDER_MODE_PLAIN;
    } else if (key == GLFW_KEY_TAB || key == GLFW_KEY_DOWN) {
        v->panel_sel = (v->panel_sel + 1) % PANEL_N;
    } else if (key == GLFW_KEY_UP) {
        v->panel_sel = (v->panel_sel + PANEL_N - 1) % PANEL_N;
    } else if (key == GLFW_KEY_RIGHT || key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD) {
        ui_send(L, UI_CMD_PARAM, v->panel_sel, 1.0f);
    } else if (key == GLFW_KEY_LEFT || key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) {
        ui_send(L, UI_CMD_PARAM, v->panel_sel, -1.0f);
    } else if (key == GLFW_KEY_I || key == GLFW_KEY_LEFT_BRACKET ||
               key == GLFW_KEY_RIGHT_BRACKET) {
        /* I shows / hides the second iso-surface; [ and ] move its level (and show it). */
        if (key == GLFW_KEY_I) {
            v->iso2_on = !v->iso2_on;
        } else {
            const float d = key == GLFW_KEY_LEFT_BRACKET ? -ISO2_STEP : ISO2_STEP;
            const float lv = roundf((v->iso2_level + d) * 100.0f) / 100.0f;
            v->iso2_level = lv < ISO2_MIN ? ISO2_MIN : (lv > ISO2_MAX ? ISO2_MAX : lv);
            v->iso2_on = true;
        }
        ui_send(L, UI_CMD_ISO2, v->iso2_on ? 1 : 0, v->iso2_level);
    } else if (key == GLFW_KEY_M) {
        v->colour = (v->colour + 1) % COLOUR_MAP_COUNT;
        ui_send(L, UI_CMD_COLOUR, v->colour, 0.0f);
    } else if (key == GLFW_KEY_A || key == GLFW_KEY_S) {
        ui_send(L, UI_CMD_PARAM, panel_row(key == GLFW_KEY_A ? PANEL_HOST_ACTION : PANEL_HOST_SHAPE),
                1.0f);
    } else if (key == GLFW_KEY_P) {
        ui_send(L, UI_CMD_PARAM, panel_row(PANEL_HOST_COLOUR), v->shift ? -1.0f : 1.0f);
    } else if (key == GLFW_KEY_X || key == GLFW_KEY_Y || key == GLFW_KEY_Z) {
        ui_send(L, UI_CMD_PARAM, panel_row(PANEL_HOST_MIRROR),
                HOST_MIRROR_TOGGLE_X + (float)(key - GLFW_KEY_X));
    } else if (key == GLFW_KEY_K) {
        ui_send(L, UI_CMD_REFINE, 0, 0.0f); /* knot insertion: R halves */
    } else if (key == GLFW_KEY_ESCAPE) {
        /* In order after the keys before it; straight to the flag if the queue is full. */
        ui_cmd_t c;
        memset(&c, 0, sizeof(c));
        c.kind = UI_CMD_STOP;
        v->quit = true;
        if (!ui_queue_push(&L->q, &c))
            atomic_store(&L->want_stop, 1);
    }
}

static void hud_text(const live_t *L, const view_t *v, const live_frame_t *fr, char *out,
                     size_t cap)
{
    const float *pr = fr->params;
    const float fx = fr->tm.force_n[0], fy = fr->tm.force_n[1], fz = fr->tm.force_n[2];
    const int t = fr->tool >= 0 && fr->tool < TOOL_KIND_COUNT ? fr->tool : 0;
    const int b = fr->filter >= 0 && fr->filter < BETA_FILTER_COUNT ? fr->filter : 0;
    const int sel = v->panel_sel;
    const host_tool_t *ht = &fr->host_tool;
    char mirror[8], host[160], sel_v[48];
    host_mirror_name(ht->mirror, mirror);
    snprintf(host, sizeof(host), "%s %s  mirror %s", host_action_name(ht->action),
             host_shape_name(ht->shape), mirror);
    if (host_action_has_strength(ht->action))
        snprintf(host + strlen(host), sizeof(host) - strlen(host), "  strength %.3g %s",
                 (double)ht->strength,
                 ht->action == HOST_ACT_CHISEL || ht->action == HOST_ACT_SQUIRT ? "mm/s" : "/s");
    const int pal = palette_index(ht->rgb);
    char paint[48];
    snprintf(paint, sizeof(paint), "%s%s%u %u %u", pal >= 0 ? PAINT_PALETTE[pal].name : "",
             pal >= 0 ? " " : "", ht->rgb[0], ht->rgb[1], ht->rgb[2]);
    if (host_action_paints(ht->action))
        snprintf(host + strlen(host), sizeof(host) - strlen(host), "  colour %s", paint);
    if (fr->knot_ratio == 0)
        snprintf(host, sizeof(host), "carve (springs solve: no host actions)");
    const int prm = PANEL[sel].param;
    if (prm == PANEL_HOST_ACTION)
        snprintf(sel_v, sizeof(sel_v), "%s", host_action_name(ht->action));
    else if (prm == PANEL_HOST_SHAPE)
        snprintf(sel_v, sizeof(sel_v), "%s", host_shape_name(ht->shape));
    else if (prm == PANEL_HOST_MIRROR)
        snprintf(sel_v, sizeof(sel_v), "%s", mirror);
    else if (prm == PANEL_HOST_COLOUR)
        snprintf(sel_v, sizeof(sel_v), "%s", paint);
    else
        snprintf(sel_v, sizeof(sel_v), "%.4g",
                 prm == PANEL_HOST_STRENGTH ? (double)ht->strength
                 : prm == PANEL_SOLVE_STEP  ? (double)fr->solve_step_ms
                                            : (double)pr[prm]);
    char iso2[32] = "off", colour[96] = "none", undo[128];
    if (fr->undo_on)
        snprintf(undo, sizeof(undo), "undo %u | redo %u%s%s", fr->undo_n, fr->redo_n,
                 fr->undo_note[0] ? ": " : "", fr->undo_note);
    else
        snprintf(undo, sizeof(undo), "%s", fr->undo_note[0] ? fr->undo_note : "undo off");
    if (fr->iso2_on)
        snprintf(iso2, sizeof(iso2), "%.2f (clay %.2f)", (double)fr->iso2_level, (double)fr->iso);
    if (fr->colour != COLOUR_MAP_NONE)
        snprintf(colour, sizeof(colour), "%s, x default: %.3g (left) .. %.3g (right)",
                 colour_map_name((colour_map_t)fr->colour), (double)fr->colour_lo,
                 (double)fr->colour_hi);
    snprintf(out, cap,
             "%s  loop %.0f Hz  worst tick %.0f us  link %.1f ms  force %.2f N  t %.2f s  "
             "view %.0f fps%s\n"
             "tool %s%s  beta %s  radius %.1f mm  stiffness %.2f N/mm  clay k %.3g  damping %.3g"
             "  plastic %.3g Hz  alpha %.3g  solve step %.1f ms\n"
             "iso2 %s  colour %s  knots R %d%s%s  carve does %s  %s\n"
             "> %s = %s   [1-6 tool  B beta  TAB/UP/DOWN pick  -/+ change  SHIFT add<>remove"
             "  C shading  I iso2  [ ] level  M colour  K refine  A action  S shape  X Y Z mirror  P paint colour"
             "  CTRL+Z undo  CTRL+SHIFT+Z/CTRL+Y redo"
             "  ESC quit]",
             fr->have_tm ? safety_state_name((safety_state_t)fr->tm.state) : "NO BOARD",
             (double)fr->loop_hz, fr->worst_tick_ns / 1000.0, (double)fr->link_latency_ms,
             sqrt((double)fx * fx + (double)fy * fy + (double)fz * fz), fr->t_s, v->fps,
             L->wo->fast ? "  fast" : "", TOOL_NAMES[t], fr->inverted ? " (inverted)" : "",
             FILTER_NAMES[b], (double)pr[PARAM_RADIUS_MM], (double)pr[PARAM_STIFFNESS_N_PER_MM],
             (double)pr[PARAM_CLAY_STIFFNESS], (double)pr[PARAM_CLAY_DAMPING],
             (double)pr[PARAM_PLASTIC_RATE_HZ], (double)pr[PARAM_ALPHA],
             (double)fr->solve_step_ms, iso2, colour, fr->knot_ratio,
             fr->knot_note[0] ? ": " : "", fr->knot_note, host, undo, PANEL[sel].label, sel_v);
}

/* True when fr, with the meshes the last frame showed, would draw that frame again but for the
 * HUD's figures: the tool within 0.05 mm (under a pixel at the default view), the force within
 * 0.005 N (0.05 mm of its arrow), the same window box and second iso-surface. */
static bool same_picture(const view_t *v, const live_frame_t *fr)
{
    const render_scene_t *d = &v->drawn;
    if (!v->drawn_any || d->show_tool != fr->have_tm || d->show_box != fr->have_box ||
        d->show_wire != (fr->iso2_on && fr->mesh2_serial != 0))
        return false;
    if (fr->have_tm) {
        const vec3_t p = vec3(fr->tm.pos_m[0], fr->tm.pos_m[1], fr->tm.pos_m[2]);
        const vec3_t f = vec3(fr->tm.force_n[0], fr->tm.force_n[1], fr->tm.force_n[2]);
        const float r = fr->tool_radius_m > 0.0f ? fr->tool_radius_m : 0.004f;
        if (vec3_norm(vec3_sub(p, d->tool_pos_m)) > 5e-5f || r != d->tool_radius_m ||
            vec3_norm(vec3_sub(f, d->force_n)) > 0.005f)
            return false;
    }
    if (fr->have_box && (vec3_norm(vec3_sub(fr->box_lo_m, d->box_lo_m)) > 0.0f ||
                         vec3_norm(vec3_sub(fr->box_hi_m, d->box_hi_m)) > 0.0f))
        return false;
    return !d->show_wire || d->wire_on_top == (fr->iso2_level > fr->iso);
}

static void scene_from_frame(view_t *v, const live_frame_t *fr)
{
    render_scene_t *s = &v->scene;
    s->show_tool = fr->have_tm;
    s->tool_pos_m = vec3(fr->tm.pos_m[0], fr->tm.pos_m[1], fr->tm.pos_m[2]);
    s->tool_radius_m = fr->tool_radius_m > 0.0f ? fr->tool_radius_m : 0.004f;
    s->show_force = fr->have_tm;
    s->force_n = vec3(fr->tm.force_n[0], fr->tm.force_n[1], fr->tm.force_n[2]);
    s->show_box = fr->have_box;
    s->box_lo_m = fr->box_lo_m;
    s->box_hi_m = fr->box_hi_m;
    s->show_wire = fr->iso2_on && fr->mesh2_serial != 0;
    s->wire_on_top = fr->iso2_level > fr->iso; /* an inner level is seen through the clay */
}

static void draw_all(live_t *L, view_t *v, const live_frame_t *fr, int w, int h)
{
    camera_matrices(&v->cam, (float)w / (float)h, v->scene.view, v->scene.proj);
    renderer_draw(&v->r, &v->scene, w, h);
    char text[1024];
    hud_text(L, v, fr, text, sizeof(text));
    const float scale = w >= 1500 ? 2.0f : 1.0f;
    hud_draw(&v->hud, text, scale, w, h);
    if (fr->colour != COLOUR_MAP_NONE) {
        /* The legend: the ramp under the text, lowest value on the left. */
        const float y = hud_band_height(text, scale) + 4.0f * scale;
        hud_draw_ramp(&v->hud, colour_ramp_rgb, 32, 4.0f * scale, y, 192.0f * scale,
                      10.0f * scale, w, h);
    }
}

/* Draws one window frame. While the clay is changing (a mesh upload within the last
 * INTERACTIVE_NS) it is drawn straight into the window without multisampling, which on
 * llvmpipe costs about half as much and so shows a stroke sooner; once it has been still that
 * long, frames are drawn 4x multisampled offscreen and resolved into the window. */
static void draw_frame(live_t *L, view_t *v, const live_frame_t *fr, int w, int h,
                       uint64_t now)
{
    const bool changing = v->last_upload_ns != 0 && now - v->last_upload_ns < INTERACTIVE_NS;
    if (!changing && !v->aa_failed) {
        if (v->aa_ready && (v->aa.width != w || v->aa.height != h)) {
            render_target_free(&v->aa);
            v->aa_ready = false;
        }
        if (!v->aa_ready) {
            char e[256];
            v->aa_ready = render_target_init(&v->aa, &v->gl, w, h, 4, e, sizeof(e)) == ARGIL_OK;
            v->aa_failed = !v->aa_ready;
        }
    }
    if (!changing && v->aa_ready) {
        render_target_bind(&v->aa);
        draw_all(L, v, fr, w, h);
        render_target_present(&v->aa);
    } else {
        v->gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        draw_all(L, v, fr, w, h);
    }
}

static bool write_shot(live_t *L, view_t *v, const live_frame_t *fr, const char *path, int w,
                       int h, char *err, size_t err_len)
{
    if (v->shot_ready && (v->shot.width != w || v->shot.height != h)) {
        render_target_free(&v->shot);
        v->shot_ready = false;
    }
    if (!v->shot_ready) {
        free(v->shot_rgb);
        v->shot_rgb = malloc((size_t)w * (size_t)h * 3);
        if (v->shot_rgb == NULL ||
            render_target_init(&v->shot, &v->gl, w, h, 4, err, err_len) != ARGIL_OK)
            return false;
        v->shot_ready = true;
    }
    render_target_bind(&v->shot);
    draw_all(L, v, fr, w, h);
    render_target_read_rgb(&v->shot, v->shot_rgb);
    v->gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    return png_write_rgb(path, w, h, v->shot_rgb, err, err_len) == ARGIL_OK;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *x, size_t n)
{
    if (n == 0)
        return 0.0;
    qsort(x, n, sizeof(*x), cmp_double);
    return x[n / 2];
}

/* Applies the scripted input events due by simulated time t_s; true when there were any. */
static bool play_script(live_t *L, view_t *v, double t_s)
{
    bool any = false;
    while (v->next_ev < v->script.count && v->script.ev[v->next_ev].at_s <= t_s) {
        const ui_event_t *e = &v->script.ev[v->next_ev++];
        any = true;
        switch (e->kind) {
        case UI_EV_KEY: on_key(L, v, e->code); break;
        case UI_EV_SHIFT: v->shift = e->down; break;
        case UI_EV_CTRL: v->ctrl = e->down; break;
        case UI_EV_CURSOR:
            v->cx = e->x;
            v->cy = e->y;
            break;
        case UI_EV_LEFT: v->left = e->down; break;
        case UI_EV_RIGHT: v->right = e->down; break;
        case UI_EV_WHEEL: camera_zoom(&v->cam, e->x); break;
        }
    }
    return any;
}

/* Sleeps until a publish of the kind asked for (WAIT_ANY, WAIT_NEWS), an input event or
 * timeout_ns, whichever comes first; returns at once when a snapshot is already waiting. */
static void wait_for_news(live_t *L, view_t *v, int kind, uint64_t timeout_ns)
{
    atomic_store(&L->render_waiting, kind);
    /* After the announcement: a publish from now on sees it (both sequentially consistent). */
    if (!triple_buffer_has_fresh(&L->tb))
        glfw_window_wait(&v->win, (double)timeout_ns * 1e-9);
    atomic_store(&L->render_waiting, WAIT_NONE);
}

/* The render loop's state from pass to pass, and what the current pass found. */
typedef struct {
    double next_shot_s;           /* simulated time of the next --frames picture */
    uint64_t last_swap_ns;        /* wall clock: the last swap returned (0: none yet) */
    uint64_t done_at_ns;          /* ... the session's last snapshot was taken (0: not yet) */
    uint64_t taken_ns;            /* ... the newest snapshot was taken */
    frame_pacer_cfg_t pc;
    frame_pacer_t pacer;
    int status;                   /* 1 once a picture could not be written */
    int drawn_w, drawn_h;         /* the window size of the last frame drawn */
    bool have_frame;              /* a snapshot was taken */
    bool undrawn;                 /* the newest snapshot taken is not drawn yet */
    const live_frame_t *fr;       /* the newest snapshot taken */
    bool done;                    /* this pass: the session has ended */
    bool input;                   /* this pass: keys, the wheel, a drag or scripted events */
    bool fresh;                   /* this pass: a new snapshot was taken */
    int w, h;                     /* this pass: the window size in pixels */
} loop_state_t;

/* Whether a frame is due this pass, and why (frame_pacer_due decides when). */
typedef struct {
    bool unshown;                 /* the snapshot holds a change no frame has counted yet */
    bool urgent;                  /* undrawn with a new mesh or such a change */
    bool visible;                 /* undrawn and it changes the picture, not only the HUD */
    bool draw;
    uint64_t now_ns;              /* wall clock at the decision (after a frame: its swap) */
    uint64_t draw_at_ns;          /* when a frame will be due if nothing else happens */
} frame_plan_t;

/* Wall clock along one frame. */
typedef struct {
    uint64_t start_ns, uploaded_ns, drawn_ns, swapped_ns;
} frame_times_t;

/* Polls the window: a close request stops the session and each key pressed goes to on_key;
 * true when there was a key. */
static bool poll_keys(live_t *L, view_t *v, glfw_input_t *in)
{
    glfw_window_poll(&v->win, in);
    if (glfw_window_should_close(&v->win))
        atomic_store(&L->want_stop, 1);
    bool input = false;
    int key;
    if (v->script.count == 0) { /* the modifiers the keys below were pressed with */
        v->ctrl = in->ctrl;
        v->shift = in->shift;
    }
    while (glfw_window_take_key(&v->win, &key)) {
        on_key(L, v, key);
        input = true;
    }
    return input;
}

/* Takes the newest snapshot, and notes when the session's last one was taken. */
static void take_snapshot(live_t *L, loop_state_t *S)
{
    uint32_t slot;
    S->fresh = triple_buffer_take(&L->tb, &slot);
    S->fr = &L->slot[slot];
    if (S->fresh) {
        S->taken_ns = now_ns();
        S->have_frame = true;
        S->undrawn = true;
    }
    if (S->done && S->done_at_ns == 0)
        S->done_at_ns = now_ns(); /* the snapshot just taken is the session's last */
}

/* The cursor, buttons and Shift from the input script (its events due by simulated time t_s)
 * or from the window, the wheel zooming the camera; true when that was input. */
static bool read_pointer(live_t *L, view_t *v, const glfw_input_t *in, double t_s)
{
    if (v->script.count > 0)
        return play_script(L, v, t_s);
    v->cx = in->cursor_x;
    v->cy = in->cursor_y;
    v->left = in->left_down;
    v->right = in->right_down;
    v->shift = in->shift;
    const double scroll = glfw_window_take_scroll(&v->win);
    camera_zoom(&v->cam, scroll);
    return scroll != 0.0;
}

/* Turns the pointer into commands: a right drag turns the camera, Shift inverts the tool, and
 * with --mouse the ray under the cursor goes to the session. */
static void steer_view(live_t *L, view_t *v, loop_state_t *S)
{
    S->w = S->h = 0;
    glfw_window_size(&v->win, &S->w, &S->h);
    const int w = S->w, h = S->h;
    const bool moved = v->cx != v->prev_cx || v->cy != v->prev_cy;
    if (v->right && v->prev_right && moved && w > 0 && h > 0) {
        camera_arcball(&v->cam, v->prev_cx, v->prev_cy, v->cx, v->cy, w, h);
        S->input = true;
    }
    if (v->shift != v->prev_shift)
        ui_send(L, UI_CMD_INVERT, v->shift ? 1 : 0, 0);
    if (L->wo->mouse && w > 0 && h > 0 && (v->left || v->prev_left || moved || S->fresh)) {
        vec3_t o, d;
        camera_ray(&v->cam, v->cx, v->cy, w, h, &o, &d);
        ui_cmd_t c;
        memset(&c, 0, sizeof(c));
        c.kind = UI_CMD_MOUSE;
        c.arg = v->left ? 1 : 0;
        c.origin_m[0] = o.x, c.origin_m[1] = o.y, c.origin_m[2] = o.z;
        c.dir[0] = d.x, c.dir[1] = d.y, c.dir[2] = d.z;
        ui_queue_push(&L->q, &c);
    }
    v->prev_cx = v->cx;
    v->prev_cy = v->cy;
    v->prev_right = v->right;
    v->prev_shift = v->shift;
    v->prev_left = v->left;
}

/* Hands the renderer the snapshot's meshes it does not hold yet; true when the clay's mesh was
 * new to it (uploaded, or failed to). */
static bool upload_meshes(view_t *v, const live_frame_t *fr)
{
    const bool clay = fr->mesh_serial != 0 && fr->mesh_serial != v->uploaded_serial;
    if (clay && renderer_set_mesh(&v->r, &fr->mesh) == ARGIL_OK)
        v->uploaded_serial = fr->mesh_serial;
    if (fr->iso2_on && fr->mesh2_serial != 0 && fr->mesh2_serial != v->uploaded2_serial &&
        renderer_set_wire_mesh(&v->r, &fr->mesh2) == ARGIL_OK)
        v->uploaded2_serial = fr->mesh2_serial;
    return clay;
}

/* With --frames, a picture of the snapshot every screenshot_every_s of simulated time (named
 * by its simulated ms); one that cannot be written stops the session. */
static void shoot_frames(live_t *L, view_t *v, loop_state_t *S, char *err, size_t err_len)
{
    const sculpt_window_opts_t *wo = L->wo;
    const live_frame_t *fr = S->fr;
    if (!(S->w > 0 && S->h > 0 && S->have_frame && fr->t_s + 1e-9 >= S->next_shot_s &&
          wo->frames_dir))
        return;
    char path[4096];
    snprintf(path, sizeof(path), "%s/frame_%06ld.png", wo->frames_dir, lround(fr->t_s * 1000.0));
    scene_from_frame(v, fr);
    (void)upload_meshes(v, fr);
    if (!write_shot(L, v, fr, path, S->w, S->h, err, err_len)) {
        S->status = 1;
        atomic_store(&L->want_stop, 1);
    }
    while (S->next_shot_s <= fr->t_s + 1e-9)
        S->next_shot_s += wo->screenshot_every_s;
}

/* Decides whether to draw now: frame_pacer_due on what the snapshot and the input bring, and
 * always once more for the session's last snapshot. */
static void plan_frame(live_t *L, view_t *v, loop_state_t *S, frame_plan_t *pl)
{
    const live_frame_t *fr = S->fr;
    const bool new_mesh =
        (fr->mesh_serial != 0 && fr->mesh_serial != v->drawn_serial) ||
        (fr->iso2_on && fr->mesh2_serial != 0 && fr->mesh2_serial != v->drawn2_serial);
    pl->unshown = fr->has_change && fr->change_pub > v->counted_pub;
    pl->urgent = S->undrawn && (new_mesh || pl->unshown);
    /* A snapshot that changes only the HUD's figures waits for the HUD's next refresh. */
    pl->visible = pl->urgent || (S->undrawn && !same_picture(v, fr));
    pl->now_ns = now_ns();
    pl->draw_at_ns = pl->now_ns;
    const frame_pacer_in_t pin = {pl->visible, pl->urgent,
                                  S->input || S->w != S->drawn_w || S->h != S->drawn_h,
                                  !S->done && atomic_load(&L->inflight) != 0};
    pl->draw = frame_pacer_due(&S->pacer, &S->pc, &pin, pl->now_ns, &pl->draw_at_ns) ||
               (S->done && S->undrawn);
}

/* Counts a drawn frame: its upload, draw and swap times when it uploaded, why it was drawn, and
 * the frame rate and cost since the swap before. */
static void count_frame(view_t *v, const loop_state_t *S, const frame_plan_t *pl,
                        const frame_times_t *t, bool uploaded)
{
    if (v->n_upload < LATENCY_SAMPLES && uploaded) {
        v->upload_ms[v->n_upload] = (double)(t->uploaded_ns - t->start_ns) * 1e-6;
        v->draw_ms[v->n_upload] = (double)(t->drawn_ns - t->uploaded_ns) * 1e-6;
        v->swap_ms[v->n_upload++] = (double)(t->swapped_ns - t->drawn_ns) * 1e-6;
    }
    if (pl->urgent)
        v->n_drawn_mesh++;
    else if (pl->visible)
        v->n_drawn_snapshot++;
    else
        v->n_drawn_other++;
    if (S->last_swap_ns != 0) {
        const double dt_ms = (double)(t->swapped_ns - S->last_swap_ns) * 1e-6;
        if (dt_ms > 0.0)
            v->fps = v->fps > 0.0 ? 0.9 * v->fps + 0.1 * (1000.0 / dt_ms) : 1000.0 / dt_ms;
        if (v->n_frame < LATENCY_SAMPLES) {
            v->frame_ms[v->n_frame] = dt_ms;
            v->cost_ms[v->n_frame++] = (double)(t->swapped_ns - t->start_ns) * 1e-6;
        }
    }
}

/* Counts the change the frame shows first: wall clock from the impulse's arrival at the host to
 * the return of the first swap whose frame shows the solve step that integrated it, by stage. */
static void count_latency(view_t *v, const loop_state_t *S, const frame_times_t *t)
{
    const live_frame_t *fr = S->fr;
    if (v->n_latency < LATENCY_SAMPLES) {
        const uint64_t at[STAGE_COUNT + 1] = {fr->arrival_ns, fr->solved_ns, fr->meshed_ns,
                                              S->taken_ns, t->uploaded_ns, t->drawn_ns,
                                              t->swapped_ns};
        for (int k = 0; k < STAGE_COUNT; k++)
            v->stage_ms[k][v->n_latency] =
                at[k + 1] >= at[k] ? (double)(at[k + 1] - at[k]) * 1e-6 : 0.0;
        v->latency_ms[v->n_latency++] = (double)(t->swapped_ns - fr->arrival_ns) * 1e-6;
    }
    v->counted_pub = fr->change_pub;
}

/* Draws the snapshot (uploading what changed), swaps, and counts the frame's figures. */
static void present_frame(live_t *L, view_t *v, loop_state_t *S, frame_plan_t *pl)
{
    const live_frame_t *fr = S->fr;
    frame_times_t t = {pl->now_ns, 0, 0, 0};
    bool uploaded = upload_meshes(v, fr);
    if (fr->mesh_serial != v->drawn_serial) {
        uploaded = true;
        v->drawn_serial = fr->mesh_serial;
    }
    v->drawn2_serial = fr->mesh2_serial;
    t.uploaded_ns = now_ns();
    if (uploaded)
        v->last_upload_ns = t.uploaded_ns;
    scene_from_frame(v, fr);
    if (S->w > 0 && S->h > 0)
        draw_frame(L, v, fr, S->w, S->h, t.uploaded_ns);
    v->drawn = v->scene;
    v->drawn_any = true;
    S->drawn_w = S->w;
    S->drawn_h = S->h;
    t.drawn_ns = now_ns();
    glfw_window_swap(&v->win);
    t.swapped_ns = now_ns();
    count_frame(v, S, pl, &t, uploaded);
    frame_pacer_drawn(&S->pacer, t.start_ns, t.swapped_ns);
    S->last_swap_ns = t.swapped_ns;
    if (S->undrawn)
        atomic_store(&L->shown_pub, fr->pub_seq);
    if (S->undrawn && pl->unshown)
        count_latency(v, S, &t);
    S->undrawn = false;
    pl->now_ns = t.swapped_ns;
}

/* Sleeps until the frame is due or the linger after the session runs out, unless a publish or
 * input wakes the thread first. */
static void sleep_until_due(live_t *L, view_t *v, const loop_state_t *S, const frame_plan_t *pl)
{
    uint64_t until = pl->draw_at_ns;
    if (S->done) {
        const uint64_t end_ns = S->done_at_ns + (uint64_t)(L->wo->linger_s * 1e9);
        until = end_ns < until ? end_ns : until;
    }
    /* Before draw_at only a new mesh is worth a frame: other publishes may sleep on. */
    wait_for_news(L, v, pl->visible ? WAIT_NEWS : WAIT_ANY,
                  until > pl->now_ns ? until - pl->now_ns : 0);
}

/* The window's main loop. Frames start when frame_pacer says so: at once for a snapshot with a
 * new mesh (or a change not shown yet) and for input that changes the view, other snapshots at
 * most 60 a second and held back a little while an impulse is on its way to a mesh, and 4 a
 * second with nothing new. In between the thread sleeps until a publish or an input event wakes
 * it, leaving the cores to the session thread. */
static int render_loop(live_t *L, view_t *v, char *err, size_t err_len)
{
    const sculpt_window_opts_t *wo = L->wo;
    loop_state_t S;
    memset(&S, 0, sizeof(S));
    S.next_shot_s = wo->screenshot_every_s > 0.0 ? 0.0 : INFINITY;
    frame_pacer_cfg_default(&S.pc);
    frame_pacer_init(&S.pacer);
    S.fr = &L->slot[L->tb.front];
    for (;;) {
        S.done = atomic_load(&L->session_done) != 0;
        glfw_input_t in;
        S.input = poll_keys(L, v, &in);
        take_snapshot(L, &S);
        S.input |= read_pointer(L, v, &in, S.fr->t_s);
        steer_view(L, v, &S);
        shoot_frames(L, v, &S, err, err_len);
        frame_plan_t pl;
        plan_frame(L, v, &S, &pl);
        if (pl.draw)
            present_frame(L, v, &S, &pl);
        if (S.done && !S.undrawn &&
            (atomic_load(&L->want_stop) || v->quit ||
             (double)(pl.now_ns - S.done_at_ns) * 1e-9 >= wo->linger_s))
            break;
        if (!pl.draw)
            sleep_until_due(L, v, &S, &pl);
    }
    if (wo->screenshot_path) {
        int w = 0, h = 0;
        glfw_window_size(&v->win, &w, &h);
        if (w > 0 && h > 0 && !write_shot(L, v, S.fr, wo->screenshot_path, w, h, err, err_len))
            S.status = 1;
    }
    return S.status;
}

/* Loads the scripted input (--input) and creates the directory for --frames; on failure nothing
 * is left loaded. */
static argil_err_t window_inputs(view_t *v, const session_opts_t *so, const sculpt_window_opts_t *wo,
                                 char *err, size_t err_len)
{
    ui_input_init(&v->script);
    if (wo->input_path != NULL &&
        ui_input_load(&v->script, wo->input_path, err, err_len) != UI_INPUT_OK)
        return ARGIL_ERR_PARSE;
    if (wo->frames_dir != NULL && so->out_dir != NULL)
        (void)mkdir(so->out_dir, 0777); /* the session creates it too; errors show below */
    if (wo->frames_dir != NULL && mkdir(wo->frames_dir, 0777) != 0 && errno != EEXIST) {
        snprintf(err, err_len, "%s: cannot create directory: %s", wo->frames_dir,
                 strerror(errno));
        ui_input_free(&v->script);
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}

/* Opens the window with its renderer and HUD and sets the first scene and camera; on failure
 * nothing is left open. */
static argil_err_t view_open(view_t *v, const session_opts_t *so, const sculpt_window_opts_t *wo,
                             char *err, size_t err_len)
{
    char title[256];
    snprintf(title, sizeof(title), "argil sculpt — %s",
             so->script_path ? so->script_path : "mouse");
    /* No samples in the window itself: still frames are drawn multisampled offscreen and
     * resolved into it (draw_frame). */
    if (glfw_window_open(&v->win, wo->width, wo->height, true, 0, title, &v->gl, err,
                         err_len) != ARGIL_OK)
        return ARGIL_ERR_STATE;
    argil_err_t rc = renderer_init(&v->r, &v->gl, err, err_len);
    if (rc == ARGIL_OK)
        rc = hud_init(&v->hud, &v->gl, err, err_len);
    if (rc != ARGIL_OK) {
        hud_free(&v->hud);
        renderer_free(&v->r);
        glfw_window_close(&v->win);
        return ARGIL_ERR_STATE;
    }
    v->gl.Enable(GL_MULTISAMPLE);
    render_scene_default(&v->scene);
    v->scene.closed_mesh = true; /* mc_blocks meshes are closed, CCW seen from outside */
    camera_frame(&v->cam, vec3(-0.036f, -0.036f, -0.036f), vec3(0.036f, 0.036f, 0.036f));
    camera_orbit(&v->cam, -30.0f * (float)M_PI / 180.0f, 25.0f * (float)M_PI / 180.0f);
    return ARGIL_OK;
}

/* Frees what view_open opened and the frames drawn since hold. */
static void view_close(view_t *v)
{
    if (v->shot_ready)
        render_target_free(&v->shot);
    if (v->aa_ready)
        render_target_free(&v->aa);
    free(v->shot_rgb);
    hud_free(&v->hud);
    renderer_free(&v->r);
    glfw_window_close(&v->win);
}

/* Sets up the state the two threads share and the session's options with the per-tick hook;
 * the view starts with the second iso-surface and colour map the options ask for. */
static void live_init(live_t *L, view_t *v, const session_opts_t *so, const sculpt_window_opts_t *wo)
{
    triple_buffer_init(&L->tb);
    for (int i = 0; i < 3; i++) {
        mesh_init(&L->slot[i].mesh);
        mesh_init(&L->slot[i].mesh2);
    }
    L->iso2_on = wo->iso2 >= ISO2_MIN && wo->iso2 <= ISO2_MAX;
    L->iso2_level = L->iso2_on ? wo->iso2 : 0.3f;
    L->colour = wo->colour > 0 && wo->colour < COLOUR_MAP_COUNT ? wo->colour : COLOUR_MAP_NONE;
    v->iso2_on = L->iso2_on;
    v->iso2_level = L->iso2_level;
    v->colour = L->colour;
    ui_queue_init(&L->q);
    atomic_init(&L->want_stop, 0);
    atomic_init(&L->session_done, 0);
    atomic_init(&L->shown_pub, 0);
    atomic_init(&L->render_waiting, WAIT_NONE);
    atomic_init(&L->inflight, 0);
    L->win = &v->win;
    L->wo = wo;
    L->so = *so;
    L->stop = so->stop;
    L->pending_since_s = -1.0;
    live_hand_init(&L->hand);
    live_hand_cfg_default(&L->hand_cfg);
    L->hook.on_tick = on_tick;
    L->hook.ctx = L;
    L->hook.hold_open = wo->mouse;
    L->so.hook = &L->hook;
    if (wo->mouse)
        L->so.script_path = NULL;
}

/* Frees the session thread's meshers and the snapshots' meshes. */
static void live_free(live_t *L)
{
    if (L->mcb_ready)
        mc_blocks_free(&L->mcb);
    if (L->mcb2_ready)
        mc_blocks_free(&L->mcb2);
    for (int i = 0; i < 3; i++) {
        mesh_free(&L->slot[i].mesh);
        mesh_free(&L->slot[i].mesh2);
    }
}

/* --report: the frame-time, latency and frame-count figures (sorts the samples). */
static void report_frames(view_t *v)
{
    const size_t nf = v->n_frame, nl = v->n_latency;
    const double fm = median(v->frame_ms, nf), lm = median(v->latency_ms, nl);
    const double lmax = nl ? v->latency_ms[nl - 1] : 0.0;
    const double l90 = nl ? v->latency_ms[nl * 9 / 10] : 0.0;
    printf("  live window         %zu frames, frame time median %.1f ms; change to "
           "screen median %.1f ms, p90 %.1f ms, max %.1f ms (%zu changes)\n",
           nf, fm, lm, l90, lmax, nl);
    printf("  latency stages      median ms:");
    for (int k = 0; k < STAGE_COUNT; k++)
        printf(" %s %.1f", STAGE_NAMES[k], median(v->stage_ms[k], nl));
    printf("; frames with an upload: upload %.1f, draw %.1f, swap %.1f (%zu)\n",
           median(v->upload_ms, v->n_upload), median(v->draw_ms, v->n_upload),
           median(v->swap_ms, v->n_upload), v->n_upload);
    printf("  frames drawn        %zu for a new mesh, %zu for the tool or view, %zu for "
           "input or the HUD alone; frame cost (start to swap) median %.1f ms\n",
           v->n_drawn_mesh, v->n_drawn_snapshot, v->n_drawn_other,
           median(v->cost_ms, nf));
}

/* --report: the tool and the view as the session's last snapshot has them. */
static void report_end_state(live_t *L)
{
    uint32_t slot;
    triple_buffer_take(&L->tb, &slot);
    const live_frame_t *fr = &L->slot[slot];
    const int t = fr->tool >= 0 && fr->tool < TOOL_KIND_COUNT ? fr->tool : 0;
    const int b = fr->filter >= 0 && fr->filter < BETA_FILTER_COUNT ? fr->filter : 0;
    printf("  tool at the end     %s%s, radius %.2f mm, stiffness %.3f N/mm, beta %s, "
           "clay stiffness %.3g, damping %.3g, plastic rate %.3g Hz\n",
           TOOL_NAMES[t], fr->inverted ? " (inverted)" : "",
           (double)fr->params[PARAM_RADIUS_MM],
           (double)fr->params[PARAM_STIFFNESS_N_PER_MM], FILTER_NAMES[b],
           (double)fr->params[PARAM_CLAY_STIFFNESS],
           (double)fr->params[PARAM_CLAY_DAMPING],
           (double)fr->params[PARAM_PLASTIC_RATE_HZ]);
    char iso2[16] = "off";
    if (fr->iso2_on)
        snprintf(iso2, sizeof(iso2), "%.2f", (double)fr->iso2_level);
    printf("  view at the end     iso2 %s, colour %s (%.3g .. %.3g x default), solve "
           "step %.1f ms\n",
           iso2, colour_map_name((colour_map_t)fr->colour), (double)fr->colour_lo,
           (double)fr->colour_hi, (double)fr->solve_step_ms);
}

/* Runs the session thread behind the render loop until both have ended: the session's error,
 * else the render loop's (a picture not written), with the session's summary in *sum. */
static argil_err_t run_threads(live_t *L, view_t *v, session_summary_t *sum, char *err,
                               size_t err_len)
{
    pthread_t th;
    if (pthread_create(&th, NULL, session_main, L) != 0) {
        snprintf(err, err_len, "cannot start the session thread");
        return ARGIL_ERR_STATE;
    }
    char rerr[512] = "";
    const int status = render_loop(L, v, rerr, sizeof(rerr));
    atomic_store(&L->want_stop, 1);
    pthread_join(th, NULL);
    *sum = L->sum;
    if (L->wo->mouse)
        sum->interrupted = false; /* closing the window is how a mouse session ends */
    argil_err_t rc = L->rc;
    if (rc != ARGIL_OK)
        snprintf(err, err_len, "%s", L->err);
    else if (status != 0) {
        snprintf(err, err_len, "%s", rerr);
        rc = ARGIL_ERR_IO;
    }
    if (L->wo->report) {
        report_frames(v);
        report_end_state(L);
    }
    return rc;
}

argil_err_t sculpt_window_run(session_opts_t *so, const sculpt_window_opts_t *wo,
                              session_summary_t *sum, bool *window_failed, char *err,
                              size_t err_len)
{
    *window_failed = false;
    memset(sum, 0, sizeof(*sum));
    live_t *L = calloc(1, sizeof(*L));
    view_t *v = calloc(1, sizeof(*v));
    if (L == NULL || v == NULL) {
        free(L);
        free(v);
        snprintf(err, err_len, "out of memory for the window");
        return ARGIL_ERR_NOMEM;
    }
    argil_err_t rc = window_inputs(v, so, wo, err, err_len);
    if (rc != ARGIL_OK) {
        free(L);
        free(v);
        return rc;
    }
    if (view_open(v, so, wo, err, err_len) != ARGIL_OK) {
        *window_failed = true;
        ui_input_free(&v->script);
        free(L);
        free(v);
        return ARGIL_ERR_STATE;
    }
    live_init(L, v, so, wo);
    rc = run_threads(L, v, sum, err, err_len);
    view_close(v);
    ui_input_free(&v->script);
    live_free(L);
    free(L);
    free(v);
    return rc;
}
