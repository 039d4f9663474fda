/* The arm's geometry in closed form: forward kinematics, Jacobian, elbow-down inverse
 * kinematics and encoder scaling, used by the board every tick and by the simulator. */
#include "arm_kin.h"

#include <math.h>
#include <stddef.h>

#define ARM_TWO_PI 6.28318530717958647692f
#define ARM_PI 3.14159265358979323846f
#define ARM_HALF_PI 1.57079632679489661923f
/* arm_ik accepts a solution this far outside a joint limit (float round-off) and clamps it. */
#define ARM_IK_LIMIT_TOL_RAD 1e-4f

/* cos x as sin(x + π/2): gcc would fuse sinf(x) and cosf(x) into sincosf, which the
 * freestanding check (toolchain/check-freestanding.sh) does not allow. */
static float cos_via_sin(float x)
{
    return sinf(x + ARM_HALF_PI);
}

void arm_desc_default(arm_desc_t *d)
{
    /* PHANToM Premium 1.0-class arm; every figure is explained in docs/arm.md. */
    static const float q_min[ARGIL_DRIVES] = {-1.0f, -1.5f, 0.35f};
    static const float q_max[ARGIL_DRIVES] = {1.0f, 0.5f, 2.5f};
    static const float q_home[ARGIL_DRIVES] = {0.0f, -0.9f, 1.8f};
    d->link1_m = 0.14f;
    d->link2_m = 0.14f;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        d->gear_ratio[j] = 10.0f;
        d->encoder_counts_per_rev[j] = 4000;
        d->rated_torque_nm[j] = 0.030f;
        d->q_min_rad[j] = q_min[j];
        d->q_max_rad[j] = q_max[j];
        d->q_home_rad[j] = q_home[j];
    }
}

vec3_t arm_fk(const arm_desc_t *d, const float q_rad[ARGIL_DRIVES])
{
    const float a = q_rad[1];
    const float b = q_rad[1] + q_rad[2];
    const float r = d->link1_m * cos_via_sin(a) + d->link2_m * cos_via_sin(b);
    const float h = d->link1_m * sinf(a) + d->link2_m * sinf(b);
    return vec3(r * sinf(q_rad[0]), h, r * cos_via_sin(q_rad[0]));
}

void arm_jacobian(const arm_desc_t *d, const float q_rad[ARGIL_DRIVES],
                  float j[3][ARGIL_DRIVES])
{
    const float s0 = sinf(q_rad[0]), c0 = cos_via_sin(q_rad[0]);
    const float a = q_rad[1];
    const float b = q_rad[1] + q_rad[2];
    const float l2s = d->link2_m * sinf(b), l2c = d->link2_m * cos_via_sin(b);
    const float r = d->link1_m * cos_via_sin(a) + l2c;
    const float h = d->link1_m * sinf(a) + l2s;
    /* dr/dq1 = -h, dh/dq1 = r, dr/dq2 = -L2 sin b, dh/dq2 = L2 cos b */
    j[0][0] = r * c0;
    j[0][1] = -h * s0;
    j[0][2] = -l2s * s0;
    j[1][0] = 0.0f;
    j[1][1] = r;
    j[1][2] = l2c;
    j[2][0] = -r * s0;
    j[2][1] = -h * c0;
    j[2][2] = -l2s * c0;
}

void arm_jt_force(const float j[3][ARGIL_DRIVES], vec3_t force_n, float tau_nm[ARGIL_DRIVES])
{
    for (int c = 0; c < ARGIL_DRIVES; c++)
        tau_nm[c] = j[0][c] * force_n.x + j[1][c] * force_n.y + j[2][c] * force_n.z;
}

/* Clamps *q into [lo, hi] when it is at most the tolerance outside; false when further out. */
static bool within_limit(float *q, float lo, float hi)
{
    if (!(*q >= lo - ARM_IK_LIMIT_TOL_RAD && *q <= hi + ARM_IK_LIMIT_TOL_RAD))
        return false;
    *q = fminf(fmaxf(*q, lo), hi);
    return true;
}

/* Wraps an angle into (-pi, pi]. */
static float wrap_pi(float a)
{
    if (a > ARM_PI)
        a -= ARM_TWO_PI;
    else if (a <= -ARM_PI)
        a += ARM_TWO_PI;
    return a;
}

/* Elbow-down solution in the arm's vertical plane for radial distance r (signed) and height h;
 * false when out of reach or outside the pitch/elbow limits. */
static bool ik_plane(const arm_desc_t *d, float r, float h, float *q1, float *q2)
{
    const float l1 = d->link1_m, l2 = d->link2_m;
    float c2 = (r * r + h * h - l1 * l1 - l2 * l2) / (2.0f * l1 * l2);
    if (!(c2 >= -1.0f - 1e-5f && c2 <= 1.0f + 1e-5f))
        return false;
    c2 = fminf(fmaxf(c2, -1.0f), 1.0f);
    /* Elbow down: the elbow lies below the shoulder-tip line, i.e. q2 >= 0. */
    const float a2 = acosf(c2);
    const float a1 = wrap_pi(atan2f(h, r) - atan2f(l2 * sinf(a2), l1 + l2 * c2));
    float t1 = a1, t2 = a2;
    if (!within_limit(&t1, d->q_min_rad[1], d->q_max_rad[1]) ||
        !within_limit(&t2, d->q_min_rad[2], d->q_max_rad[2]))
        return false;
    *q1 = t1;
    *q2 = t2;
    return true;
}

bool arm_ik(const arm_desc_t *d, vec3_t tip_m, float q_rad[ARGIL_DRIVES])
{
    if (!vec3_isfinite(tip_m))
        return false;
    const float rho = sqrtf(tip_m.x * tip_m.x + tip_m.z * tip_m.z);
    /* Two yaw readings reach the same point: in front of the yaw axis (r = +rho) or, with the
     * yaw turned half a revolution, behind it (r = -rho). Joint limits decide. */
    for (int k = 0; k < 2; k++) {
        const float sgn = k == 0 ? 1.0f : -1.0f;
        float q0 = rho > 0.0f ? atan2f(sgn * tip_m.x, sgn * tip_m.z) : 0.0f;
        float q1, q2;
        if (!within_limit(&q0, d->q_min_rad[0], d->q_max_rad[0]))
            continue;
        if (!ik_plane(d, sgn * rho, tip_m.y, &q1, &q2))
            continue;
        q_rad[0] = q0;
        q_rad[1] = q1;
        q_rad[2] = q2;
        return true;
    }
    return false;
}

vec3_t arm_workspace_centre(const arm_desc_t *d)
{
    return arm_fk(d, d->q_home_rad);
}

/* Joint radians per motor encoder count. */
static float rad_per_count(const arm_desc_t *d, int joint)
{
    return ARM_TWO_PI / (d->gear_ratio[joint] * (float)d->encoder_counts_per_rev[joint]);
}

float arm_counts_to_rad(const arm_desc_t *d, int joint, int32_t counts)
{
    if (joint < 0 || joint >= ARGIL_DRIVES)
        return NAN;
    return d->q_home_rad[joint] + (float)counts * rad_per_count(d, joint);
}

int32_t arm_rad_to_counts(const arm_desc_t *d, int joint, float q_rad)
{
    if (joint < 0 || joint >= ARGIL_DRIVES || !isfinite(q_rad))
        return 0;
    const float x = (q_rad - d->q_home_rad[joint]) / rad_per_count(d, joint);
    if (x >= 2147483520.0f)
        return INT32_MAX;
    if (x <= -2147483520.0f)
        return INT32_MIN;
    return (int32_t)x; /* the conversion truncates toward zero */
}
