/* The lockstep rig (rig.h): device, sim HAL and board core, one step at a time. */
#include "rig.h"

#include <string.h>

void sim_rig_cfg_default(sim_rig_cfg_t *cfg)
{
    sim_params_default(&cfg->sim);
    board_cfg_default(&cfg->board);
}

argil_err_t sim_rig_init(sim_rig_t *r, const sim_rig_cfg_t *cfg)
{
    r->sim_params = cfg->sim;
    sim_device_init(&r->dev, &r->sim_params);
    hal_sim_init(&r->hal);
    board_cfg_t bc = cfg->board;
    bc.arm = r->sim_params.arm.desc;
    if (board_init(&r->board, &bc) != ARGIL_OK)
        return ARGIL_ERR_ARG;
    hal_sim_set_tick_us(&r->hal, bc.tick_us);
    board_io_init(&r->io);
    r->from_board.n = 0;
    r->peak_delivered_force_n = 0.0f;
    return ARGIL_OK;
}

void sim_rig_set_hand(sim_rig_t *r, vec3_t pos_m, vec3_t vel_m_s, bool button1, bool button2)
{
    sim_device_set_hand(&r->dev, pos_m, vel_m_s, button1, button2);
}

void sim_rig_release_hand(sim_rig_t *r)
{
    sim_device_release_hand(&r->dev);
}

vec3_t sim_rig_tip_m(const sim_rig_t *r)
{
    return sim_device_tip_m(&r->dev);
}

void sim_rig_step_device_frames(sim_rig_t *r, uint32_t dt_us, can_batch_t *to_board)
{
    to_board->n = 0;
    hal_sim_take_from_board(&r->hal, &r->from_board);
    sim_device_step(&r->dev, &r->from_board, hal_sim_gpio_out(&r->hal), to_board, dt_us);
    hal_sim_set_gpio_in(&r->hal, sim_device_gpio_in(&r->dev));
    const float delivered = vec3_norm(sim_device_delivered_force_n(&r->dev));
    if (delivered > r->peak_delivered_force_n)
        r->peak_delivered_force_n = delivered;
}

void sim_rig_step_device(sim_rig_t *r, uint32_t dt_us)
{
    can_batch_t to_board;
    sim_rig_step_device_frames(r, dt_us, &to_board);
    hal_sim_put_to_board(&r->hal, &to_board);
}

uint32_t sim_rig_step_board(sim_rig_t *r)
{
    return board_run_tick(&r->board, &r->io, &r->hal);
}

uint32_t sim_rig_step_ns(sim_rig_t *r, uint32_t dt_us)
{
    sim_rig_step_device(r, dt_us);
    return sim_rig_step_board(r);
}

argil_err_t sim_rig_host_send(sim_rig_t *r, const uint8_t *frame, size_t len)
{
    return hal_sim_host_send(&r->hal, frame, len);
}

size_t sim_rig_host_receive(sim_rig_t *r, uint8_t *buf, size_t cap)
{
    return hal_sim_host_receive(&r->hal, buf, cap);
}

void sim_rig_board_stats(const sim_rig_t *r, sim_rig_board_stats_t *out)
{
    out->ticks = r->board.stats.ticks;
    out->deadline_misses = r->board.stats.deadline_misses;
    memcpy(out->deadline_miss_tick, r->board.stats.deadline_miss_tick,
           sizeof(out->deadline_miss_tick));
    out->worst_compute_ns = r->board.stats.worst_compute_ns;
    out->preempted_ticks = r->board.stats.preempted_ticks;
    out->preempted_over_period = r->board.stats.preempted_over_period;
    memcpy(out->preempted_over_tick, r->board.stats.preempted_over_tick,
           sizeof(out->preempted_over_tick));
    out->link_errors = r->board.stats.link_errors;
    out->peak_force_n = r->board.stats.peak_force_n;
    out->peak_delivered_force_n = r->peak_delivered_force_n;
    out->max_force_n = r->board.cfg.max_force_n;
    out->state = r->board.safety.state;
    out->fault = r->board.safety.fault;
}
