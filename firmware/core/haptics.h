/* Force mapping on the local window: what the hand feels and how the tool's motion becomes
 * forces on the window's density springs. Sources: Hua & Qin §5.2 and §6.1 (eq. 7, the β
 * filter, point/curve/area tools, iso-surface rendering, probing), Guo et al. (gradient +
 * virtual contact point, friction by limiting its motion), McDonnell et al. §7.1 (rope).
 * Model space throughout; the device-to-model transform is a uniform scale, so force
 * directions carry over unchanged. */
#ifndef ARGIL_HAPTICS_H
#define ARGIL_HAPTICS_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/proto.h"
#include "shared/vec3.h"
#include "window.h"

#define HAPTICS_CURVE_SAMPLES_MAX 17   /* paths along a curve tool */
#define HAPTICS_AREA_SAMPLES_MAX 9     /* paths per side of an area tool */
#define HAPTICS_MARCH_STEPS 64         /* cell steps searching the surface along the normal */
#define HAPTICS_BISECT_STEPS 6         /* then bisections: 1/64 of a cell (0.02 mm at 1.25 mm) */

typedef struct {
    bool prev_valid;
    vec3_t prev_pos_m;
    bool in_contact;
    vec3_t vcp_m;              /* virtual contact point: where the tool centre rests on the surface */
    bool grabbing;             /* button held with pull or rope */
    bool pushing;              /* button held with push (the clay may flow) */
    bool let_go;               /* a pull or rope let go: the next contact starts embedded */
    float embedded_m;          /* how deep the tool sat in the clay when it let go; contact
                                  counts only the penetration beyond it, and it shrinks as the
                                  tool comes out, so the bump it raised does not throw it */
    vec3_t grab_pos_m;         /* reference point where the button went down */
    float grab_density;
} haptics_t;

typedef struct {
    vec3_t force_n;            /* on the hand, before the board's limits */
    float potential_j;         /* energy stored in the virtual spring being rendered */
    bool contact;
    bool sculpting;            /* forces went to the density springs this tick */
    bool yielding;             /* push: the contact force reached the yield force */
    vec3_t work_m;             /* where the sculpting forces went (centre of the nodes touched) */
    float work_radius_m;       /* … and how far from there */
    int32_t touched_lo[3];     /* node box [lo, hi] that received impulses this tick; */
    int32_t touched_hi[3];     /* … empty when lo > hi on any axis */
    bool hold_edge;            /* the button went down or up this tick with a tool whose force
                                  law it changes (push: the contact slides freely while the
                                  clay may flow; pull, rope: the spring to the grab point), so
                                  the force may step */
} haptics_out_t;

void haptics_init(haptics_t *h);

/* Forgets the tool's path and contact (after a window swap or a fault), so no stroke spans
 * the gap. */
void haptics_reset_path(haptics_t *h);

/* Signed distance (m, positive inside) from p to the iso-surface along the field's gradient
 * line, searched up to reach_m (beyond it: ±reach), and the outward normal; false when p is
 * outside the window or the field is flat at p. */
bool haptics_surface_distance(const window_buf_t *win, vec3_t p_m, float iso, float reach_m,
                              float *dist_m, vec3_t *normal);

/* β(d) for a node at distance d from a path, support radius r (0 beyond r). */
float haptics_beta(beta_filter_t filter, float dist_m, float radius_m);

/* One tick of the tool against the window. While the button is held and sculpt_allowed,
 * sculpting forces go to win->force and their impulses (N·s) to impulse_ns (one per node). */
void haptics_process(haptics_t *h, const msg_tool_t *tool, window_buf_t *win, vec3_t pos_m,
                     vec3_t vel_m_s, bool button, bool sculpt_allowed, float dt_s,
                     float *impulse_ns, haptics_out_t *out);

#endif
