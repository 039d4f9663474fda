/* Force mapping on the local window (Hua & Qin §5.2): what the hand feels and how the tool's
 * motion turns into forces on the window's density springs. Model space throughout; the
 * device-to-model transform is a uniform scale, so force directions carry over unchanged. */
#ifndef ARGIL_HAPTICS_H
#define ARGIL_HAPTICS_H

#include <stdbool.h>

#include "shared/proto.h"
#include "shared/vec3.h"
#include "window.h"

typedef struct {
    bool prev_valid;
    vec3_t prev_pos_m;
    bool grabbing;             /* button held with a sculpting tool */
    vec3_t grab_pos_m;         /* reference point where the button went down */
    float grab_density;
} haptics_t;

typedef struct {
    vec3_t force_n;            /* on the hand, before safety limits */
    bool contact;
    bool sculpting;
} haptics_out_t;

void haptics_init(haptics_t *h);

/* Forgets the tool's path (after a window swap or a fault), so no stroke spans the gap. */
void haptics_reset_path(haptics_t *h);

/* One tick: contact force from the window's trilinear gradient, and, while the button is held
 * and sculpt_allowed, the sculpting force f = -α ∫C s dc along this tick's path (Hua & Qin
 * eq. 7) spread over the nodes near the tool by a Gaussian filter β. The node impulses are
 * added to impulse_ns (one per window sample) and the node forces to win->force. */
void haptics_process(haptics_t *h, const msg_tool_t *tool, window_buf_t *win, vec3_t pos_m,
                     vec3_t vel_m_s, bool button, bool sculpt_allowed, float dt_s,
                     float *impulse_ns, haptics_out_t *out);

#endif
