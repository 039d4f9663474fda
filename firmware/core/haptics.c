/* Force mapping: contact through a virtual contact point, sculpting by Hua & Qin eq. 7. */
#include "haptics.h"

#include <math.h>

#define CARVE_DRAG_N_S_PER_M 4.0f     /* viscous feel of cutting through clay */
#define PULL_STIFFNESS_FRACTION 0.15f /* pull tool: spring to the grab point, share of contact k */

void haptics_init(haptics_t *h)
{
    h->prev_valid = false;
    h->prev_pos_m = vec3(0, 0, 0);
    h->in_contact = false;
    h->vcp_m = vec3(0, 0, 0);
    h->grabbing = false;
    h->pushing = false;
    h->let_go = false;
    h->embedded_m = 0.0f;
    h->grab_pos_m = vec3(0, 0, 0);
    h->grab_density = 0.0f;
}

void haptics_reset_path(haptics_t *h)
{
    h->prev_valid = false;
    h->in_contact = false;
}

/* Where the field crosses iso inside the bracket [t_a, t_b] whose ends hold f_a = d - iso on one
 * side and f_b on the other (or 0): the linear interpolant's zero, so the crossing moves
 * continuously with the densities. The bisection midpoint alone jumps by half a bracket (1/128
 * of a cell) when a density change of ~1e-6 flips one comparison, and the force with it; such
 * steps made two runs differing only by round-off end up to 0.8 mm apart (docs/haptics.md). */
static float bracket_crossing(float t_a, float f_a, float t_b, float f_b)
{
    const float df = f_a - f_b;
    if (!(df != 0.0f))
        return 0.5f * (t_a + t_b);
    float w = f_a / df;                  /* 0 at t_a, 1 at t_b */
    w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
    return t_a + w * (t_b - t_a);
}

bool haptics_surface_distance(const window_buf_t *win, vec3_t p_m, float iso, float reach_m,
                              float *dist_m, vec3_t *normal)
{
    float d;
    vec3_t g;
    if (!window_sample(win, p_m, &d, &g))
        return false;
    const float gn = vec3_norm(g);
    if (!(gn > 1e-6f))
        return false;
    /* Along the gradient line through p (Guo et al.'s contact point along the force direction):
     * march a cell at a time towards the surface — outward when p is inside, inward when
     * outside — until the density crosses iso, then bisect within that step. */
    const vec3_t n = vec3_scale(g, -1.0f / gn);
    const float f0 = d - iso;
    const float dir = f0 > 0.0f ? 1.0f : -1.0f;
    const float step = win->spacing_m;
    int steps = (int)ceilf(reach_m / step);
    if (steps > HAPTICS_MARCH_STEPS)
        steps = HAPTICS_MARCH_STEPS;
    float t_in = 0.0f, t_out = -1.0f, f_in = f0, f_out = 0.0f;
    for (int k = 1; k <= steps; k++) {
        const float t = dir * step * (float)k;
        float dk;
        if (!window_density(win, vec3_add(p_m, vec3_scale(n, t)), &dk))
            break;
        if ((dk - iso) * f0 <= 0.0f) {
            t_out = t;
            f_out = dk - iso;
            break;
        }
        t_in = t;
        f_in = dk - iso;
    }
    *normal = n;
    if (t_out == -1.0f) {
        /* No surface within reach: deep inside counts as the reach, outside as beyond it. */
        *dist_m = dir * (float)steps * step;
        return true;
    }
    for (int k = 0; k < HAPTICS_BISECT_STEPS; k++) {
        const float t = 0.5f * (t_in + t_out);
        float dk;
        if (!window_density(win, vec3_add(p_m, vec3_scale(n, t)), &dk))
            break;
        if ((dk - iso) * f0 > 0.0f) {
            t_in = t;
            f_in = dk - iso;
        } else {
            t_out = t;
            f_out = dk - iso;
        }
    }
    *dist_m = bracket_crossing(t_in, f_in, t_out, f_out);
    return isfinite(*dist_m);
}

float haptics_beta(beta_filter_t filter, float dist_m, float radius_m)
{
    if (!(dist_m < radius_m) || !(radius_m > 0.0f))
        return 0.0f;
    const float u = dist_m / radius_m;
    switch (filter) {
    case BETA_CONSTANT: return 1.0f;
    case BETA_GAUSSIAN: return expf(-2.0f * u * u); /* σ = radius / 2 */
    case BETA_SPHERICAL: return sqrtf(1.0f - u * u);
    case BETA_CYLINDRICAL: return 1.0f;             /* distance is measured to the path line */
    case BETA_CONICAL: return 1.0f - u;
    }
    return 0.0f;
}

/* Squared shortest distance from q to the segment [a, b]; with cylindrical β, to its
 * infinite line. */
static float segment_distance2(vec3_t q, vec3_t a, vec3_t b, bool line)
{
    const vec3_t ab = vec3_sub(b, a);
    const float len2 = vec3_dot(ab, ab);
    float t = len2 > 0.0f ? vec3_dot(vec3_sub(q, a), ab) / len2 : 0.0f;
    if (!line) {
        if (t < 0.0f) t = 0.0f;
        if (t > 1.0f) t = 1.0f;
    }
    const vec3_t d = vec3_sub(q, vec3_add(a, vec3_scale(ab, t)));
    return vec3_dot(d, d);
}

/* Distance from v to the interval [lo, hi] (0 inside). */
static inline float box_gap(float v, float lo, float hi)
{
    return v < lo ? lo - v : (v > hi ? v - hi : 0.0f);
}

/* Grows the box of nodes that received impulses this tick by [lo, hi]. */
static void touch_box(haptics_out_t *out, const int32_t lo[3], const int32_t hi[3])
{
    for (int k = 0; k < 3; k++) {
        if (lo[k] < out->touched_lo[k])
            out->touched_lo[k] = lo[k];
        if (hi[k] > out->touched_hi[k])
            out->touched_hi[k] = hi[k];
    }
}

/* Spreads impulse j (N·s on the density axis) over the nodes within radius of the segment
 * [a, b] with the filter β (for a short path: the corners of the cells it crosses, and their
 * neighbours when the radius is larger than a cell). Returns true when any node received it. */
static bool spread_segment(window_buf_t *win, beta_filter_t filter, vec3_t a, vec3_t b,
                           float radius_m, float j, float dt_s, float *impulse_ns,
                           haptics_out_t *out)
{
    if (!(j != 0.0f) || !isfinite(j))
        return false;
    const float inv_h = 1.0f / win->spacing_m;
    /* At least √3 cells, so the 8 corners of every cell the path crosses are reached. */
    const float r_min = 1.7321f * win->spacing_m;
    const float r = radius_m > r_min ? radius_m : r_min;
    const float lo_p[3] = {fminf(a.x, b.x) - r, fminf(a.y, b.y) - r, fminf(a.z, b.z) - r};
    const float hi_p[3] = {fmaxf(a.x, b.x) + r, fmaxf(a.y, b.y) + r, fmaxf(a.z, b.z) + r};
    const float org[3] = {win->origin_m.x, win->origin_m.y, win->origin_m.z};
    int32_t lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = (int32_t)ceilf((lo_p[k] - org[k]) * inv_h);
        hi[k] = (int32_t)floorf((hi_p[k] - org[k]) * inv_h);
        if (lo[k] < 0) lo[k] = 0;
        if (hi[k] > win->dims[k] - 1) hi[k] = win->dims[k] - 1;
    }
    const bool line = filter == BETA_CYLINDRICAL && vec3_norm(vec3_sub(b, a)) > 1e-9f;
    /* Nodes whose squared distance is beyond this are outside β's support (sqrt(d²) ≥ r even
     * after rounding): skipped before the square root and β. */
    const float cull2 = r * r * 1.0001f;
    /* A node is at least as far from the segment as from the segment's bounding box: rows and
     * nodes whose distance to that box is beyond the support are skipped before the exact
     * distance (not for the cylindrical filter's infinite line). */
    const float box_lo[3] = {fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)};
    const float box_hi[3] = {fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)};
    bool any = false;
    for (int32_t z = lo[2]; z <= hi[2]; z++) {
        for (int32_t y = lo[1]; y <= hi[1]; y++) {
            const vec3_t row = window_node_pos(win, 0, y, z);
            const float dy = box_gap(row.y, box_lo[1], box_hi[1]);
            const float dz = box_gap(row.z, box_lo[2], box_hi[2]);
            const float dyz2 = dy * dy + dz * dz;
            if (!line && !(dyz2 < cull2))
                continue;
            for (int32_t x = lo[0]; x <= hi[0]; x++) {
                const vec3_t q = window_node_pos(win, x, y, z);
                const float dx = box_gap(q.x, box_lo[0], box_hi[0]);
                if (!line && !(dx * dx + dyz2 < cull2))
                    continue;
                const float d2 = segment_distance2(q, a, b, line);
                if (!(d2 < cull2))
                    continue;
                const float beta = haptics_beta(filter, sqrtf(d2), r);
                if (beta <= 0.0f)
                    continue;
                const int32_t i = window_index(win, x, y, z);
                impulse_ns[i] += j * beta;
                win->force[i] += j * beta / dt_s;
                any = true;
            }
        }
    }
    if (any)
        touch_box(out, lo, hi);
    return any;
}

/* Hua & Qin eq. 7 for one path a → b: f = sign · α · l · s, spread by β. */
static bool apply_path(window_buf_t *win, const msg_tool_t *tool, vec3_t a, vec3_t b, float s,
                       float sign, float radius_m, float dt_s, float *impulse_ns,
                       haptics_out_t *out)
{
    const float l = vec3_norm(vec3_sub(b, a));
    return spread_segment(win, (beta_filter_t)tool->filter, a, b, radius_m,
                          sign * tool->alpha * l * s, dt_s, impulse_ns, out);
}

/* How far from its reference point a tool's paths and their β reach. */
static float tool_reach(const msg_tool_t *tool, const window_buf_t *win)
{
    const float r_min = 1.7321f * win->spacing_m;
    const float r = tool->radius_m > r_min ? tool->radius_m : r_min;
    if (tool->shape == TOOL_SHAPE_POINT)
        return r;
    /* Half the diagonal of the curve or square, plus a sample spacing of β. */
    const float half = tool->shape == TOOL_SHAPE_AREA ? 0.7072f * tool->length_m : 0.5f * tool->length_m;
    return half + (r > win->spacing_m ? r : win->spacing_m) + win->spacing_m;
}

/* The paths a tool's shape sweeps this tick, each applied with eq. 7. s < 0 means "use the
 * density met at each path's midpoint". */
static bool apply_tool_paths(window_buf_t *win, const msg_tool_t *tool, vec3_t from, vec3_t to,
                             float s_fixed, float sign, float dt_s, float *impulse_ns,
                             haptics_out_t *out)
{
    vec3_t u = vec3(tool->axis[0], tool->axis[1], tool->axis[2]);
    int nu = 1, nv = 1;
    float step = 0.0f;
    vec3_t e1 = vec3(0, 0, 0), e2 = vec3(0, 0, 0);
    float radius = tool->radius_m;
    if (tool->shape != TOOL_SHAPE_POINT && tool->length_m > 0.0f) {
        const int max = tool->shape == TOOL_SHAPE_CURVE ? HAPTICS_CURVE_SAMPLES_MAX
                                                        : HAPTICS_AREA_SAMPLES_MAX;
        int k = (int)ceilf(tool->length_m / win->spacing_m) + 1;
        if (k > max) k = max;
        if (k < 2) k = 2;
        step = tool->length_m / (float)(k - 1);
        radius = step > win->spacing_m ? step : win->spacing_m;
        if (tool->shape == TOOL_SHAPE_CURVE) {
            nu = k;
            e1 = u;
        } else {
            nu = nv = k;
            /* Two unit vectors spanning the plane normal to the axis. */
            const vec3_t helper = fabsf(u.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0);
            e1 = vec3_cross(u, helper);
            e1 = vec3_scale(e1, 1.0f / vec3_norm(e1));
            e2 = vec3_cross(u, e1);
        }
    }
    bool any = false;
    for (int i = 0; i < nu; i++) {
        for (int j = 0; j < nv; j++) {
            const float ou = nu > 1 ? ((float)i - 0.5f * (float)(nu - 1)) * step : 0.0f;
            const float ov = nv > 1 ? ((float)j - 0.5f * (float)(nv - 1)) * step : 0.0f;
            const vec3_t off = vec3_add(vec3_scale(e1, ou), vec3_scale(e2, ov));
            const vec3_t a = vec3_add(from, off), b = vec3_add(to, off);
            float s = s_fixed;
            if (s < 0.0f) {
                if (!window_density(win, vec3_scale(vec3_add(a, b), 0.5f), &s))
                    continue;
            }
            any |= apply_path(win, tool, a, b, s, sign, radius, dt_s, impulse_ns, out);
        }
    }
    return any;
}

/* How far along u from p the field first reaches iso (the tool's surface meets the clay), up
 * to reach; reach when it does not. */
static float first_crossing(const window_buf_t *win, vec3_t p, vec3_t u, float iso, float reach,
                            float f_start)
{
    const float step = win->spacing_m;
    int steps = (int)ceilf(reach / step);
    if (steps > HAPTICS_MARCH_STEPS)
        steps = HAPTICS_MARCH_STEPS;
    float t_out = 0.0f, f_out = f_start;
    for (int k = 1; k <= steps; k++) {
        const float t = k == steps ? reach : step * (float)k;
        float d;
        if (!window_density(win, vec3_add(p, vec3_scale(u, t)), &d))
            return reach;
        if (d >= iso) {
            float t_in = t, f_in = d - iso;
            for (int b = 0; b < HAPTICS_BISECT_STEPS; b++) {
                const float m = 0.5f * (t_in + t_out);
                if (!window_density(win, vec3_add(p, vec3_scale(u, m)), &d))
                    break;
                if (d >= iso) {
                    t_in = m;
                    f_in = d - iso;
                } else {
                    t_out = m;
                    f_out = d - iso;
                }
            }
            return bracket_crossing(t_in, f_in, t_out, f_out);
        }
        t_out = t;
        f_out = d - iso;
    }
    return reach;
}

/* Penetration of a sphere tool of radius r into the clay and the direction to push it out,
 * from rays along 14 directions (axes and diagonals): the penetration-weighted rays give the
 * direction n, and the depth is the deepest ray's scaled by how much the rays agree,
 * |Σ u·pen| / Σ pen·|u·n|. A tool in a dent feels its floor and walls, where a single
 * gradient at the centre would be ambiguous; and in a bore its own size the walls on either side cancel, so a
 * sideways shift δ is felt as about K·δ instead of flipping the full force from one wall to
 * the other (the 55 Hz buzz of the default session's push). Continuous in the tool's position
 * while its centre is outside the clay. False when nothing penetrates. */
static bool sphere_penetration(const window_buf_t *win, vec3_t p, float r, float iso,
                               float *pen_m, vec3_t *normal)
{
    static const float D = 0.57735027f;
    static const float DIRS[14][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1},
                                      {0, 0, -1}, {D, D, D}, {D, D, -D}, {D, -D, D},
                                      {D, -D, -D}, {-D, D, D}, {-D, D, -D}, {-D, -D, D},
                                      {-D, -D, -D}};
    float d0;
    if (!window_density(win, p, &d0))
        return false;
    if (d0 >= iso) {
        /* The centre itself is in the clay: fall back to the gradient line. */
        float dist;
        if (!haptics_surface_distance(win, p, iso, r + 4.0f * win->spacing_m, &dist, normal))
            return false;
        *pen_m = dist + r;
        return *pen_m > 0.0f;
    }
    float best = 0.0f, pens[14];
    vec3_t dir = vec3(0, 0, 0);
    for (int k = 0; k < 14; k++) {
        const vec3_t u = vec3(DIRS[k][0], DIRS[k][1], DIRS[k][2]);
        pens[k] = r - first_crossing(win, p, u, iso, r, d0 - iso);
        if (pens[k] <= 0.0f)
            continue;
        dir = vec3_sub(dir, vec3_scale(u, pens[k]));
        if (pens[k] > best)
            best = pens[k];
    }
    const float dn = vec3_norm(dir);
    if (!(best > 0.0f) || !(dn > 0.0f))
        return false;
    const vec3_t n = vec3_scale(dir, 1.0f / dn);
    /* How much the rays agree: |Σ u·pen| over Σ pen·|u·n|. 1 when every ray meets clay on the
     * same side (a floor, a wall, a cup: the deepest ray's depth as it is), less when walls face
     * each other, 0 in a bore whose walls balance. */
    float spread = 0.0f;
    for (int k = 0; k < 14; k++)
        if (pens[k] > 0.0f)
            spread += pens[k] * fabsf(vec3_dot(vec3(DIRS[k][0], DIRS[k][1], DIRS[k][2]), n));
    *pen_m = spread > 0.0f ? best * fminf(1.0f, dn / spread) : 0.0f;
    *normal = n;
    return *pen_m > 0.0f;
}

/* Contact of the tool sphere with the iso-surface, through a virtual contact point whose
 * sliding is limited by Coulomb friction. */
static vec3_t contact_force(haptics_t *h, const msg_tool_t *tool, const window_buf_t *win,
                            vec3_t p, float friction, float *potential_j, bool *contact)
{
    *contact = false;
    *potential_j = 0.0f;
    const float iso = (tool->flags & TOOL_FLAG_ISO) ? tool->iso : win->iso;
    float pen;
    vec3_t n;
    bool hit;
    if (tool->radius_m > win->spacing_m) {
        hit = sphere_penetration(win, p, tool->radius_m, iso, &pen, &n);
    } else {
        /* A small tool: the gradient line through its centre (Guo et al.). */
        float dist;
        hit = haptics_surface_distance(win, p, iso, tool->radius_m + 4.0f * win->spacing_m,
                                       &dist, &n);
        pen = dist + tool->radius_m;
        hit = hit && pen > 0.0f;
    }
    if (!hit) {
        h->in_contact = false;
        h->let_go = false;
        h->embedded_m = 0.0f;
        return vec3(0, 0, 0);
    }
    /* Let go inside the clay a pull raised around the tool: that depth is where contact
     * starts, and coming out lowers it. */
    if (h->let_go) {
        h->embedded_m = pen;
        h->let_go = false;
    }
    h->embedded_m = fminf(h->embedded_m, pen);
    pen -= h->embedded_m;
    if (!(pen > 0.0f)) {
        h->in_contact = false;
        return vec3(0, 0, 0);
    }
    vec3_t vcp = vec3_add(p, vec3_scale(n, pen));
    if (h->in_contact && friction > 0.0f) {
        /* Stick while the old contact point's tangential offset is within μ·pen, else slide
         * to the edge of that cone (Guo et al.: friction by limiting the VCP's motion). */
        vec3_t off = vec3_sub(h->vcp_m, vcp);
        off = vec3_sub(off, vec3_scale(n, vec3_dot(off, n)));
        const float lim = friction * pen;
        const float ol = vec3_norm(off);
        vcp = vec3_add(vcp, ol > lim && ol > 0.0f ? vec3_scale(off, lim / ol) : off);
    }
    h->vcp_m = vcp;
    h->in_contact = true;
    *contact = true;
    const vec3_t stretch = vec3_sub(vcp, p);
    *potential_j = 0.5f * tool->contact_stiffness_n_per_m * vec3_dot(stretch, stretch);
    return vec3_scale(stretch, tool->contact_stiffness_n_per_m);
}

/* Probing (Hua & Qin §6.1): viscous force ∝ the local spring stiffness, each node weighted
 * by 1 − d/R within radius R. */
static vec3_t probe_force(const msg_tool_t *tool, const window_buf_t *win, vec3_t p, vec3_t v)
{
    const float r = tool->radius_m;
    const float inv_h = 1.0f / win->spacing_m;
    const float c[3] = {(p.x - win->origin_m.x) * inv_h, (p.y - win->origin_m.y) * inv_h,
                        (p.z - win->origin_m.z) * inv_h};
    int32_t lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = (int32_t)ceilf(c[k] - r * inv_h);
        hi[k] = (int32_t)floorf(c[k] + r * inv_h);
        if (lo[k] < 0) lo[k] = 0;
        if (hi[k] > win->dims[k] - 1) hi[k] = win->dims[k] - 1;
    }
    float wsum = 0.0f, ksum = 0.0f;
    for (int32_t z = lo[2]; z <= hi[2]; z++)
        for (int32_t y = lo[1]; y <= hi[1]; y++)
            for (int32_t x = lo[0]; x <= hi[0]; x++) {
                const float d = vec3_norm(vec3_sub(window_node_pos(win, x, y, z), p));
                const float w = haptics_beta(BETA_CONICAL, d, r);
                if (w <= 0.0f)
                    continue;
                const int32_t i = window_index(win, x, y, z);
                /* Only material counts: a spring in empty space is not felt. */
                const float m = win->density[i] > win->iso ? 1.0f : win->density[i] / win->iso;
                wsum += w;
                ksum += w * m * window_node_stiffness(win, i);
            }
    if (!(wsum > 0.0f))
        return vec3(0, 0, 0);
    return vec3_scale(v, -tool->probe_gain * ksum / wsum);
}

void haptics_process(haptics_t *h, const msg_tool_t *tool, window_buf_t *win, vec3_t pos_m,
                     vec3_t vel_m_s, bool button, bool sculpt_allowed, float dt_s,
                     float *impulse_ns, haptics_out_t *out)
{
    out->force_n = vec3(0, 0, 0);
    out->potential_j = 0.0f;
    out->contact = false;
    out->sculpting = false;
    out->yielding = false;
    out->hold_edge = false;
    out->work_m = pos_m;
    out->work_radius_m = 0.0f;
    for (int k = 0; k < 3; k++) {
        out->touched_lo[k] = INT32_MAX;
        out->touched_hi[k] = -1;
    }
    if (!win) {
        h->prev_valid = false;
        h->grabbing = false;
    h->pushing = false;
        h->in_contact = false;
        return;
    }
    const vec3_t prev = h->prev_valid ? h->prev_pos_m : pos_m;
    h->prev_pos_m = pos_m;
    h->prev_valid = true;

    const bool hold = button && sculpt_allowed;
    if (hold && !h->grabbing) {
        float d;
        h->grab_pos_m = pos_m;
        h->grab_density = window_density(win, pos_m, &d) ? d : 0.0f;
        if (h->grab_density < win->iso)
            h->grab_density = win->iso;
    }
    const bool grabbing = hold && (tool->kind == TOOL_PULL || tool->kind == TOOL_ROPE);
    const bool pushing = tool->kind == TOOL_PUSH && hold;
    out->hold_edge = h->grabbing != grabbing || h->pushing != pushing;
    if (h->grabbing && !grabbing)
        h->let_go = true;
    h->grabbing = grabbing;
    h->pushing = pushing;

    switch (tool->kind) {
    case TOOL_CARVE:
        if (hold) {
            /* The host removes the material; the hand feels a drag proportional to density. */
            float d;
            if (window_density(win, pos_m, &d))
                out->force_n = vec3_scale(vel_m_s, -CARVE_DRAG_N_S_PER_M * d);
            h->in_contact = false;
            return;
        }
        break;
    case TOOL_PULL:
        if (hold) {
            /* Raise density along the path with the grabbed density (eq. 7, positive); feel a
             * spring back to the grab point. */
            out->sculpting = apply_tool_paths(win, tool, prev, pos_m, h->grab_density, 1.0f,
                                              dt_s, impulse_ns, out);
            out->work_m = pos_m;
            out->work_radius_m = tool_reach(tool, win);
            const vec3_t s = vec3_sub(pos_m, h->grab_pos_m);
            const float k = PULL_STIFFNESS_FRACTION * tool->contact_stiffness_n_per_m;
            out->force_n = vec3_scale(s, -k);
            out->potential_j = 0.5f * k * vec3_dot(s, s);
            h->in_contact = false;
            return;
        }
        break;
    case TOOL_ROPE:
        if (hold) {
            /* A rope from the grab point: the hand feels the spring, and the grabbed nodes
             * (spread by β) are drawn with the spring's tension. */
            const vec3_t s = vec3_sub(pos_m, h->grab_pos_m);
            const float k = tool->rope_stiffness_n_per_m;
            const float tension_n = k * vec3_norm(s);
            out->force_n = vec3_scale(s, -k);
            out->potential_j = 0.5f * k * vec3_dot(s, s);
            out->sculpting = spread_segment(win, (beta_filter_t)tool->filter, h->grab_pos_m,
                                            h->grab_pos_m, tool->radius_m, tension_n * dt_s, dt_s,
                                            impulse_ns, out);
            out->work_m = h->grab_pos_m;
            out->work_radius_m = tool->radius_m;
            h->in_contact = false;
            return;
        }
        break;
    case TOOL_PROBE:
        out->force_n = probe_force(tool, win, pos_m, vel_m_s);
        h->in_contact = false;
        return;
    default:
        break;
    }

    /* Clay that is being pushed flows: the contact point slides freely while the push tool
     * works it, so the yield is not felt as stick-slip. */
    out->force_n = contact_force(h, tool, win, pos_m, pushing ? 0.0f : tool->friction,
                                 &out->potential_j, &out->contact);
    if (tool->kind == TOOL_PUSH && hold && out->contact) {
        /* The clay holds until the contact force reaches its yield force, then flows along
         * the tool's path: eq. 7 with the density met, negative (lower density). */
        const float fn = vec3_norm(out->force_n);
        out->yielding = fn >= tool->yield_force_n;
        if (out->yielding && fn > 0.0f) {
            /* The clay is worked where the tool meets it: the front of the tool sphere, one
             * radius from its centre against the contact normal. */
            const vec3_t front = vec3_scale(out->force_n, -tool->radius_m / fn);
            out->sculpting = apply_tool_paths(win, tool, vec3_add(prev, front),
                                              vec3_add(pos_m, front), -1.0f, -1.0f, dt_s,
                                              impulse_ns, out);
            out->work_m = vec3_add(pos_m, front);
            out->work_radius_m = tool_reach(tool, win);
        }
    }
}
