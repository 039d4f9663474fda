/* make bench, haptic rendering: Z-width (the stiffest virtual wall the simulated arm renders
 * stably at 1 kHz, with and without the passivity controller) and the tick cost of point,
 * curve and area tools on 16³ and 32³ windows. Usage: bench_haptics [zwidth|tick TOOL EDGE] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The SIL rig asserts with cmocka's names; here a failed setup is fatal. */
#define assert_non_null(p) do { if (!(p)) { fprintf(stderr, "bench: setup failed\n"); exit(1); } } while (0)
#define assert_int_equal(a, b) do { if ((a) != (b)) { fprintf(stderr, "bench: setup failed: %s\n", #a); exit(1); } } while (0)
#include "tests/sil/rig.h"

#define H 0.00125f

/* A wall window: material below z = wall_z (model), edge samples per axis, around centre. */
static void send_wall(rig_t *r, float wall_z, vec3_t centre, int edge)
{
    static float d[ARGIL_WINDOW_SAMPLES_MAX];
    const vec3_t o = vec3(centre.x - 0.5f * (float)(edge - 1) * H, centre.y - 0.5f * (float)(edge - 1) * H,
                          centre.z - 0.5f * (float)(edge - 1) * H);
    for (int z = 0; z < edge; z++)
        for (int i = 0; i < edge * edge; i++) {
            float v = 0.5f + 0.5f * (wall_z - (o.z + (float)z * H)) / (4.0f * H);
            d[i + edge * edge * z] = v < 0 ? 0 : (v > 1 ? 1 : v);
        }
    spring_material_t mat;
    spring_material_default(&mat);
    const int32_t dims[3] = {edge, edge, edge};
    rig_send_window(r, d, NULL, dims, o, H, &mat);
}

/* Presses a lightly held stylus (100 N/m, 0.2 N·s/m grip: a relaxed hand) into a wall of
 * stiffness k; true when, after the impact has had 0.5 s to die out, the tip moves less than
 * 0.05 mm peak to peak and the board is still ACTIVE. */
static bool wall_stable(float k_n_per_mm, bool passivity, float *pp_mm)
{
    rig_t *r = rig_new_mode(k_n_per_mm, true);
    r->rig.board.cfg.passivity = passivity;
    r->rig.dev.p.hand.stiffness_n_per_m = 100.0f;
    r->rig.dev.p.hand.damping_n_s_per_m = 0.2f;
    const vec3_t tip = rig_tip_model(r);
    const float wall = tip.z - r->tool.radius_m - 0.002f;
    send_wall(r, wall, tip, 16);
    if (rig_until_active(r, 1000) < 0) {
        rig_free(r);
        return false;
    }
    /* The hand drives 10 mm into the wall at 100 mm/s. */
    rig_move(r, vec3_add(tip, vec3(0, 0, -0.012f)), 120);
    float lo = 1.0f, hi = -1.0f;
    for (int ms = 0; ms < 1000; ms++) {
        rig_tick(r);
        if (ms >= 500) {
            const float z = rig_tip_model(r).z;
            if (z < lo) lo = z;
            if (z > hi) hi = z;
        }
    }
    *pp_mm = (hi - lo) * 1e3f;
    const bool ok = r->rig.board.safety.state == SAFETY_ACTIVE && *pp_mm < 0.05f;
    rig_free(r);
    return ok;
}

static void zwidth(void)
{
    const float ks[] = {0.5f, 1.0f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 12.0f, 16.0f};
    for (int pc = 1; pc >= 0; pc--) {
        float best = 0.0f;
        printf("  passivity controller %s:", pc ? "on " : "off");
        for (size_t i = 0; i < sizeof(ks) / sizeof(ks[0]); i++) {
            float pp;
            const bool ok = wall_stable(ks[i], pc != 0, &pp);
            printf(" %g:%s(%.3f)", (double)ks[i], ok ? "ok" : "NO", (double)pp);
            if (ok && ks[i] > best)
                best = ks[i];
            if (!ok)
                break;
        }
        printf("\n  => largest stable wall %s PC: %.1f N/mm (goal >= 2 N/mm; CHAI3D defaults: "
               "0.4-1.0 Touch/Omni, 3 Falcon)\n", pc ? "with" : "without", (double)best);
    }
}

/* Runs 2 s of sculpting with the given tool on a wall window (the session's tick path), for
 * callgrind to count; prints nothing but a checksum so the work is not optimised away. */
static void tick_workload(const char *shape, int edge)
{
    rig_t *r = rig_new_mode(1.0f, true);
    r->rig.board.cfg.safety.overrun_streak = 0; /* under valgrind every tick overruns */
    const vec3_t tip = rig_tip_model(r);
    send_wall(r, tip.z - r->tool.radius_m - 0.001f, tip, edge);
    msg_tool_t t = rig_tool(r, TOOL_PUSH, 1.0f);
    t.yield_force_n = 0.2f;
    t.length_m = 0.008f;
    t.axis[0] = 1.0f;
    t.axis[2] = 0.0f;
    t.shape = strcmp(shape, "curve") == 0 ? TOOL_SHAPE_CURVE
              : strcmp(shape, "area") == 0 ? TOOL_SHAPE_AREA : TOOL_SHAPE_POINT;
    rig_set_tool(r, &t);
    if (rig_until_active(r, 1000) < 0) {
        fprintf(stderr, "bench: board did not become active\n");
        exit(1);
    }
    r->btn1 = true;
    rig_move(r, vec3_add(tip, vec3(0.003f, 0, -0.004f)), 1000);
    rig_move(r, vec3_add(tip, vec3(-0.003f, 0, -0.004f)), 1000);
    printf("%s %d: peak %.3f N, %u swaps, %u ticks\n", shape, edge,
           (double)r->rig.board.stats.peak_force_n, r->rig.board.stats.windows_swapped, r->rig.board.stats.ticks);
    rig_free(r);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "zwidth") == 0) {
        zwidth();
        return 0;
    }
    if (argc >= 4 && strcmp(argv[1], "tick") == 0) {
        tick_workload(argv[2], atoi(argv[3]));
        return 0;
    }
    fprintf(stderr, "usage: bench_haptics zwidth | tick point|curve|area 16|32\n");
    return 2;
}
