/* Sculpting tools on the B-spline working space: Hua & Qin §6.2 geometric tools (sphere,
 * cylinder, box, torus, self-defined) that write new coefficients, Ferley et al. §4 actions
 * (toothpaste, eraser, soft eraser, paint, soft paint, smooth, stamp def(v), freeform tools),
 * Hua & Qin §6.1 chisel / squirt / sweep / interior sculpting, Zhang et al. §3 contact
 * h = f + β g, and mirroring across the model's x, y or z plane. Every application refreshes
 * d = A p over the touched samples, marks their blocks dirty and is one undo step. */
#ifndef ARGIL_TOOLS_H
#define ARGIL_TOOLS_H

#include <stddef.h>
#include <stdint.h>

#include "host/model/field.h"
#include "host/model/undo.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef enum { TOOL_SPHERE = 0, TOOL_CYLINDER, TOOL_BOX, TOOL_TORUS, TOOL_CUSTOM, TOOL_FREEFORM } tool_kind_t;

/* A tool shaped like part of a model (Ferley §4.1.2): a dense copy of its densities, sampled
 * trilinearly; origin_m is the copy's corner in the tool's local frame. */
typedef struct {
    float *density;
    int32_t dims[3];
    float spacing_m;
    vec3_t origin_m;
    float iso, band_m;
} tool_freeform_t;

typedef struct {
    tool_kind_t kind;
    float radius_m;        /* sphere; cylinder radius; torus major radius */
    float radius2_m;       /* torus tube radius */
    float half_len_m;      /* cylinder half length along local z */
    vec3_t half_m;         /* box half extents */
    field_sdf_fn custom;   /* self-defined tool: signed distance, positive inside */
    void *custom_ctx;
    float custom_bound_m;  /* radius of a ball (about the tool origin) holding the custom tool */
    const tool_freeform_t *freeform;
} tool_shape_t;

typedef struct {
    vec3_t pos_m;
    float rot[3][3];       /* local → model: columns are the tool's axes (orthonormal) */
} tool_pose_t;

typedef enum {
    TOOL_CARVE = 0,        /* Hua & Qin §6.2 carving; also Ferley's eraser (hard remove) */
    TOOL_ADD,              /* the negated geometric tool */
    TOOL_TOOTHPASTE,       /* Ferley: add the tool's contribution, progressively */
    TOOL_SOFT_ERASE,       /* Ferley: subtract the tool's contribution */
    TOOL_PAINT,            /* Ferley: colour where the tool has a contribution */
    TOOL_SOFT_PAINT,       /* Ferley: colour weighted by tool potential and sample density */
    TOOL_SMOOTH,           /* Ferley: local low-pass of the field */
    TOOL_STAMP,            /* Ferley §4.3: add strength * def(v) */
    TOOL_CHISEL,           /* Hua & Qin §6.1: remove a constant depth along the surface normal */
    TOOL_SQUIRT,           /* the opposite of the chisel */
    TOOL_INTERIOR_CARVE,   /* carve inside the solid, the outer shell kept */
    TOOL_CONTACT           /* Zhang et al. §3: h = f + β g, g = α (f_tool - c) */
} tool_action_t;

/* How an application turns the tool into coefficients. QUASI (the default, fastest): each
 * coefficient takes the action's value at its own centre (quasi-interpolation). LSQ (Hua & Qin
 * §6.2): the coefficients of the tool's box are fitted in the least-squares sense to the
 * tool-modified samples, min Σ_s (A p - d_target)², by fit_iters CGLS iterations from the
 * quasi-interpolated start, matrix-free with the separable A and Aᵀ; the ring of coefficients
 * around the box stays. LSQ serves carve, add, toothpaste, soft erase, stamp and contact. */
typedef enum { TOOL_FIT_QUASI = 0, TOOL_FIT_LSQ } tool_fit_t;
#define TOOL_FIT_ITERS_MAX 32

/* Ferley Fig. 11-12 deformation function parameters: def(0) = -1, def(s) = 0 with slope k,
 * def(s + m) = n (the bulge) with slope 0, def(s + m + r) = 0; C1, cubic pieces. */
typedef struct {
    float s, m, r, k, n;
} tool_stamp_t;

typedef struct {
    tool_action_t action;
    float strength;        /* toothpaste / soft erase / smooth / soft paint rate, stamp amplitude */
    float rgb[3];
    tool_stamp_t stamp;
    float depth_m;         /* chisel / squirt */
    float alpha;           /* Zhang contact: < 0 dents, > 0 bulges */
    uint32_t mirror;       /* bit a: also apply mirrored across the plane axis a = mirror_origin */
    vec3_t mirror_origin_m;
    tool_fit_t fit;        /* TOOL_FIT_QUASI (default) or TOOL_FIT_LSQ */
    int32_t fit_iters;     /* LSQ: CGLS iterations, 1..TOOL_FIT_ITERS_MAX (default 6) */
} tool_params_t;

typedef struct {
    size_t coefs_visited, coefs_changed, samples_refreshed;
} tool_stats_t;

void tool_params_default(tool_params_t *p, tool_action_t action);
void tool_pose_at(tool_pose_t *pose, vec3_t pos_m);

/* Signed distance of the shape at a local point (m, positive inside). */
float tool_sd(const tool_shape_t *t, vec3_t local_m);
/* Radius of a ball about the tool origin that holds the shape. */
float tool_bound_m(const tool_shape_t *t);

/* Ferley's def(v). */
float tool_stamp_def(const tool_stamp_t *st, float v);

/* Applies the tool once at pose (and its mirror images). u may be NULL (no undo step);
 * stats may be NULL. ARGIL_ERR_ARG for an invalid shape or parameters, ARGIL_ERR_NONFINITE,
 * ARGIL_ERR_NOMEM. */
argil_err_t tool_apply(field_t *f, const tool_shape_t *t, const tool_pose_t *pose,
                       const tool_params_t *p, undo_t *u, tool_stats_t *stats);

/* Applies the tool along the polyline pts[0..n) (a stroke / Hua & Qin's sweep) at spacing
 * ≤ band/2, as one undo step. */
argil_err_t tool_stroke(field_t *f, const tool_shape_t *t, const tool_pose_t *pose,
                        const vec3_t *pts_m, size_t n, const tool_params_t *p, undo_t *u);

/* Copies the field's densities in sample box [slo, shi) into a freeform tool whose local
 * origin is the box centre. ARGIL_ERR_ARG, ARGIL_ERR_NOMEM. */
argil_err_t tool_freeform_from_field(tool_freeform_t *ff, const field_t *f, const int32_t slo[3],
                                     const int32_t shi[3]);
void tool_freeform_free(tool_freeform_t *ff);

#endif
