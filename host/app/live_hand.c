/* The mouse-driven hand (see live_hand.h). */
#include "host/app/live_hand.h"

#include <math.h>

void live_hand_cfg_default(live_hand_cfg_t *c)
{
    c->hover_m = 0.002f;
    c->press_extra_m = 0.003f;
    c->pull_m = 0.008f;
    c->press_rate_m_s = 0.008f;
    c->max_speed_m_s = 0.15f;
}

void live_hand_init(live_hand_t *h)
{
    h->have_target = false;
    h->target_m = vec3(0, 0, 0);
    h->pressing = false;
    h->anchor_m = vec3(0, 0, 0);
    h->plane_n = vec3(0, 0, -1);
    h->depth_m = 0.0f;
}

static bool finite3(vec3_t v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

bool live_hand_raycast(const grid_t *g, vec3_t origin_m, vec3_t dir, vec3_t *hit_m)
{
    if (!finite3(origin_m) || !finite3(dir) || !(vec3_norm(dir) > 0.5f))
        return false;
    /* Slab test against the grid's box. */
    const float o[3] = {origin_m.x, origin_m.y, origin_m.z}, d[3] = {dir.x, dir.y, dir.z};
    int32_t b0[3], b1[3];
    grid_bounds(g, b0, b1);
    const vec3_t org = grid_box_origin(g, b0);
    const float lo[3] = {org.x, org.y, org.z};
    float t0 = 0.0f, t1 = INFINITY;
    for (int a = 0; a < 3; a++) {
        const float hi = lo[a] + (float)(b1[a] - b0[a] - 1) * g->spacing_m;
        if (fabsf(d[a]) < 1e-12f) {
            if (o[a] < lo[a] || o[a] > hi)
                return false;
            continue;
        }
        float ta = (lo[a] - o[a]) / d[a], tb = (hi - o[a]) / d[a];
        if (ta > tb) {
            const float t = ta;
            ta = tb;
            tb = t;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    if (!(t0 <= t1))
        return false;
    const float step = 0.5f * g->spacing_m;
    const int32_t n = (int32_t)((t1 - t0) / step) + 2;
    float prev = t0;
    for (int32_t i = 0; i < n; i++) {
        const float t = fminf(t0 + (float)i * step, t1);
        if (grid_density_at(g, vec3_add(origin_m, vec3_scale(dir, t))) >= g->iso) {
            float a = prev, b = t;
            for (int k = 0; k < 9; k++) { /* step / 2^9 = spacing / 1024 */
                const float m = 0.5f * (a + b);
                if (grid_density_at(g, vec3_add(origin_m, vec3_scale(dir, m))) >= g->iso)
                    b = m;
                else
                    a = m;
            }
            *hit_m = vec3_add(origin_m, vec3_scale(dir, b));
            return true;
        }
        prev = t;
    }
    return false;
}

/* Where the ray meets the plane through p with normal n (the ray's own foot when parallel). */
static vec3_t ray_plane(vec3_t origin_m, vec3_t dir, vec3_t p, vec3_t n)
{
    const float den = vec3_dot(dir, n);
    if (fabsf(den) < 1e-6f)
        return p;
    const float t = vec3_dot(vec3_sub(p, origin_m), n) / den;
    return vec3_add(origin_m, vec3_scale(dir, t > 0.0f ? t : 0.0f));
}

void live_hand_step(live_hand_t *h, const live_hand_cfg_t *cfg, const grid_t *g,
                    vec3_t origin_m, vec3_t dir, bool button_down, bool outward,
                    float tool_radius_m, float dt_s, vec3_t *pos_m, vec3_t *vel_m_s,
                    int *buttons)
{
    if (!h->have_target) {
        h->target_m = *pos_m;
        h->have_target = true;
    }
    vec3_t goal = h->target_m;
    vec3_t hit;
    const bool finite_ray = finite3(origin_m) && finite3(dir) && vec3_norm(dir) > 0.5f;
    if (button_down && !h->pressing && finite_ray && live_hand_raycast(g, origin_m, dir, &hit)) {
        h->pressing = true;
        h->anchor_m = hit;
        h->plane_n = dir;
        h->depth_m = 0.0f;
    } else if (!button_down) {
        h->pressing = false;
    }
    if (h->pressing) {
        const float deepest = outward ? -cfg->pull_m : tool_radius_m + cfg->press_extra_m;
        const float rate = cfg->press_rate_m_s * dt_s;
        h->depth_m = outward ? fmaxf(h->depth_m - rate, deepest) : fminf(h->depth_m + rate, deepest);
        const vec3_t across = finite_ray ? ray_plane(origin_m, dir, h->anchor_m, h->plane_n)
                                         : h->anchor_m;
        goal = vec3_add(across, vec3_scale(h->plane_n, h->depth_m));
    } else if (finite_ray) {
        if (live_hand_raycast(g, origin_m, dir, &hit)) {
            goal = vec3_sub(hit, vec3_scale(dir, tool_radius_m + cfg->hover_m));
        } else {
            /* Off the clay: follow the cursor across the plane through the grid's centre. */
            const float half = 0.5f * (float)(g->dims[0] - 1) * g->spacing_m;
            const vec3_t c = vec3_add(g->origin_m, vec3(half, half, half));
            goal = ray_plane(origin_m, dir, c, dir);
        }
    }
    const vec3_t step = vec3_sub(goal, h->target_m);
    const float len = vec3_norm(step), max_len = cfg->max_speed_m_s * dt_s;
    const vec3_t prev = h->target_m;
    h->target_m = len > max_len ? vec3_add(h->target_m, vec3_scale(step, max_len / len)) : goal;
    *pos_m = h->target_m;
    *vel_m_s = dt_s > 0.0f ? vec3_scale(vec3_sub(h->target_m, prev), 1.0f / dt_s) : vec3(0, 0, 0);
    *buttons = h->pressing ? 1 : 0;
}
