/* make bench, haptic rendering: the Z-width of the board's wall on the simulated arm (bounces of
 * a free stylus, a light grip, a held wall, the felt stiffness, swept over stiffness, damping,
 * passivity controller and loop rate; docs/haptics.md "The Z-width bench") and the tick cost of
 * point, curve and area tools on 16³ and 32³ windows. Usage: bench_haptics [zwidth|tick TOOL EDGE] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The SIL rig asserts with cmocka's names; here a failed setup is fatal. */
#define assert_non_null(p) do { if (!(p)) { fprintf(stderr, "bench: setup failed\n"); exit(1); } } while (0)
#define assert_true(c) do { if (!(c)) { fprintf(stderr, "bench: setup failed: %s\n", #c); exit(1); } } while (0)
#define assert_int_equal(a, b) do { if ((a) != (b)) { fprintf(stderr, "bench: setup failed: %s\n", #a); exit(1); } } while (0)
#include "tests/sil/rig.h"

#define H 0.00125f

/* A wall window: material below z = wall_z (model), edge samples per axis, around centre. */
static void send_wall(rig_t *r, float wall_z, vec3_t centre, int edge)
{
    static float d[ARGIL_WINDOW_SAMPLES_MAX];
    const vec3_t o = vec3(centre.x - 0.5f * (float)(edge - 1) * H, centre.y - 0.5f * (float)(edge - 1) * H,
                          centre.z - 0.5f * (float)(edge - 1) * H);
    for (int z = 0; z < edge; z++)
        for (int i = 0; i < edge * edge; i++) {
            float v = 0.5f + 0.5f * (wall_z - (o.z + (float)z * H)) / (4.0f * H);
            d[i + edge * edge * z] = v < 0 ? 0 : (v > 1 ? 1 : v);
        }
    spring_material_t mat;
    spring_material_default(&mat);
    const int32_t dims[3] = {edge, edge, edge};
    rig_send_window(r, d, NULL, dims, o, H, &mat);
}

/* ---------- The Z-width bench (docs/haptics.md, "The Z-width bench") ---------- */

#define WALL_EDGE 16             /* window samples per axis: 18.75 mm, the wall 6.4 mm below its top */
#define BOUNCES_MAX 32
#define CONTACT_QUIET_MS 50      /* a throw is over this long after its last contact ended */
#define THROW_WATCH_MS 600       /* … or this long after the release */
#define RELEASE_GAP_M 0.0001f    /* the hand lets go this far from contact (tool surface to
                                  * wall), or 2 ms of travel away when that is farther */
#define STILL_PP_M 0.00005f      /* moving less than this peak to peak is at rest (2.5 counts) */
#define HELD_FORCE_N 1.0f
#define HELD_PP_GOAL_N 0.05f
#define HELD_DEPTHS 4            /* held-wall runs, their depths spread over … */
#define HELD_COUNT_M 0.000019f   /* … one encoder count at the tip along z (docs/haptics.md) */

static const float throw_speeds_m_s[] = {0.025f, 0.05f, 0.1f, 0.2f, 0.4f};
#define N_SPEEDS (sizeof(throw_speeds_m_s) / sizeof(throw_speeds_m_s[0]))

/* One wall as the sweep renders it. */
typedef struct {
    float k_n_per_mm;
    float b_n_s_per_m;           /* virtual contact damping (when !shipped) */
    bool shipped;                /* the board's default damping instead, b0 + K·τ */
    bool passivity;              /* board.cfg.passivity */
    uint32_t tick_us;            /* loop period; the device steps by the same dt */
    bool one_tick_velocity;      /* the velocity before 2026-12-04: a one-tick backward
                                    difference (velocity_tolerance_m = 0), not the window */
} wall_cfg_t;

/* The wall's virtual contact damping, N·s/m. */
static float wall_damping(const wall_cfg_t *c)
{
    board_cfg_t def;
    board_cfg_default(&def);
    return c->shipped ? def.contact_damping_n_s_per_m + c->k_n_per_mm * 1e3f * def.contact_damping_s
                      : c->b_n_s_per_m;
}

/* A manual-host rig whose window is a flat wall below the stylus (material at model z < wall_z,
 * normal +z), gap_m from the tool's surface, with the hand's grip set; NULL if never ACTIVE. */
/* The simulated arm every wall runs on: the default (rigid) arm, or arm_params_premium's
 * (cable mode, current loop, 12-bit DAC: docs/arm.md) with `zwidth premium`. */
static bool premium_arm;

static rig_t *wall_rig_new(const wall_cfg_t *c, float gap_m, float grip_n_per_m,
                           float grip_n_s_per_m, float *wall_z)
{
    rig_t *r = rig_new_mode(c->k_n_per_mm, true);
    if (premium_arm) {
        /* the same geometry, gears and encoders (the board's arm is unchanged), the
         * Premium dynamics: the device starts over with them before its first step */
        arm_params_premium(&r->rig.sim_params.arm);
        sim_device_init(&r->rig.dev, &r->rig.sim_params);
    }
    rig_set_tick_us(r, c->tick_us);
    board_cfg_t *bc = &r->rig.board.cfg; /* after board_init: a negative B is allowed here */
    bc->passivity = c->passivity;
    if (!c->shipped) {
        bc->contact_damping_n_s_per_m = c->b_n_s_per_m;
        bc->contact_damping_s = 0.0f;
    }
    if (c->one_tick_velocity)
        bc->velocity_tolerance_m = 0.0f;
    r->rig.dev.p.hand.stiffness_n_per_m = grip_n_per_m;
    r->rig.dev.p.hand.damping_n_s_per_m = grip_n_s_per_m;
    const vec3_t tip = rig_tip_model(r);
    *wall_z = tip.z - r->tool.radius_m - gap_m;
    send_wall(r, *wall_z, vec3(tip.x, tip.y, *wall_z - 0.003f), WALL_EDGE);
    if (rig_until_active(r, 1000) < 0) {
        rig_free(r);
        return NULL;
    }
    return r;
}

/* How far the tool is into the wall now (sim truth), m; negative: above it. */
static float wall_penetration_m(const rig_t *r, float wall_z)
{
    return wall_z - (rig_tip_model(r).z - r->tool.radius_m);
}

/* ½ K p² of a wall of stiffness k_n_per_mm at penetration pen_m (0 outside it). */
static double wall_stored_j(float k_n_per_mm, float pen_m)
{
    return pen_m > 0.0f ? 0.5 * k_n_per_mm * 1e3 * (double)pen_m * (double)pen_m : 0.0;
}

/* One contact episode: from the tick the board's force turns non-zero until both that force
 * and the drives' torques are zero again. Its ends are decided on the encoders, so the tip
 * (truth) may be up to a count inside the wall there: the energy at each end is the arm's
 * kinetic energy plus what a lossless wall spring would hold at the true penetration. */
typedef struct {
    double e_in_j, e_out_j;      /* ½ q̇ᵀM q̇ of the arm + ½ K p², at the start and the end */
    double u_in_j, u_out_j;      /* … the ½ K p² parts */
    double work_j;               /* ∫ τ_joint · q̇ dt of the motors over it: > 0 put energy in */
    float v_in_m_s;              /* tip speed into the wall at the start */
    bool open;                   /* still going when the case ended */
} contact_t;

typedef struct {
    float k_n_per_mm, wall_z;    /* the wall, for its stored energy */
    contact_t c[BOUNCES_MAX];
    int n;                       /* episodes started (the last may be open) */
    int dropped;                 /* episodes beyond BOUNCES_MAX */
    bool in_contact;
    uint32_t ticks, last_start_tick, last_end_tick;
    bool faulted;                /* the board left ACTIVE */
} contacts_t;

static void contacts_init(contacts_t *cs, float k_n_per_mm, float wall_z)
{
    memset(cs, 0, sizeof(*cs));
    cs->k_n_per_mm = k_n_per_mm;
    cs->wall_z = wall_z;
}

/* The wall spring's energy now (truth) and the arm's kinetic energy. */
static void contacts_energy(const rig_t *r, const contacts_t *cs, double *u_j, double *ke_j)
{
    *u_j = wall_stored_j(cs->k_n_per_mm, wall_penetration_m(r, cs->wall_z));
    *ke_j = arm_sim_kinetic_energy_j(&r->rig.dev.arm, &r->rig.dev.p.arm);
}

/* The motors' work on the arm over the step just done, and whether any drive applied torque:
 * the drives hold their torques over a whole step, so it is exactly Σ gear · τ · Δq. */
static double motor_work_j(const sim_device_t *d, const double q0[ARGIL_DRIVES], bool *torque)
{
    float tau[ARGIL_DRIVES];
    sim_device_motor_torque_nm(d, tau);
    double w = 0.0;
    *torque = false;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        const double peak = d->p.arm.peak_torque_nm[j];
        const double t = tau[j] > peak ? peak : (tau[j] < -peak ? -peak : (double)tau[j]);
        w += d->p.arm.desc.gear_ratio[j] * t * (d->arm.q_rad[j] - q0[j]);
        *torque = *torque || tau[j] != 0.0f;
    }
    return w;
}

/* One board tick of r, following the contact episodes and the motors' work on the arm. */
static void contacts_tick(rig_t *r, contacts_t *cs)
{
    const sim_device_t *d = &r->rig.dev;
    double q0[ARGIL_DRIVES];
    memcpy(q0, d->arm.q_rad, sizeof(q0));
    rig_tick(r);
    bool torque;
    const double w = motor_work_j(d, q0, &torque);
    const bool force = vec3_norm(r->rig.board.force_n) > 0.0f;
    contact_t *c = cs->n > 0 && cs->n <= BOUNCES_MAX ? &cs->c[cs->n - 1] : NULL;
    if (cs->in_contact && c)
        c->work_j += w;
    double u, ke;
    if (!cs->in_contact && force) {
        cs->in_contact = true;
        cs->last_start_tick = cs->ticks;
        if (cs->n < BOUNCES_MAX) {
            c = &cs->c[cs->n];
            memset(c, 0, sizeof(*c));
            contacts_energy(r, cs, &u, &ke);
            c->u_in_j = u;
            c->e_in_j = ke + u;
            c->v_in_m_s = -sim_device_tip_vel_m_s(d).z;
            c->open = true;
        } else {
            cs->dropped++;
        }
        cs->n++;
    } else if (cs->in_contact && !force && !torque) {
        cs->in_contact = false;
        cs->last_end_tick = cs->ticks;
        if (c) {
            contacts_energy(r, cs, &u, &ke);
            c->u_out_j = u;
            c->e_out_j = ke + u;
            c->open = false;
        }
    }
    if (r->rig.board.safety.state != SAFETY_ACTIVE)
        cs->faulted = true;
    cs->ticks++;
}

/* Gives an episode still open at the end of a case the energy it holds then. */
static void contacts_finish(const rig_t *r, contacts_t *cs)
{
    if (!cs->in_contact || cs->n <= 0 || cs->n > BOUNCES_MAX)
        return;
    contact_t *c = &cs->c[cs->n - 1];
    double ke;
    contacts_energy(r, cs, &c->u_out_j, &ke);
    c->e_out_j = ke + c->u_out_j;
}

/* What the display gave the arm over a contact beyond what a lossless wall returns: the motors'
 * work plus the change of the wall spring's energy (≤ 0: passive). */
static double contact_excess_j(const contact_t *c)
{
    return c->work_j + c->u_out_j - c->u_in_j;
}

/* Peak-to-peak of a series, kept as it comes. */
typedef struct {
    float lo, hi;
    int n;
} span_t;

static void span_add(span_t *s, float v)
{
    if (s->n == 0 || v < s->lo)
        s->lo = v;
    if (s->n == 0 || v > s->hi)
        s->hi = v;
    s->n++;
}

static float span_pp(const span_t *s)
{
    return s->n > 0 ? s->hi - s->lo : 0.0f;
}

/* Case 1: the result of one throw of the free stylus. */
typedef struct {
    contacts_t cs;
    float speed_m_s;             /* the hand's speed before letting go */
    bool touched;                /* the stylus reached the wall */
    bool released_late;          /* the board's force was on before the hand let go */
    bool oscillating;            /* still bouncing or moving in contact at THROW_WATCH_MS */
} throw_t;

/* Throws the stylus at the wall: the hand (default grip) carries it at speed toward the wall
 * over a run-up of 40 ms (at least 3 mm) and lets go RELEASE_GAP_M or 2 ms of travel before
 * contact; then the free stylus meets the wall alone. Over when it has been clear of the wall
 * for CONTACT_QUIET_MS, or THROW_WATCH_MS after the release. */
static bool wall_throw(const wall_cfg_t *c, float speed_m_s, throw_t *t)
{
    memset(t, 0, sizeof(*t));
    t->speed_m_s = speed_m_s;
    const float runup = speed_m_s * 0.040f > 0.003f ? speed_m_s * 0.040f : 0.003f;
    const float release = speed_m_s * 0.002f > RELEASE_GAP_M ? speed_m_s * 0.002f : RELEASE_GAP_M;
    float wall_z;
    hand_params_t grip;
    hand_params_default(&grip);
    rig_t *r = wall_rig_new(c, runup + release, grip.stiffness_n_per_m,
                            grip.damping_n_s_per_m, &wall_z);
    if (!r)
        return false;
    const float dz = speed_m_s * (float)r->tick_us * 1e-6f;
    for (int i = 0; i < rig_ticks_in_ms(r, 1000) && !r->hand_released; i++) {
        r->hand_model_m.z -= dz;
        rig_tick(r);
        if (vec3_norm(r->rig.board.force_n) > 0.0f)
            t->released_late = true;
        if (wall_penetration_m(r, wall_z) >= -release)
            r->hand_released = true;
    }
    contacts_t *cs = &t->cs;
    contacts_init(cs, c->k_n_per_mm, wall_z);
    const uint32_t watch = (uint32_t)rig_ticks_in_ms(r, THROW_WATCH_MS);
    const uint32_t quiet = (uint32_t)rig_ticks_in_ms(r, CONTACT_QUIET_MS);
    const uint32_t tail = (uint32_t)rig_ticks_in_ms(r, 100);
    span_t last = {0};
    while (cs->ticks < watch) {
        contacts_tick(r, cs);
        if (cs->n > 0 && !cs->in_contact && cs->ticks - cs->last_end_tick >= quiet)
            break;
        if (cs->ticks >= watch - tail)
            span_add(&last, rig_tip_model(r).z);
    }
    contacts_finish(r, cs);
    t->touched = cs->n > 0;
    const bool busy = cs->in_contact || (cs->n > 0 && cs->last_start_tick >= watch - tail);
    t->oscillating = cs->ticks >= watch && busy && span_pp(&last) >= STILL_PP_M;
    rig_free(r);
    return true;
}

/* E_out / E_in of one contact (0 with nothing coming in). */
static double contact_ratio(const contact_t *c)
{
    return c->e_in_j > 0.0 ? c->e_out_j / c->e_in_j : 0.0;
}

/* Case 2: the light grip carries the stylus into the wall and holds it there. */
typedef struct {
    contacts_t cs;
    float pen_end_m;             /* penetration at the end */
    double worst_j;              /* the largest contact_excess_j of its contacts */
    bool passive, oscillating;
} grip_t;

/* The hand (100 N/m, 0.2 N·s/m: a relaxed hand) carries the stylus from 2 mm above the wall to a
 * target 10 mm into it at 100 mm/s and holds it there for 1 s. Passive: contact_excess_j ≤ 0
 * over every contact (for the one still open, up to the end). Sustained oscillation: the tip
 * still moves ≥ STILL_PP_M peak to peak over the last 0.25 s. */
static bool wall_grip(const wall_cfg_t *c, grip_t *g)
{
    memset(g, 0, sizeof(*g));
    float wall_z;
    rig_t *r = wall_rig_new(c, 0.002f, 100.0f, 0.2f, &wall_z);
    if (!r)
        return false;
    contacts_t *cs = &g->cs;
    contacts_init(cs, c->k_n_per_mm, wall_z);
    const vec3_t from = r->hand_model_m;
    const int carry = rig_ticks_in_ms(r, 120), hold = rig_ticks_in_ms(r, 1000);
    span_t last = {0};
    for (int i = 1; i <= carry + hold; i++) {
        const float u = i < carry ? (float)i / (float)carry : 1.0f;
        r->hand_model_m = vec3_add(from, vec3(0, 0, -0.012f * u));
        contacts_tick(r, cs);
        if (i > carry + hold - rig_ticks_in_ms(r, 250))
            span_add(&last, rig_tip_model(r).z);
    }
    g->pen_end_m = wall_penetration_m(r, wall_z);
    contacts_finish(r, cs);
    g->passive = !cs->faulted && cs->dropped == 0;
    for (int i = 0; i < cs->n && i < BOUNCES_MAX; i++) {
        const double e = contact_excess_j(&cs->c[i]);
        if (e > 0.0)
            g->passive = false;
        if (i == 0 || e > g->worst_j)
            g->worst_j = e;
    }
    g->oscillating = span_pp(&last) >= STILL_PP_M;
    rig_free(r);
    return true;
}

/* Case 3 at one depth: the delivered force's normal component over 1 s after the hand (default
 * grip) has pressed the stylus into the wall at HELD_FORCE_N, its target deeper by extra_m, and
 * held it for 0.5 s; false if never ACTIVE. */
static bool wall_held_at(const wall_cfg_t *c, float extra_m, float *pp_n, float *mean_n,
                         bool *faulted)
{
    float wall_z;
    hand_params_t grip;
    hand_params_default(&grip);
    rig_t *r = wall_rig_new(c, 0.002f, grip.stiffness_n_per_m, grip.damping_n_s_per_m, &wall_z);
    if (!r)
        return false;
    /* Where the grip holds the stylus at HELD_FORCE_N into a wall of stiffness K. */
    const float sink = HELD_FORCE_N / (c->k_n_per_mm * 1e3f) + HELD_FORCE_N / grip.stiffness_n_per_m;
    const vec3_t from = r->hand_model_m;
    const float travel = 0.002f + sink + extra_m;
    rig_move(r, vec3_add(from, vec3(0, 0, -travel)), (int)(travel / 0.02f * 1000.0f) + 1);
    for (int i = 0; i < rig_ticks_in_ms(r, 500); i++)
        rig_tick(r);
    span_t s = {0};
    double sum = 0.0;
    for (int i = 0; i < rig_ticks_in_ms(r, 1000); i++) {
        rig_tick(r);
        const float fz = sim_device_delivered_force_n(&r->rig.dev).z;
        span_add(&s, fz);
        sum += fz;
        if (r->rig.board.safety.state != SAFETY_ACTIVE)
            *faulted = true;
    }
    *pp_n = span_pp(&s);
    *mean_n = (float)(sum / (double)s.n);
    rig_free(r);
    return true;
}

/* Case 3: the worst of HELD_DEPTHS holds whose tip depths are spread evenly over about one
 * encoder count (0.019 mm at the tip along z): whether the force ripples depends on where the
 * rest point falls between two counts, and a person does not pick the lucky one. */
static bool wall_held(const wall_cfg_t *c, float *pp_n, float *mean_n, bool *faulted)
{
    hand_params_t grip;
    hand_params_default(&grip);
    /* The hand's target moves (1 + K / k_grip) times as far as the tip it holds in the wall. */
    const float per_tip = 1.0f + c->k_n_per_mm * 1e3f / grip.stiffness_n_per_m;
    *pp_n = 0.0f;
    *faulted = false;
    for (int i = 0; i < HELD_DEPTHS; i++) {
        float pp, mean;
        if (!wall_held_at(c, per_tip * HELD_COUNT_M * (float)i / HELD_DEPTHS, &pp, &mean, faulted))
            return false;
        if (i == 0 || pp > *pp_n) {
            *pp_n = pp;
            *mean_n = mean;
        }
    }
    return true;
}

/* Case 4, the felt stiffness: the least-squares slope of the delivered normal force against the
 * penetration (sim truth) over 0.2 .. 1.5 mm, or up to 95 % of the force limit, pressing at
 * 1 mm/s (the hand's target moves at 1 mm/s · (1 + K / k_grip), so the tip goes in at about
 * 1 mm/s). N/mm; -1 when fewer than 10 samples fall in the range. */
static float wall_felt_stiffness(const wall_cfg_t *c)
{
    float wall_z;
    hand_params_t grip;
    hand_params_default(&grip);
    rig_t *r = wall_rig_new(c, 0.002f, grip.stiffness_n_per_m, grip.damping_n_s_per_m, &wall_z);
    if (!r)
        return -1.0f;
    const vec3_t from = r->hand_model_m;
    rig_move(r, vec3_add(from, vec3(0, 0, -0.0019f)), 190);
    for (int i = 0; i < rig_ticks_in_ms(r, 100); i++)
        rig_tick(r);
    const float limit = 0.95f * (r->tool.max_force_n < r->rig.board.cfg.max_force_n
                                     ? r->tool.max_force_n : r->rig.board.cfg.max_force_n);
    const float dz = 1e-3f * (1.0f + c->k_n_per_mm * 1e3f / grip.stiffness_n_per_m) *
                     (float)r->tick_us * 1e-6f;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int i = 0; i < rig_ticks_in_ms(r, 2500); i++) {
        r->hand_model_m.z -= dz;
        rig_tick(r);
        const float p_mm = wall_penetration_m(r, wall_z) * 1e3f;
        const float f = sim_device_delivered_force_n(&r->rig.dev).z;
        if (p_mm > 1.5f || f >= limit || r->rig.board.safety.state != SAFETY_ACTIVE)
            break;
        if (p_mm >= 0.2f) {
            sx += p_mm;
            sy += f;
            sxx += (double)p_mm * p_mm;
            sxy += (double)p_mm * f;
            n++;
        }
    }
    rig_free(r);
    const double den = n * sxx - sx * sx;
    return n >= 10 && den > 0.0 ? (float)((n * sxy - sx * sy) / den) : -1.0f;
}

/* Cases 1–3 of one wall and what failed. */
typedef struct {
    throw_t throws[N_SPEEDS];
    grip_t grip;
    float held_pp_n, held_mean_n;
    bool setup_failed;           /* a rig never became ACTIVE */
    bool bounce_active;          /* case 1: some bounce left with more energy than it came in with */
    bool missed;                 /* case 1: a throw never reached the wall (the bench is wrong) */
    bool oscillating;            /* case 1 or 2: a sustained oscillation against the wall */
    bool grip_active;            /* case 2: the motors' net work over a contact > 0 */
    bool held_ripple;            /* case 3: ≥ HELD_PP_GOAL_N peak to peak */
    bool faulted;                /* the board left ACTIVE in some case */
    double worst_ratio;          /* largest E_out / E_in over the throws' bounces */
    double worst_gain_j;         /* largest E_out - E_in over them */
    double worst_work_j;         /* largest motor work over one of the throws' contacts */
    bool any_contact;
} wall_result_t;

static bool wall_passes(const wall_result_t *w)
{
    return !w->setup_failed && !w->bounce_active && !w->missed && !w->oscillating &&
           !w->grip_active && !w->held_ripple && !w->faulted;
}

/* Case 1 over every speed into w. */
static void wall_evaluate_throws(const wall_cfg_t *c, wall_result_t *w)
{
    for (size_t s = 0; s < N_SPEEDS; s++) {
        throw_t *t = &w->throws[s];
        if (!wall_throw(c, throw_speeds_m_s[s], t) || t->released_late) {
            w->setup_failed = true;
            continue;
        }
        w->missed = w->missed || !t->touched;
        w->oscillating = w->oscillating || t->oscillating || t->cs.dropped > 0;
        w->faulted = w->faulted || t->cs.faulted;
        for (int i = 0; i < t->cs.n && i < BOUNCES_MAX; i++) {
            const contact_t *k = &t->cs.c[i];
            if (k->e_out_j > k->e_in_j)
                w->bounce_active = true;
            if (contact_ratio(k) > w->worst_ratio)
                w->worst_ratio = contact_ratio(k);
            if (!w->any_contact || k->e_out_j - k->e_in_j > w->worst_gain_j)
                w->worst_gain_j = k->e_out_j - k->e_in_j;
            if (!w->any_contact || k->work_j > w->worst_work_j)
                w->worst_work_j = k->work_j;
            w->any_contact = true;
        }
    }
}

/* Cases 1–3 of one wall. */
static void wall_evaluate(const wall_cfg_t *c, wall_result_t *w)
{
    memset(w, 0, sizeof(*w));
    wall_evaluate_throws(c, w);
    if (wall_grip(c, &w->grip)) {
        w->grip_active = !w->grip.passive;
        w->oscillating = w->oscillating || w->grip.oscillating;
        w->faulted = w->faulted || w->grip.cs.faulted;
    } else {
        w->setup_failed = true;
    }
    bool held_fault = false;
    if (wall_held(c, &w->held_pp_n, &w->held_mean_n, &held_fault)) {
        w->held_ripple = !(w->held_pp_n < HELD_PP_GOAL_N);
        w->faulted = w->faulted || held_fault;
    } else {
        w->setup_failed = true;
    }
}

/* The sweep's cell for one wall: "ok", or a letter per failure. */
static void wall_cell(const wall_result_t *w, char out[8])
{
    int n = 0;
    if (w->setup_failed) out[n++] = 'S';
    if (w->faulted) out[n++] = 'F';
    if (w->missed) out[n++] = 'm';
    if (w->bounce_active) out[n++] = 'b';
    if (w->oscillating) out[n++] = 'o';
    if (w->grip_active) out[n++] = 'g';
    if (w->held_ripple) out[n++] = 'h';
    if (n == 0) {
        out[n++] = 'o';
        out[n++] = 'k';
    }
    out[n] = '\0';
}

static const float sweep_k_n_per_mm[] = {0.25f, 0.5f, 1.0f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 12.0f};
static const float sweep_b_n_s_per_m[] = {0.0f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f};
static const uint32_t sweep_tick_us[] = {1000u, 500u, 250u};
#define N_K (sizeof(sweep_k_n_per_mm) / sizeof(sweep_k_n_per_mm[0]))
#define N_B (sizeof(sweep_b_n_s_per_m) / sizeof(sweep_b_n_s_per_m[0]))
#define N_RATES (sizeof(sweep_tick_us) / sizeof(sweep_tick_us[0]))

/* What the sweep keeps for the summary. */
typedef struct {
    wall_result_t shipped_1khz[N_K]; /* board_cfg_default's rendering, controller on, 1 kHz */
    wall_result_t before_1khz[N_K];  /* the same with the one-tick velocity of before */
    wall_result_t worst;             /* the wall whose bounce gained the most energy (J) */
    bool have_worst;
    wall_cfg_t worst_cfg;
    float best_felt[N_RATES];        /* largest felt stiffness in the stable region, per rate */
    float best_felt_k[N_RATES];
} sweep_t;

static void print_definitions(void)
{
    printf("  Definitions (docs/haptics.md, \"The Z-width bench\"); all energies and forces from the\n"
           "  simulator's truth, the force as the arm delivers it: F = J^-T (gear * tau_motor)\n"
           "  (sim_device_delivered_force_n), not the board's command:\n"
           "   1 bounce: a free stylus (the default grip carries it, lets go %.1f mm or 2 ms of travel before\n"
           "     contact) thrown at", (double)(RELEASE_GAP_M * 1e3f));
    for (size_t s = 0; s < N_SPEEDS; s++)
        printf(" %g", (double)(throw_speeds_m_s[s] * 1e3f));
    printf(" mm/s;\n"
           "     a contact = board force non-zero until force and drive torques are zero again;\n"
           "     passive = E_out <= E_in for every contact (E = 1/2 qd' M qd of the arm + K p^2/2 of the\n"
           "     wall at the true penetration p: a contact's ends are decided on encoder counts), and no\n"
           "     sustained oscillation (still in contact or bouncing and moving >= %.2f mm p-p %d ms\n"
           "     after the release). W = motors' net work on the arm over a contact (> 0: energy in)\n"
           "   2 grip: a 100 N/m, 0.2 N.s/m hand carries it 10 mm past the wall at 100 mm/s, holds 1 s;\n"
           "     passive = W + change of K p^2/2 <= 0 over every contact (the open one: to the end);\n"
           "     sustained oscillation = tip >= %.2f mm p-p over the last 0.25 s\n"
           "   3 held: the default grip (800 N/m, 8 N.s/m) presses it in at %.1f N; 0.5 s to settle, then\n"
           "     delivered normal force p-p over 1 s, worst of %d depths spread over one encoder count;\n"
           "     goal < %.2f N p-p\n"
           "   4 felt stiffness: press at 1 mm/s (tip), least-squares slope of delivered normal force\n"
           "     against penetration over 0.2-1.5 mm (or to 95%% of the 3.3 N limit); goal >= 3 N/mm at\n"
           "     1 kHz, >= 5 N/mm at 4 kHz\n"
           "  Cells: ok = cases 1-3 pass; else b = a bounce gained energy, o = sustained oscillation,\n"
           "  g = grip contact not passive, h = held-wall ripple, F = board left ACTIVE, m = a throw\n"
           "  missed the wall, S = setup failed\n",
           (double)(STILL_PP_M * 1e3f), THROW_WATCH_MS, (double)(STILL_PP_M * 1e3f),
           (double)HELD_FORCE_N, HELD_DEPTHS, (double)HELD_PP_GOAL_N);
}

/* One row of the sweep (one damping at one rate and controller setting); returns the largest K
 * that passed (0: none) and keeps what the summary needs. */
static float sweep_row(const wall_cfg_t *base, size_t rate, sweep_t *sw)
{
    float best = 0.0f;
    for (size_t i = 0; i < N_K; i++) {
        wall_cfg_t c = *base;
        c.k_n_per_mm = sweep_k_n_per_mm[i];
        static wall_result_t w;
        wall_evaluate(&c, &w);
        char cell[8];
        wall_cell(&w, cell);
        printf(" %5s", cell);
        if (wall_passes(&w))
            best = c.k_n_per_mm;
        if (!sw->have_worst || w.worst_gain_j > sw->worst.worst_gain_j) {
            sw->worst = w;
            sw->worst_cfg = c;
            sw->have_worst = true;
        }
        if (rate == 0 && base->passivity && base->shipped)
            *(base->one_tick_velocity ? &sw->before_1khz[i] : &sw->shipped_1khz[i]) = w;
    }
    return best;
}

/* The sweep over loop rate × passivity controller × damping × stiffness. */
static void sweep(sweep_t *sw)
{
    for (size_t rate = 0; rate < N_RATES; rate++) {
        for (int pc = 1; pc >= 0; pc--) {
            printf("  %u Hz, passivity controller %s\n    B [N.s/m] \\ K [N/mm]:",
                   1000000u / sweep_tick_us[rate], pc ? "on" : "off");
            for (size_t i = 0; i < N_K; i++)
                printf(" %5g", (double)sweep_k_n_per_mm[i]);
            printf("  | largest passing K, felt stiffness there\n");
            for (size_t b = 0; b <= N_B + 1; b++) {
                wall_cfg_t c = {0.0f, b < N_B ? sweep_b_n_s_per_m[b] : 0.0f, b >= N_B, pc != 0,
                                sweep_tick_us[rate], b == N_B + 1};
                if (b < N_B)
                    printf("    B = %-18g:", (double)c.b_n_s_per_m);
                else if (b == N_B)
                    printf("    shipped (b0 + K*tau) :");
                else
                    printf("    .. 1-tick velocity   :");
                fflush(stdout);
                const float k = sweep_row(&c, rate, sw);
                c.k_n_per_mm = k;
                const float felt = k > 0.0f ? wall_felt_stiffness(&c) : -1.0f;
                if (k > 0.0f)
                    printf("  | %g N/mm, felt %.2f N/mm\n", (double)k, (double)felt);
                else
                    printf("  | none\n");
                if (felt > sw->best_felt[rate]) {
                    sw->best_felt[rate] = felt;
                    sw->best_felt_k[rate] = k;
                }
            }
        }
    }
}

/* Every bounce of one wall's throws: speed, E_in, E_out, their ratio and the motors' work. */
static void print_bounces(const wall_result_t *w)
{
    for (size_t s = 0; s < N_SPEEDS; s++) {
        const throw_t *t = &w->throws[s];
        printf("      thrown at %3g mm/s:", (double)(t->speed_m_s * 1e3f));
        if (t->cs.n == 0)
            printf(" no contact");
        for (int i = 0; i < t->cs.n && i < BOUNCES_MAX && i < 4; i++) {
            const contact_t *k = &t->cs.c[i];
            printf(" [v_in %.0f mm/s E_in %.4g uJ E_out/E_in %.3f W %+.4g uJ%s]",
                   (double)(k->v_in_m_s * 1e3f), k->e_in_j * 1e6, contact_ratio(k), k->work_j * 1e6,
                   k->open ? " open" : "");
        }
        if (t->cs.n > 4)
            printf(" ... %d contacts", t->cs.n);
        printf("%s\n", t->oscillating ? " SUSTAINED OSCILLATION" : "");
    }
}

/* One rendering wall by wall, at 1 kHz with the controller on: the shipped damping
 * (board_cfg_default) and, beside it, the damping before 2026-12-04. */
static void print_walls(const char *what, const wall_result_t walls[N_K])
{
    printf("  %s, passivity controller on, 1 kHz, wall by wall:\n"
           "    K [N/mm] | worst E_out/E_in | largest W per bounce | grip: W+dU, osc | held p-p (mean) | cell\n",
           what);
    for (size_t i = 0; i < N_K; i++) {
        const wall_result_t *w = &walls[i];
        char cell[8];
        wall_cell(w, cell);
        printf("    %8g | %16.3f | %+17.4f mJ | %+10.4f mJ, %-3s | %.3f N (%.2f N) | %s\n",
               (double)sweep_k_n_per_mm[i], w->worst_ratio, w->worst_work_j * 1e3,
               w->grip.worst_j * 1e3, w->grip.oscillating ? "yes" : "no",
               (double)w->held_pp_n, (double)w->held_mean_n, cell);
    }
}

/* A check that cannot fail is a defect: a wall with negative damping (it pushes along the
 * velocity) must come out non-passive. */
static void self_check_active_wall(void)
{
    const wall_cfg_t c = {1.0f, -1.0f, false, false, 1000u, false};
    static wall_result_t w;
    wall_evaluate(&c, &w);
    printf("  Check of the check: K = 1 N/mm, B = -1 N.s/m (an active wall), controller off, 1 kHz:\n");
    print_bounces(&w);
    printf("    worst E_out/E_in %.3f, grip's largest W + dU %+.4f mJ => reported %s\n", w.worst_ratio,
           w.grip.worst_j * 1e3,
           w.bounce_active && w.grip_active ? "non-passive in cases 1 and 2 (as it must be)"
           : w.bounce_active || w.grip_active ? "non-passive in one case only"
                                              : "PASSIVE: THE CHECK IS BROKEN");
}

static void zwidth(void)
{
    print_definitions();
    static sweep_t sw;
    sweep(&sw);
    board_cfg_t def;
    board_cfg_default(&def);
    char what[160];
    snprintf(what, sizeof(what), "Shipped rendering (board_cfg_default: B = %g N.s/m + K * %g ms, "
             "velocity window %g um)", (double)def.contact_damping_n_s_per_m,
             (double)(def.contact_damping_s * 1e3f), (double)(def.velocity_tolerance_m * 1e6f));
    print_walls(what, sw.shipped_1khz);
    print_walls("The same with the velocity before 2026-12-04 (a one-tick backward difference)",
                sw.before_1khz);
    printf("  Worst bounce of the sweep (largest E_out - E_in): K = %g N/mm, B = %s%g N.s/m, controller %s, %u Hz:\n",
           (double)sw.worst_cfg.k_n_per_mm, sw.worst_cfg.shipped ? "shipped " : "",
           (double)wall_damping(&sw.worst_cfg),
           sw.worst_cfg.passivity ? "on" : "off", 1000000u / (sw.worst_cfg.tick_us ? sw.worst_cfg.tick_us : 1000u));
    print_bounces(&sw.worst);
    printf("  Goals (issue 17): felt stiffness in the stable region >= 3 N/mm at 1 kHz: %.2f N/mm (K = %g) %s;\n"
           "                   >= 5 N/mm at 4 kHz: %.2f N/mm (K = %g) %s\n",
           (double)sw.best_felt[0], (double)sw.best_felt_k[0], sw.best_felt[0] >= 3.0f ? "met" : "NOT MET",
           (double)sw.best_felt[2], (double)sw.best_felt_k[2], sw.best_felt[2] >= 5.0f ? "met" : "NOT MET");
    printf("  For comparison, CHAI3D's published stiffness limits: Touch 0.4, Omni 0.7, Desktop 1.0 N/mm;\n"
           "  PHANToM Premium 1.0 (vendor) ~3.5 N/mm\n");
    self_check_active_wall();
}

/* Runs 2 s of sculpting with the given tool on a wall window (the session's tick path), for
 * callgrind to count; prints nothing but a checksum so the work is not optimised away. */
static void tick_workload(const char *shape, int edge)
{
    rig_t *r = rig_new_mode(1.0f, true);
    r->rig.board.cfg.safety.overrun_streak = 0; /* under valgrind every tick overruns */
    const vec3_t tip = rig_tip_model(r);
    send_wall(r, tip.z - r->tool.radius_m - 0.001f, tip, edge);
    msg_tool_t t = rig_tool(r, TOOL_PUSH, 1.0f);
    t.yield_force_n = 0.2f;
    t.length_m = 0.008f;
    t.axis[0] = 1.0f;
    t.axis[2] = 0.0f;
    t.shape = strcmp(shape, "curve") == 0 ? TOOL_SHAPE_CURVE
              : strcmp(shape, "area") == 0 ? TOOL_SHAPE_AREA : TOOL_SHAPE_POINT;
    rig_set_tool(r, &t);
    if (rig_until_active(r, 1000) < 0) {
        fprintf(stderr, "bench: board did not become active\n");
        exit(1);
    }
    r->btn1 = true;
    rig_move(r, vec3_add(tip, vec3(0.003f, 0, -0.004f)), 1000);
    rig_move(r, vec3_add(tip, vec3(-0.003f, 0, -0.004f)), 1000);
    printf("%s %d: peak %.3f N, %u swaps, %u ticks\n", shape, edge,
           (double)r->rig.board.stats.peak_force_n, r->rig.board.stats.windows_swapped, r->rig.board.stats.ticks);
    rig_free(r);
}

/* One wall in detail: every bounce, the grip, the held wall and the felt stiffness. */
static void wall_detail(const wall_cfg_t *c)
{
    static wall_result_t w;
    wall_evaluate(c, &w);
    char cell[8];
    wall_cell(&w, cell);
    printf("  K = %g N/mm, B = %s%g N.s/m, controller %s, %u Hz: %s\n", (double)c->k_n_per_mm,
           c->shipped ? "shipped " : "", (double)wall_damping(c),
           c->passivity ? "on" : "off", 1000000u / c->tick_us, cell);
    print_bounces(&w);
    printf("    grip: %d contacts, end penetration %.3f mm, largest W + dU %+.4f mJ, "
           "oscillating %s\n", w.grip.cs.n, (double)(w.grip.pen_end_m * 1e3f), w.grip.worst_j * 1e3,
           w.grip.oscillating ? "yes" : "no");
    printf("    held: %.4f N p-p, mean %.3f N\n", (double)w.held_pp_n, (double)w.held_mean_n);
    printf("    felt stiffness %.3f N/mm\n", (double)wall_felt_stiffness(c));
}

int main(int argc, char **argv)
{
    if (argc >= 6 && strcmp(argv[1], "wall") == 0) {
        const bool shipped = strcmp(argv[3], "shipped") == 0 || strcmp(argv[3], "before") == 0;
        const wall_cfg_t c = {(float)atof(argv[2]), (float)atof(argv[3]), shipped,
                              atoi(argv[4]) != 0, (uint32_t)atoi(argv[5]),
                              strcmp(argv[3], "before") == 0};
        wall_detail(&c);
        return 0;
    }
    if (argc >= 2 && strcmp(argv[1], "zwidth") == 0) {
        premium_arm = argc >= 3 && strcmp(argv[2], "premium") == 0;
        printf("  Arm: %s\n", premium_arm ? "arm_params_premium (cable mode 800 N m/rad, 1 kHz "
               "current loop, 12-bit torque DAC; docs/arm.md)" : "arm_params_default (rigid links, "
               "no current-loop lag, no DAC)");
        zwidth();
        return 0;
    }
    if (argc >= 4 && strcmp(argv[1], "tick") == 0) {
        tick_workload(argv[2], atoi(argv[3]));
        return 0;
    }
    fprintf(stderr, "usage: bench_haptics zwidth [premium] | wall K_N_PER_MM B_N_S_PER_M|shipped|before PC(0|1) TICK_US |\n"
                    "       tick point|curve|area 16|32\n");
    return 2;
}
