/* Force mapping: contact from the density gradient, sculpting by Hua & Qin eq. 7. */
#include "haptics.h"

#include <math.h>

#define CARVE_DRAG_N_S_PER_M 4.0f   /* viscous feel of cutting through clay */
#define PULL_STIFFNESS_FRACTION 0.15f /* rope-like pull, as a share of the contact stiffness */

void haptics_init(haptics_t *h)
{
    h->prev_valid = false;
    h->prev_pos_m = vec3(0, 0, 0);
    h->grabbing = false;
    h->grab_pos_m = vec3(0, 0, 0);
    h->grab_density = 0.0f;
}

void haptics_reset_path(haptics_t *h)
{
    h->prev_valid = false;
}

/* Contact force of a sphere tool of radius r against the iso-surface: penetration estimated
 * from the density and its gradient, pushed out along the outward normal. */
static vec3_t contact_force(const window_buf_t *win, vec3_t p, float radius_m, float k,
                            bool *contact)
{
    float d;
    vec3_t g;
    *contact = false;
    if (!window_sample(win, p, &d, &g))
        return vec3(0, 0, 0);
    const float gn = vec3_norm(g);
    if (!(gn > 1e-6f))
        return vec3(0, 0, 0);
    const float inside_m = (d - win->iso) / gn; /* signed distance, positive inside */
    const float pen_m = inside_m + radius_m;
    if (pen_m <= 0.0f)
        return vec3(0, 0, 0);
    *contact = true;
    return vec3_scale(g, -k * pen_m / gn);
}

/* Spreads impulse j (N·s on the density axis) over the nodes within radius of p with a
 * Gaussian filter β (σ = radius/2). */
static void spread(window_buf_t *win, vec3_t p, float radius_m, float j, float dt_s,
                   float *impulse_ns)
{
    const float inv_h = 1.0f / win->spacing_m;
    int32_t lo[3], hi[3];
    const float c[3] = {(p.x - win->origin_m.x) * inv_h, (p.y - win->origin_m.y) * inv_h,
                        (p.z - win->origin_m.z) * inv_h};
    const float r_cells = radius_m * inv_h;
    for (int a = 0; a < 3; a++) {
        lo[a] = (int32_t)ceilf(c[a] - r_cells);
        hi[a] = (int32_t)floorf(c[a] + r_cells);
        if (lo[a] < 0) lo[a] = 0;
        if (hi[a] > win->dims[a] - 1) hi[a] = win->dims[a] - 1;
    }
    const float two_sigma2 = 2.0f * (0.5f * radius_m) * (0.5f * radius_m);
    const float r2 = radius_m * radius_m;
    for (int32_t z = lo[2]; z <= hi[2]; z++) {
        for (int32_t y = lo[1]; y <= hi[1]; y++) {
            for (int32_t x = lo[0]; x <= hi[0]; x++) {
                const vec3_t q = window_node_pos(win, x, y, z);
                const vec3_t dq = vec3_sub(q, p);
                const float dist2 = vec3_dot(dq, dq);
                if (dist2 > r2)
                    continue;
                const float beta = expf(-dist2 / two_sigma2);
                const int32_t i = window_index(win, x, y, z);
                impulse_ns[i] += j * beta;
                win->force[i] += j * beta / dt_s;
            }
        }
    }
}

void haptics_process(haptics_t *h, const msg_tool_t *tool, window_buf_t *win, vec3_t pos_m,
                     vec3_t vel_m_s, bool button, bool sculpt_allowed, float dt_s,
                     float *impulse_ns, haptics_out_t *out)
{
    out->force_n = vec3(0, 0, 0);
    out->contact = false;
    out->sculpting = false;
    if (!win) {
        h->prev_valid = false;
        h->grabbing = false;
        return;
    }
    const vec3_t prev = h->prev_valid ? h->prev_pos_m : pos_m;
    h->prev_pos_m = pos_m;
    h->prev_valid = true;

    const bool sculpt_tool = tool->kind == TOOL_PUSH || tool->kind == TOOL_PULL;
    const bool hold = button && sculpt_allowed;
    if (hold && !h->grabbing) {
        float d;
        vec3_t g;
        h->grab_pos_m = pos_m;
        h->grab_density = window_sample(win, pos_m, &d, &g) ? d : 0.0f;
        if (h->grab_density < win->iso)
            h->grab_density = win->iso;
    }
    h->grabbing = hold;

    if (tool->kind == TOOL_CARVE && hold) {
        /* The host removes the material; the hand feels a drag proportional to the density. */
        float d;
        vec3_t g;
        if (window_sample(win, pos_m, &d, &g))
            out->force_n = vec3_scale(vel_m_s, -CARVE_DRAG_N_S_PER_M * d);
        return;
    }
    if (tool->kind == TOOL_PULL && hold) {
        /* Pulling clay out: raise density along the path with the grabbed density, and feel a
         * rope-like spring back to the grab point. */
        const float l = vec3_norm(vec3_sub(pos_m, prev));
        const float j = tool->alpha * l * h->grab_density; /* Hua & Qin eq. 7, positive */
        if (j > 0.0f)
            spread(win, pos_m, tool->radius_m, j, dt_s, impulse_ns);
        out->force_n = vec3_scale(vec3_sub(pos_m, h->grab_pos_m),
                                  -PULL_STIFFNESS_FRACTION * tool->contact_stiffness_n_per_m);
        out->sculpting = true;
        return;
    }

    out->force_n = contact_force(win, pos_m, tool->radius_m, tool->contact_stiffness_n_per_m,
                                 &out->contact);
    if (tool->kind == TOOL_PUSH && hold && sculpt_tool) {
        /* Pushing in: lower the density along the path by the density met on it. */
        const vec3_t mid = vec3_scale(vec3_add(prev, pos_m), 0.5f);
        float s;
        vec3_t g;
        if (window_sample(win, mid, &s, &g)) {
            const float l = vec3_norm(vec3_sub(pos_m, prev));
            const float j = -tool->alpha * l * s; /* Hua & Qin eq. 7 */
            if (j < 0.0f)
                spread(win, pos_m, tool->radius_m, j, dt_s, impulse_ns);
            out->sculpting = true;
        }
    }
}
