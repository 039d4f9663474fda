/* The device side of a scenario, one tick at a time (see sim_runner.h). */
#include "sim_runner.h"

#include <stdio.h>
#include <string.h>

void sim_runner_init(sim_runner_t *r, const sim_params_t *p, const scenario_t *scn,
                     bool gpio_observed, sim_log_fn log, void *log_ctx)
{
    memset(r, 0, sizeof(*r));
    r->scn = scn;
    sim_device_init(&r->dev, p);
    can_faults_init(&r->faults);
    r->home_tip_m = sim_device_tip_m(&r->dev);
    r->hand_from_m = r->home_tip_m;
    r->hand_to_m = r->home_tip_m;
    r->hand_held = true;
    r->gpio_observed = gpio_observed;
    r->log = log;
    r->log_ctx = log_ctx;
}

static void emit(sim_runner_t *r, const char *text)
{
    if (r->log)
        r->log(r->log_ctx, r->now_us, text);
}

/* Where the hand's target is at now_us on its current straight-line move. */
static vec3_t hand_target(const sim_runner_t *r, int64_t now_us, vec3_t *vel_m_s)
{
    const int64_t into = now_us - r->move_start_us;
    if (r->move_dur_us <= 0 || into >= r->move_dur_us) {
        *vel_m_s = vec3(0, 0, 0);
        return r->hand_to_m;
    }
    const float u = (float)((double)into / (double)r->move_dur_us);
    const vec3_t d = vec3_sub(r->hand_to_m, r->hand_from_m);
    *vel_m_s = vec3_scale(d, 1e6f / (float)r->move_dur_us);
    return vec3_add(r->hand_from_m, vec3_scale(d, u));
}

static void apply(sim_runner_t *r, const scn_step_t *st)
{
    vec3_t vel;
    switch (st->action) {
    case SCN_HAND:
        r->hand_from_m = hand_target(r, r->now_us, &vel);
        r->hand_to_m = vec3_add(r->home_tip_m, vec3(st->p_mm[0] * 1e-3f, st->p_mm[1] * 1e-3f,
                                                   st->p_mm[2] * 1e-3f));
        r->move_start_us = r->now_us;
        r->move_dur_us = st->dur_us;
        if (!r->hand_held)
            r->hand_from_m = sim_device_tip_m(&r->dev);
        r->hand_held = true;
        break;
    case SCN_HAND_RELEASE:
        r->hand_held = false;
        break;
    case SCN_BUTTON:
        if (st->a == 1)
            r->btn1 = st->b != 0;
        else
            r->btn2 = st->b != 0;
        break;
    case SCN_ESTOP:
        sim_device_set_estop(&r->dev, st->a != 0);
        break;
    case SCN_DRIVE_FAULT_LINE:
        r->drive_fault_line_low = st->a != 0;
        break;
    case SCN_EMCY:
        sim_device_inject_drive_fault(&r->dev, st->a - 1);
        break;
    case SCN_HEARTBEAT:
        can_faults_heartbeat(&r->faults, st->a, st->b != 0);
        break;
    case SCN_ENCODER_JUMP:
        can_faults_encoder_jump(&r->faults, st->a, st->b);
        break;
    case SCN_CAN_DROP:
        can_faults_set_drop(&r->faults, st->ppm, st->seed);
        break;
    case SCN_CAN_DELAY:
        can_faults_set_delay(&r->faults, st->dur_us);
        break;
    case SCN_BUS_OFF:
        can_faults_bus_off(&r->faults);
        break;
    case SCN_BUS_RESTART:
        can_faults_bus_restart(&r->faults);
        break;
    default:
        return; /* host side: the caller's */
    }
    char text[SCN_TEXT_LEN + 24];
    snprintf(text, sizeof(text), "inject line=%u %s", (unsigned)st->line, st->text);
    emit(r, text);
}

/* Watches DRIVE_ENABLE (logged on change) and WDOG_KICK (a stale kick cuts the power, as the
 * arm's hardware watchdog does; judged only while sampled at least every 1.5 ms and afresh for
 * each tick, as a kick that toggles every tick cannot be seen at a slower rate). Returns the
 * levels the drives act on. */
static uint32_t watch_outputs(sim_runner_t *r, uint32_t gpio_out, uint32_t dt_us)
{
    if (!r->gpio_observed)
        return GPIO_OUT_DRIVE_ENABLE;
    const uint32_t kick = GPIO_OUT_WDOG_KICK, en = GPIO_OUT_DRIVE_ENABLE;
    if (!r->have_gpio_out || ((gpio_out ^ r->last_gpio_out) & kick) != 0 || dt_us > 1500u ||
        r->outputs_reused)
        r->last_kick_us = r->device_us;
    if (!r->have_gpio_out || ((gpio_out ^ r->last_gpio_out) & en) != 0) {
        emit(r, (gpio_out & en) ? "gpio_out DRIVE_ENABLE=1" : "gpio_out DRIVE_ENABLE=0");
        if (gpio_out & en)
            r->last_kick_us = r->device_us;
    }
    r->have_gpio_out = true;
    r->last_gpio_out = gpio_out;
    if (!(gpio_out & en)) {
        r->wdog_expired = false;
    } else if (!r->wdog_expired && r->device_us - r->last_kick_us > SIM_WDOG_TIMEOUT_US) {
        r->wdog_expired = true;
        emit(r, "note watchdog expired: WDOG_KICK stale with DRIVE_ENABLE high, power cut");
    }
    return r->wdog_expired ? (gpio_out & ~en) : gpio_out;
}

void sim_runner_tick(sim_runner_t *r, const can_batch_t *from_board, uint32_t gpio_out,
                     can_batch_t *to_board, uint32_t dt_us)
{
    if (r->scn && !r->holding) {
        while (r->next_step < r->scn->n_steps && r->scn->step[r->next_step].t_us <= r->now_us)
            apply(r, &r->scn->step[r->next_step++]);
    }
    const uint32_t levels = watch_outputs(r, gpio_out, dt_us);
    if (r->hand_held) {
        vec3_t vel;
        const vec3_t target = hand_target(r, r->now_us, &vel);
        sim_device_set_hand(&r->dev, target, vel, r->btn1, r->btn2);
    } else {
        sim_device_release_hand(&r->dev);
        r->dev.btn1 = r->btn1;
        r->dev.btn2 = r->btn2;
    }
    can_batch_t to_drives, from_drives;
    can_faults_from_board(&r->faults, from_board, &to_drives, r->device_us);
    sim_device_step(&r->dev, &to_drives, levels, &from_drives, dt_us);
    can_faults_to_board(&r->faults, &from_drives, to_board, r->device_us);
    r->device_us += dt_us;
    if (!r->holding)
        r->now_us += dt_us;
}

void sim_runner_hold(sim_runner_t *r, bool hold)
{
    r->holding = hold;
}

uint32_t sim_runner_gpio_in(const sim_runner_t *r)
{
    uint32_t in = sim_device_gpio_in(&r->dev);
    if (r->drive_fault_line_low)
        in &= ~GPIO_IN_DRIVE_FAULT_N;
    return in;
}

bool sim_runner_done(const sim_runner_t *r)
{
    return r->scn != NULL && r->now_us >= r->scn->duration_us;
}
