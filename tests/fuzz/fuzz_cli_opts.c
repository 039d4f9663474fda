/* libFuzzer target for the option values argil sculpt and argil connect share (host/app/
 * cli_opts.h) and the host tool names connect parses (host/model/host_tool.h): arbitrary bytes as
 * each value. A value that parses must land inside its documented set. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/cli_opts.h"
#include "host/model/host_tool.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(int ok)
{
    if (!ok)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char s[256];
    const size_t n = size < sizeof(s) - 1 ? size : sizeof(s) - 1;
    memcpy(s, data, n);
    s[n] = '\0';
    peer_global_solve_t gs;
    if (cli_global_solve(s, &gs))
        check(gs == PEER_SOLVE_BSPLINE || gs == PEER_SOLVE_SPRINGS);
    int r = 0;
    if (cli_knot_ratio(s, &r))
        check(r == 1 || r == 2 || r == 4);
    uint32_t tick_us = 0;
    if (cli_rate_hz(s, &tick_us))
        check(tick_us == 1000u || tick_us == 500u || tick_us == 250u);
    float sec = 0.0f;
    if (cli_autosave_s(s, &sec))
        check(isfinite(sec) && sec >= 0.0009f && sec <= 3600.0f);
    const int a = host_action_from_name(s);
    check(a >= -1 && a < HOST_ACT_COUNT);
    if (a >= 0)
        check(strcmp(host_action_name((host_action_t)a), s) == 0);
    const int h = host_shape_from_name(s);
    check(h >= -1 && h < HOST_SHAPE_COUNT);
    const int m = host_mirror_from_name(s);
    check(m >= -1 && m <= (int)HOST_MIRROR_ALL);
    if (m >= 0) {
        char name[8];
        host_mirror_name((uint32_t)m, name);
        check(host_mirror_from_name(name) == m);
    }
    return 0;
}
