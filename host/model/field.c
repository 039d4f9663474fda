/* Uniform cubic B-spline over sparse blocks: sample refresh d = A p by three 1D passes (the
 * tensor-product separability of A), evaluation with gradient, quasi-interpolating fill. */
#include "host/model/field.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FIELD_BOX_MAX ((int64_t)1 << 27)

void field_material_default(field_material_t *m)
{
    m->mass_kg = 1.0e-3f;
    m->damping_n_s = 0.05f;
    m->stiffness_n = 1.0f;
    m->coupling_n = 2.0f;
}

/* Uniform cubic B-spline segment weights at fraction t of a span (Hua & Qin eq. 1, uniform knots). */
static void field_weights(double t, float w[4])
{
    const double t2 = t * t, t3 = t2 * t, u = 1.0 - t;
    w[0] = (float)(u * u * u / 6.0);
    w[1] = (float)((3.0 * t3 - 6.0 * t2 + 4.0) / 6.0);
    w[2] = (float)((-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0);
    w[3] = (float)(t3 / 6.0);
}

static void field_dweights(double t, double dw[4])
{
    const double t2 = t * t, u = 1.0 - t;
    dw[0] = -0.5 * u * u;
    dw[1] = 1.5 * t2 - 2.0 * t;
    dw[2] = -1.5 * t2 + t + 0.5;
    dw[3] = 0.5 * t2;
}

argil_err_t field_init(field_t *f, float coef_spacing_m, int32_t ratio, vec3_t origin_m)
{
    memset(f, 0, sizeof(*f));
    if (!isfinite(coef_spacing_m) || !(coef_spacing_m > 0.0f) || ratio < 1 || ratio > FIELD_RATIO_MAX)
        return ARGIL_ERR_ARG;
    if (!vec3_isfinite(origin_m))
        return ARGIL_ERR_NONFINITE;
    f->coef_spacing_m = coef_spacing_m;
    f->ratio = ratio;
    f->sample_spacing_m = coef_spacing_m / (float)ratio;
    f->origin_m = origin_m;
    f->iso = 0.5f;
    f->band_m = 3.0f * coef_spacing_m;
    field_material_default(&f->material);
    for (int32_t ph = 0; ph < ratio; ph++)
        field_weights((double)ph / (double)ratio, f->wtab[ph]);
    const float cdef[FC_NCH] = {0.0f, 0.0f, 0.0f};
    const float sdef[FS_NCH] = {0.0f, 0.0f, 0.8f, 0.8f, 0.8f, 1.0f, 1.0f, 1.0f, 0.0f, 0.0f};
    argil_err_t e = sparse_init(&f->coef, FC_NCH, cdef);
    if (e == ARGIL_OK)
        e = sparse_init(&f->samp, FS_NCH, sdef);
    if (e != ARGIL_OK)
        field_free(f);
    return e;
}

void field_free(field_t *f)
{
    sparse_free(&f->coef);
    sparse_free(&f->samp);
    free(f->scratch);
    f->scratch = NULL;
    f->scratch_n = 0;
}

float field_profile(float signed_dist_m, float band_m)
{
    const float v = 0.5f + 0.5f * signed_dist_m / band_m;
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

vec3_t field_coef_pos(const field_t *f, const int32_t c[3])
{
    const float h = f->coef_spacing_m;
    return vec3(f->origin_m.x + h * (float)c[0], f->origin_m.y + h * (float)c[1],
                f->origin_m.z + h * (float)c[2]);
}

vec3_t field_sample_pos(const field_t *f, const int32_t s[3])
{
    const float h = f->sample_spacing_m;
    return vec3(f->origin_m.x + h * (float)s[0], f->origin_m.y + h * (float)s[1],
                f->origin_m.z + h * (float)s[2]);
}

static int32_t field_floordiv(int32_t a, int32_t b)
{
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}

int32_t field_sample_taps(const field_t *f, int32_t s, float w[4])
{
    const int32_t q = field_floordiv(s, f->ratio);
    memcpy(w, f->wtab[s - q * f->ratio], sizeof(float) * 4);
    return q - 1;
}

void field_coefs_of_samples(const field_t *f, const int32_t slo[3], const int32_t shi[3],
                            int32_t clo[3], int32_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = field_floordiv(slo[a], f->ratio) - 1;
        chi[a] = field_floordiv(shi[a] - 1, f->ratio) + 3;
    }
}

void field_samples_of_coefs(const field_t *f, const int32_t clo[3], const int32_t chi[3],
                            int32_t slo[3], int32_t shi[3])
{
    /* coefficient c has support (c - 2, c + 2) in knot units */
    for (int a = 0; a < 3; a++) {
        slo[a] = (clo[a] - 2) * f->ratio + 1;
        shi[a] = (chi[a] - 1 + 2) * f->ratio;
    }
}

bool field_point_taps(const field_t *f, vec3_t x_m, int32_t lo[3], float w[3][4])
{
    const double u[3] = {((double)x_m.x - f->origin_m.x) / f->coef_spacing_m,
                         ((double)x_m.y - f->origin_m.y) / f->coef_spacing_m,
                         ((double)x_m.z - f->origin_m.z) / f->coef_spacing_m};
    for (int a = 0; a < 3; a++) {
        if (!isfinite(u[a]) || fabs(u[a]) > (double)SPARSE_INDEX_MAX / 2)
            return false;
        const double fl = floor(u[a]);
        lo[a] = (int32_t)fl - 1;
        field_weights(u[a] - fl, w[a]);
    }
    return true;
}

float field_eval(const field_t *f, vec3_t x_m, vec3_t *grad)
{
    const double u[3] = {((double)x_m.x - f->origin_m.x) / f->coef_spacing_m,
                         ((double)x_m.y - f->origin_m.y) / f->coef_spacing_m,
                         ((double)x_m.z - f->origin_m.z) / f->coef_spacing_m};
    float w[3][4];
    double dw[3][4];
    int32_t lo[3];
    for (int a = 0; a < 3; a++) {
        if (!isfinite(u[a]) || fabs(u[a]) > (double)SPARSE_INDEX_MAX / 2) {
            if (grad != NULL)
                *grad = vec3(0.0f, 0.0f, 0.0f);
            return 0.0f;
        }
        const double fl = floor(u[a]);
        lo[a] = (int32_t)fl - 1;
        field_weights(u[a] - fl, w[a]);
        field_dweights(u[a] - fl, dw[a]);
    }
    float p[64];
    const int32_t dims[3] = {4, 4, 4};
    sparse_read_box(&f->coef, FC_P, lo, dims, p);
    double v = 0.0, gx = 0.0, gy = 0.0, gz = 0.0;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0, sx = 0.0;
            for (int i = 0; i < 4; i++) {
                s += (double)p[i + 4 * (j + 4 * k)] * w[0][i];
                sx += (double)p[i + 4 * (j + 4 * k)] * dw[0][i];
            }
            v += s * w[1][j] * w[2][k];
            gx += sx * w[1][j] * w[2][k];
            gy += s * dw[1][j] * w[2][k];
            gz += s * w[1][j] * dw[2][k];
        }
    if (grad != NULL) {
        const double ih = 1.0 / f->coef_spacing_m;
        *grad = vec3((float)(gx * ih), (float)(gy * ih), (float)(gz * ih));
    }
    return (float)v;
}

float *field_scratch(field_t *f, size_t n)
{
    if (n > f->scratch_n) {
        float *p = realloc(f->scratch, n * sizeof(float));
        if (p == NULL)
            return NULL;
        f->scratch = p;
        f->scratch_n = n;
    }
    return f->scratch;
}

void field_samples_from(const field_t *f, const float *P, const int32_t clo[3], const int32_t cn[3],
                        const int32_t slo[3], const int32_t shi[3], float *out, float *tmp)
{
    int32_t blo[3], bhi[3], nc[3], ns[3];
    field_coefs_of_samples(f, slo, shi, blo, bhi);
    for (int a = 0; a < 3; a++) {
        nc[a] = bhi[a] - blo[a];
        ns[a] = shi[a] - slo[a];
    }
    const size_t sy = (size_t)cn[0], sz = (size_t)cn[0] * cn[1];
    const float *P0 = P + (size_t)(blo[0] - clo[0]) + sy * (size_t)(blo[1] - clo[1]) + sz * (size_t)(blo[2] - clo[2]);
    float *T1 = tmp, *T2 = T1 + (size_t)ns[0] * nc[1] * nc[2];
    /* d = A p with A = A_z ⊗ A_y ⊗ A_x (Hua & Qin eq. 5): one axis at a time */
    for (int32_t x = 0; x < ns[0]; x++) {
        float w[4];
        const int32_t c0 = field_sample_taps(f, slo[0] + x, w) - blo[0];
        for (int32_t z = 0; z < nc[2]; z++)
            for (int32_t y = 0; y < nc[1]; y++) {
                const float *src = P0 + sy * (size_t)y + sz * (size_t)z + c0;
                T1[(size_t)x + (size_t)ns[0] * ((size_t)y + (size_t)nc[1] * z)] =
                    w[0] * src[0] + w[1] * src[1] + w[2] * src[2] + w[3] * src[3];
            }
    }
    const size_t st = (size_t)ns[0];
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t y = 0; y < ns[1]; y++) {
            float w[4];
            const int32_t c0 = field_sample_taps(f, slo[1] + y, w) - blo[1];
            float *dst = T2 + st * (y + (size_t)ns[1] * z);
            const float *s0 = T1 + st * (c0 + (size_t)nc[1] * z);
            for (int32_t x = 0; x < ns[0]; x++)
                dst[x] = w[0] * s0[x] + w[1] * s0[x + st] + w[2] * s0[x + 2 * st] + w[3] * s0[x + 3 * st];
        }
    const size_t plane = (size_t)ns[0] * ns[1];
    for (int32_t z = 0; z < ns[2]; z++) {
        float w[4];
        const int32_t c0 = field_sample_taps(f, slo[2] + z, w) - blo[2];
        const float *s0 = T2 + plane * (size_t)c0;
        float *dst = out + plane * (size_t)z;
        for (size_t i = 0; i < plane; i++)
            dst[i] = w[0] * s0[i] + w[1] * s0[i + plane] + w[2] * s0[i + 2 * plane] + w[3] * s0[i + 3 * plane];
    }
}

argil_err_t field_refresh(field_t *f, const int32_t slo[3], const int32_t shi[3])
{
    int32_t clo[3], chi[3], nc[3], ns[3];
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        ns[a] = shi[a] - slo[a];
        if (ns[a] < 1)
            return ARGIL_ERR_ARG;
        vol *= ns[a] + 4 * f->ratio;
        if (vol > FIELD_BOX_MAX)
            return ARGIL_ERR_ARG;
    }
    field_coefs_of_samples(f, slo, shi, clo, chi);
    for (int a = 0; a < 3; a++)
        nc[a] = chi[a] - clo[a];
    const size_t n_p = (size_t)nc[0] * nc[1] * nc[2];
    const size_t n_1 = (size_t)ns[0] * nc[1] * nc[2];
    const size_t n_2 = (size_t)ns[0] * ns[1] * nc[2];
    const size_t n_3 = (size_t)ns[0] * ns[1] * ns[2];
    float *buf = field_scratch(f, n_p + n_1 + n_2 + n_3);
    if (buf == NULL)
        return ARGIL_ERR_NOMEM;
    float *P = buf, *T = P + n_p, *D = T + n_1 + n_2;
    sparse_read_box(&f->coef, FC_P, clo, nc, P);
    field_samples_from(f, P, clo, nc, slo, shi, D, T);
    return sparse_write_box(&f->samp, FS_D, slo, ns, D);
}

argil_err_t field_fill(field_t *f, field_sdf_fn sd, void *ctx, vec3_t lo_m, vec3_t hi_m)
{
    if (sd == NULL)
        return ARGIL_ERR_ARG;
    if (!vec3_isfinite(lo_m) || !vec3_isfinite(hi_m))
        return ARGIL_ERR_NONFINITE;
    const float lo[3] = {lo_m.x, lo_m.y, lo_m.z}, hi[3] = {hi_m.x, hi_m.y, hi_m.z};
    const float o[3] = {f->origin_m.x, f->origin_m.y, f->origin_m.z};
    int32_t clo[3], chi[3], nc[3];
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        const double a0 = ceil(((double)lo[a] - o[a]) / f->coef_spacing_m);
        const double a1 = floor(((double)hi[a] - o[a]) / f->coef_spacing_m);
        if (!(a1 >= a0) || fabs(a0) > SPARSE_INDEX_MAX / 2 || fabs(a1) > SPARSE_INDEX_MAX / 2)
            return ARGIL_ERR_ARG;
        clo[a] = (int32_t)a0;
        chi[a] = (int32_t)a1 + 1;
        nc[a] = chi[a] - clo[a];
        vol *= nc[a];
        if (vol > FIELD_BOX_MAX)
            return ARGIL_ERR_ARG;
    }
    float *p = malloc(sizeof(float) * (size_t)vol);
    if (p == NULL)
        return ARGIL_ERR_NOMEM;
    size_t i = 0;
    for (int32_t z = clo[2]; z < chi[2]; z++)
        for (int32_t y = clo[1]; y < chi[1]; y++)
            for (int32_t x = clo[0]; x < chi[0]; x++) {
                const int32_t c[3] = {x, y, z};
                p[i++] = field_profile(sd(ctx, field_coef_pos(f, c)), f->band_m);
            }
    argil_err_t e = sparse_write_box(&f->coef, FC_P, clo, nc, p);
    free(p);
    if (e != ARGIL_OK)
        return e;
    int32_t slo[3], shi[3], ns[3];
    field_samples_of_coefs(f, clo, chi, slo, shi);
    e = field_refresh(f, slo, shi);
    if (e != ARGIL_OK)
        return e;
    for (int a = 0; a < 3; a++)
        ns[a] = shi[a] - slo[a];
    float *d = malloc(sizeof(float) * (size_t)ns[0] * ns[1] * ns[2]);
    if (d == NULL)
        return ARGIL_ERR_NOMEM;
    sparse_read_box(&f->samp, FS_D, slo, ns, d);
    e = sparse_write_box(&f->samp, FS_REST, slo, ns, d);
    free(d);
    return e;
}
