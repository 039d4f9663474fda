/* make bench: the cost of every board tick over the default sculpting session (simulated arm,
 * board core, host peer in lockstep, as `argil sculpt` runs it). Natively: wall-clock time of
 * each board_run_tick (CLOCK_MONOTONIC), median, 99th percentile and worst. Under
 * `valgrind --tool=callgrind --collect-atstart=no --combine-dumps=yes`: collection is switched
 * on only inside board_run_tick and the counters are dumped after every tick, so each dump part
 * of the output file holds exactly one tick's instructions (tests/bench.sh reads them).
 * --paint-stiffness SCALE: the B-spline global solve, with the clay's stiffness painted SCALE×
 * (40 mm round the +z pole, where the default script pushes) before the session, so the board
 * gets two-channel windows (per-node stiffness).
 * Usage: bench_ticks [--window 16|32] [--script FILE] [--max-ticks N] [--paint-stiffness SCALE] */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Debian's valgrind package ships these headers; without them the bench still times ticks. */
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#include <valgrind/valgrind.h>
#else
#define CALLGRIND_TOGGLE_COLLECT
#define CALLGRIND_DUMP_STATS
#define RUNNING_ON_VALGRIND 0
#endif

#include "host/app/peer.h"
#include "host/app/script.h"
#include "host/model/grid.h"
#include "sim/rig/rig.h"

/* The same scene as host/app/session.c: an 88³ grid of 1.25 mm, a 30 mm clay sphere at the
 * origin, the stylus starting 60 mm in front of it, 2 s to become ACTIVE, 0.3 s tail. */
#define GRID_EDGE 88
#define SPACING_M 0.00125f
#define CLAY_RADIUS_M 0.030f
#define START_Z_M 0.060f
#define SETTLE_S 2.0
#define TAIL_S 0.3

typedef struct {
    sim_rig_t rig;
    grid_t grid;
    peer_t peer;
    script_t script;
    script_player_t player;
    vec3_t offset_m;
    uint8_t rx[SIM_RIG_LINK_BYTES];
} bench_t;

static bool bench_send(void *ctx, const uint8_t *frame, size_t len)
{
    bench_t *b = ctx;
    return sim_rig_host_send(&b->rig, frame, len) == ARGIL_OK;
}

static void tool_from_player(const bench_t *b, msg_tool_t *t)
{
    const script_player_t *p = &b->player;
    memset(t, 0, sizeof(*t));
    t->kind = (uint8_t)p->tool;
    t->shape = (uint8_t)p->shape;
    t->filter = (uint8_t)p->filter;
    t->flags = TOOL_FLAG_ISO;
    t->radius_m = p->params[PARAM_RADIUS_MM] * 1e-3f;
    t->length_m = p->params[PARAM_LENGTH_MM] * 1e-3f;
    t->axis[0] = p->axis.x;
    t->axis[1] = p->axis.y;
    t->axis[2] = p->axis.z;
    t->alpha = p->params[PARAM_ALPHA];
    t->contact_stiffness_n_per_m = p->params[PARAM_STIFFNESS_N_PER_MM] * 1e3f;
    t->max_force_n = p->params[PARAM_MAX_FORCE_N];
    t->iso = p->params[PARAM_ISO];
    t->yield_force_n = p->params[PARAM_YIELD_FORCE_N];
    t->friction = p->params[PARAM_FRICTION];
    t->probe_gain = p->params[PARAM_PROBE_GAIN];
    t->rope_stiffness_n_per_m = p->params[PARAM_ROPE_STIFFNESS_N_PER_MM] * 1e3f;
    t->model_scale = 1.0f;
    t->model_offset_m[0] = b->offset_m.x;
    t->model_offset_m[1] = b->offset_m.y;
    t->model_offset_m[2] = b->offset_m.z;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    int edge = 16;
    const char *script_path = "scripts/default.scn";
    long max_ticks_arg = 0;
    float paint_scale = 0.0f;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--window") == 0 && i + 1 < argc)
            edge = atoi(argv[++i]);
        else if (strcmp(argv[i], "--script") == 0 && i + 1 < argc)
            script_path = argv[++i];
        else if (strcmp(argv[i], "--max-ticks") == 0 && i + 1 < argc)
            max_ticks_arg = atol(argv[++i]);
        else if (strcmp(argv[i], "--paint-stiffness") == 0 && i + 1 < argc)
            paint_scale = (float)atof(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_ticks [--window 16|32] [--script FILE] [--max-ticks N] "
                            "[--paint-stiffness SCALE]\n");
            return 2;
        }
    }
    bench_t *b = calloc(1, sizeof(*b));
    if (!b) {
        fprintf(stderr, "bench_ticks: out of memory\n");
        return 1;
    }
    char err[256];
    script_init(&b->script);
    if (script_load(&b->script, script_path, err, sizeof(err)) != SCRIPT_OK) {
        fprintf(stderr, "bench_ticks: %s\n", err);
        return 1;
    }
    sim_rig_cfg_t rc;
    sim_rig_cfg_default(&rc);
    /* Under valgrind a tick takes ~50x longer; the overrun-streak fault would end the session. */
    if (RUNNING_ON_VALGRIND)
        rc.board.safety.overrun_streak = 0;
    if (sim_rig_init(&b->rig, &rc) != ARGIL_OK) {
        fprintf(stderr, "bench_ticks: board configuration refused\n");
        return 1;
    }
    const int32_t dims[3] = {GRID_EDGE, GRID_EDGE, GRID_EDGE};
    const float half = 0.5f * (float)(GRID_EDGE - 1) * SPACING_M;
    if (grid_init(&b->grid, dims, SPACING_M, vec3(-half, -half, -half)) != ARGIL_OK) {
        fprintf(stderr, "bench_ticks: cannot allocate the grid\n");
        return 1;
    }
    grid_fill_sphere(&b->grid, vec3(0, 0, 0), CLAY_RADIUS_M);
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    pc.window_edge = edge;
    if (paint_scale > 0.0f)
        pc.global_solve = PEER_SOLVE_BSPLINE;
    if (peer_init(&b->peer, &pc, &b->grid, bench_send, NULL, b) != ARGIL_OK) {
        fprintf(stderr, "bench_ticks: window edge %d refused\n", edge);
        return 2;
    }
    if (paint_scale > 0.0f &&
        peer_paint_material(&b->peer, PEER_MAT_STIFFNESS, vec3(0, 0, CLAY_RADIUS_M), 0.040f,
                            paint_scale) != ARGIL_OK) {
        fprintf(stderr, "bench_ticks: paint scale %g refused\n", (double)paint_scale);
        return 2;
    }
    b->offset_m = vec3_sub(vec3(0, 0, START_Z_M), sim_rig_tip_m(&b->rig));
    script_player_init(&b->player, &b->script, vec3(0, 0, START_Z_M));

    const uint32_t dt_us = rc.board.tick_us;
    const float dt_s = (float)dt_us * 1e-6f;
    const double total_s = SETTLE_S + script_duration_s(&b->script) + TAIL_S;
    uint64_t max_ticks = (uint64_t)(total_s / dt_s) + 1u;
    if (max_ticks_arg > 0 && (uint64_t)max_ticks_arg < max_ticks)
        max_ticks = (uint64_t)max_ticks_arg;
    uint64_t *wall = calloc(max_ticks, sizeof(*wall));
    if (!wall) {
        fprintf(stderr, "bench_ticks: out of memory\n");
        return 1;
    }
    bool started = false, finished = false;
    double finished_at_s = 0.0;
    uint64_t active_ticks = 0, tick;
    peer_request_arm(&b->peer);
    (void)peer_send_hello(&b->peer, "bench");
    for (tick = 0; tick < max_ticks; tick++) {
        const double t_s = (double)tick * dt_s;
        if (!started && b->peer.have_tm && b->peer.last_tm.state == SAFETY_ACTIVE)
            started = true;
        if (!started && t_s > SETTLE_S) {
            fprintf(stderr, "bench_ticks: the board did not become ACTIVE\n");
            return 1;
        }
        if (started && !finished && script_player_step(&b->player, dt_s)) {
            finished = true;
            finished_at_s = t_s;
        }
        if (finished && t_s - finished_at_s >= TAIL_S)
            break;
        if (b->player.params_changed) {
            msg_tool_t tool;
            tool_from_player(b, &tool);
            peer_set_tool(&b->peer, &tool);
            b->grid.material.stiffness = b->player.params[PARAM_CLAY_STIFFNESS];
            b->grid.material.damping = b->player.params[PARAM_CLAY_DAMPING];
            b->grid.material.plastic_rate_hz = b->player.params[PARAM_PLASTIC_RATE_HZ];
            b->player.params_changed = 0;
        }
        const vec3_t target = vec3_sub(b->player.pos_m, b->offset_m);
        sim_rig_set_hand(&b->rig, target, b->player.vel_m_s, (b->player.buttons & 1) != 0,
                         (b->player.buttons & 2) != 0);
        sim_rig_step_device(&b->rig, dt_us);

        /* The measured part: one board tick, nothing else. */
        const double t0 = now_ns();
        CALLGRIND_TOGGLE_COLLECT;
        (void)sim_rig_step_board(&b->rig);
        CALLGRIND_TOGGLE_COLLECT;
        const double t1 = now_ns();
        CALLGRIND_DUMP_STATS;
        wall[tick] = (uint64_t)(t1 - t0);
        if (b->rig.board.safety.state == SAFETY_ACTIVE)
            active_ticks++;

        const size_t n = sim_rig_host_receive(&b->rig, b->rx, sizeof(b->rx));
        peer_receive(&b->peer, b->rx, n);
        peer_tick(&b->peer, dt_us);
    }
    const uint64_t ticks = tick;
    qsort(wall, ticks, sizeof(*wall), cmp_u64);
    printf("window %d^3: %llu ticks (%.2f s simulated, %llu ACTIVE), final state %s\n", edge,
           (unsigned long long)ticks, (double)ticks * dt_s, (unsigned long long)active_ticks,
           safety_state_name(b->rig.board.safety.state));
    if (paint_scale > 0.0f)
        printf("painted %gx: %u windows, %u chunks sent\n", (double)paint_scale,
               b->peer.stats.windows_sent, b->peer.stats.chunks_sent);
    if (ticks > 0)
        printf("wall per tick: median %.1f us, p99 %.1f us, worst %.1f us\n",
               (double)wall[(ticks - 1) / 2] * 1e-3, (double)wall[(ticks * 99 - 1) / 100] * 1e-3,
               (double)wall[ticks - 1] * 1e-3);
    free(wall);
    peer_free(&b->peer);
    grid_free(&b->grid);
    script_free(&b->script);
    free(b);
    return 0;
}
