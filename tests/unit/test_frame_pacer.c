/* The live window's frame pacing: which frames start at once, which wait and how long, and a
 * simulated stroke in which the hold keeps routine frames from delaying the meshes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "host/render/frame_pacer.h"

#define MS 1000000ull

static void test_rules(void **state)
{
    (void)state;
    frame_pacer_cfg_t c;
    frame_pacer_cfg_default(&c);
    frame_pacer_t p;
    frame_pacer_init(&p);
    uint64_t due = 0;
    const frame_pacer_in_t none = {false, false, false, false};
    /* The first frame is due at once, with or without news. */
    assert_true(frame_pacer_due(&p, &c, &none, 5000 * MS, &due));
    assert_true(due == 5000 * MS);
    /* A frame from 5000 ms to 5010 ms. */
    frame_pacer_drawn(&p, 5000 * MS, 5010 * MS);
    /* Nothing new: the next at the idle period after the swap (4 Hz for the HUD). */
    assert_false(frame_pacer_due(&p, &c, &none, 5011 * MS, &due));
    assert_true(due == 5260 * MS);
    assert_true(frame_pacer_due(&p, &c, &none, 5260 * MS, &due));
    /* A new mesh, or input: at once, even right after the swap. */
    const frame_pacer_in_t mesh = {true, true, false, false};
    assert_true(frame_pacer_due(&p, &c, &mesh, 5010 * MS, &due));
    const frame_pacer_in_t input = {false, false, true, false};
    assert_true(frame_pacer_due(&p, &c, &input, 5010 * MS, &due));
    /* Another snapshot (the tool moved): a display period after the last start. */
    const frame_pacer_in_t snap = {true, false, false, false};
    assert_false(frame_pacer_due(&p, &c, &snap, 5012 * MS, &due));
    assert_true(due == 5000 * MS + 16666667u);
    /* ... and with a change on its way, up to 12 ms after the swap (22 ms > 16.7 ms). */
    const frame_pacer_in_t held = {true, false, false, true};
    assert_false(frame_pacer_due(&p, &c, &held, 5017 * MS, &due));
    assert_true(due == 5022 * MS);
    assert_true(frame_pacer_due(&p, &c, &held, 5022 * MS, &due));
    /* A hold never delays a frame past the display period's own due time when that is later. */
    frame_pacer_drawn(&p, 6000 * MS, 6002 * MS);
    assert_false(frame_pacer_due(&p, &c, &held, 6003 * MS, &due));
    assert_true(due == 6000 * MS + 16666667u);
}

typedef struct {
    int frames;
    double max_wait_ms, sum_wait_ms;
    int meshes;
} sim_result_t;

/* One simulated second: meshes published every mesh_period_ms (impulses in flight all the time
 * but the first 2 ms after each, as in a stroke), tool snapshots at 60 Hz, every frame taking
 * frame_ms; in 0.1 ms steps. Returns the wait of each mesh after the first 50 ms from its
 * publication to the start of the first frame that shows it. */
static sim_result_t simulate(uint64_t hold_ns, double frame_ms, double mesh_period_ms)
{
    frame_pacer_cfg_t c;
    frame_pacer_cfg_default(&c);
    c.hold_ns = hold_ns;
    frame_pacer_t p;
    frame_pacer_init(&p);
    sim_result_t r = {0, 0.0, 0.0, 0};
    const uint64_t step = 100000u, t0 = 1000 * MS, frame_ns = (uint64_t)(frame_ms * 1e6);
    uint64_t busy_until = 0, start = 0, next_snap = t0, next_mesh = t0 + 3 * MS;
    uint64_t pending_mesh = 0; /* publication time of the oldest mesh no frame has started on */
    bool undrawn = false, urgent = false, in_frame = false;
    for (uint64_t t = t0; t < t0 + 1000 * MS; t += step) {
        if (in_frame && t >= busy_until) {
            frame_pacer_drawn(&p, start, busy_until);
            in_frame = false;
        }
        if (mesh_period_ms > 0.0 && t >= next_mesh) {
            if (pending_mesh == 0)
                pending_mesh = next_mesh;
            undrawn = urgent = true;
            next_mesh += (uint64_t)(mesh_period_ms * 1e6);
        }
        if (t >= next_snap) {
            undrawn = true;
            next_snap += 16666667u;
        }
        const bool inflight =
            mesh_period_ms > 0.0 && (double)(next_mesh - t) <= (mesh_period_ms - 2.0) * 1e6;
        if (in_frame)
            continue;
        const frame_pacer_in_t in = {undrawn, urgent, false, inflight};
        uint64_t due;
        if (frame_pacer_due(&p, &c, &in, t, &due)) {
            if (pending_mesh != 0 && pending_mesh >= t0 + 50 * MS) {
                const double w = (double)(t - pending_mesh) * 1e-6;
                r.max_wait_ms = w > r.max_wait_ms ? w : r.max_wait_ms;
                r.sum_wait_ms += w;
                r.meshes++;
                pending_mesh = 0;
            }
            pending_mesh = 0;
            undrawn = urgent = false;
            start = t;
            busy_until = t + frame_ns;
            in_frame = true;
            r.frames++;
        }
    }
    return r;
}

static void test_stroke_simulated(void **state)
{
    (void)state;
    /* A stroke with a 20 ms solve step: a new mesh every 20 ms, frames that take 10 ms. With
     * the hold every mesh starts its frame at once; without it the routine frame (the tool) due
     * 16.7 ms after the last start is still drawing when the mesh comes, which waits 6.7 ms. */
    const sim_result_t held = simulate(12 * MS, 10.0, 20.0);
    const sim_result_t free_run = simulate(0, 10.0, 20.0);
    printf("stroke, 20 ms meshes, 10 ms frames: mesh wait max %.1f ms mean %.2f ms (%d meshes, %d frames) with "
           "the hold; max %.1f ms mean %.2f ms (%d, %d) without\n",
           held.max_wait_ms, held.sum_wait_ms / held.meshes, held.meshes, held.frames,
           free_run.max_wait_ms, free_run.sum_wait_ms / free_run.meshes, free_run.meshes,
           free_run.frames);
    assert_true(held.meshes >= 45);
    assert_true(held.max_wait_ms <= 0.11);
    assert_true(free_run.max_wait_ms >= 6.0);
    /* The 100 Hz solve with frames slower than the meshes (17 ms): every frame shows the newest
     * mesh, none waits longer than one frame, and the window still draws ~60 frames a second. */
    const sim_result_t slow = simulate(12 * MS, 17.0, 10.0);
    printf("stroke, 17 ms frames: mesh wait max %.1f ms mean %.2f ms, %d frames\n",
           slow.max_wait_ms, slow.sum_wait_ms / slow.meshes, slow.frames);
    assert_true(slow.max_wait_ms <= 17.1);
    assert_true(slow.frames >= 55);
    /* No stroke: tool snapshots at 60 Hz give 60 frames a second, not more. */
    const sim_result_t still = simulate(12 * MS, 8.0, 0.0);
    printf("no stroke: %d frames in 1 s\n", still.frames);
    assert_true(still.frames >= 58 && still.frames <= 61);
}

static void test_idle(void **state)
{
    (void)state;
    /* Nothing published: a frame every 250 ms for the HUD, so 4 or 5 in a second. */
    frame_pacer_cfg_t c;
    frame_pacer_cfg_default(&c);
    frame_pacer_t p;
    frame_pacer_init(&p);
    const frame_pacer_in_t none = {false, false, false, false};
    int frames = 0;
    for (uint64_t t = 1000 * MS; t < 2000 * MS; t += MS) {
        uint64_t due;
        if (frame_pacer_due(&p, &c, &none, t, &due)) {
            frame_pacer_drawn(&p, t, t + 5 * MS);
            frames++;
        } else {
            assert_true(due > t);
        }
    }
    assert_true(frames >= 4 && frames <= 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rules),
        cmocka_unit_test(test_stroke_simulated),
        cmocka_unit_test(test_idle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
