/* Zhang et al. §5: an RBF implicit f(x) = Σ w_i |x - c_i|³ + p0 + p1 x + p2 y + p3 z fitted to
 * surface samples with one interior and one exterior constraint each (the 3n+4 system). Its size
 * is set by the number of centres, never by the number of edits; f > 0 inside. */
#ifndef ARGIL_RBF_H
#define ARGIL_RBF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/mesh/mesh.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

#define RBF_CENTRES_MAX 4096u /* a 3n+4 dense system beyond this is too slow to be useful */

typedef struct {
    uint32_t n;       /* centres */
    float *centre_m;  /* 3 per centre */
    float *weight;    /* 1 per centre */
    float poly[4];    /* p0 + p1 x + p2 y + p3 z */
    float rms_err_m;  /* fitting error at the surface samples (|f| / |grad f|) */
    float max_err_m;
} rbf_model_t;

typedef struct {
    uint32_t max_surface_samples; /* surface samples used (spread evenly); 3x as many centres */
    float offset_m;               /* interior / exterior constraint distance along the normal */
    const volatile int *stop;     /* set non-zero to abandon the fit (ARGIL_ERR_STATE) */
    void (*progress)(void *ctx, double fraction); /* may be NULL */
    void *progress_ctx;
} rbf_opts_t;

/* Sensible defaults: 600 surface samples, offset 1 % of the cloud's bounding-box diagonal. */
void rbf_opts_default(rbf_opts_t *o);

/* Fits to points (pos + unit outward normal); reports the error over all points. ARGIL_ERR_ARG
 * (fewer than 4 points, non-finite input), NOMEM, STATE (stopped, or a singular system). */
argil_err_t rbf_fit(const mesh_t *points, const rbf_opts_t *o, rbf_model_t *out);

/* f at p (positive inside). */
float rbf_eval(const rbf_model_t *r, vec3_t p_m);

/* Allocates room for n centres (weights zero). ARGIL_ERR_ARG above RBF_CENTRES_MAX, NOMEM. */
argil_err_t rbf_alloc(rbf_model_t *r, uint32_t n);

/* Frees r's arrays; r becomes empty. */
void rbf_free(rbf_model_t *r);

#endif
