/* The host's B-spline working space: a uniform cubic scalar B-spline (Hua & Qin eq. 1) whose
 * coefficients, and the density samples d = A p it drives (eq. 5), live in sparse blocks
 * (Ferley §3.1). Samples also carry colour and the painted material (Hua & Qin §6.3). */
#ifndef ARGIL_FIELD_H
#define ARGIL_FIELD_H

#include <stdbool.h>
#include <stdint.h>

#include "host/model/sparse.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

#define FIELD_RATIO_MAX 8   /* samples per coefficient spacing */

/* Coefficient channels. */
enum { FC_P = 0, FC_V, FC_FIXED, FC_NCH };
/* Sample channels: density, rest density, colour, material scales (1 = the base material),
 * rest-length offset (density units; > 0 inflates), accumulated external force (N). */
enum { FS_D = 0, FS_REST, FS_R, FS_G, FS_B, FS_MASS, FS_DAMP, FS_STIFF, FS_RESTLEN, FS_FORCE, FS_NCH };

/* The base material every sample's painted scale multiplies. */
typedef struct {
    float mass_kg;                   /* per sample */
    float damping_n_s;               /* per unit density rate */
    float stiffness_n;               /* spring to the rest density, per unit density */
    float coupling_n;                /* 4D spring to each of the 6 neighbours, density part */
} field_material_t;

typedef struct {
    float coef_spacing_m;            /* knot spacing h_c */
    int32_t ratio;                   /* samples per knot span R: sample spacing h_c / R */
    float sample_spacing_m;
    vec3_t origin_m;                 /* position of coefficient (0,0,0) and sample (0,0,0) */
    float iso;                       /* surface level, 0.5; density 1 inside, 0 outside */
    float band_m;                    /* half-width of the density ramp, 3 h_c */
    field_material_t material;
    float wtab[FIELD_RATIO_MAX][4];  /* basis weights of the 4 coefficients per sample phase */
    sparse_t coef, samp;
    uint32_t lattice_gen;            /* +1 at every field_refine: coefficient indices name new places */
    float *scratch;                  /* grows as needed (host side) */
    size_t scratch_n;
} field_t;

/* An empty field. ARGIL_ERR_ARG for a spacing that is not finite and > 0 or a ratio outside
 * 1..FIELD_RATIO_MAX; ARGIL_ERR_NONFINITE origin; ARGIL_ERR_NOMEM. */
argil_err_t field_init(field_t *f, float coef_spacing_m, int32_t ratio, vec3_t origin_m);
void field_free(field_t *f);

/* Default base material (mass 1e-3 kg, damping 0.05 N s, stiffness 1 N, coupling 2 N). */
void field_material_default(field_material_t *m);

/* clamp(0.5 + 0.5 sd / band, 0, 1): the density profile across a surface, sd > 0 inside
 * (inline: the tools call it per coefficient). */
static inline float field_profile(float signed_dist_m, float band_m)
{
    const float v = 0.5f + 0.5f * signed_dist_m / band_m;
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

vec3_t field_coef_pos(const field_t *f, const int32_t c[3]);
vec3_t field_sample_pos(const field_t *f, const int32_t s[3]);

/* First coefficient index and 4 weights for sample index s along one axis. */
int32_t field_sample_taps(const field_t *f, int32_t s, float w[4]);

/* Coefficient box [clo, chi) that samples [slo, shi) depend on; sample box [slo, shi) that
 * coefficients [clo, chi) influence. */
void field_coefs_of_samples(const field_t *f, const int32_t slo[3], const int32_t shi[3],
                            int32_t clo[3], int32_t chi[3]);
void field_samples_of_coefs(const field_t *f, const int32_t clo[3], const int32_t chi[3],
                            int32_t slo[3], int32_t shi[3]);

/* The 4x4x4 coefficients (first index lo) and per-axis weights of the B-spline at x; false for
 * a non-finite or far-away x. */
bool field_point_taps(const field_t *f, vec3_t x_m, int32_t lo[3], float w[3][4]);

/* Value of the B-spline at x (density units); grad (may be NULL) gets the analytic gradient (1/m). */
float field_eval(const field_t *f, vec3_t x_m, vec3_t *grad);

/* A host-side buffer of at least n floats kept between calls (NULL when out of memory); its
 * contents are lost by the next field_scratch or field_refresh. */
float *field_scratch(field_t *f, size_t n);

/* Recomputes d = A p (Hua & Qin eq. 5) for the samples in [slo, shi), separably, and marks the
 * changed blocks dirty for re-meshing. ARGIL_ERR_ARG for an empty or huge box, ARGIL_ERR_NOMEM. */
argil_err_t field_refresh(field_t *f, const int32_t slo[3], const int32_t shi[3]);

/* d = A p (eq. 5) for the sample box [slo, shi) from the dense coefficient box P (first index
 * clo, dims cn, x fastest), which must hold every coefficient those samples depend on; out gets
 * the samples (x fastest). tmp holds ns_x*nc_y*nc_z + ns_x*ns_y*nc_z floats for the coefficient
 * box of the samples. Same arithmetic in the same order as field_refresh, so results match bit
 * for bit. */
void field_samples_from(const field_t *f, const float *P, const int32_t clo[3], const int32_t cn[3],
                        const int32_t slo[3], const int32_t shi[3], float *out, float *tmp);

/* out = Aᵀ D (the transpose of field_samples_from): for every coefficient of the dense box
 * (first index clo, dims cn, x fastest) the sum of A(s, c) D(s) over the samples s of [slo, shi)
 * (D x fastest); taps that fall outside the coefficient box are dropped. tmp holds
 * cn_x*ns_y*ns_z + cn_x*cn_y*ns_z floats. */
void field_coefs_from(const field_t *f, const float *D, const int32_t slo[3], const int32_t shi[3],
                      const int32_t clo[3], const int32_t cn[3], float *out, float *tmp);

/* Signed distance callback (m, positive inside) used to build shapes. */
typedef float (*field_sdf_fn)(void *ctx, vec3_t x_m);

/* Sets every coefficient whose centre lies in [lo_m, hi_m] to the profile of sd (quasi-
 * interpolation), refreshes the samples and makes them the rest shape. */
argil_err_t field_fill(field_t *f, field_sdf_fn sd, void *ctx, vec3_t lo_m, vec3_t hi_m);

/* Knot insertion at the middle of every knot span (uniform refinement by the two-scale relation
 * of the cubic B-spline, per axis q_2c = (p_c-1 + 6 p_c + p_c+1) / 8, q_2c+1 = (p_c + p_c+1) / 2):
 * the knot spacing halves and the field's value is unchanged everywhere (to float rounding).
 * The samples keep their lattice (the ratio halves, so it must be even) and every sample channel
 * but d, which is recomputed from the new coefficients; velocities refine like p; a new
 * coefficient is fixed when all the coefficients it is made from were. band_m stays.
 * ARGIL_ERR_ARG for an odd ratio or indices that would leave the sparse range (field unchanged);
 * ARGIL_ERR_NOMEM (unchanged when it happens before the new coefficients replace the old, else
 * some d may still hold the old values: field_refresh them).
 * The refinement is global (every span of every block): the working space is one uniform lattice,
 * so a knot inserted in a region only would need a second, hierarchical level (docs/model.md).
 * lattice_gen is incremented: undo steps recorded before it are refused (undo_undo, undo_redo),
 * since their coefficient indices now name other coefficients. Cost: 8x the coefficients. */
argil_err_t field_refine(field_t *f);

#endif
