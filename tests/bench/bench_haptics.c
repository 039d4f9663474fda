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

#include "tests/sil/wall_throw.h"

/* ---------- The Z-width bench (docs/haptics.md, "The Z-width bench") ---------- */

#define HELD_FORCE_N 1.0f
#define HELD_PP_GOAL_N 0.05f
#define HELD_DEPTHS 4            /* held-wall runs, their depths spread over … */
#define HELD_COUNT_M 0.000019f   /* … one encoder count at the tip along z (docs/haptics.md) */

static const float throw_speeds_m_s[] = {0.025f, 0.05f, 0.1f, 0.2f, 0.4f};
#define N_SPEEDS (sizeof(throw_speeds_m_s) / sizeof(throw_speeds_m_s[0]))

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
    wall_send_window(r, tip.z - r->tool.radius_m - 0.001f, tip, edge);
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
        wall_premium_arm = argc >= 3 && strcmp(argv[2], "premium") == 0;
        printf("  Arm: %s\n", wall_premium_arm ? "arm_params_premium (cable mode 800 N m/rad, 1 kHz "
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
