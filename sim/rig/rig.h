/* The in-process simulated board: the simulated arm and drives, the sim HAL and the board core
 * stepped together in lockstep (DESIGN.md "Layers"). The host's session and sim link, the SIL
 * tests and the benches drive it through this header; the host sees it as a byte link. */
#ifndef ARGIL_SIM_RIG_H
#define ARGIL_SIM_RIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "firmware/core/board_hal.h"
#include "firmware/hal/hal_sim.h"
#include "shared/argil_err.h"
#include "shared/safety_codes.h"
#include "shared/vec3.h"
#include "sim/sim_device.h"

#define SIM_RIG_LINK_BYTES HAL_SIM_LINK_BYTES   /* most bytes one receive returns */

typedef struct {
    sim_params_t sim;              /* the arm, its drives and the hand */
    board_cfg_t board;             /* board.arm is set to sim.arm.desc by sim_rig_init */
} sim_rig_cfg_t;

typedef struct {
    sim_params_t sim_params;
    sim_device_t dev;
    hal_t hal;
    board_t board;
    board_io_t io;
    can_batch_t from_board;        /* the frames the board sent in the last step */
    float peak_delivered_force_n;  /* the largest force the arm delivered at the tip
                                      (sim_device_delivered_force_n after each step) */
} sim_rig_t;

/* What the board reports of itself, for a session's summary. */
typedef struct {
    uint32_t ticks;
    uint32_t deadline_misses;
    uint32_t deadline_miss_tick[BOARD_PREEMPTED_KEPT]; /* the first ones' tick numbers */
    uint32_t worst_compute_ns;
    uint32_t preempted_ticks;      /* not timed: the machine took the core (board_stats_t) */
    uint32_t preempted_over_period;
    uint32_t preempted_over_tick[BOARD_PREEMPTED_KEPT];
    uint32_t link_errors;          /* frames the board's decoder refused */
    float peak_force_n;            /* the board's command, which the board clamps itself */
    float peak_delivered_force_n;  /* the simulated arm's truth: what the motors delivered */
    float max_force_n;             /* the board's configured limit */
    safety_state_t state;
    fault_code_t fault;
} sim_rig_board_stats_t;

/* The simulator's and the board's defaults. */
void sim_rig_cfg_default(sim_rig_cfg_t *cfg);

/* ARGIL_ERR_ARG when the board refuses its configuration. */
argil_err_t sim_rig_init(sim_rig_t *r, const sim_rig_cfg_t *cfg);

/* The hand holds the stylus towards pos_m (device frame) until the next call. */
void sim_rig_set_hand(sim_rig_t *r, vec3_t pos_m, vec3_t vel_m_s, bool button1, bool button2);

/* The hand lets go of the stylus. */
void sim_rig_release_hand(sim_rig_t *r);

/* Where the stylus tip is now, device frame. */
vec3_t sim_rig_tip_m(const sim_rig_t *r);

/* Advances the arm and drives by dt_us, then runs one board tick; returns its compute time. */
uint32_t sim_rig_step_ns(sim_rig_t *r, uint32_t dt_us);

/* The first half of a step: the arm and drives advance by dt_us on the board's last frames and
 * GPIO outputs, and their frames and lines wait for the board. */
void sim_rig_step_device(sim_rig_t *r, uint32_t dt_us);

/* The same step with the device's frames for the board returned in to_board instead of queued
 * (a test that delivers them late queues them itself with hal_sim_put_to_board); its GPIO lines
 * are set as usual. */
void sim_rig_step_device_frames(sim_rig_t *r, uint32_t dt_us, can_batch_t *to_board);

/* The second half: one board tick; returns its compute time. */
uint32_t sim_rig_step_board(sim_rig_t *r);

/* Queues one frame from the host to the board; ARGIL_ERR_FULL when the link has no room. */
argil_err_t sim_rig_host_send(sim_rig_t *r, const uint8_t *frame, size_t len);

/* Takes the board's frames to the host (back to back); returns their length, 0 when none. */
size_t sim_rig_host_receive(sim_rig_t *r, uint8_t *buf, size_t cap);

void sim_rig_board_stats(const sim_rig_t *r, sim_rig_board_stats_t *out);

#endif
