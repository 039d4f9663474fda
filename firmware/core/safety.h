/* The board's safety state machine (DESIGN.md "Safety states"): decides, every tick, whether the
 * drives may be powered and how much of the computed force may reach the hand. */
#ifndef ARGIL_SAFETY_H
#define ARGIL_SAFETY_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/safety_codes.h"

typedef struct {
    uint32_t host_timeout_us;      /* host heartbeat silence that is a fault (default 50 ms) */
    uint32_t host_fade_us;         /* force fades to zero over this after the host is lost (20 ms) */
    uint32_t overrun_streak;       /* consecutive deadline overruns that are a fault (3); 0 = never */
} safety_cfg_t;

typedef struct {
    bool estop_pressed;
    bool drive_fault_line;         /* DRIVE_FAULT_N is low */
    bool drives_enabled;           /* every drive reports OPERATION_ENABLED */
    bool drive_heartbeat_lost;
    bool drive_emcy;
    bool window_ready;             /* a complete, finite window is in use */
    bool host_heartbeat;           /* a host heartbeat arrived this tick */
    bool arm_request;              /* host command ARM this tick */
    bool disarm_request;
    bool nonfinite;                /* the tick saw NaN/Inf in its inputs or its force */
    bool force_limit_exceeded;
    bool deadline_overrun;         /* the previous tick overran its period */
    bool bus_error;                /* CAN bus-off, or error-passive too long */
    bool velocity_limit_exceeded;  /* tool speed above board_cfg_t.max_velocity_m_s */
} safety_inputs_t;

typedef struct {
    safety_state_t state;
    fault_code_t fault;            /* why the last FAULT/ESTOP was entered */
    uint32_t host_silence_us;      /* since the last host heartbeat */
    uint32_t overruns_in_row;
    float fade;                    /* 1 → 0 while fading out after the host is lost */
    bool host_seen;                /* a heartbeat arrived since the last fault */
    bool entered;                  /* state changed in the last safety_process */
} safety_t;

void safety_cfg_default(safety_cfg_t *cfg);
void safety_init(safety_t *s);

/* Advances the state machine by dt_us and returns the force scale to apply, 0 … 1. */
float safety_process(safety_t *s, const safety_cfg_t *cfg, const safety_inputs_t *in,
                     uint32_t dt_us);

/* True when the drives may have power (ARMED or ACTIVE, or fading out after the host left). */
bool safety_drives_on(const safety_t *s);

/* True when sculpting (changing the clay) is allowed. */
bool safety_may_sculpt(const safety_t *s);

#endif
