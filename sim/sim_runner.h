/* One tick of the simulated device as a scenario plays it: the hand's moves and the device-side
 * faults of a scenario (sim/scenario.h) are applied on time, the drives' and the board's CAN
 * frames pass through the fault layer (sim/can_faults.h), and every injection and every change
 * of the board's DRIVE_ENABLE output is reported to an event-log callback. The SIL rig and
 * argil-sim call the same sim_runner_tick; only argil-sim's socket and GPIO I/O are outside. */
#ifndef ARGIL_SIM_RUNNER_H
#define ARGIL_SIM_RUNNER_H

#include <stdbool.h>
#include <stdint.h>

#include "sim/can_faults.h"
#include "sim/scenario.h"
#include "sim/sim_device.h"

/* Called for each event: t_us on the scenario clock, one line of text (no newline), e.g.
 * "inject line=7 estop press" or "gpio_out DRIVE_ENABLE=0". */
typedef void (*sim_log_fn)(void *ctx, int64_t t_us, const char *event);

#define SIM_WDOG_TIMEOUT_US 20000  /* WDOG_KICK unchanged this long with DRIVE_ENABLE high */

typedef struct {
    const scenario_t *scn;        /* may be NULL: no script, no faults */
    uint32_t next_step;
    sim_device_t dev;
    can_faults_t faults;
    vec3_t home_tip_m;            /* device frame: scenario hand positions are relative to it */
    vec3_t hand_from_m, hand_to_m;
    int64_t move_start_us, move_dur_us;
    bool hand_held;
    bool btn1, btn2;
    bool drive_fault_line_low;    /* DRIVE_FAULT_N pulled low by the scenario */
    bool gpio_observed;           /* the board's outputs are really read (else taken as on) */
    bool outputs_reused;          /* set by the caller: this tick's gpio_out is the sample of an
                                     earlier tick (several SYNCs taken in one read), so a kick
                                     that toggles every tick cannot be judged from it */
    bool have_gpio_out;
    uint32_t last_gpio_out;
    int64_t last_kick_us;         /* WDOG_KICK last changed (device clock) */
    bool wdog_expired;            /* the device's watchdog cut the drives' power */
    bool holding;                 /* before the scenario's start: the device runs, its clock and
                                     script wait (sim_runner_hold) */
    int64_t now_us;               /* scenario time */
    int64_t device_us;            /* the device's own time: every tick, held or not (the
                                     watchdog and the CAN fault layer run on it) */
    sim_log_fn log;
    void *log_ctx;
} sim_runner_t;

/* Device at rest, hand holding at home; scn may be NULL. gpio_observed: false when nobody reads
 * the board's outputs (argil-sim without GPIO): DRIVE_ENABLE is then taken as high. */
void sim_runner_init(sim_runner_t *r, const sim_params_t *p, const scenario_t *scn,
                     bool gpio_observed, sim_log_fn log, void *log_ctx);

/* One tick of dt_us at the runner's clock: applies the scenario's device-side steps that are
 * due (host-side steps are the caller's), passes from_board through the fault layer to the
 * drives, steps the device, and passes the drives' frames through the fault layer into
 * to_board (cleared first). gpio_out: the board's GPIO_OUT_* levels now. */
void sim_runner_tick(sim_runner_t *r, const can_batch_t *from_board, uint32_t gpio_out,
                     can_batch_t *to_board, uint32_t dt_us);

/* Holds the scenario before its start (hold true): the device keeps answering the board
 * (boot, NMT, drives, the hand at home) while the scenario clock stays at 0 and no step is
 * applied; false starts it. A rig holds until the board is ready to sculpt (docs/sim.md,
 * "Scenario time 0"). */
void sim_runner_hold(sim_runner_t *r, bool hold);

/* GPIO_IN_* levels for the board now (device levels, with a scenario's DRIVE_FAULT_N pull). */
uint32_t sim_runner_gpio_in(const sim_runner_t *r);

/* True once the scenario's duration has passed (never without a scenario). */
bool sim_runner_done(const sim_runner_t *r);

#endif
