/* libFuzzer target: the scenario parser (sim/scenario.c) must refuse any input with a code, a
 * line and a message, never crash or read out of bounds; what it accepts must be in range. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sim/scenario.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static scenario_t s;
    scn_error_t err;
    const scn_err_t rc = scenario_parse(&s, (const char *)data, size, &err);
    if (rc != SCN_OK) {
        if (err.code != rc || err.line == 0 || err.msg[0] == '\0' ||
            memchr(err.msg, '\0', sizeof(err.msg)) == NULL)
            __builtin_trap();
        return 0;
    }
    if (s.duration_us <= 0 || s.duration_us > SCN_TIME_MAX_US || s.n_steps > SCN_STEPS_MAX ||
        s.n_expects > SCN_EXPECTS_MAX)
        __builtin_trap();
    int64_t prev = 0;
    for (uint32_t i = 0; i < s.n_steps; i++) {
        const scn_step_t *st = &s.step[i];
        if (st->t_us < prev || st->t_us > s.duration_us || (unsigned)st->action >= SCN_ACTION_COUNT ||
            st->ppm > 1000000u)
            __builtin_trap();
        if ((st->action == SCN_EMCY || st->action == SCN_HEARTBEAT ||
             st->action == SCN_ENCODER_JUMP) && (st->a < 1 || st->a > 3))
            __builtin_trap();
        prev = st->t_us;
    }
    for (uint32_t i = 0; i < s.n_expects; i++) {
        const int64_t until = scenario_until_us(&s, &s.expect[i]);
        if (until < s.expect[i].t_us && s.expect[i].until != SCN_UNTIL_NONE)
            __builtin_trap();
        if (until > s.duration_us)
            __builtin_trap();
    }
    return 0;
}
