/* Tool application: the union of the tool's poses (stroke points, mirror images) gives one signed
 * distance per point; the action turns it into new coefficients (or colours), then the touched
 * samples are refreshed from the coefficients and the rest shape follows the edit. */
#include "host/model/tools.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/model/cgls.h"

#define TOOL_POSES_MAX 4096
#define TOOL_BOX_MAX ((int64_t)1 << 26)

void tool_params_default(tool_params_t *p, tool_action_t action)
{
    memset(p, 0, sizeof(*p));
    p->action = action;
    p->strength = 0.5f;
    p->rgb[0] = 0.8f;
    p->rgb[1] = 0.3f;
    p->rgb[2] = 0.2f;
    p->stamp.s = 1.0f;   /* tool surface at v = s (v is the distance from the tool centre in radii) */
    p->stamp.m = 0.3f;
    p->stamp.r = 0.5f;
    p->stamp.k = 2.0f;
    p->stamp.n = 0.3f;
    p->depth_m = 0.0f;
    p->alpha = -1.0f;
    p->fit = TOOL_FIT_QUASI;
    p->fit_iters = 6;
}

void tool_pose_at(tool_pose_t *pose, vec3_t pos_m)
{
    memset(pose, 0, sizeof(*pose));
    pose->pos_m = pos_m;
    pose->rot[0][0] = pose->rot[1][1] = pose->rot[2][2] = 1.0f;
}

static float tool_freeform_sd(const tool_freeform_t *ff, vec3_t l)
{
    const float u[3] = {(l.x - ff->origin_m.x) / ff->spacing_m, (l.y - ff->origin_m.y) / ff->spacing_m,
                        (l.z - ff->origin_m.z) / ff->spacing_m};
    int32_t i0[3];
    float t[3];
    for (int a = 0; a < 3; a++) {
        if (!(u[a] >= 0.0f) || !(u[a] <= (float)(ff->dims[a] - 1)))
            return -2.0f * ff->band_m * ff->iso;
        i0[a] = (int32_t)u[a];
        if (i0[a] > ff->dims[a] - 2)
            i0[a] = ff->dims[a] - 2 < 0 ? 0 : ff->dims[a] - 2;
        t[a] = u[a] - (float)i0[a];
    }
    float v = 0.0f; /* Ferley §4.1.2: trilinear reconstruction of the copied field */
    for (int c = 0; c < 8; c++) {
        int32_t q[3];
        float w = 1.0f;
        for (int a = 0; a < 3; a++) {
            const int bit = (c >> a) & 1;
            q[a] = i0[a] + bit < ff->dims[a] ? i0[a] + bit : ff->dims[a] - 1;
            w *= bit ? t[a] : 1.0f - t[a];
        }
        v += w * ff->density[q[0] + (size_t)ff->dims[0] * (q[1] + (size_t)ff->dims[1] * q[2])];
    }
    return (v - ff->iso) * 2.0f * ff->band_m; /* inverse of the ramp profile */
}

float tool_sd(const tool_shape_t *t, vec3_t l)
{
    switch (t->kind) {
    case TOOL_SPHERE:
        return t->radius_m - vec3_norm(l);
    case TOOL_CYLINDER: {
        const float dr = sqrtf(l.x * l.x + l.y * l.y) - t->radius_m, dz = fabsf(l.z) - t->half_len_m;
        const float ox = dr > 0.0f ? dr : 0.0f, oz = dz > 0.0f ? dz : 0.0f;
        const float in = dr > dz ? dr : dz;
        return -(sqrtf(ox * ox + oz * oz) + (in < 0.0f ? in : 0.0f));
    }
    case TOOL_BOX: {
        const float q[3] = {fabsf(l.x) - t->half_m.x, fabsf(l.y) - t->half_m.y, fabsf(l.z) - t->half_m.z};
        float o = 0.0f, mx = q[0];
        for (int a = 0; a < 3; a++) {
            o += q[a] > 0.0f ? q[a] * q[a] : 0.0f;
            mx = q[a] > mx ? q[a] : mx;
        }
        return -(sqrtf(o) + (mx < 0.0f ? mx : 0.0f));
    }
    case TOOL_TORUS: {
        const float qx = sqrtf(l.x * l.x + l.y * l.y) - t->radius_m;
        return t->radius2_m - sqrtf(qx * qx + l.z * l.z);
    }
    case TOOL_CUSTOM:
        return t->custom(t->custom_ctx, l);
    default:
        return tool_freeform_sd(t->freeform, l);
    }
}

float tool_bound_m(const tool_shape_t *t)
{
    switch (t->kind) {
    case TOOL_SPHERE:
        return t->radius_m;
    case TOOL_CYLINDER:
        return sqrtf(t->radius_m * t->radius_m + t->half_len_m * t->half_len_m);
    case TOOL_BOX:
        return vec3_norm(t->half_m);
    case TOOL_TORUS:
        return t->radius_m + t->radius2_m;
    case TOOL_CUSTOM:
        return t->custom_bound_m;
    default: {
        const tool_freeform_t *ff = t->freeform;
        const vec3_t far = vec3(ff->origin_m.x + ff->spacing_m * (float)(ff->dims[0] - 1),
                                ff->origin_m.y + ff->spacing_m * (float)(ff->dims[1] - 1),
                                ff->origin_m.z + ff->spacing_m * (float)(ff->dims[2] - 1));
        const float a = vec3_norm(ff->origin_m), b = vec3_norm(far);
        return a > b ? a : b;
    }
    }
}

float tool_stamp_def(const tool_stamp_t *st, float v)
{
    /* Ferley et al. Fig. 11, with k read as the slope at v = s */
    const float s = st->s, m = st->m, r = st->r, k = st->k, n = st->n;
    if (v < 0.0f)
        v = 0.0f;
    if (v < s)
        return (s * k - 2.0f) / (s * s * s) * v * v * v + (3.0f - s * k) / (s * s) * v * v - 1.0f;
    if (v < s + m) {
        const float o = v - s;
        return (k * m - 2.0f * n) / (m * m * m) * o * o * o + (3.0f * n - 2.0f * k * m) / (m * m) * o * o + k * o;
    }
    if (v < s + m + r) {
        const float o = v - s - m;
        return 2.0f * n / (r * r * r) * o * o * o - 3.0f * n / (r * r) * o * o + n;
    }
    return 0.0f;
}

static bool tool_shape_ok(const tool_shape_t *t)
{
    switch (t->kind) {
    case TOOL_SPHERE:
        return isfinite(t->radius_m) && t->radius_m > 0.0f;
    case TOOL_CYLINDER:
        return isfinite(t->radius_m) && t->radius_m > 0.0f && isfinite(t->half_len_m) && t->half_len_m > 0.0f;
    case TOOL_BOX:
        return vec3_isfinite(t->half_m) && t->half_m.x > 0.0f && t->half_m.y > 0.0f && t->half_m.z > 0.0f;
    case TOOL_TORUS:
        return isfinite(t->radius_m) && isfinite(t->radius2_m) && t->radius2_m > 0.0f && t->radius_m > 0.0f;
    case TOOL_CUSTOM:
        return t->custom != NULL && isfinite(t->custom_bound_m) && t->custom_bound_m > 0.0f;
    case TOOL_FREEFORM:
        return t->freeform != NULL && t->freeform->density != NULL && t->freeform->dims[0] >= 2 &&
               t->freeform->dims[1] >= 2 && t->freeform->dims[2] >= 2 && t->freeform->spacing_m > 0.0f;
    default:
        return false;
    }
}

/* True for the actions whose per-point rule needs only the old value and the signed distance,
 * so it applies to samples as well as to coefficients (the least-squares fit needs that). */
static bool tool_action_lsq_ok(tool_action_t a)
{
    return a == TOOL_CARVE || a == TOOL_ADD || a == TOOL_TOOTHPASTE || a == TOOL_SOFT_ERASE ||
           a == TOOL_STAMP || a == TOOL_CONTACT;
}

static bool tool_params_ok(const tool_params_t *p)
{
    const tool_stamp_t *s = &p->stamp;
    if (p->fit != TOOL_FIT_QUASI &&
        (p->fit != TOOL_FIT_LSQ || !tool_action_lsq_ok(p->action) || p->fit_iters < 1 ||
         p->fit_iters > TOOL_FIT_ITERS_MAX))
        return false;
    return (unsigned)p->action <= TOOL_CONTACT && isfinite(p->strength) && p->strength >= 0.0f &&
           isfinite(p->depth_m) && isfinite(p->alpha) && isfinite(p->rgb[0]) && isfinite(p->rgb[1]) &&
           isfinite(p->rgb[2]) && vec3_isfinite(p->mirror_origin_m) && (p->mirror >> 3) == 0 &&
           (p->action != TOOL_STAMP || (s->s > 0.0f && s->m > 0.0f && s->r > 0.0f && isfinite(s->k) &&
                                        isfinite(s->n) && isfinite(s->s + s->m + s->r)));
}

/* Local coordinates of x for pose: rotᵀ (x - pos); mirrored poses carry a reflection in rot. */
static vec3_t tool_local(const tool_pose_t *q, vec3_t x)
{
    const vec3_t d = vec3_sub(x, q->pos_m);
    return vec3(q->rot[0][0] * d.x + q->rot[1][0] * d.y + q->rot[2][0] * d.z,
                q->rot[0][1] * d.x + q->rot[1][1] * d.y + q->rot[2][1] * d.z,
                q->rot[0][2] * d.x + q->rot[1][2] * d.y + q->rot[2][2] * d.z);
}

typedef struct {
    const tool_shape_t *t;
    const tool_pose_t *poses;
    size_t n;
    float reach_m;
} tool_union_t;

/* Signed distance of the pose q's tool at x, given d = x - q.pos and dd = |d|²: a sphere needs
 * no rotation (its distance is rotation-invariant; for the axis-aligned and mirrored poses the
 * result is the same float as through tool_local). */
static float tool_pose_sd(const tool_union_t *U, const tool_pose_t *q, vec3_t x, float dd)
{
    return U->t->kind == TOOL_SPHERE ? U->t->radius_m - sqrtf(dd) : tool_sd(U->t, tool_local(q, x));
}

/* Signed distance of the union of all poses at x (-inf when no pose reaches x). */
static float tool_union_sd(const tool_union_t *U, vec3_t x)
{
    float best = -INFINITY;
    const float r2 = U->reach_m * U->reach_m;
    for (size_t i = 0; i < U->n; i++) {
        const vec3_t d = vec3_sub(x, U->poses[i].pos_m);
        const float dd = vec3_dot(d, d);
        if (dd > r2)
            continue;
        const float sd = tool_pose_sd(U, &U->poses[i], x, dd);
        if (sd > best)
            best = sd;
    }
    return best;
}

/* The same over the poses idx[0..m) only (those whose reach holds the row of x). */
static float tool_union_sd_of(const tool_union_t *U, const uint32_t *idx, size_t m, vec3_t x)
{
    float best = -INFINITY;
    const float r2 = U->reach_m * U->reach_m;
    for (size_t k = 0; k < m; k++) {
        const tool_pose_t *q = &U->poses[idx[k]];
        const vec3_t d = vec3_sub(x, q->pos_m);
        const float dd = vec3_dot(d, d);
        if (dd > r2)
            continue;
        const float sd = tool_pose_sd(U, q, x, dd);
        if (sd > best)
            best = sd;
    }
    return best;
}

/* The poses whose reach ball meets the coefficient row at (y_m, z_m) (their indices into idx,
 * count returned) and the part [*x0, *x1) of the row's n coefficients at positions px that
 * they can reach, one coefficient of margin each side for rounding. */
static size_t tool_row_poses(const tool_union_t *U, const float *px, int32_t n, float h, float y_m,
                             float z_m, uint32_t *idx, int32_t *x0, int32_t *x1)
{
    const float r2 = U->reach_m * U->reach_m;
    size_t m = 0;
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < U->n; i++) {
        const float dy = y_m - U->poses[i].pos_m.y, dz = z_m - U->poses[i].pos_m.z;
        const float rem = r2 - (dy * dy + dz * dz);
        if (!(rem >= -1e-6f * r2))
            continue;
        const float half = sqrtf(rem > 0.0f ? rem : 0.0f);
        lo = fminf(lo, U->poses[i].pos_m.x - half);
        hi = fmaxf(hi, U->poses[i].pos_m.x + half);
        idx[m++] = (uint32_t)i;
    }
    *x0 = *x1 = 0;
    if (m == 0 || n == 0)
        return 0;
    const double a = floor(((double)lo - px[0]) / h) - 1.0, b = ceil(((double)hi - px[0]) / h) + 2.0;
    *x0 = a < 0.0 ? 0 : (a > (double)n ? n : (int32_t)a);
    *x1 = b < 0.0 ? 0 : (b > (double)n ? n : (int32_t)b);
    return m;
}

static float tool_clamp01(float v)
{
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

/* New coefficient value from the old one and the union's signed distance at the coefficient
 * (always inlined: the switch on the action is then hoisted out of the callers' loops). */
__attribute__((always_inline)) static inline float tool_action_coef(const field_t *f, const tool_params_t *p,
                                                                    float bound, float pold, float sd,
                                                                    vec3_t x, const float *nb6)
{
    const float phi = field_profile(sd, f->band_m);
    switch (p->action) {
    case TOOL_CARVE:
        return pold < 1.0f - phi ? pold : 1.0f - phi;
    case TOOL_ADD:
        return pold > phi ? pold : phi;
    case TOOL_TOOTHPASTE: /* Ferley §4.2: add the tool's contribution */
        return tool_clamp01(pold + p->strength * phi);
    case TOOL_SOFT_ERASE:
        return tool_clamp01(pold - p->strength * phi);
    case TOOL_SMOOTH: {
        const float avg = (nb6[0] + nb6[1] + nb6[2] + nb6[3] + nb6[4] + nb6[5]) / 6.0f;
        const float a = tool_clamp01(p->strength * phi);
        return pold + a * (avg - pold);
    }
    case TOOL_STAMP: { /* Ferley §4.3: v_deformTool = def(v_tool(P)) */
        const float v = p->stamp.s * (1.0f - sd / bound);
        return tool_clamp01(pold + p->strength * tool_stamp_def(&p->stamp, v));
    }
    case TOOL_CHISEL:
    case TOOL_SQUIRT: { /* shifting the level set by depth along the normal: Δf = |∇f| depth */
        vec3_t g;
        (void)field_eval(f, x, &g);
        const float dv = vec3_norm(g) * p->depth_m * phi;
        return tool_clamp01(p->action == TOOL_CHISEL ? pold - dv : pold + dv);
    }
    case TOOL_INTERIOR_CARVE: /* only coefficients deeper than the density ramp: the shell stays */
        if (pold < 1.0f)
            return pold;
        return pold < 1.0f - phi ? pold : 1.0f - phi;
    case TOOL_CONTACT: { /* Zhang et al. eq. 2-3: h = f + β g, g = α (f_tool - c) in V1, β = 1 there */
        const float c = f->iso;
        if (phi <= c)
            return pold; /* outside V1 g = 0, so β = f_tool / c has nothing to scale */
        return tool_clamp01(pold + p->alpha * (phi - c));
    }
    default:
        return pold;
    }
}

/* True when the action cannot change a coefficient of value pold, whatever the tool: the
 * signed distance need not be computed (carving empty space, adding to full material). */
static bool tool_coef_fixed_point(tool_action_t a, float pold)
{
    switch (a) {
    case TOOL_CARVE:
        return pold <= 0.0f;
    case TOOL_INTERIOR_CARVE:
        return !(pold >= 1.0f);
    case TOOL_ADD:
        return pold >= 1.0f;
    default:
        return false;
    }
}

/* Stores new densities dnew (rows dn_row, planes dn_plane floats apart) for the samples [lo, hi)
 * of sample block key; the rest density moves by the same Δd (a plastic edit); changed values are
 * noted for undo and the block marked dirty. *nchanged counts the samples whose density changed. */
static argil_err_t tool_store_samples(field_t *f, const int32_t key[3], const int32_t lo[3],
                                      const int32_t hi[3], const float *dnew, size_t dn_row,
                                      size_t dn_plane, undo_t *u, size_t *nchanged)
{
    sparse_block_t *b = sparse_find(&f->samp, key);
    const int32_t n0 = hi[0] - lo[0], n1 = hi[1] - lo[1], n2 = hi[2] - lo[2];
    const int32_t off[3] = {lo[0] - key[0] * SPARSE_B, lo[1] - key[1] * SPARSE_B, lo[2] - key[2] * SPARSE_B};
    const float d_def = f->samp.defaults[FS_D];
    const size_t rowb = sizeof(float) * (size_t)n0;
    bool any = false;
    for (int32_t z = 0; z < n2 && !any; z++)
        for (int32_t y = 0; y < n1 && !any; y++) {
            const float *dn = dnew + dn_row * (size_t)y + dn_plane * (size_t)z;
            if (b != NULL) {
                const size_t li = (size_t)off[0] + SPARSE_B * ((size_t)(off[1] + y) + SPARSE_B * (size_t)(off[2] + z));
                any = memcmp(b->data + FS_D * SPARSE_BN + li, dn, rowb) != 0;
            } else {
                for (int32_t x = 0; x < n0 && !any; x++)
                    any = memcmp(&d_def, &dn[x], sizeof(float)) != 0;
            }
        }
    if (!any)
        return ARGIL_OK;
    if (b == NULL) {
        argil_err_t e = sparse_touch(&f->samp, key, &b);
        if (e != ARGIL_OK)
            return e;
    }
    b->dirty = true;
    for (int32_t z = 0; z < n2; z++)
        for (int32_t y = 0; y < n1; y++) {
            const size_t li = (size_t)off[0] + SPARSE_B * ((size_t)(off[1] + y) + SPARSE_B * (size_t)(off[2] + z));
            const float *dn = dnew + dn_row * (size_t)y + dn_plane * (size_t)z;
            float *d = b->data + FS_D * SPARSE_BN + li, *r = b->data + FS_REST * SPARSE_BN + li;
            if (memcmp(d, dn, rowb) == 0)
                continue;
            for (int32_t x = 0; x < n0; x++) {
                if (memcmp(&d[x], &dn[x], sizeof(float)) == 0)
                    continue;
                if (u != NULL) { /* one 12-byte change: undo_note_drest recomputes the rest alike */
                    const int32_t ijk[3] = {lo[0] + x, lo[1] + y, lo[2] + z};
                    const argil_err_t e = undo_note_drest(u, ijk, d[x], dn[x], r[x]);
                    if (e != ARGIL_OK)
                        return e;
                }
                r[x] = r[x] + (dn[x] - d[x]); /* the edit is plastic: the rest shape moves with it */
                d[x] = dn[x];
                (*nchanged)++;
            }
        }
    return ARGIL_OK;
}

/* Marks the sample blocks coefficient c reaches: samples ((c-2)R, (c+2)R) per axis. */
static void tool_mark_reach(const int32_t c[3], int32_t R, const int32_t klo[3], const int32_t kn[3],
                            uint8_t *mark)
{
    int32_t k0[3], k1[3];
    for (int a = 0; a < 3; a++) {
        k0[a] = sparse_block_of((c[a] - 2) * R + 1) - klo[a];
        k1[a] = sparse_block_of((c[a] + 2) * R - 1) - klo[a];
        k0[a] = k0[a] < 0 ? 0 : k0[a];
        k1[a] = k1[a] >= kn[a] ? kn[a] - 1 : k1[a];
    }
    for (int32_t kz = k0[2]; kz <= k1[2]; kz++)
        for (int32_t ky = k0[1]; ky <= k1[1]; ky++)
            for (int32_t kx = k0[0]; kx <= k1[0]; kx++)
                mark[(size_t)kx + (size_t)kn[0] * ((size_t)ky + (size_t)kn[1] * kz)] = 1;
}

/* The boxes of one application: coefficients read [clo, clo+cn), free [blo, blo+bn), samples
 * [slo, shi), sample blocks [klo, klo+kn). */
typedef struct {
    const int32_t *clo, *cn, *blo, *bn, *slo, *shi, *klo, *kn;
} tool_box_t;

/* Zeroes every coefficient of the C box outside the free box. */
static void tool_mask_free(const tool_box_t *B, float *x)
{
    int32_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = B->blo[a] - B->clo[a];
        hi[a] = lo[a] + B->bn[a];
    }
    const size_t row = (size_t)B->cn[0];
    for (int32_t z = 0; z < B->cn[2]; z++)
        for (int32_t y = 0; y < B->cn[1]; y++) {
            float *r = x + row * ((size_t)y + (size_t)B->cn[1] * z);
            if (z < lo[2] || z >= hi[2] || y < lo[1] || y >= hi[1]) {
                memset(r, 0, sizeof(float) * row);
                continue;
            }
            memset(r, 0, sizeof(float) * (size_t)lo[0]);
            memset(r + hi[0], 0, sizeof(float) * (row - (size_t)hi[0]));
        }
}

/* A and Aᵀ of tool_fit_lsq's least squares over the box B; Aᵀ keeps only the free coefficients. */
typedef struct {
    const field_t *f;
    const tool_box_t *B;
    float *tmp;
} tool_fit_op_t;

static void tool_fit_a(void *ctx, const float *p, float *out)
{
    const tool_fit_op_t *o = ctx;
    field_samples_from(o->f, p, o->B->clo, o->B->cn, o->B->slo, o->B->shi, out, o->tmp);
}

static void tool_fit_at(void *ctx, const float *r, float *out)
{
    const tool_fit_op_t *o = ctx;
    field_coefs_from(o->f, r, o->B->slo, o->B->shi, o->B->clo, o->B->cn, out, o->tmp);
    tool_mask_free(o->B, out);
}

/* Hua & Qin §6.2 least-squares fit: the free coefficients minimise Σ_s (A p - d_target)² over the
 * samples they reach, d_target = the action applied to each sample's old density; CGLS from the
 * quasi-interpolated values (the change list on entry), whose result replaces the change list. */
static argil_err_t tool_fit_lsq(field_t *f, const tool_union_t *U, const tool_params_t *p, float bound,
                                const tool_box_t *B, const float *C, uint32_t *ch_ci, float *ch_after,
                                size_t *nch, uint8_t *mark)
{
    int32_t sn[3];
    size_t ns = 1, nc = 1;
    for (int a = 0; a < 3; a++) {
        sn[a] = B->shi[a] - B->slo[a];
        ns *= (size_t)sn[a];
        nc *= (size_t)B->cn[a];
    }
    const size_t ntA = (size_t)sn[0] * B->cn[1] * B->cn[2] + (size_t)sn[0] * sn[1] * B->cn[2];
    const size_t ntT = (size_t)B->cn[0] * sn[1] * sn[2] + (size_t)B->cn[0] * B->cn[1] * sn[2];
    float *buf = malloc(sizeof(float) * (3 * ns + 3 * nc + (ntA > ntT ? ntA : ntT)));
    if (buf == NULL)
        return ARGIL_ERR_NOMEM;
    float *r = buf, *q = r + ns, *dt = q + ns, *P = dt + ns, *g = P + nc, *dir = g + nc, *tmp = dir + nc;
    memcpy(P, C, sizeof(float) * nc);
    for (size_t k = 0; k < *nch; k++)
        P[ch_ci[k]] = ch_after[k];
    /* targets: the action applied to the samples' old densities */
    field_samples_from(f, C, B->clo, B->cn, B->slo, B->shi, dt, tmp);
    size_t i = 0;
    for (int32_t z = 0; z < sn[2]; z++)
        for (int32_t y = 0; y < sn[1]; y++)
            for (int32_t x = 0; x < sn[0]; x++, i++) {
                const int32_t s[3] = {B->slo[0] + x, B->slo[1] + y, B->slo[2] + z};
                const vec3_t xs = field_sample_pos(f, s);
                const float sd = tool_union_sd(U, xs);
                if (sd != -INFINITY && !tool_coef_fixed_point(p->action, dt[i]))
                    dt[i] = tool_action_coef(f, p, bound, dt[i], sd, xs, NULL);
            }
    /* CGLS on A_F p_F = d_target - A_X p_X */
    field_samples_from(f, P, B->clo, B->cn, B->slo, B->shi, r, tmp);
    for (i = 0; i < ns; i++)
        r[i] = dt[i] - r[i];
    tool_fit_op_t o = {f, B, tmp};
    const cgls_op_t op = {tool_fit_a, tool_fit_at, &o, nc, ns};
    (void)cgls_solve(&op, p->fit_iters, P, r, g, dir, q);
    /* the fitted coefficients become the change list */
    *nch = 0;
    size_t nk = 1;
    for (int a = 0; a < 3; a++)
        nk *= (size_t)B->kn[a];
    memset(mark, 0, nk);
    const size_t sy = (size_t)B->cn[0], sz = sy * B->cn[1];
    argil_err_t e = ARGIL_OK;
    for (int32_t z = 0; z < B->bn[2]; z++)
        for (int32_t y = 0; y < B->bn[1]; y++)
            for (int32_t x = 0; x < B->bn[0]; x++) {
                const int32_t c[3] = {B->blo[0] + x, B->blo[1] + y, B->blo[2] + z};
                const size_t ci = (size_t)(c[0] - B->clo[0]) + sy * (size_t)(c[1] - B->clo[1]) +
                                  sz * (size_t)(c[2] - B->clo[2]);
                if (!isfinite(P[ci]))
                    e = ARGIL_ERR_NONFINITE;
                if (memcmp(&P[ci], &C[ci], sizeof(float)) == 0 || e != ARGIL_OK)
                    continue;
                ch_ci[*nch] = (uint32_t)ci;
                ch_after[(*nch)++] = P[ci];
                tool_mark_reach(c, f->ratio, B->klo, B->kn, mark);
            }
    free(buf);
    if (e != ARGIL_OK)
        *nch = 0;
    return e;
}

/* One coefficient action's boxes (named as in tool_box_t; the free box is [blo, blo+bn)) and the
 * arrays it lays out in the field's scratch, kept warm between edits. */
typedef struct {
    int32_t blo[3], bn[3], slo[3], shi[3], clo[3], chi[3], cn[3], klo[3], kn[3];
    size_t nc, nk, nb, naxis;     /* coefficients read, sample blocks, free coefficients, Σ bn */
    size_t sy, sz;                /* C's row and plane strides */
    float *C;                     /* the C box's coefficients */
    uint8_t *mark;                /* the sample blocks a changed coefficient reaches */
    uint32_t *ch_ci;              /* changed: index in C ... */
    float *ch_after;              /* ... and new value */
    size_t nch;
    float *pa[3];                 /* per axis: coefficient positions (m) */
    int32_t *ka[3];               /* per axis: first and last sample block reached */
    uint32_t *row_idx;            /* the poses that reach one row */
    float *run_d, *run_tmp;       /* one run of sample blocks along x: densities, tmp */
} tool_coef_pass_t;

/* The boxes of a coefficient action over the free coefficients [blo, bhi): the samples they
 * reach, the coefficients those samples read, and the sample blocks that hold them. */
static void tool_coef_boxes(const field_t *f, const int32_t blo[3], const int32_t bhi[3],
                            tool_coef_pass_t *P)
{
    field_samples_of_coefs(f, blo, bhi, P->slo, P->shi);
    field_coefs_of_samples(f, P->slo, P->shi, P->clo, P->chi);
    P->nc = 1;
    P->nk = 1;
    for (int a = 0; a < 3; a++) {
        P->blo[a] = blo[a];
        P->bn[a] = bhi[a] - blo[a];
        P->cn[a] = P->chi[a] - P->clo[a];
        P->nc *= (size_t)P->cn[a];
        P->klo[a] = sparse_block_of(P->slo[a]);
        P->kn[a] = sparse_block_of(P->shi[a] - 1) - P->klo[a] + 1;
        P->nk *= (size_t)P->kn[a];
    }
    P->nb = (size_t)P->bn[0] * P->bn[1] * P->bn[2];
    P->naxis = (size_t)P->bn[0] + P->bn[1] + P->bn[2];
    P->sy = (size_t)P->cn[0];
    P->sz = (size_t)P->cn[0] * P->cn[1];
}

/* Lays out the pass's arrays in the field's scratch for n_poses poses; false when the scratch
 * cannot grow. */
static bool tool_coef_scratch(field_t *f, size_t n_poses, tool_coef_pass_t *P)
{
    /* a run of sample blocks along x: its samples, and field_samples_from's tmp (8 samples reach
     * at most (8 - 1) / R + 5 coefficients per axis) */
    const size_t run_ns = (size_t)P->kn[0] * SPARSE_B, run_nc = (SPARSE_B - 1) / (size_t)f->ratio + 5;
    const size_t run_n = run_ns * SPARSE_B * SPARSE_B, run_tmp_n = run_ns * run_nc * (run_nc + SPARSE_B);
    const size_t nc = P->nc, nk = P->nk, nb = P->nb, naxis = P->naxis;
    float *C = field_scratch(f, nc + (nk + 3) / 4 + 2 * nb + 3 * naxis + n_poses + run_n + run_tmp_n);
    if (C == NULL)
        return false;
    P->C = C;
    P->mark = (uint8_t *)(C + nc);
    P->ch_ci = (uint32_t *)(C + nc + (nk + 3) / 4);
    P->ch_after = (float *)(P->ch_ci + nb);
    float *pos = P->ch_after + nb;
    int32_t *kr = (int32_t *)(pos + naxis);
    P->row_idx = (uint32_t *)(kr + 2 * naxis);
    P->run_d = (float *)(P->row_idx + n_poses);
    P->run_tmp = P->run_d + run_n;
    for (int a = 0, at = 0; a < 3; at += P->bn[a], a++) {
        P->pa[a] = pos + at;
        P->ka[a] = kr + 2 * at;
    }
    return true;
}

/* Fills the per-axis tables: each free coefficient's position (as field_coef_pos) and the first
 * and last of the pass's sample blocks it reaches, ((c-2)R, (c+2)R). */
static void tool_coef_axes(const field_t *f, tool_coef_pass_t *P)
{
    const float o[3] = {f->origin_m.x, f->origin_m.y, f->origin_m.z}, hc = f->coef_spacing_m;
    const int32_t R = f->ratio;
    for (int a = 0; a < 3; a++) {
        float *pa = P->pa[a];
        int32_t *ka = P->ka[a];
        const int32_t blo = P->blo[a], klo = P->klo[a], kn = P->kn[a];
        for (int32_t i = 0; i < P->bn[a]; i++) {
            const int32_t c = blo + i;
            pa[i] = o[a] + hc * (float)c; /* as field_coef_pos */
            const int32_t k0 = sparse_block_of((c - 2) * R + 1) - klo, k1 = sparse_block_of((c + 2) * R - 1) - klo;
            ka[2 * i] = k0 < 0 ? 0 : k0;
            ka[2 * i + 1] = k1 >= kn ? kn - 1 : k1;
        }
    }
}

/* Reads the C box and computes the action's new coefficients over the free box: the change list
 * (in increasing index order) and the marks of the sample blocks each change reaches. */
static void tool_coef_changes(const field_t *f, const tool_union_t *U, const tool_params_t *p,
                              float bound, tool_coef_pass_t *P)
{
    float *C = P->C;
    uint8_t *mark = P->mark;
    uint32_t *ch_ci = P->ch_ci, *row_idx = P->row_idx;
    float *ch_after = P->ch_after;
    const float *const pa[3] = {P->pa[0], P->pa[1], P->pa[2]};
    const int32_t *const ka[3] = {P->ka[0], P->ka[1], P->ka[2]};
    const int32_t blo[3] = {P->blo[0], P->blo[1], P->blo[2]}, bn[3] = {P->bn[0], P->bn[1], P->bn[2]};
    const int32_t clo[3] = {P->clo[0], P->clo[1], P->clo[2]}, kn[3] = {P->kn[0], P->kn[1], P->kn[2]};
    const size_t sy = P->sy, sz = P->sz;
    const float hc = f->coef_spacing_m;
    size_t nch = 0;
    memset(mark, 0, P->nk);
    sparse_read_box(&f->coef, FC_P, P->clo, P->cn, C);
    for (int32_t z = 0; z < bn[2]; z++)
        for (int32_t y = 0; y < bn[1]; y++) {
            const size_t row = (size_t)(blo[0] - clo[0]) + sy * (size_t)(blo[1] - clo[1] + y) +
                               sz * (size_t)(blo[2] - clo[2] + z);
            int32_t x0, x1; /* only the part of the row some pose's reach holds */
            const size_t m = tool_row_poses(U, pa[0], bn[0], hc, pa[1][y], pa[2][z], row_idx, &x0, &x1);
            const int32_t *kyz = ka[1] + 2 * y, *kzz = ka[2] + 2 * z;
            int32_t kx_lo = 1, kx_hi = 0; /* blocks along x last marked for this row (none yet) */
            for (int32_t x = x0; x < x1 && m > 0; x++) {
                const size_t ci = row + (size_t)x;
                const float pold = C[ci];
                if (tool_coef_fixed_point(p->action, pold))
                    continue;
                const vec3_t xc = vec3(pa[0][x], pa[1][y], pa[2][z]);
                const float sd = tool_union_sd_of(U, row_idx, m, xc);
                if (sd == -INFINITY)
                    continue;
                float pnew;
                if (p->action == TOOL_SMOOTH) { /* the only action that reads the neighbours */
                    const float nb6[6] = {C[ci - 1], C[ci + 1], C[ci - sy], C[ci + sy], C[ci - sz], C[ci + sz]};
                    pnew = tool_action_coef(f, p, bound, pold, sd, xc, nb6);
                } else {
                    pnew = tool_action_coef(f, p, bound, pold, sd, xc, NULL);
                }
                if (pnew == pold)
                    continue;
                ch_ci[nch] = (uint32_t)ci;
                ch_after[nch++] = pnew;
                /* the sample blocks this coefficient reaches: ((c-2)R, (c+2)R) per axis */
                const int32_t *kxx = ka[0] + 2 * x;
                if (kxx[0] >= kx_lo && kxx[1] <= kx_hi)
                    continue;
                for (int32_t kz = kzz[0]; kz <= kzz[1]; kz++)
                    for (int32_t ky = kyz[0]; ky <= kyz[1]; ky++)
                        for (int32_t kx = kxx[0]; kx <= kxx[1]; kx++)
                            mark[(size_t)kx + (size_t)kn[0] * ((size_t)ky + (size_t)kn[1] * kz)] = 1;
                kx_lo = kxx[0];
                kx_hi = kxx[1];
            }
        }
    P->nch = nch;
}

/* Writes the changed coefficients into the C box and the field (the block lookup cached per
 * block) and notes each for undo. */
static argil_err_t tool_coef_write(field_t *f, const tool_coef_pass_t *P, undo_t *u)
{
    float *C = P->C;
    const size_t sy = P->sy;
    argil_err_t e = ARGIL_OK;
    sparse_block_t *cb = NULL;
    size_t row0 = 0; /* C index of (0, cy, cz): the list is in increasing index order */
    int32_t cy = 0, cz = 0;
    for (size_t k = 0; k < P->nch && e == ARGIL_OK; k++) {
        const size_t ci = P->ch_ci[k];
        const float before = C[ci];
        C[ci] = P->ch_after[k];
        if (ci < row0) { /* not in order: start again from the first row */
            row0 = 0;
            cy = cz = 0;
        }
        while (ci >= row0 + sy) {
            row0 += sy;
            if (++cy == P->cn[1]) {
                cy = 0;
                cz++;
            }
        }
        const int32_t c[3] = {P->clo[0] + (int32_t)(ci - row0), P->clo[1] + cy, P->clo[2] + cz};
        const int32_t key[3] = {sparse_block_of(c[0]), sparse_block_of(c[1]), sparse_block_of(c[2])};
        if (cb == NULL || memcmp(cb->key, key, sizeof(key)) != 0)
            e = sparse_touch(&f->coef, key, &cb);
        if (e != ARGIL_OK)
            break;
        cb->dirty = true;
        cb->data[FC_P * SPARSE_BN + (c[0] - key[0] * SPARSE_B) +
                 SPARSE_B * ((c[1] - key[1] * SPARSE_B) + SPARSE_B * (c[2] - key[2] * SPARSE_B))] = P->ch_after[k];
        if (u != NULL)
            e = undo_note(u, UNDO_STORE_COEF, FC_P, c, before, P->ch_after[k]);
    }
    return e;
}

/* d = A p in the marked sample blocks only, a run of consecutive marked blocks along x at a time
 * (one separable pass over the run; each sample's arithmetic is the same as alone), stored with
 * the rest shape moved by the same Δd; *refreshed counts the samples computed. */
static argil_err_t tool_coef_refresh(field_t *f, const tool_coef_pass_t *P, undo_t *u,
                                     size_t *refreshed)
{
    const int32_t *klo = P->klo, *kn = P->kn, *slo = P->slo, *shi = P->shi;
    argil_err_t e = ARGIL_OK;
    size_t changed_samples = 0;
    for (int32_t kz = 0; kz < kn[2] && e == ARGIL_OK; kz++)
        for (int32_t ky = 0; ky < kn[1] && e == ARGIL_OK; ky++) {
            const uint8_t *mrow = P->mark + (size_t)kn[0] * ((size_t)ky + (size_t)kn[1] * kz);
            for (int32_t kx = 0; kx < kn[0] && e == ARGIL_OK;) {
                if (!mrow[kx]) {
                    kx++;
                    continue;
                }
                int32_t kend = kx + 1;
                while (kend < kn[0] && mrow[kend])
                    kend++;
                const int32_t key0[3] = {klo[0] + kx, klo[1] + ky, klo[2] + kz};
                int32_t lo[3], hi[3];
                for (int a = 0; a < 3; a++) {
                    const int32_t k1 = a == 0 ? klo[0] + kend - 1 : key0[a];
                    lo[a] = key0[a] * SPARSE_B > slo[a] ? key0[a] * SPARSE_B : slo[a];
                    hi[a] = (k1 + 1) * SPARSE_B < shi[a] ? (k1 + 1) * SPARSE_B : shi[a];
                }
                field_samples_from(f, P->C, P->clo, P->cn, lo, hi, P->run_d, P->run_tmp);
                const size_t dn_row = (size_t)(hi[0] - lo[0]), dn_plane = dn_row * (size_t)(hi[1] - lo[1]);
                *refreshed += dn_plane * (size_t)(hi[2] - lo[2]);
                for (; kx < kend && e == ARGIL_OK; kx++) {
                    const int32_t key[3] = {klo[0] + kx, key0[1], key0[2]};
                    const int32_t blo_x = key[0] * SPARSE_B > lo[0] ? key[0] * SPARSE_B : lo[0];
                    const int32_t bhi_x = (key[0] + 1) * SPARSE_B < hi[0] ? (key[0] + 1) * SPARSE_B : hi[0];
                    const int32_t bl[3] = {blo_x, lo[1], lo[2]}, bh[3] = {bhi_x, hi[1], hi[2]};
                    e = tool_store_samples(f, key, bl, bh, P->run_d + (blo_x - lo[0]), dn_row, dn_plane, u,
                                           &changed_samples);
                }
            }
        }
    return e;
}

/* The coefficient action within tool_apply_coefs's undo step: new coefficients (fitted by least
 * squares if asked), written back, and the samples they reach refreshed. */
static argil_err_t tool_coef_edit(field_t *f, const tool_union_t *U, const tool_params_t *p,
                                  tool_coef_pass_t *P, undo_t *u, tool_stats_t *stats)
{
    const float bound = tool_bound_m(U->t);
    if (!tool_coef_scratch(f, U->n, P))
        return ARGIL_ERR_NOMEM;
    tool_coef_axes(f, P);
    tool_coef_changes(f, U, p, bound, P);
    argil_err_t e = ARGIL_OK;
    if (p->fit == TOOL_FIT_LSQ && P->nch > 0) {
        const tool_box_t B = {P->clo, P->cn, P->blo, P->bn, P->slo, P->shi, P->klo, P->kn};
        if ((e = tool_fit_lsq(f, U, p, bound, &B, P->C, P->ch_ci, P->ch_after, &P->nch, P->mark)) != ARGIL_OK)
            return e;
    }
    if (stats != NULL) {
        stats->coefs_visited += P->nb;
        stats->coefs_changed += P->nch;
    }
    e = tool_coef_write(f, P, u);
    size_t refreshed = 0;
    if (e == ARGIL_OK)
        e = tool_coef_refresh(f, P, u, &refreshed);
    if (stats != NULL)
        stats->samples_refreshed += refreshed;
    return e;
}

/* Coefficient actions: new coefficients over [blo, bhi) from one read of the box (plus the ring
 * the samples and the smoothing need), written back where they changed; then d = A p again only
 * in the sample blocks a changed coefficient reaches (Hua & Qin eq. 5), the rest shape moved by
 * the same Δd, and the changes noted for undo as they are made. */
static argil_err_t tool_apply_coefs(field_t *f, const tool_union_t *U, const tool_params_t *p,
                                    const int32_t blo[3], const int32_t bhi[3], undo_t *u,
                                    tool_stats_t *stats)
{
    tool_coef_pass_t P;
    tool_coef_boxes(f, blo, bhi, &P);
    argil_err_t e = ARGIL_OK;
    if (u != NULL && (e = undo_begin(u, f, P.blo, P.blo, 0, P.slo, P.slo, 0)) != ARGIL_OK)
        return e;
    e = tool_coef_edit(f, U, p, &P, u, stats);
    if (u != NULL) { /* whatever was done, even partly, is one undo step */
        const argil_err_t ec = undo_commit(u, f);
        if (e == ARGIL_OK)
            e = ec;
    }
    return e;
}

static argil_err_t tool_apply_union(field_t *f, const tool_union_t *U, const tool_params_t *p,
                                    undo_t *u, tool_stats_t *stats)
{
    vec3_t lo = U->poses[0].pos_m, hi = lo;
    for (size_t i = 1; i < U->n; i++) {
        const vec3_t q = U->poses[i].pos_m;
        lo = vec3(fminf(lo.x, q.x), fminf(lo.y, q.y), fminf(lo.z, q.z));
        hi = vec3(fmaxf(hi.x, q.x), fmaxf(hi.y, q.y), fmaxf(hi.z, q.z));
    }
    const float lw[3] = {lo.x - U->reach_m, lo.y - U->reach_m, lo.z - U->reach_m};
    const float hw[3] = {hi.x + U->reach_m, hi.y + U->reach_m, hi.z + U->reach_m};
    const float o[3] = {f->origin_m.x, f->origin_m.y, f->origin_m.z};
    const bool paint = p->action == TOOL_PAINT || p->action == TOOL_SOFT_PAINT;
    const float h = paint ? f->sample_spacing_m : f->coef_spacing_m;
    int32_t blo[3], bhi[3], bn[3];
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        const double l = ceil(((double)lw[a] - o[a]) / h), r = floor(((double)hw[a] - o[a]) / h);
        if (!isfinite(l) || !isfinite(r) || fabs(l) > SPARSE_INDEX_MAX / 4 || fabs(r) > SPARSE_INDEX_MAX / 4)
            return ARGIL_ERR_ARG;
        blo[a] = (int32_t)l;
        bhi[a] = (int32_t)r + 1;
        if (bhi[a] <= blo[a])
            return ARGIL_OK; /* the tool falls between lattice points */
        bn[a] = bhi[a] - blo[a];
        vol *= bn[a] + 2;
        if (vol > TOOL_BOX_MAX)
            return ARGIL_ERR_ARG;
    }
    argil_err_t e = ARGIL_OK;
    if (paint) {
        if (u != NULL && (e = undo_begin(u, f, blo, blo, 0, blo, bhi,
                                          (1u << FS_R) | (1u << FS_G) | (1u << FS_B))) != ARGIL_OK)
            return e;
        const size_t n = (size_t)vol;
        float *buf = malloc(sizeof(float) * n * 4);
        if (buf == NULL)
            e = ARGIL_ERR_NOMEM;
        float *d = buf != NULL ? buf + 3 * n : NULL;
        for (int c = 0; c < 3 && buf != NULL; c++)
            sparse_read_box(&f->samp, FS_R + c, blo, bn, buf + (size_t)c * n);
        if (buf != NULL)
            sparse_read_box(&f->samp, FS_D, blo, bn, d);
        size_t i = 0;
        for (int32_t z = 0; z < bn[2] && buf != NULL; z++)
            for (int32_t y = 0; y < bn[1]; y++)
                for (int32_t x = 0; x < bn[0]; x++, i++) {
                    const int32_t s[3] = {blo[0] + x, blo[1] + y, blo[2] + z};
                    const float phi = field_profile(tool_union_sd(U, field_sample_pos(f, s)), f->band_m);
                    for (int c = 0; c < 3; c++) {
                        float *col = buf + (size_t)c * n + i;
                        if (p->action == TOOL_PAINT) {
                            if (phi >= f->iso)
                                *col = p->rgb[c];
                        } else { /* soft paint takes the sample's own density into account */
                            *col += (p->rgb[c] - *col) * tool_clamp01(p->strength * phi * d[i]);
                        }
                    }
                }
        for (int c = 0; c < 3 && e == ARGIL_OK; c++)
            e = sparse_write_box(&f->samp, FS_R + c, blo, bn, buf + (size_t)c * n);
        free(buf);
        if (stats != NULL)
            stats->samples_refreshed += n;
        if (u != NULL) { /* whatever was done, even partly, is one undo step */
            const argil_err_t ec = undo_commit(u, f);
            e = e != ARGIL_OK ? e : ec;
        }
        return e;
    }
    return tool_apply_coefs(f, U, p, blo, bhi, u, stats);
}

/* Reach of the tool's influence beyond its origin for this action. */
static float tool_reach(const field_t *f, const tool_shape_t *t, const tool_params_t *p)
{
    const float b = tool_bound_m(t);
    float r = b + f->band_m + f->coef_spacing_m;
    if (p->action == TOOL_STAMP) {
        const float rs = b * (p->stamp.s + p->stamp.m + p->stamp.r) / p->stamp.s;
        r = rs > r ? rs : r;
    }
    return r;
}

/* Adds the mirror images of pose q (bits of mirror) to out; returns the count written. */
static size_t tool_mirrors(const tool_pose_t *q, const tool_params_t *p, tool_pose_t *out)
{
    size_t n = 0;
    const float o[3] = {p->mirror_origin_m.x, p->mirror_origin_m.y, p->mirror_origin_m.z};
    for (uint32_t m = 0; m < 8; m++) {
        if ((m & ~p->mirror) != 0)
            continue;
        tool_pose_t r = *q;
        float pos[3] = {q->pos_m.x, q->pos_m.y, q->pos_m.z};
        for (int a = 0; a < 3; a++)
            if (m & (1u << a)) {
                pos[a] = 2.0f * o[a] - pos[a];
                for (int c = 0; c < 3; c++)
                    r.rot[a][c] = -r.rot[a][c]; /* reflection S·rot */
            }
        r.pos_m = vec3(pos[0], pos[1], pos[2]);
        out[n++] = r;
    }
    return n;
}

/* Every stroke point (spaced ≤ band / 2) and its mirror images, applied as one union. */
static argil_err_t tool_run(field_t *f, const tool_shape_t *t, const tool_pose_t *pose,
                            const vec3_t *pts, size_t n, const tool_params_t *p, undo_t *u,
                            tool_stats_t *stats)
{
    if (f == NULL || t == NULL || pose == NULL || pts == NULL || p == NULL || n == 0 ||
        !tool_shape_ok(t) || !tool_params_ok(p))
        return ARGIL_ERR_ARG;
    for (size_t i = 0; i < n; i++)
        if (!vec3_isfinite(pts[i]))
            return ARGIL_ERR_NONFINITE;
    const float step = 0.5f * f->band_m;
    size_t count = 1;
    for (size_t i = 1; i < n; i++) {
        const float len = vec3_norm(vec3_sub(pts[i], pts[i - 1]));
        count += (size_t)ceilf(len / step);
        if (count > TOOL_POSES_MAX)
            return ARGIL_ERR_ARG;
    }
    tool_pose_t *poses = malloc(sizeof(tool_pose_t) * count * 8);
    if (poses == NULL)
        return ARGIL_ERR_NOMEM;
    size_t np = 0;
    tool_pose_t q = *pose;
    q.pos_m = pts[0];
    np += tool_mirrors(&q, p, poses + np);
    for (size_t i = 1; i < n; i++) {
        const vec3_t d = vec3_sub(pts[i], pts[i - 1]);
        const size_t k = (size_t)ceilf(vec3_norm(d) / step);
        for (size_t j = 1; j <= k; j++) {
            q.pos_m = vec3_add(pts[i - 1], vec3_scale(d, (float)j / (float)k));
            np += tool_mirrors(&q, p, poses + np);
        }
    }
    const tool_union_t U = {t, poses, np, tool_reach(f, t, p)};
    argil_err_t e = tool_apply_union(f, &U, p, u, stats);
    free(poses);
    return e;
}

argil_err_t tool_apply(field_t *f, const tool_shape_t *t, const tool_pose_t *pose,
                       const tool_params_t *p, undo_t *u, tool_stats_t *stats)
{
    if (pose == NULL)
        return ARGIL_ERR_ARG;
    return tool_run(f, t, pose, &pose->pos_m, 1, p, u, stats);
}

argil_err_t tool_stroke(field_t *f, const tool_shape_t *t, const tool_pose_t *pose,
                        const vec3_t *pts_m, size_t n, const tool_params_t *p, undo_t *u)
{
    return tool_run(f, t, pose, pts_m, n, p, u, NULL);
}

argil_err_t tool_freeform_from_field(tool_freeform_t *ff, const field_t *f, const int32_t slo[3],
                                     const int32_t shi[3])
{
    memset(ff, 0, sizeof(*ff));
    int64_t vol = 1;
    for (int a = 0; a < 3; a++) {
        ff->dims[a] = shi[a] - slo[a];
        if (ff->dims[a] < 2)
            return ARGIL_ERR_ARG;
        vol *= ff->dims[a];
        if (vol > TOOL_BOX_MAX)
            return ARGIL_ERR_ARG;
    }
    ff->density = malloc(sizeof(float) * (size_t)vol);
    if (ff->density == NULL)
        return ARGIL_ERR_NOMEM;
    sparse_read_box(&f->samp, FS_D, slo, ff->dims, ff->density);
    ff->spacing_m = f->sample_spacing_m;
    ff->origin_m = vec3(-0.5f * ff->spacing_m * (float)(ff->dims[0] - 1),
                        -0.5f * ff->spacing_m * (float)(ff->dims[1] - 1),
                        -0.5f * ff->spacing_m * (float)(ff->dims[2] - 1));
    ff->iso = f->iso;
    ff->band_m = f->band_m;
    return ARGIL_OK;
}

void tool_freeform_free(tool_freeform_t *ff)
{
    free(ff->density);
    ff->density = NULL;
}
