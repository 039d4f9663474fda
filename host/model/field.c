/* Uniform cubic B-spline over sparse blocks: sample refresh d = A p by three 1D passes (the
 * tensor-product separability of A), evaluation with gradient, quasi-interpolating fill. */
#include "host/model/field.h"

#include "host/model/f32_buf.h"
#include "host/model/floor_div.h"
#include "host/model/model_hot.h"

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

int32_t field_sample_taps(const field_t *f, int32_t s, float w[4])
{
    const int32_t q = floor_div_i32(s, f->ratio);
    memcpy(w, f->wtab[s - q * f->ratio], sizeof(float) * 4);
    return q - 1;
}

void field_coefs_of_samples(const field_t *f, const int32_t slo[3], const int32_t shi[3],
                            int32_t clo[3], int32_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = floor_div_i32(slo[a], f->ratio) - 1;
        chi[a] = floor_div_i32(shi[a] - 1, f->ratio) + 3;
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
    return f32_buf_reserve(&f->scratch, &f->scratch_n, n) ? f->scratch : NULL;
}

MODEL_HOT void field_samples_from(const field_t *f, const float *P, const int32_t clo[3], const int32_t cn[3],
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
    /* d = A p with A = A_z ⊗ A_y ⊗ A_x (Hua & Qin eq. 5): one axis at a time; along x the taps
     * of CHUNK samples at a time, each row written contiguously */
    enum { CHUNK = 64 };
    for (int32_t x0 = 0; x0 < ns[0]; x0 += CHUNK) {
        const int32_t m = ns[0] - x0 < CHUNK ? ns[0] - x0 : CHUNK;
        int32_t c0[CHUNK];
        float w[CHUNK][4];
        for (int32_t k = 0; k < m; k++)
            c0[k] = field_sample_taps(f, slo[0] + x0 + k, w[k]) - blo[0];
        if (f->ratio == 1) { /* one phase: the same weights, taps one coefficient apart (vectorised) */
            const float w0 = w[0][0], w1 = w[0][1], w2 = w[0][2], w3 = w[0][3];
            for (int32_t z = 0; z < nc[2]; z++)
                for (int32_t y = 0; y < nc[1]; y++) {
                    const float *q = P0 + sy * (size_t)y + sz * (size_t)z + c0[0];
                    float *dst = T1 + (size_t)x0 + (size_t)ns[0] * ((size_t)y + (size_t)nc[1] * z);
                    for (int32_t k = 0; k < m; k++)
                        dst[k] = w0 * q[k] + w1 * q[k + 1] + w2 * q[k + 2] + w3 * q[k + 3];
                }
            continue;
        }
        for (int32_t z = 0; z < nc[2]; z++)
            for (int32_t y = 0; y < nc[1]; y++) {
                const float *src = P0 + sy * (size_t)y + sz * (size_t)z;
                float *dst = T1 + (size_t)x0 + (size_t)ns[0] * ((size_t)y + (size_t)nc[1] * z);
                for (int32_t k = 0; k < m; k++) {
                    const float *q = src + c0[k];
                    dst[k] = w[k][0] * q[0] + w[k][1] * q[1] + w[k][2] * q[2] + w[k][3] * q[3];
                }
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

void field_coefs_from(const field_t *f, const float *D, const int32_t slo[3], const int32_t shi[3],
                      const int32_t clo[3], const int32_t cn[3], float *out, float *tmp)
{
    int32_t ns[3];
    for (int a = 0; a < 3; a++)
        ns[a] = shi[a] - slo[a];
    const size_t cx = (size_t)cn[0];
    float *T1 = tmp, *T2 = T1 + cx * ns[1] * ns[2];
    memset(T1, 0, sizeof(float) * cx * ns[1] * ns[2]);
    memset(T2, 0, sizeof(float) * cx * cn[1] * ns[2]);
    memset(out, 0, sizeof(float) * cx * cn[1] * cn[2]);
    /* x = Aᵀ d with Aᵀ = A_zᵀ ⊗ A_yᵀ ⊗ A_xᵀ: one axis at a time, scattering each sample's 4 taps */
    enum { CHUNK = 64 }; /* the x taps of CHUNK samples at a time, used by every row */
    for (int32_t x0 = 0; x0 < ns[0]; x0 += CHUNK) {
        const int32_t m = ns[0] - x0 < CHUNK ? ns[0] - x0 : CHUNK;
        int32_t c0[CHUNK];
        float w[CHUNK][4];
        bool inside = true;
        for (int32_t k = 0; k < m; k++) {
            c0[k] = field_sample_taps(f, slo[0] + x0 + k, w[k]) - clo[0];
            inside = inside && c0[k] >= 0 && c0[k] + 4 <= cn[0];
        }
        for (size_t r = 0; r < (size_t)ns[1] * ns[2]; r++) {
            float *dst = T1 + cx * r;
            const float *src = D + (size_t)ns[0] * r + x0;
            for (int32_t k = 0; k < m; k++) {
                float *q = dst + c0[k];
                if (inside) {
                    q[0] += w[k][0] * src[k];
                    q[1] += w[k][1] * src[k];
                    q[2] += w[k][2] * src[k];
                    q[3] += w[k][3] * src[k];
                } else {
                    for (int j = 0; j < 4; j++)
                        if (c0[k] + j >= 0 && c0[k] + j < cn[0])
                            q[j] += w[k][j] * src[k];
                }
            }
        }
    }
    for (int32_t z = 0; z < ns[2]; z++)
        for (int32_t y = 0; y < ns[1]; y++) {
            float w[4];
            const int32_t c0 = field_sample_taps(f, slo[1] + y, w) - clo[1];
            const float *src = T1 + cx * ((size_t)y + (size_t)ns[1] * z);
            for (int j = 0; j < 4; j++) {
                if (c0 + j < 0 || c0 + j >= cn[1])
                    continue;
                float *dst = T2 + cx * ((size_t)(c0 + j) + (size_t)cn[1] * z);
                for (size_t i = 0; i < cx; i++)
                    dst[i] += w[j] * src[i];
            }
        }
    const size_t plane = cx * cn[1];
    for (int32_t z = 0; z < ns[2]; z++) {
        float w[4];
        const int32_t c0 = field_sample_taps(f, slo[2] + z, w) - clo[2];
        const float *src = T2 + plane * (size_t)z;
        for (int j = 0; j < 4; j++) {
            if (c0 + j < 0 || c0 + j >= cn[2])
                continue;
            float *dst = out + plane * (size_t)(c0 + j);
            for (size_t i = 0; i < plane; i++)
                dst[i] += w[j] * src[i];
        }
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

#define FIELD_REF_IN (SPARSE_B + 4)        /* coarse coefficients read per block and axis */
#define FIELD_REF_OUT (2 * SPARSE_B + 4)   /* fine coefficients written per block and axis */

/* One axis of the two-scale relation on a dense box (x fastest): in has n_in[a] points along
 * axis a starting at coarse index lo_c, out gets 2 n_in - 4 points starting at fine index
 * 2 lo_c + 2; fixed flags combine by min (fixed only when every parent is). */
static void field_refine_axis(const float *in, const int32_t dims_in[3], int a, bool flags, float *out)
{
    int32_t dims_out[3] = {dims_in[0], dims_in[1], dims_in[2]};
    dims_out[a] = 2 * dims_in[a] - 4;
    const size_t st_in[3] = {1, (size_t)dims_in[0], (size_t)dims_in[0] * dims_in[1]};
    const size_t st_out[3] = {1, (size_t)dims_out[0], (size_t)dims_out[0] * dims_out[1]};
    for (int32_t z = 0; z < dims_out[2]; z++)
        for (int32_t y = 0; y < dims_out[1]; y++)
            for (int32_t x = 0; x < dims_out[0]; x++) {
                int32_t o[3] = {x, y, z};
                const int32_t j = o[a] + 2; /* fine index relative to 2 lo_c */
                const int32_t c = j / 2;    /* coarse parent relative to lo_c */
                o[a] = 0;
                const float *b = in + st_in[0] * o[0] + st_in[1] * o[1] + st_in[2] * o[2];
                const float pm = b[st_in[a] * (c - 1)], p0 = b[st_in[a] * c], pp = b[st_in[a] * (c + 1)];
                float v;
                if (flags)
                    v = (j & 1) ? fminf(p0, pp) : fminf(pm, fminf(p0, pp));
                else
                    v = (j & 1) ? 0.5f * (p0 + pp) : 0.125f * (pm + 6.0f * p0 + pp);
                out[st_out[0] * x + st_out[1] * y + st_out[2] * z] = v;
            }
}

argil_err_t field_refine(field_t *f)
{
    if (f->ratio % 2 != 0)
        return ARGIL_ERR_ARG;
    size_t nkeys = 0, slot = 0;
    for (const sparse_block_t *b; (b = sparse_next(&f->coef, &slot)) != NULL;) {
        for (int a = 0; a < 3; a++)
            if (b->key[a] > SPARSE_INDEX_MAX / (4 * SPARSE_B) || b->key[a] < -SPARSE_INDEX_MAX / (4 * SPARSE_B))
                return ARGIL_ERR_ARG;
        nkeys++;
    }
    sparse_t fine;
    argil_err_t e = sparse_init(&fine, FC_NCH, f->coef.defaults);
    if (e != ARGIL_OK)
        return e;
    /* per coarse block: its coefficients and a ring of 2, refined along x, y, z, written where they
     * differ from the defaults (neighbouring blocks write the same values where they overlap) */
    float *buf = malloc(sizeof(float) * 3 * FIELD_REF_OUT * FIELD_REF_OUT * FIELD_REF_OUT);
    if (buf == NULL) {
        sparse_free(&fine);
        return ARGIL_ERR_NOMEM;
    }
    float *A = buf, *B = A + FIELD_REF_OUT * FIELD_REF_OUT * FIELD_REF_OUT, *C = B + FIELD_REF_OUT * FIELD_REF_OUT * FIELD_REF_OUT;
    slot = 0;
    for (const sparse_block_t *b; e == ARGIL_OK && (b = sparse_next(&f->coef, &slot)) != NULL;) {
        int32_t lo[3], flo[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = b->key[a] * SPARSE_B - 2;
            flo[a] = 2 * lo[a] + 2;
        }
        for (int ch = 0; ch < FC_NCH && e == ARGIL_OK; ch++) {
            const int32_t d0[3] = {FIELD_REF_IN, FIELD_REF_IN, FIELD_REF_IN};
            const int32_t d1[3] = {FIELD_REF_OUT, FIELD_REF_IN, FIELD_REF_IN};
            const int32_t d2[3] = {FIELD_REF_OUT, FIELD_REF_OUT, FIELD_REF_IN};
            const int32_t d3[3] = {FIELD_REF_OUT, FIELD_REF_OUT, FIELD_REF_OUT};
            sparse_read_box(&f->coef, ch, lo, d0, A);
            field_refine_axis(A, d0, 0, ch == FC_FIXED, B);
            field_refine_axis(B, d1, 1, ch == FC_FIXED, C);
            field_refine_axis(C, d2, 2, ch == FC_FIXED, A);
            e = sparse_write_box(&fine, ch, flo, d3, A);
        }
    }
    free(buf);
    size_t nsb = 0;
    int32_t (*keys)[3] =
        e == ARGIL_OK ? malloc(sizeof(int32_t[3]) * (f->samp.blocks.count + 1)) : NULL;
    if (keys == NULL) {
        sparse_free(&fine);
        return e != ARGIL_OK ? e : ARGIL_ERR_NOMEM;
    }
    slot = 0;
    for (const sparse_block_t *b; (b = sparse_next(&f->samp, &slot)) != NULL;)
        memcpy(keys[nsb++], b->key, sizeof(keys[0]));
    sparse_free(&f->coef);
    f->coef = fine;
    f->lattice_gen++;
    f->coef_spacing_m *= 0.5f;
    f->ratio /= 2;
    for (int32_t ph = 0; ph < f->ratio; ph++)
        field_weights((double)ph / (double)f->ratio, f->wtab[ph]);
    /* d = A p again with the finer basis (equal up to rounding) */
    for (size_t k = 0; k < nsb && e == ARGIL_OK; k++) {
        const int32_t slo[3] = {keys[k][0] * SPARSE_B, keys[k][1] * SPARSE_B, keys[k][2] * SPARSE_B};
        const int32_t shi[3] = {slo[0] + SPARSE_B, slo[1] + SPARSE_B, slo[2] + SPARSE_B};
        e = field_refresh(f, slo, shi);
    }
    free(keys);
    return e;
}
