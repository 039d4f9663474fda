/* The Z-width bench's wall, thrown stylus and contact bookkeeping (docs/haptics.md, "The
 * Z-width bench"), shared by tests/bench/bench_haptics.c and the SIL bounce test: a manual-host
 * rig whose window is a flat wall, a free stylus thrown onto it, and each contact's energy in
 * and out from the simulator's truth. Include after tests/sil/rig.h. */
#ifndef ARGIL_SIL_WALL_THROW_H
#define ARGIL_SIL_WALL_THROW_H

#define WALL_SPACING_M 0.00125f  /* the wall window's sample spacing */

/* A wall window: material below z = wall_z (model), edge samples per axis, around centre. */
static inline void wall_send_window(rig_t *r, float wall_z, vec3_t centre, int edge)
{
    static float d[ARGIL_WINDOW_SAMPLES_MAX];
    const vec3_t o = vec3(centre.x - 0.5f * (float)(edge - 1) * WALL_SPACING_M, centre.y - 0.5f * (float)(edge - 1) * WALL_SPACING_M,
                          centre.z - 0.5f * (float)(edge - 1) * WALL_SPACING_M);
    for (int z = 0; z < edge; z++)
        for (int i = 0; i < edge * edge; i++) {
            float v = 0.5f + 0.5f * (wall_z - (o.z + (float)z * WALL_SPACING_M)) / (4.0f * WALL_SPACING_M);
            d[i + edge * edge * z] = v < 0 ? 0 : (v > 1 ? 1 : v);
        }
    spring_material_t mat;
    spring_material_default(&mat);
    const int32_t dims[3] = {edge, edge, edge};
    rig_send_window(r, d, NULL, dims, o, WALL_SPACING_M, &mat);
}

#define WALL_EDGE 16             /* window samples per axis: 18.75 mm, the wall 6.4 mm below its top */
#define BOUNCES_MAX 32
#define CONTACT_QUIET_MS 50      /* a throw is over this long after its last contact ended */
#define THROW_WATCH_MS 600       /* … or this long after the release */
#define RELEASE_GAP_M 0.0001f    /* the hand lets go this far from contact (tool surface to
                                  * wall), or 2 ms of travel away when that is farther */
#define STILL_PP_M 0.00005f      /* moving less than this peak to peak is at rest (2.5 counts) */


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
static inline float wall_damping(const wall_cfg_t *c)
{
    board_cfg_t def;
    board_cfg_default(&def);
    return c->shipped ? def.contact_damping_n_s_per_m + c->k_n_per_mm * 1e3f * def.contact_damping_s
                      : c->b_n_s_per_m;
}

/* The simulated arm every wall runs on: the default (rigid) arm, or arm_params_premium's
 * (cable mode, current loop, 12-bit DAC: docs/arm.md) with `zwidth premium`. */
static bool wall_premium_arm;

/* A manual-host rig whose window is a flat wall below the stylus (material at model z < wall_z,
 * normal +z), gap_m from the tool's surface, with the hand's grip set; NULL if never ACTIVE. */

static inline rig_t *wall_rig_new(const wall_cfg_t *c, float gap_m, float grip_n_per_m,
                           float grip_n_s_per_m, float *wall_z)
{
    rig_t *r = rig_new_mode(c->k_n_per_mm, true);
    if (wall_premium_arm) {
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
    wall_send_window(r, *wall_z, vec3(tip.x, tip.y, *wall_z - 0.003f), WALL_EDGE);
    if (rig_until_active(r, 1000) < 0) {
        rig_free(r);
        return NULL;
    }
    return r;
}

/* WALL_SPACING_Mow far the tool is into the wall now (sim truth), m; negative: above it. */
static inline float wall_penetration_m(const rig_t *r, float wall_z)
{
    return wall_z - (rig_tip_model(r).z - r->tool.radius_m);
}

/* ½ K p² of a wall of stiffness k_n_per_mm at penetration pen_m (0 outside it). */
static inline double wall_stored_j(float k_n_per_mm, float pen_m)
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

static inline void contacts_init(contacts_t *cs, float k_n_per_mm, float wall_z)
{
    memset(cs, 0, sizeof(*cs));
    cs->k_n_per_mm = k_n_per_mm;
    cs->wall_z = wall_z;
}

/* The wall spring's energy now (truth) and the arm's kinetic energy. */
static inline void contacts_energy(const rig_t *r, const contacts_t *cs, double *u_j, double *ke_j)
{
    *u_j = wall_stored_j(cs->k_n_per_mm, wall_penetration_m(r, cs->wall_z));
    *ke_j = arm_sim_kinetic_energy_j(&r->rig.dev.arm, &r->rig.dev.p.arm);
}

/* The motors' work on the arm over the step just done, and whether any drive applied torque:
 * the drives hold their torques over a whole step, so on the default arm it is exactly
 * Σ gear · τ · Δq (on the Premium profile, whose current loop lags and whose cable twists
 * between motor and link, an estimate). */
static inline double motor_work_j(const sim_device_t *d, const double q0[ARGIL_DRIVES], bool *torque)
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
static inline void contacts_tick(rig_t *r, contacts_t *cs)
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
static inline void contacts_finish(const rig_t *r, contacts_t *cs)
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
static inline double contact_excess_j(const contact_t *c)
{
    return c->work_j + c->u_out_j - c->u_in_j;
}

/* Peak-to-peak of a series, kept as it comes. */
typedef struct {
    float lo, hi;
    int n;
} span_t;

static inline void span_add(span_t *s, float v)
{
    if (s->n == 0 || v < s->lo)
        s->lo = v;
    if (s->n == 0 || v > s->hi)
        s->hi = v;
    s->n++;
}

static inline float span_pp(const span_t *s)
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
static inline bool wall_throw(const wall_cfg_t *c, float speed_m_s, throw_t *t)
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
static inline double contact_ratio(const contact_t *c)
{
    return c->e_in_j > 0.0 ? c->e_out_j / c->e_in_j : 0.0;
}

#endif
