/* CANopen / CiA 402 frames as argil's board and simulated drives exchange them:
 * NMT, SYNC, RPDO1 (controlword + target torque), TPDO1 (statusword + position + torque),
 * heartbeat and EMCY. Encoders and decoders only; the state machines live with their owners
 * (firmware/core/drives.c is the master, sim/drive.c the drive). */
#ifndef ARGIL_CANOPEN_H
#define ARGIL_CANOPEN_H

#include <stdbool.h>
#include <stdint.h>

#include "argil_err.h"

/* A classic CAN frame (11-bit identifier), the fields of Linux's struct can_frame. */
typedef struct {
    uint32_t id;       /* 11-bit COB-ID */
    uint8_t len;       /* 0..8 */
    uint8_t data[8];
} can_frame_t;

#define CAN_BATCH_MAX 32u
/* The frames one side hands the other in one tick. */
typedef struct {
    uint8_t n;
    can_frame_t f[CAN_BATCH_MAX];
} can_batch_t;

/* Appends a frame; returns ARGIL_ERR_FULL when the batch holds CAN_BATCH_MAX already. */
argil_err_t can_batch_push(can_batch_t *b, const can_frame_t *f);

/* COB-ID bases (CiA 301 pre-defined connection set); node ids are 1..127. */
#define CANOPEN_COB_NMT 0x000u
#define CANOPEN_COB_SYNC 0x080u
#define CANOPEN_COB_EMCY 0x080u   /* + node */
#define CANOPEN_COB_TPDO1 0x180u  /* + node: drive → board */
#define CANOPEN_COB_RPDO1 0x200u  /* + node: board → drive */
#define CANOPEN_COB_HEARTBEAT 0x700u /* + node */

typedef enum {
    NMT_CMD_START = 0x01,
    NMT_CMD_STOP = 0x02,
    NMT_CMD_PREOP = 0x80,
    NMT_CMD_RESET_NODE = 0x81,
    NMT_CMD_RESET_COMM = 0x82
} nmt_cmd_t;

typedef enum {
    NMT_STATE_BOOTUP = 0x00,
    NMT_STATE_STOPPED = 0x04,
    NMT_STATE_OPERATIONAL = 0x05,
    NMT_STATE_PREOP = 0x7F
} nmt_state_t;

/* EMCY error codes (CiA 301 / CiA 402) and error-register bits the drives use. */
#define CANOPEN_EMCY_NO_ERROR 0x0000u        /* sent when a fault is reset */
#define CANOPEN_EMCY_OVERCURRENT 0x2310u     /* continuous over-current (CiA 402) */
#define CANOPEN_ERRREG_GENERIC 0x01u
#define CANOPEN_ERRREG_CURRENT 0x02u

/* CiA 402 controlword commands (bits 0-3 and 7). */
#define CIA402_CW_SHUTDOWN 0x0006u
#define CIA402_CW_SWITCH_ON 0x0007u
#define CIA402_CW_ENABLE_OP 0x000Fu
#define CIA402_CW_DISABLE_VOLTAGE 0x0000u
#define CIA402_CW_QUICK_STOP 0x0002u
#define CIA402_CW_FAULT_RESET 0x0080u

typedef enum {
    CIA402_NOT_READY = 0,
    CIA402_SWITCH_ON_DISABLED,
    CIA402_READY_TO_SWITCH_ON,
    CIA402_SWITCHED_ON,
    CIA402_OPERATION_ENABLED,
    CIA402_QUICK_STOP_ACTIVE,
    CIA402_FAULT_REACTION_ACTIVE,
    CIA402_FAULT
} cia402_state_t;

/* The power state a statusword reports (CiA 402 bit patterns). */
cia402_state_t cia402_state_from_statusword(uint16_t statusword);
/* The statusword a drive in state s reports (voltage-enabled bit set where applicable). */
uint16_t cia402_statusword(cia402_state_t s);

void canopen_nmt_encode(can_frame_t *f, nmt_cmd_t cmd, uint8_t node); /* node 0 = all */
void canopen_sync_encode(can_frame_t *f);
/* Target torque in per-mille of the motor's rated torque (CiA 402 object 0x6071). */
void canopen_rpdo_encode(can_frame_t *f, uint8_t node, uint16_t controlword,
                         int16_t target_torque_permille);
void canopen_tpdo_encode(can_frame_t *f, uint8_t node, uint16_t statusword,
                         int32_t position_counts, int16_t torque_permille);
void canopen_heartbeat_encode(can_frame_t *f, uint8_t node, nmt_state_t state);
void canopen_emcy_encode(can_frame_t *f, uint8_t node, uint16_t error_code,
                         uint8_t error_register);

/* Decoders return false when the frame is not of that kind or has the wrong length. */
bool canopen_nmt_decode(const can_frame_t *f, nmt_cmd_t *cmd, uint8_t *node);
bool canopen_is_sync(const can_frame_t *f);
bool canopen_rpdo_decode(const can_frame_t *f, uint8_t *node, uint16_t *controlword,
                         int16_t *target_torque_permille);
bool canopen_tpdo_decode(const can_frame_t *f, uint8_t *node, uint16_t *statusword,
                         int32_t *position_counts, int16_t *torque_permille);
bool canopen_heartbeat_decode(const can_frame_t *f, uint8_t *node, nmt_state_t *state);
bool canopen_emcy_decode(const can_frame_t *f, uint8_t *node, uint16_t *error_code,
                         uint8_t *error_register);

#endif
