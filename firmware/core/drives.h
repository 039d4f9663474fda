/* CiA 402 master for the arm's drives: NMT start, power state machine, SYNC + RPDO every tick,
 * TPDO and heartbeat supervision. Node id of joint j is j + 1. */
#ifndef ARGIL_DRIVES_H
#define ARGIL_DRIVES_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/canopen.h"

typedef struct {
    uint32_t heartbeat_timeout_us;   /* consumer time per drive (default 100 ms + margin) */
} drives_cfg_t;

typedef struct {
    nmt_state_t nmt;
    bool seen;                       /* any heartbeat since init */
    uint32_t heartbeat_age_us;
    cia402_state_t power;            /* from the latest statusword */
    int32_t position_counts;
    int16_t torque_permille;
    bool position_valid;             /* a TPDO arrived since init */
    bool emcy;                       /* an EMCY arrived and has not been cleared by a re-arm */
    uint16_t emcy_code;
    bool start_sent;
} drive_link_t;

typedef struct {
    drive_link_t d[ARGIL_DRIVES];
    uint16_t controlword[ARGIL_DRIVES];
    uint32_t frames_rx;
    uint32_t frames_unknown;
} drives_t;

void drives_cfg_default(drives_cfg_t *cfg);
void drives_init(drives_t *dr);

/* Takes in the frames the drives sent since the last tick. */
void drives_receive(drives_t *dr, const can_batch_t *rx);

/* Ages the heartbeats by dt_us and appends this tick's frames (NMT when needed, RPDO per
 * drive with the controlword for want_enabled and the torque, then SYNC) to tx. Torque is
 * forced to zero for any drive not in OPERATION_ENABLED or when want_enabled is false. */
void drives_process(drives_t *dr, const drives_cfg_t *cfg, bool want_enabled,
                    const int16_t torque_permille[ARGIL_DRIVES], uint32_t dt_us,
                    can_batch_t *tx);

/* Clears latched EMCY flags (the host re-armed). */
void drives_clear_emcy(drives_t *dr);

bool drives_all_enabled(const drives_t *dr);
bool drives_heartbeat_lost(const drives_t *dr, const drives_cfg_t *cfg);
bool drives_any_emcy(const drives_t *dr);
bool drives_positions_valid(const drives_t *dr);

#endif
