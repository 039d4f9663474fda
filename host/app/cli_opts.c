/* Option values argil sculpt and argil connect share. */
#include "host/app/cli_opts.h"

#include <stdlib.h>
#include <string.h>

bool cli_global_solve(const char *v, peer_global_solve_t *out)
{
    if (!v || (strcmp(v, "bspline") != 0 && strcmp(v, "springs") != 0))
        return false;
    *out = v[0] == 'b' ? PEER_SOLVE_BSPLINE : PEER_SOLVE_SPRINGS;
    return true;
}

bool cli_knot_ratio(const char *v, int *out)
{
    if (!v || (strcmp(v, "1") != 0 && strcmp(v, "2") != 0 && strcmp(v, "4") != 0))
        return false;
    *out = v[0] - '0';
    return true;
}

bool cli_rate_hz(const char *v, uint32_t *tick_us)
{
    if (!v || (strcmp(v, "1000") != 0 && strcmp(v, "2000") != 0 && strcmp(v, "4000") != 0))
        return false;
    *tick_us = 1000000u / (uint32_t)atoi(v);
    return true;
}

bool cli_autosave_s(const char *v, float *out)
{
    char *end = NULL;
    const double sec = v ? strtod(v, &end) : 0.0;
    if (!v || end == v || *end != '\0' || !(sec >= 0.001 && sec <= 3600.0))
        return false;
    *out = (float)sec;
    return true;
}

const char *cli_global_solve_text(peer_global_solve_t gs)
{
    return gs == PEER_SOLVE_BSPLINE ? "B-spline model (implicit)" : "density springs (explicit)";
}
