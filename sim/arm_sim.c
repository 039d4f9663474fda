/* Arm dynamics for the simulated device. The arm is counterbalanced (no gravity); its moving
 * mass is lumped at the stylus tip, so with tip acceleration a = J q̈ + J̇ q̇ Lagrange gives, for
 * rigid joints (motor and link one body),
 *   (Jᵀ m J + L + R) q̈ = τ·gear + Jᵀ F_ext − τ_friction − Jᵀ m J̇ q̇,   R = diag(I_rotor gear²),
 * L = diag(link inertia). A compliant joint splits its rotor off behind the cable spring
 * τ_c = k (qm − q) + d (q̇m − q̇): the link row takes τ_c in place of the motor torque, friction
 * and R, and the rotor I_rotor gear² q̈m = τ·gear − τ_c − τ_friction(q̇m) (docs/arm.md).
 * Double precision inside: this is the "physics", the board sees it only through encoders. */
#include "arm_sim.h"

#include <math.h>
#include <stddef.h>

void arm_params_default(arm_params_t *p)
{
    arm_desc_default(&p->desc);
    p->tip_mass_kg = 0.075f;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        p->rotor_inertia_kg_m2[j] = 1.1e-6f;
        p->viscous_nm_s_per_rad[j] = 0.002f;
        p->coulomb_nm[j] = 0.005f;
        p->peak_torque_nm[j] = p->desc.rated_torque_nm[j] * (float)ARM_PEAK_TORQUE_PERMILLE / 1000.0f;
        p->link_inertia_kg_m2[j] = 0.0f;
        p->cable_compliance_rad_per_nm[j] = 0.0f;
        p->cable_damping_nm_s_per_rad[j] = 0.0f;
        p->current_loop_hz[j] = 0.0f;
        p->torque_dac_bits[j] = 0u;
    }
    p->coulomb_smooth_rad_s = 0.01f;
    p->substep_us = ARM_SIM_SUBSTEP_US;
}

void arm_params_premium(arm_params_t *p)
{
    /* each value's source and its tip equivalent at home: docs/arm.md, "Premium profile" */
    static const float link_inertia_kg_m2[ARGIL_DRIVES] = {5e-4f, 5e-5f, 5e-5f};
    arm_params_default(p);
    p->tip_mass_kg = 0.050f;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        p->viscous_nm_s_per_rad[j] = 1e-4f;
        p->coulomb_nm[j] = 0.003f;
        p->link_inertia_kg_m2[j] = link_inertia_kg_m2[j];
        p->cable_compliance_rad_per_nm[j] = 1.0f / 800.0f;
        p->cable_damping_nm_s_per_rad[j] = 0.017f;
        p->current_loop_hz[j] = 1000.0f;
        p->torque_dac_bits[j] = 12u;
    }
}

bool arm_sim_joint_compliant(const arm_params_t *p, int j)
{
    return p->cable_compliance_rad_per_nm[j] > 0.0f;
}

/* The width ε of the Coulomb friction's tanh smoothing (1e-3 rad/s when none is set). */
static double friction_width_rad_s(const arm_params_t *p)
{
    return p->coulomb_smooth_rad_s > 0.0f ? (double)p->coulomb_smooth_rad_s : 1e-3;
}

/* The inertia the rotor of joint j brings, joint side: I_rotor gear². */
static double rotor_at_joint(const arm_params_t *p, int j)
{
    const double g = p->desc.gear_ratio[j];
    return (double)p->rotor_inertia_kg_m2[j] * g * g;
}

/* The smallest diagonal term M adds to m JᵀJ (link inertia, plus the rotor on a rigid joint):
 * a lower bound on the link side's smallest eigenvalue in every pose. */
static double link_side_floor_kg_m2(const arm_params_t *p)
{
    double lo = INFINITY;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        double i = (double)p->link_inertia_kg_m2[j];
        if (!arm_sim_joint_compliant(p, j))
            i += rotor_at_joint(p, j);
        lo = fmin(lo, i);
    }
    return lo;
}

uint32_t arm_sim_substep_max_us(const arm_params_t *p)
{
    const double eps = friction_width_rad_s(p);
    const double link_floor = link_side_floor_kg_m2(p);
    double rate = 0.0; /* the largest s / I or ω / ARM_SIM_OMEGA_H_MAX over the joints, 1/s */
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        const bool compliant = arm_sim_joint_compliant(p, j);
        /* the body friction acts on: the rotor alone, or the rigid joint's whole floor */
        const double inertia = compliant ? rotor_at_joint(p, j)
                                         : rotor_at_joint(p, j) + (double)p->link_inertia_kg_m2[j];
        const double damper = compliant ? fabs((double)p->cable_damping_nm_s_per_rad[j]) : 0.0;
        const double slope = fabs((double)p->coulomb_nm[j]) / eps +
                             fabs((double)p->viscous_nm_s_per_rad[j]) + damper;
        if (!(inertia > 0.0) || (compliant && !(link_floor > 0.0)))
            return 1u;
        rate = fmax(rate, slope / inertia);
        if (compliant) {
            const double k = 1.0 / (double)p->cable_compliance_rad_per_nm[j];
            const double inv = 1.0 / inertia + 1.0 / link_floor;
            rate = fmax(rate, damper / link_floor);
            rate = fmax(rate, sqrt(k * inv) / ARM_SIM_OMEGA_H_MAX);
        }
    }
    if (!(rate > 1.0)) /* 1 s or more: no sub-step this long is asked for */
        return 1000000u;
    const double h_us = 1e6 / rate;
    return h_us < 1.0 ? 1u : (uint32_t)h_us;
}

uint32_t arm_sim_substep_us(const arm_params_t *p)
{
    const uint32_t hi = arm_sim_substep_max_us(p);
    return p->substep_us < 1u ? 1u : p->substep_us > hi ? hi : p->substep_us;
}

/* Kinematic terms at (q, q̇): Jacobian, tip position, tip velocity and the velocity-product
 * acceleration J̇ q̇ (the tip acceleration when q̈ = 0). Any output may be NULL. */
static void kin_terms(const arm_params_t *p, const double q[ARGIL_DRIVES],
                      const double qd[ARGIL_DRIVES], double jac[3][ARGIL_DRIVES],
                      double tip[3], double tip_vel[3], double acc_bias[3])
{
    const double l1 = p->desc.link1_m, l2 = p->desc.link2_m;
    const double s0 = sin(q[0]), c0 = cos(q[0]);
    const double a = q[1], b = q[1] + q[2];
    const double l1s = l1 * sin(a), l1c = l1 * cos(a);
    const double l2s = l2 * sin(b), l2c = l2 * cos(b);
    const double r = l1c + l2c, h = l1s + l2s;
    double j[3][ARGIL_DRIVES] = {
        {r * c0, -h * s0, -l2s * s0},
        {0.0, r, l2c},
        {-r * s0, -h * c0, -l2s * c0},
    };
    if (jac != NULL)
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < ARGIL_DRIVES; k++)
                jac[i][k] = j[i][k];
    if (tip != NULL) {
        tip[0] = r * s0;
        tip[1] = h;
        tip[2] = r * c0;
    }
    if (qd == NULL)
        return;
    if (tip_vel != NULL)
        for (int i = 0; i < 3; i++)
            tip_vel[i] = j[i][0] * qd[0] + j[i][1] * qd[1] + j[i][2] * qd[2];
    if (acc_bias != NULL) {
        const double ad = qd[1], bd = qd[1] + qd[2], q0d = qd[0];
        const double rd = -(l1s * ad + l2s * bd);
        const double rdd = -(l1c * ad * ad + l2c * bd * bd); /* with q̈ = 0 */
        const double hdd = -(l1s * ad * ad + l2s * bd * bd);
        acc_bias[0] = rdd * s0 + 2.0 * rd * c0 * q0d - r * s0 * q0d * q0d;
        acc_bias[1] = hdd;
        acc_bias[2] = rdd * c0 - 2.0 * rd * s0 * q0d - r * c0 * q0d * q0d;
    }
}

/* The link side's M = Jᵀ m J + L (+ R on rigid joints) from a Jacobian. */
static void mass_from_jacobian(const arm_params_t *p, const double j[3][ARGIL_DRIVES],
                               double m[ARGIL_DRIVES][ARGIL_DRIVES])
{
    for (int r = 0; r < ARGIL_DRIVES; r++) {
        for (int c = 0; c < ARGIL_DRIVES; c++) {
            double s = 0.0;
            for (int i = 0; i < 3; i++)
                s += j[i][r] * j[i][c];
            m[r][c] = (double)p->tip_mass_kg * s;
        }
        if (!arm_sim_joint_compliant(p, r))
            m[r][r] += rotor_at_joint(p, r);
        m[r][r] += (double)p->link_inertia_kg_m2[r];
    }
}

void arm_sim_mass_matrix(const arm_params_t *p, const double q_rad[ARGIL_DRIVES],
                         double m[ARGIL_DRIVES][ARGIL_DRIVES])
{
    double j[3][ARGIL_DRIVES];
    kin_terms(p, q_rad, NULL, j, NULL, NULL, NULL);
    mass_from_jacobian(p, j, m);
}

bool arm_sim_solve3(const double a[3][3], const double b[3], double x[3])
{
    double m[3][4];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[r][c] = a[r][c];
        m[r][3] = b[r];
    }
    for (int c = 0; c < 3; c++) {
        int piv = c;
        for (int r = c + 1; r < 3; r++)
            if (fabs(m[r][c]) > fabs(m[piv][c]))
                piv = r;
        if (!(fabs(m[piv][c]) > 1e-300))
            return false;
        if (piv != c)
            for (int k = 0; k < 4; k++) {
                const double t = m[c][k];
                m[c][k] = m[piv][k];
                m[piv][k] = t;
            }
        for (int r = c + 1; r < 3; r++) {
            const double f = m[r][c] / m[c][c];
            for (int k = c; k < 4; k++)
                m[r][k] -= f * m[c][k];
        }
    }
    for (int r = 2; r >= 0; r--) {
        double s = m[r][3];
        for (int k = r + 1; k < 3; k++)
            s -= m[r][k] * x[k];
        x[r] = s / m[r][r];
    }
    return true;
}

void arm_sim_init(arm_sim_t *sim, const arm_params_t *p, const float q0_rad[ARGIL_DRIVES])
{
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        double q = isfinite(q0_rad[j]) ? (double)q0_rad[j] : (double)p->desc.q_home_rad[j];
        q = fmin(fmax(q, (double)p->desc.q_min_rad[j]), (double)p->desc.q_max_rad[j]);
        sim->q_rad[j] = q;
        sim->qd_rad_s[j] = 0.0;
        sim->qdd_rad_s2[j] = 0.0;
        sim->qm_rad[j] = q; /* the cable unloaded */
        sim->qmd_rad_s[j] = 0.0;
        sim->torque_nm[j] = 0.0;
    }
}

void arm_sim_kin_now(const arm_sim_t *sim, const arm_params_t *p, arm_kin_now_t *k)
{
    kin_terms(p, sim->q_rad, sim->qd_rad_s, k->jac, k->tip_m, k->tip_vel_m_s, k->acc_bias_m_s2);
}

/* The motor torque the current loop of joint j applies over the next h seconds (its mean, so the
 * impulse is exact for a command held over the sub-step), moving the loop's state to the
 * sub-step's end: τ' = (cmd − τ) / T_c, T_c = 1 / (2π f_c). No lag when f_c is not positive. */
static double current_loop(arm_sim_t *sim, const arm_params_t *p, int j, double cmd_nm, double h)
{
    const double f_hz = p->current_loop_hz[j];
    if (!(f_hz > 0.0)) {
        sim->torque_nm[j] = cmd_nm;
        return cmd_nm;
    }
    const double tc = 1.0 / (2.0 * M_PI * f_hz);
    const double decay = exp(-h / tc);
    const double gap = sim->torque_nm[j] - cmd_nm;
    sim->torque_nm[j] = cmd_nm + gap * decay;
    return cmd_nm + gap * (tc / h) * (1.0 - decay);
}

/* The cable torque k (qm − q) + d (q̇m − q̇) on compliant joint j, joint side (motor → link). */
static double cable_torque_nm(const arm_sim_t *sim, const arm_params_t *p, int j)
{
    const double k = 1.0 / (double)p->cable_compliance_rad_per_nm[j];
    return k * (sim->qm_rad[j] - sim->q_rad[j]) +
           (double)p->cable_damping_nm_s_per_rad[j] * (sim->qmd_rad_s[j] - sim->qd_rad_s[j]);
}

/* t less joint j's friction at velocity v: viscous, then tanh-smoothed Coulomb. */
static double less_friction_nm(const arm_params_t *p, int j, double t, double v)
{
    t -= (double)p->viscous_nm_s_per_rad[j] * v;
    t -= (double)p->coulomb_nm[j] * tanh(v / friction_width_rad_s(p));
    return t;
}

/* Semi-implicit Euler for joint c's link side, then the hard stops (restitution 0). */
static void advance_link(arm_sim_t *sim, const arm_params_t *p, int c, double qdd, double h)
{
    sim->qdd_rad_s2[c] = qdd;
    sim->qd_rad_s[c] += h * qdd;
    sim->q_rad[c] += h * sim->qd_rad_s[c];
    const double lo = p->desc.q_min_rad[c], hi = p->desc.q_max_rad[c];
    if (sim->q_rad[c] < lo) {
        sim->q_rad[c] = lo;
        if (sim->qd_rad_s[c] < 0.0)
            sim->qd_rad_s[c] = 0.0;
    } else if (sim->q_rad[c] > hi) {
        sim->q_rad[c] = hi;
        if (sim->qd_rad_s[c] > 0.0)
            sim->qd_rad_s[c] = 0.0;
    }
}

/* One semi-implicit Euler sub-step of h seconds from the kinematics k at the present state;
 * cmd_nm is the commanded motor torque (motor side, clamped), which the current loop follows. */
static void substep(arm_sim_t *sim, const arm_params_t *p, const arm_kin_now_t *k,
                    const double cmd_nm[ARGIL_DRIVES], const double force_n[3], double h)
{
    double m[ARGIL_DRIVES][ARGIL_DRIVES];
    double tau[ARGIL_DRIVES], qdd[ARGIL_DRIVES], motor_tau[ARGIL_DRIVES], cable[ARGIL_DRIVES];
    mass_from_jacobian(p, (const double(*)[ARGIL_DRIVES])k->jac, m);
    for (int c = 0; c < ARGIL_DRIVES; c++) {
        const bool compliant = arm_sim_joint_compliant(p, c);
        motor_tau[c] = current_loop(sim, p, c, cmd_nm[c], h) * (double)p->desc.gear_ratio[c];
        cable[c] = compliant ? cable_torque_nm(sim, p, c) : 0.0;
        double t = compliant ? cable[c] : motor_tau[c];
        for (int i = 0; i < 3; i++)
            t += k->jac[i][c] * (force_n[i] - (double)p->tip_mass_kg * k->acc_bias_m_s2[i]);
        tau[c] = compliant ? t : less_friction_nm(p, c, t, sim->qd_rad_s[c]);
    }
    if (!arm_sim_solve3((const double(*)[3])m, tau, qdd))
        qdd[0] = qdd[1] = qdd[2] = 0.0; /* cannot happen while M's diagonal terms are positive */
    for (int c = 0; c < ARGIL_DRIVES; c++) {
        if (arm_sim_joint_compliant(p, c)) {
            const double t = less_friction_nm(p, c, motor_tau[c] - cable[c], sim->qmd_rad_s[c]);
            const double qmdd = t / rotor_at_joint(p, c);
            sim->qmd_rad_s[c] += h * qmdd;
            sim->qm_rad[c] += h * sim->qmd_rad_s[c];
            advance_link(sim, p, c, qdd[c], h);
        } else {
            advance_link(sim, p, c, qdd[c], h);
            sim->qm_rad[c] = sim->q_rad[c];
            sim->qmd_rad_s[c] = sim->qd_rad_s[c];
        }
    }
}

/* The commanded motor torques (clamped to the peak limit; non-finite counts as 0) and the tip
 * force (0 unless finite), in double. */
static void step_inputs(const arm_params_t *p, const float motor_torque_nm[ARGIL_DRIVES],
                        vec3_t tip_force_n, double cmd_nm[ARGIL_DRIVES], double f[3])
{
    for (int c = 0; c < ARGIL_DRIVES; c++) {
        const double peak = p->peak_torque_nm[c];
        const double t = isfinite(motor_torque_nm[c]) ? (double)motor_torque_nm[c] : 0.0;
        cmd_nm[c] = fmin(fmax(t, -peak), peak);
    }
    const bool ok = vec3_isfinite(tip_force_n);
    f[0] = ok ? tip_force_n.x : 0.0;
    f[1] = ok ? tip_force_n.y : 0.0;
    f[2] = ok ? tip_force_n.z : 0.0;
}

void arm_sim_substep_from(arm_sim_t *sim, const arm_params_t *p, const arm_kin_now_t *k,
                          const float motor_torque_nm[ARGIL_DRIVES], vec3_t tip_force_n,
                          uint32_t h_us)
{
    double cmd[ARGIL_DRIVES], f[3];
    step_inputs(p, motor_torque_nm, tip_force_n, cmd, f);
    substep(sim, p, k, cmd, f, (double)h_us * 1e-6);
}

void arm_sim_step(arm_sim_t *sim, const arm_params_t *p,
                  const float motor_torque_nm[ARGIL_DRIVES], vec3_t tip_force_n,
                  uint32_t dt_us)
{
    double cmd[ARGIL_DRIVES], f[3];
    step_inputs(p, motor_torque_nm, tip_force_n, cmd, f);
    const uint32_t sub_us = arm_sim_substep_us(p);
    while (dt_us > 0) {
        const uint32_t h_us = dt_us < sub_us ? dt_us : sub_us;
        arm_kin_now_t k;
        arm_sim_kin_now(sim, p, &k);
        substep(sim, p, &k, cmd, f, (double)h_us * 1e-6);
        dt_us -= h_us;
    }
}

double arm_sim_kinetic_energy_j(const arm_sim_t *sim, const arm_params_t *p)
{
    double m[ARGIL_DRIVES][ARGIL_DRIVES], e = 0.0;
    arm_sim_mass_matrix(p, sim->q_rad, m);
    for (int r = 0; r < ARGIL_DRIVES; r++)
        for (int c = 0; c < ARGIL_DRIVES; c++)
            e += sim->qd_rad_s[r] * m[r][c] * sim->qd_rad_s[c];
    for (int j = 0; j < ARGIL_DRIVES; j++)
        if (arm_sim_joint_compliant(p, j))
            e += rotor_at_joint(p, j) * sim->qmd_rad_s[j] * sim->qmd_rad_s[j];
    return 0.5 * e;
}

double arm_sim_cable_energy_j(const arm_sim_t *sim, const arm_params_t *p)
{
    double e = 0.0;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        if (!arm_sim_joint_compliant(p, j))
            continue;
        const double twist = sim->qm_rad[j] - sim->q_rad[j];
        e += twist * twist / (double)p->cable_compliance_rad_per_nm[j];
    }
    return 0.5 * e;
}

double arm_sim_encoder_rad(const arm_sim_t *sim, const arm_params_t *p, int j)
{
    return arm_sim_joint_compliant(p, j) ? sim->qm_rad[j] : sim->q_rad[j];
}

void arm_sim_applied_torque_nm(const arm_sim_t *sim, float out[ARGIL_DRIVES])
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        out[j] = (float)sim->torque_nm[j];
}

vec3_t arm_sim_tip_m(const arm_sim_t *sim, const arm_params_t *p)
{
    double t[3];
    kin_terms(p, sim->q_rad, NULL, NULL, t, NULL, NULL);
    return vec3_from_d(t);
}

vec3_t arm_sim_tip_vel_m_s(const arm_sim_t *sim, const arm_params_t *p)
{
    double v[3];
    kin_terms(p, sim->q_rad, sim->qd_rad_s, NULL, NULL, v, NULL);
    return vec3_from_d(v);
}

void arm_sim_q_rad(const arm_sim_t *sim, float q_rad[ARGIL_DRIVES])
{
    for (int k = 0; k < ARGIL_DRIVES; k++)
        q_rad[k] = (float)sim->q_rad[k];
}
