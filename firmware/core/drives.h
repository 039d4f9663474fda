/* CiA 402 master for the arm's drives: NMT start/stop, power state machine, SYNC + RPDO every
 * tick, TPDO, heartbeat consumer, EMCY decoding, and the bus state from SocketCAN error frames
 * (error-passive, bus-off, restart) with a bounded recovery time. Node id of joint j is j + 1. */
#ifndef ARGIL_DRIVES_H
#define ARGIL_DRIVES_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/argil_limits.h"
#include "shared/can_err.h"
#include "shared/canopen.h"

typedef enum {
    CAN_BUS_ACTIVE = 0,     /* error-active: normal */
    CAN_BUS_PASSIVE = 1,    /* error-passive: frames still flow, the bus is sick */
    CAN_BUS_OFF = 2         /* the controller left the bus: nothing flows */
} can_bus_state_t;

typedef struct {
    uint32_t heartbeat_timeout_us;   /* consumer time per drive (CiA 301 0x1016); default
                                        ARGIL_DRIVE_HEARTBEAT_CONSUMER_US (250 ms for drives
                                        beating every 100 ms: one lost heartbeat tolerated) */
    uint32_t bus_passive_fault_us;   /* error-passive this long is a fault (default 100 ms) */
    uint32_t bus_recovery_us;        /* bus-off not restarted within this is unrecoverable
                                        (default 500 ms); the owner then gives up */
} drives_cfg_t;

typedef struct {
    nmt_state_t nmt;
    bool seen;                       /* any heartbeat since init */
    uint32_t heartbeat_age_us;
    cia402_state_t power;            /* from the latest statusword */
    uint16_t statusword;
    int32_t position_counts;
    int16_t torque_permille;
    bool position_valid;             /* a TPDO arrived since init */
    uint32_t tpdos;                  /* TPDOs taken since init (wraps): a new position or not */
    bool emcy;                       /* an EMCY arrived and has not been cleared by a re-arm */
    uint16_t emcy_code;              /* the latest non-zero error code */
    uint8_t emcy_register;           /* its error register (object 0x1001) */
    uint32_t emcy_count;             /* non-zero EMCYs since init */
    bool start_sent;
} drive_link_t;

typedef struct {
    drive_link_t d[ARGIL_DRIVES];
    uint16_t controlword[ARGIL_DRIVES];
    uint32_t frames_rx;
    uint32_t frames_unknown;
    can_bus_state_t bus;
    uint32_t bus_state_us;           /* time spent in the current bus state */
    uint32_t bus_off_events;
    uint32_t bus_passive_events;
    uint32_t bus_restarts;
    uint32_t error_frames;
    uint32_t fault_reset_left_us;    /* while > 0, drives in FAULT get fault resets even off */
} drives_t;

void drives_cfg_default(drives_cfg_t *cfg);
void drives_init(drives_t *dr);

/* Takes in the frames the drives sent since the last tick, and SocketCAN error frames. */
void drives_receive(drives_t *dr, const can_batch_t *rx);

/* Ages the heartbeats and the bus state by dt_us and appends this tick's frames (NMT when
 * needed, RPDO per drive with the controlword for want_enabled and the torque, then SYNC) to
 * tx. Torque is forced to zero for any drive not in OPERATION_ENABLED or when want_enabled is
 * false; an enabled drive that must stop gets quick stop. Nothing is queued while bus-off. */
void drives_process(drives_t *dr, const drives_cfg_t *cfg, bool want_enabled,
                    const int16_t torque_permille[ARGIL_DRIVES], uint32_t dt_us,
                    can_batch_t *tx);

/* Appends the frames that leave the drives safe on shutdown: zero torque with disable voltage
 * to every operational drive, then NMT stop to each node. */
void drives_shutdown(drives_t *dr, can_batch_t *tx);

/* Clears latched EMCY flags (the host re-armed). */
void drives_clear_emcy(drives_t *dr);

/* For the next for_us: a drive in FAULT gets the CiA 402 fault reset (bit 7 edges) even while
 * the drives are to stay off, so a drive that tripped (EMCY, DRIVE_FAULT_N low) can clear and
 * the host's re-arm can succeed. Power is never enabled by this. */
void drives_request_fault_reset(drives_t *dr, uint32_t for_us);

bool drives_all_enabled(const drives_t *dr);
bool drives_heartbeat_lost(const drives_t *dr, const drives_cfg_t *cfg);
bool drives_any_emcy(const drives_t *dr);
bool drives_positions_valid(const drives_t *dr);

/* True when the bus is a fault for the safety machine: bus-off, or error-passive for longer
 * than cfg->bus_passive_fault_us. */
bool drives_bus_error(const drives_t *dr, const drives_cfg_t *cfg);
/* True when bus-off has lasted longer than cfg->bus_recovery_us. */
bool drives_bus_unrecoverable(const drives_t *dr, const drives_cfg_t *cfg);

/* The CiA 301 class of an EMCY error code, in a few English words ("current", "voltage"…). */
const char *drives_emcy_class(uint16_t code);
const char *drives_bus_state_name(can_bus_state_t s);

#endif
