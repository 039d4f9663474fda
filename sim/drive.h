/* One CiA 402 servo drive in cyclic synchronous torque mode, emulated at CAN level: the
 * CANopen NMT slave (boot-up, heartbeat producer), RPDO1/TPDO1 on SYNC, EMCY, the CiA 402
 * power state machine and the torque stage behind the hardware power-enable input.
 * Behaviour in detail: docs/arm.md "Drive emulation". */
#ifndef ARGIL_DRIVE_H
#define ARGIL_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/canopen.h"

typedef struct {
    uint32_t heartbeat_period_us;  /* heartbeat producer time (0x1017); 0 = off; default 100 ms */
    float rated_torque_nm;         /* motor rated torque = 1000 ‰ (0x6076) */
    float peak_torque_nm;          /* torque limit the drive clips to (0x6072 in N m) */
    uint32_t quick_stop_us;        /* QUICK_STOP_ACTIVE lasts this long, then SWITCH_ON_DISABLED */
    uint8_t dac_bits;              /* torque command resolution: 2^bits codes over ±peak (the
                                      current reference's DAC/PWM); 0 = continuous, at most 24 */
} drive_cfg_t;

typedef struct {
    drive_cfg_t cfg;
    uint8_t node;                  /* 1..127 */
    nmt_state_t nmt;
    bool boot_pending;             /* (re)initialised: boot-up goes out at the next tick */
    uint32_t heartbeat_timer_us;
    cia402_state_t power;
    uint16_t controlword;          /* latest RPDO1 */
    int16_t target_torque_permille;
    bool sync_pending;             /* a SYNC arrived since the last tick */
    bool fault_pending;            /* injected, acted on at the next tick */
    uint16_t fault_code;
    uint8_t error_register;        /* 0x1001 */
    bool emcy_reset_pending;       /* fault was reset: EMCY "no error" goes out */
    uint32_t quick_stop_timer_us;
    float torque_nm;               /* motor torque applied since the latest tick */
    uint32_t tx_dropped;           /* frames lost because the tx batch was full */
} drive_t;

/* Heartbeat 100 ms, rated 0.030 N m, peak 4x rated, quick stop 10 ms, continuous torque (the
 * default arm). */
void drive_cfg_default(drive_cfg_t *cfg);

/* Powers the drive up: NOT_READY, NMT initialising; the boot-up heartbeat goes out at the
 * first drive_tick, after which the drive is PRE-OPERATIONAL and SWITCH_ON_DISABLED. */
void drive_init(drive_t *d, uint8_t node, const drive_cfg_t *cfg);

/* Takes one frame off the bus: NMT (this node or all), SYNC (noted for the next tick), and in
 * OPERATIONAL this node's RPDO1 (controlword applied to the power state machine at once,
 * target torque latched). Other frames are ignored. */
void drive_receive(drive_t *d, const can_frame_t *f);

/* Advances the drive by dt_us: boot-up / heartbeat, a pending fault (EMCY, FAULT), the quick
 * stop timer, the torque stage (torque only in OPERATIONAL + OPERATION_ENABLED with the
 * power-enable input high, clipped to ±peak, rounded to the DAC's step) and, if a SYNC arrived, TPDO1 with the
 * statusword, position_counts and the applied torque in ‰. Frames are appended to tx. */
void drive_tick(drive_t *d, int32_t position_counts, bool power_enabled, uint32_t dt_us,
                can_batch_t *tx);

/* Makes the drive trip (e.g. CANOPEN_EMCY_OVERCURRENT): torque off at once, FAULT_REACTION_
 * ACTIVE, then at the next tick EMCY (code, error_register) and FAULT. */
void drive_inject_fault(drive_t *d, uint16_t error_code, uint8_t error_register);

/* The motor torque the drive applies now, N m (motor side). */
float drive_motor_torque_nm(const drive_t *d);

/* True while the drive's fault output is active (FAULT_REACTION_ACTIVE or FAULT). */
bool drive_fault_active(const drive_t *d);

#endif
