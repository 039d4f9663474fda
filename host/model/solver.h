/* Dynamics of the density springs on B-spline coefficients (Hua & Qin §5): samples d = A p +
 * d_fixed, M d'' + D d' + K (d - r) = f projected by Aᵀ (eq. 8, 11); explicit (lumped mass and damping,
 * semi-implicit Euler) and implicit backward-Euler (eq. 12, conjugate gradients, warm start,
 * ≤ 8 iterations) with the adaptive step of §7. AᵀMA, AᵀDA, AᵀKA are applied matrix-free through
 * the separability A = A_z ⊗ A_y ⊗ A_x and never assembled. A solver holds one dense region: a
 * whole patch, or the physical window cut from the sparse field (host/model/physwin.h). */
#ifndef ARGIL_SOLVER_H
#define ARGIL_SOLVER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/model/bspline.h"
#include "shared/argil_err.h"

#define SOLVER_ROW_MAX 64        /* coefficients in one constraint row (a 4x4x4 support) */
#define SOLVER_CG_ITERS_MAX 8    /* Hua & Qin §5.3 */

/* One linear row over region coefficients: Σ w_j p[idx_j] should equal target. */
typedef struct {
    int32_t n;
    int32_t idx[SOLVER_ROW_MAX];
    float w[SOLVER_ROW_MAX];
    float target;
    float k_n;                   /* soft rows: spring stiffness (N per unit density) */
    int32_t pivot;               /* hard rows: the entry eliminated (Hua & Qin eq. 14-16) */
} solver_row_t;

typedef struct {
    float dt_s;                  /* step; halved by the adaptive rule, never below dt_min_s */
    float dt_min_s;
    float acc_threshold;         /* |p''| (density/s²) above which the step is halved (§7) */
    int32_t cg_iters_max;        /* 1..8 */
    float cg_tol;                /* relative residual that ends CG early */
} solver_cfg_t;

typedef struct {
    float residual;              /* last implicit step: |r| / |b| of the reduced system */
    int32_t cg_iters;
    int32_t halvings;            /* step halvings during the last call */
    float max_acc;               /* largest |p''| accepted in the last call */
} solver_stats_t;

/* One axis of A (or Aᵀ) as a band: outputs in chunks of SOLVER_BAND outputs, chunk c reads inputs
 * [lo[c], lo[c] + n[c]) with SOLVER_BAND weights per input (0 where an output does not reach it),
 * so the pass runs SOLVER_BAND outputs wide instead of gathering 4 taps per output. Rebuilt by
 * solver_material_changed; when it cannot allocate, w is NULL and the gather loops are used. */
#define SOLVER_BAND 8
typedef struct {
    int32_t *lo, *n;
    float *w;
    size_t nchunk, w_cap;
} solver_band_t;

typedef struct {
    int32_t nc[3], ns[3];
    size_t ncoef, nsamp;
    int32_t *tap_first[3];       /* per axis and sample: first of 4 coefficients (0..nc-4) */
    float *tap_w[3];             /* per axis and sample: 4 weights (0 for coefficients outside) */
    int32_t *tapt_lo[3], *tapt_hi[3]; /* per axis and coefficient: samples [lo, hi) it reaches (derived) */
    float *p, *p_prev;           /* coefficients now and one step ago */
    float dt_prev_s;             /* step that separates p_prev from p */
    uint8_t *fixed;              /* 1 = coefficient held where it is (fixed point) */
    const float *fixed_next;     /* NULL, or where each fixed coefficient is at the end of the
                                  * next step (moved by another solve); caller-owned, ncoef */
    float *d_fixed;              /* samples: part of d from coefficients outside the region */
    float *mass_kg, *damp_n_s;   /* samples */
    float *kscale;               /* samples: painted stiffness scale (1 = base) */
    float *rest;                 /* samples: rest density incl. the rest-length offset */
    float *force_n;              /* samples: external force, constant over the step */
    float k_rest_n, coupling_n;  /* base stiffness of the rest and the neighbour springs */
    float *kedge[3];             /* samples: neighbour spring to +x/+y/+z (derived) */
    float *kdiag;                /* samples: rest spring + the 6 neighbour springs (derived) */
    float *sdiag;                /* samples: 2 m + dt D + 2 dt² kdiag of the implicit step (derived) */
    solver_row_t *soft, *hard;
    int32_t nsoft, nhard, soft_cap, hard_cap;
    solver_cfg_t cfg;
    solver_stats_t stats;
    float *mlump, *dlump;        /* lumped coefficient mass Aᵀ(m ⊙ A1), damping alike (derived) */
    float *w_nc[6], *w_ns[4], *w_mid;   /* scratch */
    solver_band_t band_a, band_at;      /* A and Aᵀ along x as banded blocks (derived) */
} solver_t;

void solver_cfg_default(solver_cfg_t *c);

/* A region of nc coefficients and ns samples with taps all zero, p = 0, mass 1e-3 kg, damping
 * 0.05 N s, stiffness scale 1, k_rest 1 N, coupling 2 N. ARGIL_ERR_ARG for nc < 4 or ns < 1 on
 * an axis or an invalid cfg; ARGIL_ERR_NOMEM. */
argil_err_t solver_init(solver_t *s, const int32_t nc[3], const int32_t ns[3], const solver_cfg_t *cfg);
void solver_free(solver_t *s);

/* A region over a whole patch: ns samples spread evenly over its domain, p = the patch's
 * coefficients, taps from its (possibly non-uniform) knots; the outermost coefficient layer is
 * held fixed (it reaches the domain only through the tail of its basis). */
argil_err_t solver_init_patch(solver_t *s, const bspline_t *b, const int32_t ns[3],
                              const solver_cfg_t *cfg);

/* Must be called after the taps, the material arrays or k_rest/coupling change (rebuilds the
 * derived arrays, among them the x-axis bands of A and Aᵀ: until the first call after
 * solver_init, A and Aᵀ read the taps directly, the slower way). */
void solver_material_changed(solver_t *s);

/* d = A p + d_fixed for the current p (nsamp floats). */
void solver_densities(solver_t *s, float *d);

/* Adds a soft constraint spring row (Hua & Qin §6.3) or a hard linear row eliminated by
 * eq. 14-16. Hard rows: the pivot must not appear in any other hard row nor be fixed.
 * ARGIL_ERR_ARG for a bad row, ARGIL_ERR_NOMEM. */
argil_err_t solver_add_soft(solver_t *s, const solver_row_t *row);
argil_err_t solver_add_hard(solver_t *s, const solver_row_t *row);

/* One explicit step of cfg.dt_s (halved while |p''| exceeds the threshold). */
argil_err_t solver_step_explicit(solver_t *s);

/* One implicit backward-Euler step (Hua & Qin eq. 12), CG as configured; stats.residual set. */
argil_err_t solver_step_implicit(solver_t *s);

/* Largest stable explicit step estimated by power iteration on the lumped system. */
float solver_explicit_dt_max_s(solver_t *s);

#endif
