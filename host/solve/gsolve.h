/* The session's global solve on the B-spline model (Hua & Qin eq. 8-12, DESIGN.md "Data flow"
 * step 8): a sparse uniform B-spline field (host/model/field.h) laid on the grid's sample
 * lattice, stepped implicitly (backward Euler, CG, warm start) in a physical window
 * (host/model/physwin.h) around the board's window. The dense grid stays the sampled view the
 * board's windows are cut from, the mesher reads and the journal records: every step copies
 * the field's densities into the grid in the box it changed. */
#ifndef ARGIL_GLOBAL_SOLVE_H
#define ARGIL_GLOBAL_SOLVE_H

#include <stdbool.h>
#include <stdint.h>

#include "host/model/host_tool.h"
#include "host/model/field.h"
#include "host/model/grid.h"
#include "host/model/physwin.h"
#include "shared/argil_err.h"
#include "shared/density_springs.h"
#include "shared/vec3.h"

/* Samples per coefficient spacing R (the session's --knot-ratio; gsolve_init_ratio). 1 puts a
 * coefficient on every grid sample, so the free interior of the window moves exactly as the
 * grid's springs would (d'' = M^-1 f), only with the implicit step; 2 or 4 put one every 2 or 4
 * samples (fewer coefficients, smoother clay; the window's sample box grows with R, so R = 4 is
 * not cheaper than 2: docs/model.md), and each gsolve_refine halves R. */
#define GSOLVE_RATIO_DEFAULT 1
#define GSOLVE_RATIO_MAX 4
/* At R > 1 the seed's quasi-interpolant is improved by this many CGLS iterations of the least
 * squares fit to the grid's samples (at R = 1, A is square and the seed stays as it was). */
#define GSOLVE_SEED_FIT_ITERS 8
/* CG's relative stopping residual: 0, every step runs all SOLVER_CG_ITERS_MAX iterations. The
 * right side b of eq. 12 holds 4 M~ p (the whole clay's density), so any tolerance relative to
 * |b| lets a slow motion pass as converged with 0 iterations: the warm start 2 p_i - p_i-1 then
 * only extrapolates it, undamped (measured: 1e-4 and 1e-6 both left a pushed sample drifting at
 * a constant rate long after the push; the springs and all-8-iteration steps stop it). */
#define GSOLVE_CG_TOL 0.0f
/* A window rests once a step without external force moves no sample of the view by more than
 * this (density units: 1e-3 /s at 100 Hz, a surface creeping ~0.01 mm/s). */
#define GSOLVE_REST_DD 1e-5f
/* A region the board's window left rests once a step moves no sample of it by more than
 * this (4e-3 /s at 100 Hz: the surface creeps ~0.03 mm/s on the 7.5 mm density ramp). Looser
 * than GSOLVE_REST_DD: the main window is stepped anyway, a settling region costs a second
 * step per period while it moves, and CG's undamped high-frequency modes keep a window near
 * 1e-5 for long after the clay visibly stopped. */
#define GSOLVE_SETTLE_DD 5e-5f
/* ... for this many steps in a row (a motion that turns round is slow for a step or two). */
#define GSOLVE_SETTLE_QUIET_STEPS 10
/* Coefficients (knot spans, at any R) past the layers the window left that a settling region
 * keeps, held on the window's path: a free coefficient's row of the implicit system reaches
 * the samples of its support ((c - 2, c + 2) knot spans), the neighbour springs one sample
 * further, and the coefficients whose supports touch those, 3 spans away; anything farther
 * does not enter its equations, so clipping the region there changes nothing but round-off. */
#define GSOLVE_SETTLE_MARGIN 3
/* The grid view follows a field density once it differs by more than this. */
#define GSOLVE_VIEW_EPS 1e-5f

typedef enum { GSOLVE_MAT_STIFFNESS = 0, GSOLVE_MAT_MASS } gsolve_material_t;

typedef struct {
    uint32_t steps;
    uint32_t windows_opened;
    uint32_t windows_moved;           /* shifted with the board's window (not reopened) */
    uint32_t carves;
    uint32_t rest_skips;              /* solve periods the resting window was not stepped */
    uint32_t refines;                 /* knot insertions (gsolve_refine) */
    int32_t last_cg_iters;
    float last_residual;
    float max_residual;
    uint64_t cg_iters_total;
    uint32_t settle_steps;            /* steps of a region the board's window left */
    uint32_t settle_rested;           /* such regions that came to rest */
    uint32_t settle_dropped;          /* such regions given up still moving (a newer one came) */
    uint32_t settle_reloads;          /* main window re-read because such a region moved it */
    uint64_t settle_coefs;            /* coefficients of the settling regions' physical windows,
                                       * summed over their steps (what a settling step costs) */
} gsolve_stats_t;

/* A region the board's window left while it was still moving (clay springing back after the
 * tool went on): stepped on, after the main window and with the main window's coefficients
 * held, until it comes to rest (Hua & Qin §6.3: the window is how the solve keeps up, not a
 * reason for the clay behind it to freeze). */
typedef struct {
    physwin_t win;
    bool open;                        /* win holds arrays (reused while the size stays) */
    bool active;                      /* box is still moving: step it */
    bool plain;                       /* win's material is the base */
    uint32_t quiet_steps;             /* steps in a row below GSOLVE_SETTLE_DD */
    float *next;                      /* where held coefficients end a step (win's ncoef) */
    int32_t box_lo[3], box_hi[3];     /* sample box the window left (the old window's box) */
} gsolve_settle_t;

typedef struct {
    field_t field;
    physwin_t win;
    bool win_open;
    bool stale;                       /* a tool changed the field under the open window */
    bool resting;                     /* the open window came to rest (not stepped) */
    bool win_plain;                   /* its material is the base (no painted scale) */
    int32_t box_lo[3], box_hi[3];     /* sample box the open window was asked to cover */
    solver_cfg_t cfg;
    spring_material_t mat;            /* the grid material the field's material was made from */
    gsolve_settle_t settle;           /* the region the window left last, while it moves */
    bool settle_enabled;              /* true (gsolve_init: see there); false: left regions
                                       * freeze where the window left them */
    bool settle_clip;                 /* true (gsolve_init): a settling region's physical window
                                       * is the layers the window left plus GSOLVE_SETTLE_MARGIN
                                       * (their bounding box); false: the whole old box */
    float *buf;                       /* window-sized scratch (samples) */
    size_t buf_n;
    gsolve_stats_t stats;
} gsolve_t;

/* A field on the grid's lattice (same origin, sample spacing = grid spacing), seeded from the
 * grid's densities (gsolve_seed_from_grid) and the grid's material. The grid is then rewritten
 * as the field's view (densities d = A p, clamped to [0, 1]). ARGIL_ERR_NOMEM, ARGIL_ERR_ARG. */
argil_err_t gsolve_init(gsolve_t *gs, grid_t *g);
/* The same with R samples per knot span (1, 2 or GSOLVE_RATIO_MAX = 4; else ARGIL_ERR_ARG): coefficient c sits on
 * grid sample R c, h_c = R x the grid spacing. */
argil_err_t gsolve_init_ratio(gsolve_t *gs, grid_t *g, int32_t ratio);
void gsolve_free(gsolve_t *gs);

/* Fits the field to the grid's densities in sample box [lo, hi) (quasi-interpolation: each
 * coefficient takes the density at its own sample R c, which a B-spline reproduces exactly on
 * the linear density ramp; at R > 1 then GSOLVE_SEED_FIT_ITERS of least squares), makes that
 * the rest shape, and writes the field's view back into the
 * grid. For a model loaded into the grid (.argil, journal recovery). */
argil_err_t gsolve_seed_from_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3]);

/* Takes the grid's material (mass, stiffness, coupling, damping per sample; plastic rate) as
 * the field's base material; painted scales stay. */
void gsolve_set_material(gsolve_t *gs, const spring_material_t *m);

/* One implicit step of dt_s over the coefficients of the sample box [lo, hi) (the physical
 * window; moved or reopened when the box changes). The grid's external forces in the window's
 * samples act over the step and are consumed. When the box moves while the clay in the old one
 * still moves, the part of the old box the window left keeps being stepped (after the window,
 * with the window's coefficients within GSOLVE_SETTLE_MARGIN held) until it rests; one such
 * region at a time, the newest. Writes the sample
 * box whose densities changed into dlo/dhi (dlo = dhi: none; the bounding box of both regions)
 * and the largest |density change|. */
argil_err_t gsolve_step(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                        float dt_s, int32_t dlo[3], int32_t dhi[3], float *max_change);

/* Frees the physical window and any settling region (the field is current after every step);
 * the next step opens a new window. */
void gsolve_close_window(gsolve_t *gs);

/* Samples per knot span now (R): the session's start value, halved by every gsolve_refine. */
int32_t gsolve_ratio(const gsolve_t *gs);

/* Knot insertion during the session (field_refine): a knot in the middle of every span of the
 * whole field, so h_c and R halve and the shape does not change: every sample's density is
 * recomputed from the finer coefficients (equal to float rounding) and the grid is rewritten
 * only where the refinement moved a density by > GSOLVE_VIEW_EPS (none measured: so neither the
 * view, the mesh, the journal nor the board's window changes). The open physical window is closed (its coefficient indices name other
 * places now); the next gsolve_step opens one on the new lattice and the motion goes on (the
 * coefficient velocities refine like p). max_dd (may be NULL) gets the largest |change| of a
 * field density over the grid's samples; lo/hi the grid box rewritten (lo = hi: none).
 * ARGIL_ERR_STATE at R = 1 (already one coefficient per sample: nothing changes);
 * ARGIL_ERR_ARG / ARGIL_ERR_NOMEM from field_refine. */
argil_err_t gsolve_refine(gsolve_t *gs, grid_t *g, float *max_dd, int32_t lo[3], int32_t hi[3]);

/* Carves a sphere out of the model (host/model/tools.c, TOOL_CARVE) and copies the result into
 * the grid; changed samples box in lo/hi (lo = hi = 0 when nothing changed). */
argil_err_t gsolve_carve_sphere(gsolve_t *gs, grid_t *g, vec3_t centre_m, float radius_m,
                                int32_t lo[3], int32_t hi[3]);

/* Paints the stiffness or mass scale within radius of centre: the scale moves toward `scale`
 * with a linear falloff (w = 1 - distance / radius; scale' = scale_old * (1 + (scale - 1) w)).
 * ARGIL_ERR_ARG for a scale that is not finite and > 0 or a bad radius. */
argil_err_t gsolve_paint(gsolve_t *gs, gsolve_material_t ch, vec3_t centre_m, float radius_m,
                         float scale);

/* The painted scale at x (nearest sample; 1 = the base material). */
float gsolve_material_at(const gsolve_t *gs, gsolve_material_t ch, vec3_t x_m);

/* Copies the painted scale of ch over the sample box [lo, lo + dims) into out (x fastest; 1 =
 * the base material, also for a box the store refuses) and returns true when any of them is not
 * 1: what the board's window needs to carry a per-node stiffness (host/app/peer.c). */
bool gsolve_material_box(const gsolve_t *gs, gsolve_material_t ch, const int32_t lo[3],
                         const int32_t dims[3], float *out);

/* Mirrors the model's painted channels (FS_STIFF, FS_MASS, FS_DAMP, FS_RESTLEN) in sample box
 * [lo, hi) (clipped to the grid) into the grid's mat channels, bit for bit, allocating a channel
 * only once it holds a painted value; bumps g->mat_writes when anything changed (the journal
 * then records it). After every paint; ARGIL_ERR_NOMEM. */
argil_err_t gsolve_material_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                    const int32_t hi[3]);

/* The other way, for a model loaded into the grid (.argil, journal recovery): the grid's
 * painted channels become the model's FS_STIFF, FS_MASS, FS_DAMP, FS_RESTLEN (absent channels
 * leave the model's as they are). ARGIL_ERR_NOMEM. */
argil_err_t gsolve_material_from_grid(gsolve_t *gs, const grid_t *g);

/* ---- the session's host tool (host/model/host_tool.h) ---- */

/* Applies the host tool once (host/model/tools.c, no undo step): its action and shape at the
 * stroke points pts_m[0..n_pts) (n_pts >= 1; between consecutive points the poses are spaced
 * <= band / 2, as tool_stroke does) and at their mirror images across the model's origin
 * planes, as one union. radius_m is the board tool's radius; axis (need not be unit, not zero)
 * orients box, cylinder and torus (a sphere ignores it); the per-second strength acts for dt_s.
 * The result is copied into the grid; the changed sample box goes to lo/hi (lo = hi = 0: none).
 * The default setting at one point is exactly gsolve_carve_sphere. ARGIL_ERR_ARG for a setting
 * out of range, a radius not in (0, 1] m, a zero or non-finite axis, n_pts 0 or dt_s not > 0;
 * ARGIL_ERR_NONFINITE for a point; ARGIL_ERR_NOMEM. */
argil_err_t gsolve_apply_tool(gsolve_t *gs, grid_t *g, const host_tool_t *ht, float radius_m,
                              vec3_t axis, const vec3_t *pts_m, size_t n_pts, float dt_s,
                              int32_t lo[3], int32_t hi[3]);

/* ---- painted colour (docs/model.md "In the session") ---- */

/* Mirrors the model's colour (FS_R, FS_G, FS_B, 0..1) in sample box [lo, hi) (clipped to the
 * grid) into the grid's rgb as bytes (round(255 v)), a block holding colour only once a sample
 * differs from GRID_RGB_DEFAULT; bumps g->rgb_writes when anything changed (the journal then
 * records it). gsolve_apply_tool calls it after a paint; call it after anything else that
 * changes the model's colour (an undo) with the box it changed. ARGIL_ERR_NOMEM. */
argil_err_t gsolve_colour_to_grid(const gsolve_t *gs, grid_t *g, const int32_t lo[3],
                                  const int32_t hi[3]);

/* The other way, for a model loaded into the grid: the grid's rgb (when present) becomes the
 * model's FS_R/G/B (byte / 255, which colour_to_grid turns back into the same byte).
 * ARGIL_ERR_NOMEM. */
argil_err_t gsolve_colour_from_grid(gsolve_t *gs, const grid_t *g);

/* ---- undo and redo in the session (host/app/session_undo.h) ---- */

/* After the field was set back to an earlier state in sample box [lo, hi) (undo or redo): the
 * physical window and any settling region close (the next step reopens them from the field),
 * and the grid view follows in the box clipped to the grid: densities (the GSOLVE_VIEW_EPS
 * rule), velocity 0, painted material and colour. The grid box goes to glo/ghi (glo = ghi:
 * none). ARGIL_ERR_NOMEM. */
argil_err_t gsolve_restored(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                            int32_t glo[3], int32_t ghi[3]);

#endif
