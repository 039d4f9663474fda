/* libFuzzer target: the log checker's readers (sim/hil_check.c) — candump -l lines and
 * argil-sim event logs — must refuse any input with a reason and a line, never crash; what they
 * accept is checked against a small scenario without crashing either. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sim/hil_check.h"
#include "sim/scenario.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static scenario_t s;
    static bool ready;
    if (!ready) {
        static const char text[] = "name fz\nduration 3s\nat 1.0 estop press\nat 2.0 rearm\n"
                                   "expect at 1.0 torque_zero within 1ms\n"
                                   "expect at 1.0 quick_stop within 1ms\n"
                                   "expect at 1.0 fault within 2ms\n"
                                   "expect at 1.0 no_torque_frames until rearm\n"
                                   "expect at 0.5 running until 0.9\n"
                                   "expect at 1.0 safe until end\n"
                                   "expect at 2.0 enabled within 300ms\n"
                                   "expect at 0.0 torque_nonzero within 1s\n";
        scn_error_t err;
        if (scenario_parse(&s, text, sizeof(text) - 1, &err) != SCN_OK)
            __builtin_trap();
        ready = true;
    }
    int64_t t;
    can_frame_t f;
    if (hil_candump_line((const char *)data, size, &t, &f) == HIL_OK && f.len > 8u)
        __builtin_trap();
    /* The first half as a candump log, the second as an event log. */
    const size_t half = size / 2u;
    hil_obs_t o;
    hil_obs_init(&o);
    uint32_t line = 0;
    hil_err_t e = hil_obs_add_candump(&o, (const char *)data, half, &line);
    if (e != HIL_OK && line == 0)
        __builtin_trap();
    e = hil_obs_add_events(&o, &s, (const char *)data + half, size - half, &line);
    if (e == HIL_OK) {
        for (uint32_t i = 0; i < s.n_expects; i++) {
            hil_result_t r;
            hil_check_expect(&s, &o, i, &r);
            if (memchr(r.msg, '\0', sizeof(r.msg)) == NULL)
                __builtin_trap();
        }
    }
    hil_obs_free(&o);
    return 0;
}
