/* Undo and redo in the session (host/app/session_undo.h): after the field was set back, the
 * windows close and the grid's view, velocity, material and colour follow it. */
#include "host/solve/gsolve.h"

#include <stdlib.h>
#include <string.h>

#include "host/solve/gsolve_internal.h"

/* After an undo or redo: the windows close and the grid view follows the field. */
argil_err_t gsolve_restored(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                            int32_t glo[3], int32_t ghi[3])
{
    for (int a = 0; a < 3; a++)
        glo[a] = ghi[a] = 0;
    /* The window holds its own p and velocity: the next step reopens it from the field. */
    gsolve_close_window(gs);
    int32_t a0[3], a1[3];
    if (!grid_clip(g, lo, hi, a0, a1))
        return ARGIL_OK;
    if (gsolve_view_to_grid(gs, g, a0, a1) < 0.0f)
        return ARGIL_ERR_NOMEM;
    int32_t an[3];
    for (int a = 0; a < 3; a++)
        an[a] = a1[a] - a0[a];
    float *zero = calloc((size_t)an[0] * (size_t)an[1] * (size_t)an[2], sizeof(float));
    if (zero == NULL)
        return ARGIL_ERR_NOMEM;
    argil_err_t e = grid_write_box(g, GRID_VELOCITY, a0, an, zero);
    free(zero);
    if (e == ARGIL_OK)
        e = gsolve_material_to_grid(gs, g, a0, a1);
    if (e == ARGIL_OK)
        e = gsolve_colour_to_grid(gs, g, a0, a1);
    if (e != ARGIL_OK)
        return e;
    memcpy(glo, a0, sizeof(a0));
    memcpy(ghi, a1, sizeof(a1));
    return ARGIL_OK;
}
