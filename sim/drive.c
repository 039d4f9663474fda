/* A CiA 402 torque drive emulated at CAN level (see drive.h and docs/arm.md). */
#include "drive.h"

#include <math.h>
#include <stddef.h>

#include "shared/arm_kin.h"

void drive_cfg_default(drive_cfg_t *cfg)
{
    cfg->heartbeat_period_us = ARGIL_DRIVE_HEARTBEAT_PERIOD_US;
    cfg->rated_torque_nm = 0.030f;
    cfg->peak_torque_nm = cfg->rated_torque_nm * (float)ARM_PEAK_TORQUE_PERMILLE / 1000.0f;
    cfg->quick_stop_us = 10000u;
    cfg->dac_bits = 0u;
}

/* tq_nm (within ±peak) on the DAC's grid: the nearest of the codes −2^(bits−1) .. 2^(bits−1) − 1
 * of 2 peak / 2^bits each (mid-tread, so zero is a code; +peak is one step out of reach). */
static float dac_quantise_nm(float tq_nm, float peak_nm, uint8_t bits)
{
    if (bits == 0u || bits > 24u || !(peak_nm > 0.0f))
        return tq_nm;
    const float half = (float)(1ul << (bits - 1u));
    const float step_nm = peak_nm / half;
    const float code = fminf(fmaxf(rintf(tq_nm / step_nm), -half), half - 1.0f);
    return code * step_nm;
}

/* Resets the application (power-on or NMT reset node). */
static void reset_application(drive_t *d)
{
    d->power = CIA402_NOT_READY;
    d->controlword = CIA402_CW_DISABLE_VOLTAGE;
    d->target_torque_permille = 0;
    d->fault_pending = false;
    d->fault_code = 0;
    d->error_register = 0;
    d->emcy_reset_pending = false;
    d->quick_stop_timer_us = 0;
    d->torque_nm = 0.0f;
}

/* Resets communication: back to initialising, boot-up at the next tick. */
static void reset_communication(drive_t *d)
{
    d->nmt = NMT_STATE_BOOTUP;
    d->boot_pending = true;
    d->heartbeat_timer_us = 0;
    d->sync_pending = false;
}

void drive_init(drive_t *d, uint8_t node, const drive_cfg_t *cfg)
{
    d->cfg = *cfg;
    d->node = node;
    d->tx_dropped = 0;
    reset_application(d);
    reset_communication(d);
}

/* Appends f to tx, counting it as dropped when there is no room. */
static void send(drive_t *d, can_batch_t *tx, const can_frame_t *f)
{
    if (tx == NULL || can_batch_push(tx, f) != ARGIL_OK)
        d->tx_dropped++;
}

/* Losing OPERATIONAL aborts the PDO connection: an enabled power stage is disabled
 * (abort connection option "disable voltage"); a fault stays a fault. */
static void leave_operational(drive_t *d, nmt_state_t to)
{
    if (d->nmt == NMT_STATE_OPERATIONAL && to != NMT_STATE_OPERATIONAL) {
        switch (d->power) {
        case CIA402_READY_TO_SWITCH_ON:
        case CIA402_SWITCHED_ON:
        case CIA402_OPERATION_ENABLED:
        case CIA402_QUICK_STOP_ACTIVE:
            d->power = CIA402_SWITCH_ON_DISABLED;
            break;
        default:
            break;
        }
        d->target_torque_permille = 0;
        d->torque_nm = 0.0f;
    }
    d->nmt = to;
}

/* Acts on an NMT command addressed to this node. */
static void handle_nmt(drive_t *d, nmt_cmd_t cmd)
{
    switch (cmd) {
    case NMT_CMD_START:
        leave_operational(d, NMT_STATE_OPERATIONAL);
        break;
    case NMT_CMD_STOP:
        leave_operational(d, NMT_STATE_STOPPED);
        d->sync_pending = false;
        break;
    case NMT_CMD_PREOP:
        leave_operational(d, NMT_STATE_PREOP);
        d->sync_pending = false;
        break;
    case NMT_CMD_RESET_NODE:
        leave_operational(d, NMT_STATE_BOOTUP);
        reset_application(d);
        reset_communication(d);
        break;
    case NMT_CMD_RESET_COMM:
        leave_operational(d, NMT_STATE_BOOTUP);
        reset_communication(d);
        break;
    default:
        break;
    }
}

/* CiA 402 power state machine: one controlword, the transitions it triggers. */
static void apply_controlword(drive_t *d, uint16_t cw)
{
    const bool reset_edge = (cw & 0x80u) != 0 && (d->controlword & 0x80u) == 0;
    d->controlword = cw;
    const cia402_state_t s = d->power;
    if (s == CIA402_FAULT) {
        if (reset_edge) { /* transition 15 */
            d->power = CIA402_SWITCH_ON_DISABLED;
            d->error_register = 0;
            d->fault_code = 0;
            d->emcy_reset_pending = true;
        }
        return;
    }
    if ((cw & 0x80u) != 0 || s == CIA402_NOT_READY || s == CIA402_FAULT_REACTION_ACTIVE)
        return;
    if ((cw & 0x02u) == 0) { /* disable voltage: 7, 9, 10, 12 */
        d->power = CIA402_SWITCH_ON_DISABLED;
    } else if ((cw & 0x06u) == 0x02u) { /* quick stop: 7, 10, 11 */
        if (s == CIA402_OPERATION_ENABLED) {
            d->power = CIA402_QUICK_STOP_ACTIVE;
            d->quick_stop_timer_us = 0;
        } else if (s == CIA402_READY_TO_SWITCH_ON || s == CIA402_SWITCHED_ON) {
            d->power = CIA402_SWITCH_ON_DISABLED;
        }
    } else if ((cw & 0x07u) == 0x06u) { /* shutdown: 2, 6, 8 */
        if (s == CIA402_SWITCH_ON_DISABLED || s == CIA402_SWITCHED_ON ||
            s == CIA402_OPERATION_ENABLED)
            d->power = CIA402_READY_TO_SWITCH_ON;
    } else if ((cw & 0x0Fu) == 0x07u) { /* switch on / disable operation: 3, 5 */
        if (s == CIA402_READY_TO_SWITCH_ON || s == CIA402_OPERATION_ENABLED)
            d->power = CIA402_SWITCHED_ON;
    } else if ((cw & 0x0Fu) == 0x0Fu) { /* enable operation: 4, or 3 + 4 */
        if (s == CIA402_READY_TO_SWITCH_ON || s == CIA402_SWITCHED_ON)
            d->power = CIA402_OPERATION_ENABLED;
    }
}

void drive_receive(drive_t *d, const can_frame_t *f)
{
    nmt_cmd_t cmd;
    uint8_t node;
    uint16_t cw;
    int16_t tq;
    if (d->boot_pending)
        return; /* still initialising */
    if (canopen_nmt_decode(f, &cmd, &node)) {
        if (node == 0 || node == d->node)
            handle_nmt(d, cmd);
    } else if (canopen_is_sync(f)) {
        if (d->nmt == NMT_STATE_OPERATIONAL)
            d->sync_pending = true;
    } else if (canopen_rpdo_decode(f, &node, &cw, &tq)) {
        if (node == d->node && d->nmt == NMT_STATE_OPERATIONAL) {
            d->target_torque_permille = tq;
            apply_controlword(d, cw);
        }
    }
}

void drive_inject_fault(drive_t *d, uint16_t error_code, uint8_t error_register)
{
    d->fault_pending = true;
    d->fault_code = error_code;
    d->error_register = error_register;
    d->power = CIA402_FAULT_REACTION_ACTIVE;
    d->torque_nm = 0.0f;
}

/* True when EMCY may be sent (CiA 301: not while stopped or initialising). */
static bool emcy_allowed(const drive_t *d)
{
    return d->nmt == NMT_STATE_PREOP || d->nmt == NMT_STATE_OPERATIONAL;
}

void drive_tick(drive_t *d, int32_t position_counts, bool power_enabled, uint32_t dt_us,
                can_batch_t *tx)
{
    can_frame_t f;
    /* NMT: boot-up, then the heartbeat producer */
    if (d->boot_pending) {
        canopen_heartbeat_encode(&f, d->node, NMT_STATE_BOOTUP);
        send(d, tx, &f);
        d->boot_pending = false;
        d->nmt = NMT_STATE_PREOP;
        d->heartbeat_timer_us = 0;
        if (d->power == CIA402_NOT_READY)
            d->power = CIA402_SWITCH_ON_DISABLED; /* transition 1: self-test passed */
    } else if (d->cfg.heartbeat_period_us > 0) {
        d->heartbeat_timer_us += dt_us;
        if (d->heartbeat_timer_us >= d->cfg.heartbeat_period_us) {
            canopen_heartbeat_encode(&f, d->node, d->nmt);
            send(d, tx, &f);
            d->heartbeat_timer_us -= d->cfg.heartbeat_period_us;
            if (d->heartbeat_timer_us >= d->cfg.heartbeat_period_us)
                d->heartbeat_timer_us = 0; /* a long tick: no burst of stale heartbeats */
        }
    }
    /* faults: the reaction completes within one tick (transitions 13, 14) */
    if (d->fault_pending) {
        d->fault_pending = false;
        d->power = CIA402_FAULT;
        d->emcy_reset_pending = false;
        if (emcy_allowed(d)) {
            canopen_emcy_encode(&f, d->node, d->fault_code, d->error_register);
            send(d, tx, &f);
        }
    } else if (d->emcy_reset_pending) {
        d->emcy_reset_pending = false;
        if (emcy_allowed(d)) {
            canopen_emcy_encode(&f, d->node, CANOPEN_EMCY_NO_ERROR, 0);
            send(d, tx, &f);
        }
    }
    /* quick stop: hold zero torque, then drop to SWITCH_ON_DISABLED (option code 2) */
    if (d->power == CIA402_QUICK_STOP_ACTIVE) {
        d->quick_stop_timer_us += dt_us;
        if (d->quick_stop_timer_us >= d->cfg.quick_stop_us)
            d->power = CIA402_SWITCH_ON_DISABLED;
    }
    /* torque stage */
    float tq_nm = 0.0f;
    if (d->nmt == NMT_STATE_OPERATIONAL && d->power == CIA402_OPERATION_ENABLED &&
        power_enabled) {
        const float peak = d->cfg.peak_torque_nm;
        tq_nm = (float)d->target_torque_permille * d->cfg.rated_torque_nm / 1000.0f;
        tq_nm = fminf(fmaxf(tq_nm, -peak), peak);
        tq_nm = dac_quantise_nm(tq_nm, peak, d->cfg.dac_bits);
    }
    d->torque_nm = tq_nm;
    /* synchronous TPDO1 */
    if (d->sync_pending) {
        d->sync_pending = false;
        if (d->nmt == NMT_STATE_OPERATIONAL) {
            float pm = d->cfg.rated_torque_nm > 0.0f ? tq_nm / d->cfg.rated_torque_nm * 1000.0f
                                                     : 0.0f;
            pm = fminf(fmaxf(pm, -32767.0f), 32767.0f);
            canopen_tpdo_encode(&f, d->node, cia402_statusword(d->power), position_counts,
                                (int16_t)lrintf(pm));
            send(d, tx, &f);
        }
    }
}

float drive_motor_torque_nm(const drive_t *d)
{
    return d->torque_nm;
}

bool drive_fault_active(const drive_t *d)
{
    return d->power == CIA402_FAULT || d->power == CIA402_FAULT_REACTION_ACTIVE;
}
