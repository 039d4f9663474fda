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

#include "host/model/field.h"
#include "host/model/grid.h"
#include "host/model/physwin.h"
#include "shared/argil_err.h"
#include "shared/density_springs.h"
#include "shared/vec3.h"

/* Samples per coefficient spacing: 1 puts a coefficient on every grid sample, so the free
 * interior of the window moves exactly as the grid's springs would (d'' = M^-1 f), only with
 * the implicit step. */
#define GSOLVE_RATIO 1
/* CG's relative stopping residual: 0, every step runs all SOLVER_CG_ITERS_MAX iterations. The
 * right side b of eq. 12 holds 4 M~ p (the whole clay's density), so any tolerance relative to
 * |b| lets a slow motion pass as converged with 0 iterations: the warm start 2 p_i - p_i-1 then
 * only extrapolates it, undamped (measured: 1e-4 and 1e-6 both left a pushed sample drifting at
 * a constant rate long after the push; the springs and all-8-iteration steps stop it). */
#define GSOLVE_CG_TOL 0.0f
/* A window rests once a step without external force moves no sample of the view by more than
 * this (density units: 1e-3 /s at 100 Hz, a surface creeping ~0.01 mm/s). */
#define GSOLVE_REST_DD 1e-5f
/* The grid view follows a field density once it differs by more than this. */
#define GSOLVE_VIEW_EPS 1e-5f

typedef enum { GSOLVE_MAT_STIFFNESS = 0, GSOLVE_MAT_MASS } gsolve_material_t;

typedef struct {
    uint32_t steps;
    uint32_t windows_opened;
    uint32_t windows_moved;           /* shifted with the board's window (not reopened) */
    uint32_t carves;
    uint32_t rest_skips;              /* solve periods the resting window was not stepped */
    int32_t last_cg_iters;
    float last_residual;
    float max_residual;
    uint64_t cg_iters_total;
} gsolve_stats_t;

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
    float *buf;                       /* window-sized scratch (samples) */
    size_t buf_n;
    gsolve_stats_t stats;
} gsolve_t;

/* A field on the grid's lattice (same origin, sample spacing = grid spacing), seeded from the
 * grid's densities (gsolve_seed_from_grid) and the grid's material. The grid is then rewritten
 * as the field's view (densities d = A p, clamped to [0, 1]). ARGIL_ERR_NOMEM, ARGIL_ERR_ARG. */
argil_err_t gsolve_init(gsolve_t *gs, grid_t *g);
void gsolve_free(gsolve_t *gs);

/* Fits the field to the grid's densities in sample box [lo, hi) (quasi-interpolation: each
 * coefficient takes the density at its own sample, which a B-spline reproduces exactly on the
 * linear density ramp), makes that the rest shape, and writes the field's view back into the
 * grid. For a model loaded into the grid (.argil, journal recovery). */
argil_err_t gsolve_seed_from_grid(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3]);

/* Takes the grid's material (mass, stiffness, coupling, damping per sample; plastic rate) as
 * the field's base material; painted scales stay. */
void gsolve_set_material(gsolve_t *gs, const spring_material_t *m);

/* One implicit step of dt_s over the coefficients of the sample box [lo, hi) (the physical
 * window; reopened when the box changes). The grid's external forces in the window's samples
 * act over the step and are consumed. Writes the sample box whose densities changed into
 * dlo/dhi (dlo = dhi: none) and the largest |density change|. */
argil_err_t gsolve_step(gsolve_t *gs, grid_t *g, const int32_t lo[3], const int32_t hi[3],
                        float dt_s, int32_t dlo[3], int32_t dhi[3], float *max_change);

/* Frees the physical window (the field is current after every step); the next step opens a
 * new one. */
void gsolve_close_window(gsolve_t *gs);

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

#endif
