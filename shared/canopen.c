/* CANopen / CiA 402 frame codec shared by the board (master) and the simulated drives:
 * byte layouts field by field, little-endian, strict id-range and length checks. */
#include "canopen.h"

#include <stddef.h>
#include <string.h>

#include "wire.h"

#define CANOPEN_NODE_MAX 127u

argil_err_t can_batch_push(can_batch_t *b, const can_frame_t *f)
{
    if (b == NULL || f == NULL)
        return ARGIL_ERR_ARG;
    if (b->n >= CAN_BATCH_MAX)
        return ARGIL_ERR_FULL;
    b->f[b->n] = *f;
    b->n++;
    return ARGIL_OK;
}

cia402_state_t cia402_state_from_statusword(uint16_t sw)
{
    switch (sw & 0x4Fu) {
    case 0x00u:
        return CIA402_NOT_READY;
    case 0x40u:
        return CIA402_SWITCH_ON_DISABLED;
    case 0x0Fu:
        return CIA402_FAULT_REACTION_ACTIVE;
    case 0x08u:
        return CIA402_FAULT;
    default:
        break;
    }
    switch (sw & 0x6Fu) {
    case 0x21u:
        return CIA402_READY_TO_SWITCH_ON;
    case 0x23u:
        return CIA402_SWITCHED_ON;
    case 0x27u:
        return CIA402_OPERATION_ENABLED;
    case 0x07u:
        return CIA402_QUICK_STOP_ACTIVE;
    default:
        break;
    }
    return CIA402_NOT_READY; /* no defined pattern: treat as not ready (never as enabled) */
}

uint16_t cia402_statusword(cia402_state_t s)
{
    /* bit 0 ready to switch on, 1 switched on, 2 operation enabled, 3 fault,
     * 4 voltage enabled, 5 quick stop (active low), 6 switch on disabled */
    switch (s) {
    case CIA402_NOT_READY:
        return 0x0000u;
    case CIA402_SWITCH_ON_DISABLED:
        return 0x0040u;
    case CIA402_READY_TO_SWITCH_ON:
        return 0x0031u;
    case CIA402_SWITCHED_ON:
        return 0x0033u;
    case CIA402_OPERATION_ENABLED:
        return 0x0037u;
    case CIA402_QUICK_STOP_ACTIVE:
        return 0x0017u;
    case CIA402_FAULT_REACTION_ACTIVE:
        return 0x001Fu;
    case CIA402_FAULT:
        return 0x0008u;
    default:
        return 0x0000u;
    }
}

/* Two's-complement reinterpretations without implementation-defined conversions. */
static int16_t as_i16(uint16_t v)
{
    return v < 0x8000u ? (int16_t)v : (int16_t)(-(int32_t)(0x10000u - v));
}

static int32_t as_i32(uint32_t v)
{
    return v < 0x80000000u ? (int32_t)v : (int32_t)(v - 0x80000000u) + INT32_MIN;
}

/* Starts a frame: id, length, all data bytes zero. */
static void frame_begin(can_frame_t *f, uint32_t id, uint8_t len)
{
    memset(f, 0, sizeof *f);
    f->id = id;
    f->len = len;
}

/* The node of a frame whose id is base + node (node 1..127); 0 when it is not of that kind. */
static uint8_t node_of(const can_frame_t *f, uint32_t base)
{
    if (f->id <= base || f->id > base + CANOPEN_NODE_MAX)
        return 0;
    return (uint8_t)(f->id - base);
}

void canopen_nmt_encode(can_frame_t *f, nmt_cmd_t cmd, uint8_t node)
{
    frame_begin(f, CANOPEN_COB_NMT, 2);
    f->data[0] = (uint8_t)cmd;
    f->data[1] = (uint8_t)(node & 0x7Fu);
}

void canopen_sync_encode(can_frame_t *f)
{
    frame_begin(f, CANOPEN_COB_SYNC, 0);
}

void canopen_rpdo_encode(can_frame_t *f, uint8_t node, uint16_t controlword,
                         int16_t target_torque_permille)
{
    frame_begin(f, CANOPEN_COB_RPDO1 + (node & 0x7Fu), 4);
    le_put_u16(&f->data[0], controlword);
    le_put_u16(&f->data[2], (uint16_t)target_torque_permille);
}

void canopen_tpdo_encode(can_frame_t *f, uint8_t node, uint16_t statusword,
                         int32_t position_counts, int16_t torque_permille)
{
    frame_begin(f, CANOPEN_COB_TPDO1 + (node & 0x7Fu), 8);
    le_put_u16(&f->data[0], statusword);
    le_put_u32(&f->data[2], (uint32_t)position_counts);
    le_put_u16(&f->data[6], (uint16_t)torque_permille);
}

void canopen_heartbeat_encode(can_frame_t *f, uint8_t node, nmt_state_t state)
{
    frame_begin(f, CANOPEN_COB_HEARTBEAT + (node & 0x7Fu), 1);
    f->data[0] = (uint8_t)state;
}

void canopen_emcy_encode(can_frame_t *f, uint8_t node, uint16_t error_code,
                         uint8_t error_register)
{
    frame_begin(f, CANOPEN_COB_EMCY + (node & 0x7Fu), 8);
    le_put_u16(&f->data[0], error_code);
    f->data[2] = error_register;
}

bool canopen_nmt_decode(const can_frame_t *f, nmt_cmd_t *cmd, uint8_t *node)
{
    if (f->id != CANOPEN_COB_NMT || f->len != 2 || f->data[1] > CANOPEN_NODE_MAX)
        return false;
    switch (f->data[0]) {
    case NMT_CMD_START:
    case NMT_CMD_STOP:
    case NMT_CMD_PREOP:
    case NMT_CMD_RESET_NODE:
    case NMT_CMD_RESET_COMM:
        break;
    default:
        return false;
    }
    *cmd = (nmt_cmd_t)f->data[0];
    *node = f->data[1];
    return true;
}

bool canopen_is_sync(const can_frame_t *f)
{
    return f->id == CANOPEN_COB_SYNC && f->len == 0;
}

bool canopen_rpdo_decode(const can_frame_t *f, uint8_t *node, uint16_t *controlword,
                         int16_t *target_torque_permille)
{
    const uint8_t n = node_of(f, CANOPEN_COB_RPDO1);
    if (n == 0 || f->len != 4)
        return false;
    *node = n;
    *controlword = le_get_u16(&f->data[0]);
    *target_torque_permille = as_i16(le_get_u16(&f->data[2]));
    return true;
}

bool canopen_tpdo_decode(const can_frame_t *f, uint8_t *node, uint16_t *statusword,
                         int32_t *position_counts, int16_t *torque_permille)
{
    const uint8_t n = node_of(f, CANOPEN_COB_TPDO1);
    if (n == 0 || f->len != 8)
        return false;
    *node = n;
    *statusword = le_get_u16(&f->data[0]);
    *position_counts = as_i32(le_get_u32(&f->data[2]));
    *torque_permille = as_i16(le_get_u16(&f->data[6]));
    return true;
}

bool canopen_heartbeat_decode(const can_frame_t *f, uint8_t *node, nmt_state_t *state)
{
    const uint8_t n = node_of(f, CANOPEN_COB_HEARTBEAT);
    if (n == 0 || f->len != 1)
        return false;
    /* bit 7 is the toggle bit of node guarding; heartbeats send it as 0 */
    switch (f->data[0]) {
    case NMT_STATE_BOOTUP:
    case NMT_STATE_STOPPED:
    case NMT_STATE_OPERATIONAL:
    case NMT_STATE_PREOP:
        break;
    default:
        return false;
    }
    *node = n;
    *state = (nmt_state_t)f->data[0];
    return true;
}

bool canopen_emcy_decode(const can_frame_t *f, uint8_t *node, uint16_t *error_code,
                         uint8_t *error_register)
{
    const uint8_t n = node_of(f, CANOPEN_COB_EMCY);
    if (n == 0 || f->len != 8)
        return false;
    *node = n;
    *error_code = le_get_u16(&f->data[0]);
    *error_register = f->data[2];
    return true;
}
