/* The session's host tool (host/model/host_tool.h) applied to the field through
 * host/model/tools.c: the grid's view, or its colour for a paint, follows in the boxes it
 * reached. */
#include "host/solve/gsolve.h"

#include <math.h>
#include <string.h>

#include "host/model/tools.h"
#include "host/solve/gsolve_internal.h"

/* The tools module's action for each host tool action. */
static const tool_action_t HOST_TO_TOOL_ACTION[HOST_ACT_COUNT] = {
    [HOST_ACT_CARVE] = TOOL_CARVE,       [HOST_ACT_ADD] = TOOL_ADD,
    [HOST_ACT_TOOTHPASTE] = TOOL_TOOTHPASTE, [HOST_ACT_SOFT_ERASE] = TOOL_SOFT_ERASE,
    [HOST_ACT_SMOOTH] = TOOL_SMOOTH,     [HOST_ACT_STAMP] = TOOL_STAMP,
    [HOST_ACT_CHISEL] = TOOL_CHISEL,     [HOST_ACT_SQUIRT] = TOOL_SQUIRT,
    [HOST_ACT_INTERIOR_CARVE] = TOOL_INTERIOR_CARVE,
    [HOST_ACT_PAINT] = TOOL_PAINT,       [HOST_ACT_SOFT_PAINT] = TOOL_SOFT_PAINT};

/* The tool's frame with local z along axis (unit): x and y complete a right-handed frame. */
static void pose_along(tool_pose_t *pose, vec3_t pos_m, vec3_t w)
{
    tool_pose_at(pose, pos_m);
    const vec3_t ref = fabsf(w.x) > 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0);
    const vec3_t uc = vec3_cross(ref, w);
    const vec3_t u = vec3_scale(uc, 1.0f / vec3_norm(uc));
    const vec3_t v = vec3_cross(w, u);
    const float col[3][3] = {{u.x, u.y, u.z}, {v.x, v.y, v.z}, {w.x, w.y, w.z}};
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            pose->rot[r][c] = col[c][r];
}

/* Applies the host tool along the stroke; the grid shows the boxes it changed. */
argil_err_t gsolve_apply_tool(gsolve_t *gs, grid_t *g, const host_tool_t *ht, float radius_m,
                              vec3_t axis, const vec3_t *pts_m, size_t n_pts, float dt_s,
                              int32_t lo[3], int32_t hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = 0;
    const float axis_len = vec3_norm(axis);
    if (ht == NULL || !host_tool_valid(ht) || !isfinite(radius_m) || !(radius_m > 0.0f) ||
        radius_m > 1.0f || !(axis_len > 1e-6f) || !isfinite(axis_len) || pts_m == NULL ||
        n_pts == 0 || !isfinite(dt_s) || !(dt_s > 0.0f))
        return ARGIL_ERR_ARG;
    for (size_t i = 0; i < n_pts; i++)
        if (!vec3_isfinite(pts_m[i]))
            return ARGIL_ERR_NONFINITE;
    field_t *f = &gs->field;
    /* A paint changes colour only: the window and its rest stay as they are. */
    const bool paints = host_action_paints(ht->action);
    const bool stale0 = gs->stale, resting0 = gs->resting;
    /* The tool changes coefficients the open window holds: reload it on the next step. */
    gs->stale = gs->win_open;
    gs->resting = false;
    tool_shape_t t;
    memset(&t, 0, sizeof(t));
    switch (ht->shape) {
    case HOST_SHAPE_BOX:
        t.kind = TOOL_BOX;
        t.half_m = vec3(radius_m, radius_m, radius_m);
        break;
    case HOST_SHAPE_CYLINDER:
        t.kind = TOOL_CYLINDER;
        t.radius_m = radius_m;
        t.half_len_m = radius_m;
        break;
    case HOST_SHAPE_TORUS:
        t.kind = TOOL_TORUS;
        t.radius_m = radius_m;
        t.radius2_m = radius_m * HOST_TORUS_TUBE_FRACTION;
        break;
    default:
        t.kind = TOOL_SPHERE;
        t.radius_m = radius_m;
        break;
    }
    tool_pose_t pose;
    if (t.kind == TOOL_SPHERE)
        tool_pose_at(&pose, pts_m[0]); /* no rotation: the eraser the session always applied */
    else
        pose_along(&pose, pts_m[0], vec3_scale(axis, 1.0f / axis_len));
    tool_params_t prm;
    tool_params_default(&prm, HOST_TO_TOOL_ACTION[ht->action]);
    const float per_step = ht->strength * dt_s;
    if (ht->action == HOST_ACT_CHISEL || ht->action == HOST_ACT_SQUIRT)
        prm.depth_m = per_step * 1e-3f; /* strength: mm per second */
    else if (host_action_has_strength(ht->action))
        prm.strength = per_step < 1.0f ? per_step : 1.0f;
    prm.mirror = ht->mirror;
    prm.mirror_origin_m = vec3(0, 0, 0); /* the model's origin planes */
    for (int c = 0; c < 3; c++)
        prm.rgb[c] = (float)ht->rgb[c] / 255.0f;
    if (paints) {
        gs->stale = stale0;
        gs->resting = resting0;
    }
    argil_err_t e;
    bool changed = true;
    if (n_pts == 1) {
        tool_stats_t st;
        memset(&st, 0, sizeof(st));
        e = tool_apply(f, &t, &pose, &prm, NULL, &st);
        changed = st.coefs_changed > 0;
    } else {
        e = tool_stroke(f, &t, &pose, pts_m, n_pts, &prm, NULL);
    }
    if (e != ARGIL_OK)
        return e;
    gs->stats.carves++;
    if (!changed && !paints)
        return ARGIL_OK;
    /* Samples a changed coefficient can reach: the tool (a stamp's rim reaches (s + m + r) / s
     * of it), the ramp and two knot spans; one box per mirror image of the stroke. */
    float bound_m = tool_bound_m(&t);
    if (ht->action == HOST_ACT_STAMP)
        bound_m *= (prm.stamp.s + prm.stamp.m + prm.stamp.r) / prm.stamp.s;
    const float reach_m = bound_m + f->band_m + 3.0f * f->coef_spacing_m;
    const float org[3] = {f->origin_m.x, f->origin_m.y, f->origin_m.z};
    bool any = false;
    for (uint32_t m = 0; m < 8; m++) {
        if ((m & ~ht->mirror) != 0)
            continue;
        float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < n_pts; i++) {
            const float p[3] = {pts_m[i].x, pts_m[i].y, pts_m[i].z};
            for (int a = 0; a < 3; a++) {
                const float c = ((m >> a) & 1u) ? -p[a] : p[a];
                bmin[a] = c < bmin[a] ? c : bmin[a];
                bmax[a] = c > bmax[a] ? c : bmax[a];
            }
        }
        int32_t slo[3], shi[3], clo[3], chi[3];
        for (int a = 0; a < 3; a++) {
            slo[a] = (int32_t)floorf((bmin[a] - org[a] - reach_m) / f->sample_spacing_m);
            shi[a] = (int32_t)ceilf((bmax[a] - org[a] + reach_m) / f->sample_spacing_m) + 1;
        }
        const float change = paints ? gsolve_colour_box_to_grid(gs, g, slo, shi)
                                    : gsolve_view_to_grid(gs, g, slo, shi);
        if (change < 0.0f)
            return ARGIL_ERR_NOMEM;
        if (change > 0.0f && grid_clip(g, slo, shi, clo, chi)) {
            for (int a = 0; a < 3; a++) {
                lo[a] = any && lo[a] < clo[a] ? lo[a] : clo[a];
                hi[a] = any && hi[a] > chi[a] ? hi[a] : chi[a];
            }
            any = true;
        }
    }
    return ARGIL_OK;
}

/* The host tool's default (carve, sphere, no mirror) at one point. */
argil_err_t gsolve_carve_sphere(gsolve_t *gs, grid_t *g, vec3_t centre_m, float radius_m,
                                int32_t lo[3], int32_t hi[3])
{
    /* The host tool's default (carve, sphere, no mirror) at one point: the same tool_apply. */
    host_tool_t ht;
    host_tool_default(&ht);
    return gsolve_apply_tool(gs, g, &ht, radius_m, vec3(0, 0, 1), &centre_m, 1, 1.0f, lo, hi);
}
