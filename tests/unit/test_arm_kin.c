/* Unit tests for shared/arm_kin: geometry, Jacobian, inverse kinematics, encoder scaling. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "shared/arm_kin.h"

/* A deterministic pseudo-random number in [0, 1) (LCG). */
static float rnd01(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / 16777216.0f;
}

/* A pose drawn uniformly inside the joint limits. */
static void random_pose(const arm_desc_t *d, uint32_t *s, float q[ARGIL_DRIVES])
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        q[j] = d->q_min_rad[j] + rnd01(s) * (d->q_max_rad[j] - d->q_min_rad[j]);
}

static void test_fk_at_home(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    const vec3_t tip = arm_fk(&d, d.q_home_rad);
    /* q_home = (0, -0.9, 1.8): elbow 0.11 m below the shoulder, tip level with it */
    assert_float_equal(tip.x, 0.0f, 1e-6f);
    assert_float_equal(tip.y, 0.0f, 1e-6f);
    assert_float_equal(tip.z, 0.28f * cosf(0.9f), 1e-6f);
    assert_true(tip.z > 0.15f && tip.z < 0.20f); /* 0.174 m in front of the shoulder */
    const vec3_t c = arm_workspace_centre(&d);
    assert_float_equal(c.x, tip.x, 0.0f);
    assert_float_equal(c.y, tip.y, 0.0f);
    assert_float_equal(c.z, tip.z, 0.0f);
    /* every home angle is inside its limits */
    for (int j = 0; j < ARGIL_DRIVES; j++)
        assert_true(d.q_home_rad[j] > d.q_min_rad[j] && d.q_home_rad[j] < d.q_max_rad[j]);
}

static void test_fk_known_poses(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    /* straight arm pointing at the user */
    const float q_str[3] = {0.0f, 0.0f, 0.0f};
    vec3_t t = arm_fk(&d, q_str);
    assert_float_equal(t.z, 0.28f, 1e-6f);
    assert_float_equal(t.x, 0.0f, 1e-6f);
    /* upper arm level, forearm straight up, yawed to the right by 90° */
    const float q_up[3] = {1.5707963f, 0.0f, 1.5707963f};
    t = arm_fk(&d, q_up);
    assert_float_equal(t.x, 0.14f, 1e-6f);
    assert_float_equal(t.y, 0.14f, 1e-6f);
    assert_float_equal(t.z, 0.0f, 1e-6f);
}

static void test_jacobian_matches_finite_differences(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    uint32_t seed = 12345u;
    const float h = 1e-3f;
    for (int n = 0; n < 50; n++) {
        float q[3], j[3][3];
        random_pose(&d, &seed, q);
        arm_jacobian(&d, q, j);
        float norm2 = 0.0f;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                norm2 += j[r][c] * j[r][c];
        const float tol = 1e-3f * sqrtf(norm2);
        for (int c = 0; c < 3; c++) {
            float qp[3] = {q[0], q[1], q[2]}, qm[3] = {q[0], q[1], q[2]};
            qp[c] += h;
            qm[c] -= h;
            const vec3_t a = arm_fk(&d, qp), b = arm_fk(&d, qm);
            assert_float_equal(j[0][c], (a.x - b.x) / (2.0f * h), tol);
            assert_float_equal(j[1][c], (a.y - b.y) / (2.0f * h), tol);
            assert_float_equal(j[2][c], (a.z - b.z) / (2.0f * h), tol);
        }
    }
}

static void test_ik_inverts_fk_across_workspace(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    uint32_t seed = 777u;
    int checked = 0;
    for (int n = 0; n < 2000; n++) {
        float q[3], qi[3];
        random_pose(&d, &seed, q);
        const vec3_t tip = arm_fk(&d, q);
        if (sqrtf(tip.x * tip.x + tip.z * tip.z) < 0.02f)
            continue; /* yaw is ill-defined near the yaw axis */
        assert_true(arm_ik(&d, tip, qi));
        for (int j = 0; j < 3; j++)
            assert_float_equal(qi[j], q[j], 1e-4f);
        checked++;
    }
    assert_true(checked > 1900);
    /* the limits themselves */
    float qi[3];
    assert_true(arm_ik(&d, arm_fk(&d, d.q_min_rad), qi));
    for (int j = 0; j < 3; j++)
        assert_float_equal(qi[j], d.q_min_rad[j], 1e-4f);
    assert_true(arm_ik(&d, arm_fk(&d, d.q_max_rad), qi));
    for (int j = 0; j < 3; j++)
        assert_float_equal(qi[j], d.q_max_rad[j], 1e-4f);
}

static void test_ik_rejects_unreachable(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    float q[3] = {9.0f, 9.0f, 9.0f};
    assert_false(arm_ik(&d, vec3(0.0f, 0.0f, 0.30f), q));     /* beyond 0.28 m reach */
    assert_false(arm_ik(&d, vec3(0.17f, 0.0f, 0.0f), q));     /* yaw 90°: past ±1 rad */
    assert_false(arm_ik(&d, vec3(0.0f, 0.0f, 0.05f), q));     /* elbow would fold past 2.5 rad */
    assert_false(arm_ik(&d, vec3(NAN, 0.0f, 0.17f), q));
    assert_float_equal(q[0], 9.0f, 0.0f);                    /* untouched on failure */
}

static void test_jt_force_known_pose(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    /* upper arm level toward the user, forearm straight up: tip (0, 0.14, 0.14) */
    const float q[3] = {0.0f, 0.0f, 1.5707963f};
    float j[3][3], tau[3];
    arm_jacobian(&d, q, j);
    /* pulling the tip toward the user tips both pitch joints down by 0.14 m × 1 N */
    arm_jt_force(j, vec3(0.0f, 0.0f, 1.0f), tau);
    assert_float_equal(tau[0], 0.0f, 1e-6f);
    assert_float_equal(tau[1], -0.14f, 1e-6f);
    assert_float_equal(tau[2], -0.14f, 1e-6f);
    /* pushing right turns the yaw at lever r = 0.14 m */
    arm_jt_force(j, vec3(2.0f, 0.0f, 0.0f), tau);
    assert_float_equal(tau[0], 0.28f, 1e-6f);
    assert_float_equal(tau[1], 0.0f, 1e-6f);
    assert_float_equal(tau[2], 0.0f, 1e-6f);
    /* lifting: shoulder lever is the horizontal distance 0.14 m, elbow lever 0 */
    arm_jt_force(j, vec3(0.0f, 3.0f, 0.0f), tau);
    assert_float_equal(tau[1], 0.42f, 1e-6f);
    assert_float_equal(tau[2], 0.0f, 1e-6f);
}

static void test_max_force_reachable_in_central_workspace(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    /* Within 0.2 m of the shoulder, 3.3 N in any direction needs at most the drives' peak
     * torque (ARM_PEAK_TORQUE_PERMILLE of rated) on every motor. */
    uint32_t seed = 99u;
    int checked = 0;
    float worst = 0.0f;
    for (int n = 0; n < 2000; n++) {
        float q[3], j[3][3];
        random_pose(&d, &seed, q);
        const vec3_t t = arm_fk(&d, q);
        if (vec3_norm(t) > 0.20f)
            continue;
        arm_jacobian(&d, q, j);
        for (int c = 0; c < 3; c++) {
            const float col = sqrtf(j[0][c] * j[0][c] + j[1][c] * j[1][c] + j[2][c] * j[2][c]);
            const float motor_nm = 3.3f * col / d.gear_ratio[c];
            const float peak_nm = d.rated_torque_nm[c] * ARM_PEAK_TORQUE_PERMILLE / 1000.0f;
            assert_true(motor_nm <= peak_nm);
            worst = fmaxf(worst, motor_nm / peak_nm);
        }
        checked++;
    }
    assert_true(checked > 200);
    assert_true(worst < 0.6f); /* ≥ 40 % headroom in the central workspace */
}

static void test_counts_round_trip(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    const float rad_per_count = 6.2831853f / (10.0f * 4000.0f);
    for (int j = 0; j < 3; j++) {
        assert_int_equal(arm_rad_to_counts(&d, j, d.q_home_rad[j]), 0);
        assert_float_equal(arm_counts_to_rad(&d, j, 0), d.q_home_rad[j], 0.0f);
        for (int32_t c = -20000; c <= 20000; c += 7) {
            const int32_t back = arm_rad_to_counts(&d, j, arm_counts_to_rad(&d, j, c));
            assert_true(back >= c - 1 && back <= c + 1);
        }
        for (float q = d.q_min_rad[j]; q <= d.q_max_rad[j]; q += 0.0137f) {
            const float back = arm_counts_to_rad(&d, j, arm_rad_to_counts(&d, j, q));
            assert_true(fabsf(back - q) <= rad_per_count * 1.01f);
        }
        /* quantisation truncates toward zero counts */
        assert_int_equal(arm_rad_to_counts(&d, j, d.q_home_rad[j] + 2.5f * rad_per_count), 2);
        assert_int_equal(arm_rad_to_counts(&d, j, d.q_home_rad[j] - 2.5f * rad_per_count), -2);
    }
    /* one joint turn is gear × 4000 counts */
    assert_float_equal(arm_counts_to_rad(&d, 0, 40000) - arm_counts_to_rad(&d, 0, 0),
                       6.2831853f, 1e-4f);
    /* bad arguments */
    assert_int_equal(arm_rad_to_counts(&d, 3, 0.0f), 0);
    assert_int_equal(arm_rad_to_counts(&d, 0, NAN), 0);
    assert_true(isnan(arm_counts_to_rad(&d, -1, 0)));
}

static void test_tip_resolution_at_home(void **state)
{
    (void)state;
    arm_desc_t d;
    arm_desc_default(&d);
    float j[3][3];
    arm_jacobian(&d, d.q_home_rad, j);
    float worst_m = 0.0f;
    for (int c = 0; c < 3; c++) {
        const float rad_per_count = 6.2831853f / (d.gear_ratio[c] * (float)d.encoder_counts_per_rev[c]);
        const float col = sqrtf(j[0][c] * j[0][c] + j[1][c] * j[1][c] + j[2][c] * j[2][c]);
        worst_m = fmaxf(worst_m, col * rad_per_count);
    }
    assert_true(worst_m < 0.05e-3f);  /* < 0.05 mm per count */
    assert_true(worst_m > 0.02e-3f);  /* ~0.027 mm, PHANToM Premium 1.0 class (0.03 mm) */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fk_at_home),
        cmocka_unit_test(test_fk_known_poses),
        cmocka_unit_test(test_jacobian_matches_finite_differences),
        cmocka_unit_test(test_ik_inverts_fk_across_workspace),
        cmocka_unit_test(test_ik_rejects_unreachable),
        cmocka_unit_test(test_jt_force_known_pose),
        cmocka_unit_test(test_max_force_reachable_in_central_workspace),
        cmocka_unit_test(test_counts_round_trip),
        cmocka_unit_test(test_tip_resolution_at_home),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
