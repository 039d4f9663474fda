/* Matrix-free density-spring dynamics on coefficients: separable A and Aᵀ, the sample-space
 * operators M, D, K, explicit and implicit (Hua & Qin eq. 12) steps, CG with elimination of
 * fixed coefficients and hard rows (eq. 14-16). */
#include "host/model/solver.h"

#include "host/model/model_hot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SOLVER_BOX_MAX ((int64_t)1 << 26)
/* The separable passes and the spring stencil are simple streaming loops: -O3 vectorises them. */
#define SOLVER_HOT MODEL_HOT_SIMD

void solver_cfg_default(solver_cfg_t *c)
{
    c->dt_s = 1.0e-3f;
    c->dt_min_s = 1.0e-6f;
    c->acc_threshold = 1.0e6f;
    c->cg_iters_max = SOLVER_CG_ITERS_MAX;
    c->cg_tol = 1.0e-4f;
}

static bool solver_cfg_ok(const solver_cfg_t *c)
{
    return isfinite(c->dt_s) && c->dt_s > 0.0f && isfinite(c->dt_min_s) && c->dt_min_s > 0.0f &&
           c->dt_min_s <= c->dt_s && !isnan(c->acc_threshold) && c->acc_threshold > 0.0f &&
           c->cg_iters_max >= 1 && c->cg_iters_max <= SOLVER_CG_ITERS_MAX && isfinite(c->cg_tol) &&
           c->cg_tol >= 0.0f;
}

void solver_free(solver_t *s)
{
    for (int a = 0; a < 3; a++) {
        free(s->tap_first[a]);
        free(s->tap_w[a]);
        free(s->kedge[a]);
        free(s->tapt_lo[a]);
        free(s->tapt_hi[a]);
    }
    free(s->kdiag);
    free(s->sdiag);
    free(s->p);
    free(s->p_prev);
    free(s->fixed);
    free(s->d_fixed);
    free(s->mass_kg);
    free(s->damp_n_s);
    free(s->kscale);
    free(s->rest);
    free(s->force_n);
    free(s->soft);
    free(s->hard);
    free(s->mlump);
    free(s->dlump);
    for (int i = 0; i < 6; i++)
        free(s->w_nc[i]);
    for (int i = 0; i < 4; i++)
        free(s->w_ns[i]);
    free(s->w_mid);
    solver_band_t *bands[2] = {&s->band_a, &s->band_at};
    for (int i = 0; i < 2; i++) {
        free(bands[i]->lo);
        free(bands[i]->n);
        free(bands[i]->w);
    }
    memset(s, 0, sizeof(*s));
}

argil_err_t solver_init(solver_t *s, const int32_t nc[3], const int32_t ns[3], const solver_cfg_t *cfg)
{
    memset(s, 0, sizeof(*s));
    int64_t vc = 1, vs = 1;
    for (int a = 0; a < 3; a++) {
        if (nc[a] < 4 || ns[a] < 1)
            return ARGIL_ERR_ARG;
        vc *= nc[a];
        vs *= ns[a];
        if (vc > SOLVER_BOX_MAX || vs > SOLVER_BOX_MAX)
            return ARGIL_ERR_ARG;
    }
    if (cfg == NULL || !solver_cfg_ok(cfg))
        return ARGIL_ERR_ARG;
    memcpy(s->nc, nc, sizeof(s->nc));
    memcpy(s->ns, ns, sizeof(s->ns));
    s->ncoef = (size_t)vc;
    s->nsamp = (size_t)vs;
    s->cfg = *cfg;
    s->dt_prev_s = cfg->dt_s;
    s->k_rest_n = 1.0f;
    s->coupling_n = 2.0f;
    bool ok = true;
    for (int a = 0; a < 3; a++) {
        s->tap_first[a] = calloc((size_t)ns[a], sizeof(int32_t));
        s->tap_w[a] = calloc((size_t)ns[a] * 4, sizeof(float));
        s->kedge[a] = calloc(s->nsamp, sizeof(float));
        s->tapt_lo[a] = calloc((size_t)nc[a], sizeof(int32_t));
        s->tapt_hi[a] = calloc((size_t)nc[a], sizeof(int32_t));
        ok = ok && s->tap_first[a] && s->tap_w[a] && s->kedge[a] && s->tapt_lo[a] && s->tapt_hi[a];
    }
    s->kdiag = calloc(s->nsamp, sizeof(float));
    s->sdiag = calloc(s->nsamp, sizeof(float));
    s->p = calloc(s->ncoef, sizeof(float));
    s->p_prev = calloc(s->ncoef, sizeof(float));
    s->fixed = calloc(s->ncoef, 1);
    s->mlump = calloc(s->ncoef, sizeof(float));
    s->dlump = calloc(s->ncoef, sizeof(float));
    s->d_fixed = calloc(s->nsamp, sizeof(float));
    s->mass_kg = malloc(s->nsamp * sizeof(float));
    s->damp_n_s = malloc(s->nsamp * sizeof(float));
    s->kscale = malloc(s->nsamp * sizeof(float));
    s->rest = calloc(s->nsamp, sizeof(float));
    s->force_n = calloc(s->nsamp, sizeof(float));
    for (int i = 0; i < 6; i++) {
        s->w_nc[i] = calloc(s->ncoef, sizeof(float));
        ok = ok && s->w_nc[i];
    }
    for (int i = 0; i < 4; i++) {
        s->w_ns[i] = calloc(s->nsamp, sizeof(float));
        ok = ok && s->w_ns[i];
    }
    const size_t mid = (size_t)ns[0] * nc[1] * nc[2] + (size_t)ns[0] * ns[1] * nc[2];
    s->w_mid = malloc(mid * sizeof(float));
    ok = ok && s->kdiag && s->sdiag && s->p && s->p_prev && s->fixed && s->mlump && s->dlump && s->d_fixed && s->mass_kg &&
         s->damp_n_s && s->kscale && s->rest && s->force_n && s->w_mid;
    if (!ok) {
        solver_free(s);
        return ARGIL_ERR_NOMEM;
    }
    for (size_t i = 0; i < s->nsamp; i++) {
        s->mass_kg[i] = 1.0e-3f;
        s->damp_n_s[i] = 0.05f;
        s->kscale[i] = 1.0f;
    }
    solver_material_changed(s);
    /* the taps are set by the caller next: A and Aᵀ gather from them directly until the next
     * solver_material_changed builds the bands (a band never holds taps older than that call) */
    s->band_a.nchunk = s->band_at.nchunk = 0;
    return ARGIL_OK;
}

/* SOLVER_BAND floats as one value (gcc and clang vector extension: one AVX register, or two SSE). */
typedef float solver_v8_t __attribute__((vector_size(SOLVER_BAND * sizeof(float))));

/* Each of rows rows: dst (dst_n floats) = the band's matrix times src (src_n floats). Every output
 * sums its inputs in increasing order from 0, the zero weights adding exact zeros, so it equals
 * the 4-tap gather w0 q0 + w1 q1 + w2 q2 + w3 q3 (and the scatter of Aᵀ) bit for bit. */
SOLVER_HOT static void solver_band_rows(const solver_band_t *b, const float *restrict src, size_t src_n,
                                        float *restrict dst, size_t dst_n, size_t rows)
{
    for (size_t r = 0; r < rows; r++) {
        const float *restrict sr = src + r * src_n;
        float *restrict dr = dst + r * dst_n;
        const float *restrict wc = b->w;
        for (size_t c = 0; c < b->nchunk; c++) {
            solver_v8_t acc = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
            const float *q = sr + b->lo[c];
            for (int32_t j = 0; j < b->n[c]; j++, wc += SOLVER_BAND) {
                solver_v8_t w;
                memcpy(&w, wc, sizeof(w));
                acc += w * q[j];
            }
            const size_t o = SOLVER_BAND * c;
            if (dst_n - o >= SOLVER_BAND)
                memcpy(dr + o, &acc, sizeof(acc));
            else
                memcpy(dr + o, &acc, sizeof(float) * (dst_n - o));
        }
    }
}

/* Weight of input `in` for output `out` along x: A (transpose = false: out a sample, in a
 * coefficient) or Aᵀ (out a coefficient, in a sample). */
static float solver_x_weight(const solver_t *s, bool transpose, int32_t out, int32_t in)
{
    const int32_t smp = transpose ? in : out, coef = transpose ? out : in;
    const int32_t t = coef - s->tap_first[0][smp];
    return t >= 0 && t < 4 ? s->tap_w[0][4 * smp + t] : 0.0f;
}

/* Builds the band of A (transpose = false) or Aᵀ along x from the taps; false when out of memory
 * (the band is then left empty and the gather loops run instead). */
static bool solver_band_build(solver_t *s, solver_band_t *b, bool transpose)
{
    const int32_t nout = transpose ? s->nc[0] : s->ns[0];
    const size_t nchunk = ((size_t)nout + SOLVER_BAND - 1) / SOLVER_BAND;
    int32_t *lo = realloc(b->lo, nchunk * sizeof(int32_t)), *n = lo ? realloc(b->n, nchunk * sizeof(int32_t)) : NULL;
    if (lo != NULL)
        b->lo = lo;
    if (n != NULL)
        b->n = n;
    if (lo == NULL || n == NULL)
        return false;
    size_t total = 0;
    for (size_t c = 0; c < nchunk; c++) {
        int32_t a = INT32_MAX, z = INT32_MIN; /* inputs [a, z) the chunk's outputs reach */
        for (int32_t o = (int32_t)(SOLVER_BAND * c); o < nout && o < (int32_t)(SOLVER_BAND * (c + 1)); o++) {
            const int32_t first = transpose ? s->tapt_lo[0][o] : s->tap_first[0][o];
            const int32_t last = transpose ? s->tapt_hi[0][o] : s->tap_first[0][o] + 4;
            if (first < last) {
                a = first < a ? first : a;
                z = last > z ? last : z;
            }
        }
        lo[c] = a < z ? a : 0;
        n[c] = a < z ? z - a : 0;
        total += (size_t)n[c];
    }
    if (total * SOLVER_BAND > b->w_cap) {
        float *w = realloc(b->w, total * SOLVER_BAND * sizeof(float));
        if (w == NULL)
            return false;
        b->w = w;
        b->w_cap = total * SOLVER_BAND;
    }
    float *w = b->w;
    for (size_t c = 0; c < nchunk; c++)
        for (int32_t j = 0; j < n[c]; j++, w += SOLVER_BAND)
            for (int32_t k = 0; k < SOLVER_BAND; k++) {
                const int32_t o = (int32_t)(SOLVER_BAND * c) + k;
                w[k] = o < nout ? solver_x_weight(s, transpose, o, lo[c] + j) : 0.0f;
            }
    b->nchunk = nchunk;
    return true;
}

/* d = A x (samples from coefficients), separable: x, then y, then z. */
SOLVER_HOT static void solver_apply_A(solver_t *s, const float *restrict x, float *restrict y)
{
    const int32_t *nc = s->nc, *ns = s->ns;
    float *T1 = s->w_mid, *T2 = T1 + (size_t)ns[0] * nc[1] * nc[2];
    const size_t rows = (size_t)nc[1] * nc[2];
    if (s->band_a.nchunk > 0)
        solver_band_rows(&s->band_a, x, (size_t)nc[0], T1, (size_t)ns[0], rows);
    else
        for (size_t r = 0; r < rows; r++) {
            const float *src = x + r * nc[0];
            float *dst = T1 + r * ns[0];
            for (int32_t i = 0; i < ns[0]; i++) {
                const float *w = s->tap_w[0] + 4 * i;
                const float *q = src + s->tap_first[0][i];
                dst[i] = w[0] * q[0] + w[1] * q[1] + w[2] * q[2] + w[3] * q[3];
            }
        }
    const size_t st = (size_t)ns[0];
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t j = 0; j < ns[1]; j++) {
            const float *w = s->tap_w[1] + 4 * j;
            const float *q = T1 + st * ((size_t)s->tap_first[1][j] + (size_t)nc[1] * z);
            float *dst = T2 + st * ((size_t)j + (size_t)ns[1] * z);
            for (int32_t i = 0; i < ns[0]; i++)
                dst[i] = w[0] * q[i] + w[1] * q[i + st] + w[2] * q[i + 2 * st] + w[3] * q[i + 3 * st];
        }
    const size_t plane = (size_t)ns[0] * ns[1];
    for (int32_t k = 0; k < ns[2]; k++) {
        const float *w = s->tap_w[2] + 4 * k;
        const float *q = T2 + plane * (size_t)s->tap_first[2][k];
        float *dst = y + plane * (size_t)k;
        for (size_t i = 0; i < plane; i++)
            dst[i] = w[0] * q[i] + w[1] * q[i + plane] + w[2] * q[i + 2 * plane] + w[3] * q[i + 3 * plane];
    }
}

#define SOLVER_GATHER_MAX 32

/* q = Σ_k w_k src_k over len floats (q += when acc), four inputs a pass: q is written n/4 times,
 * not n. */
SOLVER_HOT static void solver_gather(float *restrict q, const float *const *src, const float *w, int n,
                                     size_t len, bool acc)
{
    if (n == 0) {
        if (!acc)
            memset(q, 0, sizeof(float) * len);
        return;
    }
    for (int g = 0; g < n; g += 4) {
        const int m = n - g < 4 ? n - g : 4; /* missing inputs: weight 0 on the first one */
        const float *restrict s0 = src[g], *restrict s1 = src[g + (m > 1)], *restrict s2 = src[g + 2 * (m > 2)],
                          *restrict s3 = src[g + 3 * (m > 3)];
        const float w0 = w[g], w1 = m > 1 ? w[g + 1] : 0.0f, w2 = m > 2 ? w[g + 2] : 0.0f,
                    w3 = m > 3 ? w[g + 3] : 0.0f;
        if (g == 0 && !acc)
            for (size_t i = 0; i < len; i++)
                q[i] = w0 * s0[i] + w1 * s1[i] + w2 * s2[i] + w3 * s3[i];
        else
            for (size_t i = 0; i < len; i++)
                q[i] += w0 * s0[i] + w1 * s1[i] + w2 * s2[i] + w3 * s3[i];
    }
}

/* q (len floats) = the sum over the samples k that coefficient c touches along axis a of their
 * tap weight times the len floats at src + len * k. */
SOLVER_HOT static void solver_gather_taps(const solver_t *s, int a, int32_t c, float *restrict q,
                                          const float *src, size_t len)
{
    const float *gs[SOLVER_GATHER_MAX];
    float gw[SOLVER_GATHER_MAX];
    int n = 0;
    bool acc = false;
    for (int32_t k = s->tapt_lo[a][c]; k < s->tapt_hi[a][c]; k++) {
        const int32_t j = c - s->tap_first[a][k];
        if (j < 0 || j > 3)
            continue;
        gw[n] = s->tap_w[a][4 * k + j];
        gs[n++] = src + len * (size_t)k;
        if (n == SOLVER_GATHER_MAX) {
            solver_gather(q, gs, gw, n, len, acc);
            n = 0;
            acc = true;
        }
    }
    solver_gather(q, gs, gw, n, len, acc);
}

/* x = Aᵀ y (coefficients from samples), the transpose of solver_apply_A. */
SOLVER_HOT static void solver_apply_At(solver_t *s, const float *restrict y, float *restrict x)
{
    const float *const tw[3] = {s->tap_w[0], s->tap_w[1], s->tap_w[2]};
    const int32_t *nc = s->nc, *ns = s->ns;
    float *T1 = s->w_mid, *T2 = T1 + (size_t)ns[0] * nc[1] * nc[2];
    const size_t plane = (size_t)ns[0] * ns[1];
    /* gathered per coefficient plane (each output plane written once, four input planes a pass) */
    for (int32_t c = 0; c < nc[2]; c++)
        solver_gather_taps(s, 2, c, T2 + plane * (size_t)c, y, plane);
    const size_t st = (size_t)ns[0];
    for (int32_t z = 0; z < nc[2]; z++)
        for (int32_t c = 0; c < nc[1]; c++)
            solver_gather_taps(s, 1, c, T1 + st * ((size_t)c + (size_t)nc[1] * z),
                               T2 + st * (size_t)ns[1] * (size_t)z, st);
    const size_t rows = (size_t)nc[1] * nc[2];
    if (s->band_at.nchunk > 0) {
        solver_band_rows(&s->band_at, T1, (size_t)ns[0], x, (size_t)nc[0], rows);
        return;
    }
    memset(x, 0, sizeof(float) * s->ncoef);
    for (size_t r = 0; r < rows; r++) {
        const float *src = T1 + r * ns[0];
        float *dst = x + r * nc[0];
        for (int32_t i = 0; i < ns[0]; i++) {
            const float *w = tw[0] + 4 * i;
            float *q = dst + s->tap_first[0][i];
            const float v = src[i];
            q[0] += w[0] * v;
            q[1] += w[1] * v;
            q[2] += w[2] * v;
            q[3] += w[3] * v;
        }
    }
}

void solver_material_changed(solver_t *s)
{
    s->band_a.nchunk = s->band_at.nchunk = 0; /* the gather loops until the bands are rebuilt */
    for (int a = 0; a < 3; a++) { /* the transpose of the taps: samples each coefficient reaches */
        for (int32_t c = 0; c < s->nc[a]; c++) {
            s->tapt_lo[a][c] = s->ns[a];
            s->tapt_hi[a][c] = 0;
        }
        for (int32_t k = 0; k < s->ns[a]; k++)
            for (int32_t j = 0; j < 4; j++) {
                const int32_t c = s->tap_first[a][k] + j;
                if (c < 0 || c >= s->nc[a])
                    continue;
                s->tapt_lo[a][c] = k < s->tapt_lo[a][c] ? k : s->tapt_lo[a][c];
                s->tapt_hi[a][c] = k + 1 > s->tapt_hi[a][c] ? k + 1 : s->tapt_hi[a][c];
            }
    }
    if (!solver_band_build(s, &s->band_a, false) || !solver_band_build(s, &s->band_at, true))
        s->band_a.nchunk = s->band_at.nchunk = 0;
    const size_t stride[3] = {1, (size_t)s->ns[0], (size_t)s->ns[0] * s->ns[1]};
    for (int a = 0; a < 3; a++) {
        for (int32_t z = 0; z < s->ns[2]; z++)
            for (int32_t y = 0; y < s->ns[1]; y++)
                for (int32_t x = 0; x < s->ns[0]; x++) {
                    const int32_t c[3] = {x, y, z};
                    const size_t i = (size_t)x + stride[1] * y + stride[2] * z;
                    /* the 4D spring between neighbours; with fixed sample positions only its
                     * density component acts (Hua & Qin §5.1): stiffness = mean of the two scales */
                    s->kedge[a][i] = c[a] + 1 < s->ns[a]
                                         ? 0.5f * s->coupling_n * (s->kscale[i] + s->kscale[i + stride[a]])
                                         : 0.0f;
                }
    }
    for (size_t i = 0; i < s->nsamp; i++) {
        float k = s->k_rest_n * s->kscale[i];
        for (int a = 0; a < 3; a++)
            k += s->kedge[a][i] + (i >= stride[a] ? s->kedge[a][i - stride[a]] : 0.0f);
        s->kdiag[i] = k;
    }
    /* lumped mass Aᵀ (m ⊙ A 1) for the explicit solver */
    float *one = s->w_nc[5], *d = s->w_ns[3], *a1 = s->w_ns[2];
    for (size_t i = 0; i < s->ncoef; i++)
        one[i] = 1.0f;
    solver_apply_A(s, one, a1);
    for (size_t i = 0; i < s->nsamp; i++)
        d[i] = a1[i] * s->mass_kg[i];
    solver_apply_At(s, d, s->mlump);
    for (size_t i = 0; i < s->nsamp; i++)
        d[i] = a1[i] * s->damp_n_s[i];
    solver_apply_At(s, d, s->dlump);
    for (size_t i = 0; i < s->ncoef; i++)
        if (!(s->dlump[i] >= 0.0f))
            s->dlump[i] = 0.0f;
    for (size_t i = 0; i < s->ncoef; i++)
        if (!(s->mlump[i] > 1.0e-12f))
            s->mlump[i] = 1.0e-12f;
}

/* diag_i e_i - c Σ_a (k_a,i e_{i+a} + k_a,i-a e_{i-a}) at sample i, every neighbour checked
 * against the array ends. */
static float solver_K_at(const solver_t *s, const float *diag, float c, const float *e, size_t i)
{
    const size_t st[3] = {1, (size_t)s->ns[0], (size_t)s->ns[0] * s->ns[1]};
    float v = 0.0f;
    for (int a = 0; a < 3; a++) {
        if (i + st[a] < s->nsamp)
            v += s->kedge[a][i] * e[i + st[a]];
        if (i >= st[a])
            v += s->kedge[a][i - st[a]] * e[i - st[a]];
    }
    return diag[i] * e[i] - c * v;
}

/* out = diag ⊙ e - c Σ neighbour springs: with diag = kdiag and c = 1 this is K e on samples, the
 * rest springs plus the six neighbour springs (Hua & Qin eq. 6), (K e)_i = kdiag_i e_i -
 * Σ_a k_a,i e_{i+a} - k_a,i-a e_{i-a}; with diag = sdiag and c = 2 dt² it is the whole sample
 * operator of eq. 12 in one pass. Springs across the region's border have k = 0, so only the
 * first and last planes (and within them the first and last rows) need bounds checks. */
SOLVER_HOT static void solver_apply_Kd(const solver_t *s, const float *restrict diag, float c,
                                       const float *restrict e, float *restrict out)
{
    const size_t n = s->nsamp, sy = (size_t)s->ns[0], sz = sy * (size_t)s->ns[1];
    if (n < 2 * sz) { /* a single plane: every neighbour checked */
        for (size_t i = 0; i < n; i++)
            out[i] = solver_K_at(s, diag, c, e, i);
        return;
    }
    const float *restrict kx = s->kedge[0], *restrict ky = s->kedge[1], *restrict kz = s->kedge[2];
    for (size_t i = 0; i < sy; i++) /* first row */
        out[i] = solver_K_at(s, diag, c, e, i);
    for (size_t i = sy; i < sz; i++) /* first plane: no neighbour below */
        out[i] = diag[i] * e[i] - c * (kx[i] * e[i + 1] + kx[i - 1] * e[i - 1] + ky[i] * e[i + sy] +
                                       ky[i - sy] * e[i - sy] + kz[i] * e[i + sz]);
    for (size_t i = sz; i < n - sz; i++)
        out[i] = diag[i] * e[i] - c * (kx[i] * e[i + 1] + kx[i - 1] * e[i - 1] + ky[i] * e[i + sy] +
                                       ky[i - sy] * e[i - sy] + kz[i] * e[i + sz] + kz[i - sz] * e[i - sz]);
    for (size_t i = n - sz; i < n - sy; i++) /* last plane: no neighbour above */
        out[i] = diag[i] * e[i] - c * (kx[i] * e[i + 1] + kx[i - 1] * e[i - 1] + ky[i] * e[i + sy] +
                                       ky[i - sy] * e[i - sy] + kz[i - sz] * e[i - sz]);
    for (size_t i = n - sy; i < n; i++) /* last row */
        out[i] = solver_K_at(s, diag, c, e, i);
}

static void solver_apply_K(const solver_t *s, const float *e, float *out)
{
    solver_apply_Kd(s, s->kdiag, 1.0f, e, out);
}

void solver_densities(solver_t *s, float *d)
{
    solver_apply_A(s, s->p, d);
    for (size_t i = 0; i < s->nsamp; i++)
        d[i] += s->d_fixed[i];
}

static float solver_row_dot(const solver_row_t *r, const float *x)
{
    float v = 0.0f;
    for (int32_t j = 0; j < r->n; j++)
        v += r->w[j] * x[r->idx[j]];
    return v;
}

static argil_err_t solver_row_check(const solver_t *s, const solver_row_t *r)
{
    if (r->n < 1 || r->n > SOLVER_ROW_MAX || !isfinite(r->target) || !isfinite(r->k_n) || r->k_n < 0.0f)
        return ARGIL_ERR_ARG;
    for (int32_t j = 0; j < r->n; j++)
        if (r->idx[j] < 0 || (size_t)r->idx[j] >= s->ncoef || !isfinite(r->w[j]))
            return ARGIL_ERR_ARG;
    return ARGIL_OK;
}

static argil_err_t solver_push(solver_row_t **rows, int32_t *n, int32_t *cap, const solver_row_t *r)
{
    if (*n == *cap) {
        const int32_t nc = *cap ? 2 * *cap : 16;
        solver_row_t *p = realloc(*rows, sizeof(solver_row_t) * (size_t)nc);
        if (p == NULL)
            return ARGIL_ERR_NOMEM;
        *rows = p;
        *cap = nc;
    }
    (*rows)[(*n)++] = *r;
    return ARGIL_OK;
}

argil_err_t solver_add_soft(solver_t *s, const solver_row_t *row)
{
    argil_err_t e = solver_row_check(s, row);
    return e != ARGIL_OK ? e : solver_push(&s->soft, &s->nsoft, &s->soft_cap, row);
}

argil_err_t solver_add_hard(solver_t *s, const solver_row_t *row)
{
    argil_err_t e = solver_row_check(s, row);
    if (e != ARGIL_OK)
        return e;
    solver_row_t r = *row;
    r.pivot = 0;
    for (int32_t j = 1; j < r.n; j++)
        if (fabsf(r.w[j]) > fabsf(r.w[r.pivot]))
            r.pivot = j;
    const int32_t piv = r.idx[r.pivot];
    if (!(fabsf(r.w[r.pivot]) > 1.0e-6f) || s->fixed[piv])
        return ARGIL_ERR_ARG;
    for (int32_t j = 0; j < r.n; j++)
        if (j != r.pivot && r.idx[j] == piv)
            return ARGIL_ERR_ARG;
    for (int32_t h = 0; h < s->nhard; h++) {
        const solver_row_t *o = &s->hard[h];
        const int32_t opiv = o->idx[o->pivot];
        for (int32_t j = 0; j < o->n; j++)
            if (o->idx[j] == piv)
                return ARGIL_ERR_ARG;
        for (int32_t j = 0; j < r.n; j++)
            if (r.idx[j] == opiv)
                return ARGIL_ERR_ARG;
    }
    return solver_push(&s->hard, &s->nhard, &s->hard_cap, &r);
}

/* d = G h (+ h0 when affine): pivots from their rows (Hua & Qin eq. 14). */
static void solver_expand(const solver_t *s, float *x, bool affine)
{
    for (int32_t h = 0; h < s->nhard; h++) {
        const solver_row_t *r = &s->hard[h];
        const int32_t piv = r->idx[r->pivot];
        float acc = affine ? -r->target : 0.0f;
        for (int32_t j = 0; j < r->n; j++)
            if (j != r->pivot)
                acc += r->w[j] * x[r->idx[j]];
        x[piv] = -acc / r->w[r->pivot];
    }
}

/* y = Gᵀ y, with the eliminated and fixed entries zeroed (eq. 15-16). */
SOLVER_HOT static void solver_reduce(const solver_t *s, float *y)
{
    for (int32_t h = 0; h < s->nhard; h++) {
        const solver_row_t *r = &s->hard[h];
        const int32_t piv = r->idx[r->pivot];
        const float yp = y[piv];
        for (int32_t j = 0; j < r->n; j++)
            if (j != r->pivot)
                y[r->idx[j]] -= r->w[j] / r->w[r->pivot] * yp;
        y[piv] = 0.0f;
    }
    const uint8_t *restrict fx = s->fixed;
    for (size_t i = 0; i < s->ncoef; i++)
        y[i] = fx[i] ? 0.0f : y[i];
}

/* y = (2 M~ + dt D~ + 2 dt² K~) x, matrix-free (left side of Hua & Qin eq. 12); sdiag must hold
 * 2 m + dt D + 2 dt² kdiag for this dt (solver_step_implicit sets it). */
static void solver_apply_S(solver_t *s, const float *x, float *y, float dt)
{
    float *d = s->w_ns[0], *kd = s->w_ns[1];
    const float c2 = 2.0f * dt * dt;
    solver_apply_A(s, x, d);
    solver_apply_Kd(s, s->sdiag, c2, d, kd);
    solver_apply_At(s, kd, y);
    for (int32_t r = 0; r < s->nsoft; r++) {
        const solver_row_t *row = &s->soft[r];
        const float v = c2 * row->k_n * solver_row_dot(row, x);
        for (int32_t j = 0; j < row->n; j++)
            y[row->idx[j]] += row->w[j] * v;
    }
}

/* Σ a_i b_i in double, four partial sums (so the loop vectorises; the order is fixed, so the
 * result is the same on every run and CPU). */
SOLVER_HOT static double solver_dot(const float *restrict a, const float *restrict b, size_t n)
{
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; k++)
            v[k] += (double)a[i + k] * b[i + k];
    for (; i < n; i++)
        v[0] += (double)a[i] * b[i];
    return (v[0] + v[1]) + (v[2] + v[3]);
}

/* x += alpha q, r -= alpha Sq in one pass; returns |r|² */
SOLVER_HOT static double solver_cg_update(float *restrict x, float *restrict r, const float *restrict q,
                                          const float *restrict Sq, float alpha, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        x[i] += alpha * q[i];
        r[i] -= alpha * Sq[i];
    }
    return solver_dot(r, r, n);
}

/* q = r + beta q */
SOLVER_HOT static void solver_cg_dir(float *restrict q, const float *restrict r, float beta, size_t n)
{
    for (size_t i = 0; i < n; i++)
        q[i] = r[i] + beta * q[i];
}

/* The sample part of eq. 12's right side, with ke = K (r - d_fixed) on entry:
 * ke = 2dt² (f + ke) + 4 m dA - (2 m - dt D) dB; and sdiag = 2 m + dt D + 2dt² kdiag. */
SOLVER_HOT static void solver_rhs_samples(solver_t *s, float dt, const float *restrict dA,
                                          const float *restrict dB, float *restrict ke)
{
    const float c2 = 2.0f * dt * dt;
    const float *restrict m = s->mass_kg, *restrict dmp = s->damp_n_s, *restrict fn = s->force_n,
                          *restrict kd = s->kdiag;
    float *restrict sd = s->sdiag;
    for (size_t i = 0; i < s->nsamp; i++) {
        ke[i] = c2 * (fn[i] + ke[i]) + 4.0f * m[i] * dA[i] - (2.0f * m[i] - dt * dmp[i]) * dB[i];
        sd[i] = 2.0f * m[i] + dt * dmp[i] + c2 * kd[i];
    }
}

SOLVER_HOT static void solver_sub(float *restrict out, const float *restrict a, const float *restrict b, size_t n)
{
    for (size_t i = 0; i < n; i++)
        out[i] = a[i] - b[i];
}

/* p_prev moved so that (p - p_prev) / dt keeps the velocity when the step changes. */
static void solver_prev_for_dt(const solver_t *s, float dt, float *pp)
{
    const float q = dt / s->dt_prev_s;
    for (size_t i = 0; i < s->ncoef; i++)
        pp[i] = s->p[i] - (s->p[i] - s->p_prev[i]) * q;
}

static float solver_max_acc(const solver_t *s, const float *pn, const float *pp, float dt)
{
    float m = 0.0f;
    const float inv = 1.0f / (dt * dt);
    for (size_t i = 0; i < s->ncoef; i++) {
        const float a = fabsf((pn[i] - 2.0f * s->p[i] + pp[i]) * inv);
        if (a > m || isnan(a))
            m = isnan(a) ? INFINITY : a;
    }
    return m;
}

/* Makes p_new, reached after dt, the coefficients (the current ones become the previous);
 * ARGIL_ERR_NONFINITE, changing nothing, when p_new holds a NaN or an infinity. */
static argil_err_t solver_commit(solver_t *s, const float *p_new, float dt)
{
    for (size_t i = 0; i < s->ncoef; i++)
        if (!isfinite(p_new[i]))
            return ARGIL_ERR_NONFINITE;
    memcpy(s->p_prev, s->p, sizeof(float) * s->ncoef);
    memcpy(s->p, p_new, sizeof(float) * s->ncoef);
    s->dt_prev_s = dt;
    return ARGIL_OK;
}

argil_err_t solver_step_implicit(solver_t *s)
{
    float *pp = s->w_nc[0], *rhs = s->w_nc[1], *x = s->w_nc[2], *r = s->w_nc[3], *q = s->w_nc[4],
          *Sq = s->w_nc[5];
    float *dA = s->w_ns[2], *dB = s->w_ns[3];
    s->stats.halvings = 0;
    for (;;) {
        const float dt = s->cfg.dt_s;
        solver_prev_for_dt(s, dt, pp);
        /* right side of eq. 12: 2dt² f_p + 4 M~ p_i - (2 M~ - dt D~) p_{i-1}, with
         * f_p = Aᵀ (f + K (r - d_fixed)) (eq. 8, 11) */
        solver_apply_A(s, s->p, dA);
        solver_apply_A(s, pp, dB);
        float *e = s->w_ns[0], *ke = s->w_ns[1];
        solver_sub(e, s->rest, s->d_fixed, s->nsamp);
        solver_apply_K(s, e, ke);
        const float c2 = 2.0f * dt * dt;
        solver_rhs_samples(s, dt, dA, dB, ke);
        solver_apply_At(s, ke, rhs);
        for (int32_t k = 0; k < s->nsoft; k++) {
            const solver_row_t *row = &s->soft[k];
            for (int32_t j = 0; j < row->n; j++)
                rhs[row->idx[j]] += c2 * row->k_n * row->target * row->w[j];
        }
        /* warm start: the previous motion continued; fixed coefficients stay (or go where
         * fixed_next says); pivots from rows */
        for (size_t i = 0; i < s->ncoef; i++)
            x[i] = s->fixed[i] ? (s->fixed_next ? s->fixed_next[i] : s->p[i])
                               : 2.0f * s->p[i] - pp[i];
        solver_expand(s, x, true);
        solver_apply_S(s, x, Sq, dt);
        solver_sub(r, rhs, Sq, s->ncoef);
        solver_reduce(s, r);
        solver_reduce(s, rhs);
        const double bnorm = sqrt(solver_dot(rhs, rhs, s->ncoef));
        double rr = solver_dot(r, r, s->ncoef);
        memcpy(q, r, sizeof(float) * s->ncoef);
        int32_t it = 0;
        const double tol2 = (double)s->cfg.cg_tol * s->cfg.cg_tol * bnorm * bnorm;
        /* conjugate gradients on the reduced system G'ᵀ S G' δ = Gᵀ r (eq. 16) */
        while (it < s->cfg.cg_iters_max && rr > tol2 && rr > 0.0) {
            solver_expand(s, q, false);
            solver_apply_S(s, q, Sq, dt);
            solver_reduce(s, Sq);
            const double qSq = solver_dot(q, Sq, s->ncoef);
            if (!(qSq > 0.0))
                break;
            const double rr_new = solver_cg_update(x, r, q, Sq, (float)(rr / qSq), s->ncoef);
            const double beta = rr_new / rr;
            rr = rr_new;
            solver_cg_dir(q, r, (float)beta, s->ncoef);
            for (int32_t h = 0; h < s->nhard; h++)
                q[s->hard[h].idx[s->hard[h].pivot]] = 0.0f;
            it++;
        }
        solver_expand(s, x, true);
        const float acc = solver_max_acc(s, x, pp, dt);
        if (acc > s->cfg.acc_threshold && dt * 0.5f >= s->cfg.dt_min_s) {
            s->cfg.dt_s = dt * 0.5f; /* Hua & Qin §7: halve the step while |p''| is too large */
            s->stats.halvings++;
            continue;
        }
        if (solver_commit(s, x, dt) != ARGIL_OK)
            return ARGIL_ERR_NONFINITE;
        s->stats.cg_iters = it;
        s->stats.residual = bnorm > 0.0 ? (float)(sqrt(rr) / bnorm) : 0.0f;
        s->stats.max_acc = acc;
        return ARGIL_OK;
    }
}

/* F = Aᵀ (f - K (A p + d_fixed - r)) - D_L v - soft springs: the net force on coefficients,
 * with mass and damping lumped alike so every mode keeps the material's damping ratio. */
static void solver_force(solver_t *s, const float *p, const float *v, float *F)
{
    float *d = s->w_ns[0], *kd = s->w_ns[1];
    solver_apply_A(s, p, d);
    for (size_t i = 0; i < s->nsamp; i++)
        d[i] += s->d_fixed[i] - s->rest[i];
    solver_apply_K(s, d, kd);
    for (size_t i = 0; i < s->nsamp; i++)
        kd[i] = s->force_n[i] - kd[i];
    solver_apply_At(s, kd, F);
    for (size_t i = 0; i < s->ncoef; i++)
        F[i] -= s->dlump[i] * v[i];
    for (int32_t k = 0; k < s->nsoft; k++) {
        const solver_row_t *row = &s->soft[k];
        const float g = row->k_n * (solver_row_dot(row, p) - row->target);
        for (int32_t j = 0; j < row->n; j++)
            F[row->idx[j]] -= g * row->w[j];
    }
}

argil_err_t solver_step_explicit(solver_t *s)
{
    float *v = s->w_nc[0], *F = s->w_nc[1], *pn = s->w_nc[2];
    s->stats.halvings = 0;
    for (size_t i = 0; i < s->ncoef; i++)
        v[i] = (s->p[i] - s->p_prev[i]) / s->dt_prev_s;
    solver_force(s, s->p, v, F);
    float amax = 0.0f;
    for (size_t i = 0; i < s->ncoef; i++) {
        F[i] = s->fixed[i] ? 0.0f : F[i] / s->mlump[i];
        const float a = fabsf(F[i]);
        if (a > amax || isnan(a))
            amax = isnan(a) ? INFINITY : a;
    }
    while (amax > s->cfg.acc_threshold && s->cfg.dt_s * 0.5f >= s->cfg.dt_min_s) {
        s->cfg.dt_s *= 0.5f; /* Hua & Qin §7 */
        s->stats.halvings++;
    }
    const float dt = s->cfg.dt_s;
    for (size_t i = 0; i < s->ncoef; i++)
        pn[i] = s->p[i] + dt * (v[i] + dt * F[i]); /* semi-implicit Euler */
    solver_expand(s, pn, true);
    if (solver_commit(s, pn, dt) != ARGIL_OK)
        return ARGIL_ERR_NONFINITE;
    s->stats.max_acc = amax;
    return ARGIL_OK;
}

/* Largest eigenvalue of M_L⁻¹ X~ by power iteration, X = K (stiff = true) or D. */
static double solver_power(solver_t *s, bool stiff)
{
    float *x = s->w_nc[3], *y = s->w_nc[4];
    float *d = s->w_ns[2], *kd = s->w_ns[3];
    for (size_t i = 0; i < s->ncoef; i++)
        x[i] = s->fixed[i] ? 0.0f : ((i * 2654435761u) % 1000u) / 1000.0f - 0.5f;
    double lambda = 0.0;
    for (int it = 0; it < 60; it++) {
        solver_apply_A(s, x, d);
        if (stiff) {
            solver_apply_K(s, d, kd);
            solver_apply_At(s, kd, y);
        } else {
            for (size_t i = 0; i < s->ncoef; i++)
                y[i] = s->dlump[i] * x[i];
        }
        if (stiff)
            for (int32_t k = 0; k < s->nsoft; k++) {
                const solver_row_t *row = &s->soft[k];
                const float g = row->k_n * solver_row_dot(row, x);
                for (int32_t j = 0; j < row->n; j++)
                    y[row->idx[j]] += g * row->w[j];
            }
        for (size_t i = 0; i < s->ncoef; i++)
            y[i] = s->fixed[i] ? 0.0f : y[i] / s->mlump[i];
        const double nx = sqrt(solver_dot(x, x, s->ncoef)), ny = sqrt(solver_dot(y, y, s->ncoef));
        if (!(nx > 0.0) || !(ny > 0.0))
            return 0.0;
        lambda = ny / nx;
        for (size_t i = 0; i < s->ncoef; i++)
            x[i] = (float)(y[i] / ny);
    }
    return lambda;
}

float solver_explicit_dt_max_s(solver_t *s)
{
    /* semi-implicit Euler on x'' + γ x' + λ x = 0 is stable while λ dt² + 2 γ dt < 4 */
    const double lambda = solver_power(s, true), gamma = solver_power(s, false);
    if (!(lambda > 0.0))
        return INFINITY;
    return (float)((-gamma + sqrt(gamma * gamma + 4.0 * lambda)) / lambda);
}

argil_err_t solver_init_patch(solver_t *s, const bspline_t *b, const int32_t ns[3],
                              const solver_cfg_t *cfg)
{
    argil_err_t e = solver_init(s, b->n, ns, cfg);
    if (e != ARGIL_OK)
        return e;
    for (int a = 0; a < 3; a++) {
        const double *U = b->knots[a];
        const int32_t n = b->n[a];
        for (int32_t i = 0; i < ns[a]; i++) {
            const double t = ns[a] == 1 ? 0.5 * (U[3] + U[n])
                                        : U[3] + (U[n] - U[3]) * (double)i / (double)(ns[a] - 1);
            const int32_t span = bspline_span(U, n, t);
            double N[4], dN[4];
            bspline_basis(U, span, t, N, dN);
            s->tap_first[a][i] = span - 3;
            for (int j = 0; j < 4; j++)
                s->tap_w[a][4 * i + j] = (float)N[j];
        }
    }
    memcpy(s->p, b->coef, sizeof(float) * s->ncoef);
    memcpy(s->p_prev, b->coef, sizeof(float) * s->ncoef);
    /* the outermost coefficient layers see the domain only through a 1/6 tail of their basis;
     * they are held, as Hua & Qin §3.2 hold a patch's boundary layers */
    for (int32_t z = 0; z < s->nc[2]; z++)
        for (int32_t y = 0; y < s->nc[1]; y++)
            for (int32_t x = 0; x < s->nc[0]; x++)
                if (x == 0 || y == 0 || z == 0 || x == s->nc[0] - 1 || y == s->nc[1] - 1 || z == s->nc[2] - 1)
                    s->fixed[(size_t)x + (size_t)s->nc[0] * ((size_t)y + (size_t)s->nc[1] * z)] = 1;
    float *d = s->w_ns[2];
    solver_apply_A(s, s->p, d);
    memcpy(s->rest, d, sizeof(float) * s->nsamp);
    solver_material_changed(s);
    return ARGIL_OK;
}
