/* CiA 402 master: walks each drive to OPERATION_ENABLED when asked, streams torque, watches
 * heartbeats, EMCY and the bus state. */
#include "drives.h"

void drives_cfg_default(drives_cfg_t *cfg)
{
    cfg->heartbeat_timeout_us = ARGIL_DRIVE_HEARTBEAT_CONSUMER_US;
    cfg->bus_passive_fault_us = 100000u;
    cfg->bus_recovery_us = 500000u;
}

void drives_init(drives_t *dr)
{
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        drive_link_t *d = &dr->d[j];
        d->nmt = NMT_STATE_BOOTUP;
        d->seen = false;
        d->heartbeat_age_us = 0;
        d->power = CIA402_NOT_READY;
        d->statusword = 0;
        d->position_counts = 0;
        d->torque_permille = 0;
        d->position_valid = false;
        d->emcy = false;
        d->emcy_code = 0;
        d->emcy_register = 0;
        d->emcy_count = 0;
        d->start_sent = false;
        d->tpdos = 0;
        dr->controlword[j] = CIA402_CW_DISABLE_VOLTAGE;
    }
    dr->frames_rx = 0;
    dr->frames_unknown = 0;
    dr->bus = CAN_BUS_ACTIVE;
    dr->bus_state_us = 0;
    dr->fault_reset_left_us = 0;
    dr->bus_off_events = 0;
    dr->bus_passive_events = 0;
    dr->bus_restarts = 0;
    dr->error_frames = 0;
}

static void bus_enter(drives_t *dr, can_bus_state_t s)
{
    if (dr->bus == s)
        return;
    dr->bus = s;
    dr->bus_state_us = 0;
    if (s == CAN_BUS_OFF)
        dr->bus_off_events++;
    else if (s == CAN_BUS_PASSIVE)
        dr->bus_passive_events++;
}

/* A SocketCAN error frame: bus-off, error-passive, back to error-active, restarted. */
static void bus_error_frame(drives_t *dr, const can_frame_t *f)
{
    dr->error_frames++;
    if (f->id & ARGIL_CAN_ERR_RESTARTED) {
        /* The controller is back on the bus: the drives may have missed frames, so
         * restart NMT supervision from scratch (a fresh heartbeat window, NMT start again). */
        bus_enter(dr, CAN_BUS_ACTIVE);
        dr->bus_restarts++;
        for (int j = 0; j < ARGIL_DRIVES; j++) {
            dr->d[j].start_sent = false;
            dr->d[j].heartbeat_age_us = 0;
        }
        return;
    }
    if (f->id & ARGIL_CAN_ERR_BUSOFF) {
        bus_enter(dr, CAN_BUS_OFF);
        return;
    }
    if ((f->id & ARGIL_CAN_ERR_CRTL) && f->len >= 2 && dr->bus != CAN_BUS_OFF) {
        const uint8_t st = f->data[1];
        if (st & (ARGIL_CAN_CRTL_RX_PASSIVE | ARGIL_CAN_CRTL_TX_PASSIVE))
            bus_enter(dr, CAN_BUS_PASSIVE);
        else if (st & ARGIL_CAN_CRTL_ACTIVE)
            bus_enter(dr, CAN_BUS_ACTIVE);
    }
}

static drive_link_t *by_node(drives_t *dr, uint8_t node)
{
    return (node >= 1 && node <= ARGIL_DRIVES) ? &dr->d[node - 1] : 0;
}

void drives_receive(drives_t *dr, const can_batch_t *rx)
{
    const uint8_t n = rx->n <= CAN_BATCH_MAX ? rx->n : CAN_BATCH_MAX;
    for (uint8_t i = 0; i < n; i++) {
        const can_frame_t *f = &rx->f[i];
        uint8_t node;
        uint16_t sw, code;
        int32_t pos;
        int16_t tq;
        nmt_state_t st;
        uint8_t reg;
        drive_link_t *d;
        dr->frames_rx++;
        if (f->id & ARGIL_CAN_ERR_FLAG) {
            bus_error_frame(dr, f);
            continue;
        }
        if (canopen_tpdo_decode(f, &node, &sw, &pos, &tq) && (d = by_node(dr, node))) {
            d->power = cia402_state_from_statusword(sw);
            d->statusword = sw;
            d->position_counts = pos;
            d->torque_permille = tq;
            d->position_valid = true;
            d->tpdos++;
        } else if (canopen_heartbeat_decode(f, &node, &st) && (d = by_node(dr, node))) {
            if (st == NMT_STATE_BOOTUP)
                d->start_sent = false; /* the drive (re)booted: start it again */
            d->nmt = st;
            d->seen = true;
            d->heartbeat_age_us = 0;
        } else if (canopen_emcy_decode(f, &node, &code, &reg) && (d = by_node(dr, node))) {
            if (code != CANOPEN_EMCY_NO_ERROR) {
                d->emcy = true;
                d->emcy_code = code;
                d->emcy_register = reg;
                d->emcy_count++;
            }
        } else {
            dr->frames_unknown++;
        }
    }
}

/* The controlword that moves a drive one step towards the wanted power state. */
static uint16_t next_controlword(cia402_state_t s, bool want_enabled, bool reset_faults,
                                 uint16_t prev)
{
    if (!want_enabled && reset_faults && s == CIA402_FAULT)
        return prev == CIA402_CW_FAULT_RESET ? CIA402_CW_DISABLE_VOLTAGE : CIA402_CW_FAULT_RESET;
    if (!want_enabled) {
        return (s == CIA402_OPERATION_ENABLED) ? CIA402_CW_QUICK_STOP : CIA402_CW_DISABLE_VOLTAGE;
    }
    switch (s) {
    case CIA402_FAULT:
        /* Fault reset acts on the rising edge of bit 7: alternate with 0. */
        return prev == CIA402_CW_FAULT_RESET ? CIA402_CW_DISABLE_VOLTAGE : CIA402_CW_FAULT_RESET;
    case CIA402_SWITCH_ON_DISABLED:
    case CIA402_QUICK_STOP_ACTIVE:
        return CIA402_CW_SHUTDOWN;
    case CIA402_READY_TO_SWITCH_ON:
        return CIA402_CW_SWITCH_ON;
    case CIA402_SWITCHED_ON:
    case CIA402_OPERATION_ENABLED:
        return CIA402_CW_ENABLE_OP;
    default:
        return CIA402_CW_DISABLE_VOLTAGE;
    }
}

void drives_process(drives_t *dr, const drives_cfg_t *cfg, bool want_enabled,
                    const int16_t torque_permille[ARGIL_DRIVES], uint32_t dt_us,
                    can_batch_t *tx)
{
    (void)cfg;
    can_frame_t f;
    if (dr->bus_state_us < 0xFFFFFFFFu - dt_us)
        dr->bus_state_us += dt_us;
    dr->fault_reset_left_us = dr->fault_reset_left_us > dt_us ? dr->fault_reset_left_us - dt_us : 0;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        drive_link_t *d = &dr->d[j];
        if (d->heartbeat_age_us < 0xFFFFFFFFu - dt_us)
            d->heartbeat_age_us += dt_us;
        if (dr->bus == CAN_BUS_OFF)
            continue;
        /* A drive that announced itself but is not operational gets an NMT start. */
        if (d->seen && d->nmt != NMT_STATE_OPERATIONAL && !d->start_sent) {
            canopen_nmt_encode(&f, NMT_CMD_START, (uint8_t)(j + 1));
            (void)can_batch_push(tx, &f);
            d->start_sent = true;
        }
    }
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        drive_link_t *d = &dr->d[j];
        dr->controlword[j] = next_controlword(d->power, want_enabled,
                                             dr->fault_reset_left_us > 0, dr->controlword[j]);
        const bool may_push = want_enabled && d->power == CIA402_OPERATION_ENABLED;
        const int16_t tq = may_push ? torque_permille[j] : 0;
        if (d->nmt == NMT_STATE_OPERATIONAL && dr->bus != CAN_BUS_OFF) {
            canopen_rpdo_encode(&f, (uint8_t)(j + 1), dr->controlword[j], tq);
            (void)can_batch_push(tx, &f);
        }
    }
    if (dr->bus == CAN_BUS_OFF)
        return;
    canopen_sync_encode(&f);
    (void)can_batch_push(tx, &f);
}

void drives_shutdown(drives_t *dr, can_batch_t *tx)
{
    can_frame_t f;
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        dr->controlword[j] = CIA402_CW_DISABLE_VOLTAGE;
        if (dr->d[j].nmt == NMT_STATE_OPERATIONAL) {
            canopen_rpdo_encode(&f, (uint8_t)(j + 1), CIA402_CW_DISABLE_VOLTAGE, 0);
            (void)can_batch_push(tx, &f);
        }
    }
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        canopen_nmt_encode(&f, NMT_CMD_STOP, (uint8_t)(j + 1));
        (void)can_batch_push(tx, &f);
        dr->d[j].start_sent = false;
    }
}

void drives_clear_emcy(drives_t *dr)
{
    for (int j = 0; j < ARGIL_DRIVES; j++) {
        dr->d[j].emcy = false;
        dr->d[j].emcy_code = 0;
    }
}

bool drives_all_enabled(const drives_t *dr)
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        if (dr->d[j].power != CIA402_OPERATION_ENABLED || dr->d[j].nmt != NMT_STATE_OPERATIONAL)
            return false;
    return true;
}

bool drives_heartbeat_lost(const drives_t *dr, const drives_cfg_t *cfg)
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        if (dr->d[j].seen && dr->d[j].heartbeat_age_us > cfg->heartbeat_timeout_us)
            return true;
    return false;
}

bool drives_any_emcy(const drives_t *dr)
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        if (dr->d[j].emcy)
            return true;
    return false;
}

bool drives_positions_valid(const drives_t *dr)
{
    for (int j = 0; j < ARGIL_DRIVES; j++)
        if (!dr->d[j].position_valid)
            return false;
    return true;
}

bool drives_bus_error(const drives_t *dr, const drives_cfg_t *cfg)
{
    return dr->bus == CAN_BUS_OFF ||
           (dr->bus == CAN_BUS_PASSIVE && dr->bus_state_us >= cfg->bus_passive_fault_us);
}

bool drives_bus_unrecoverable(const drives_t *dr, const drives_cfg_t *cfg)
{
    return dr->bus == CAN_BUS_OFF && dr->bus_state_us >= cfg->bus_recovery_us;
}

const char *drives_emcy_class(uint16_t code)
{
    if (code == CANOPEN_EMCY_NO_ERROR)
        return "no error";
    if ((code & 0xFF00u) == 0x8100u)
        return "communication";
    if ((code & 0xFF00u) == 0xFF00u)
        return "device specific";
    switch (code >> 12) {
    case 0x1u: return "generic";
    case 0x2u: return "current";
    case 0x3u: return "voltage";
    case 0x4u: return "temperature";
    case 0x5u: return "device hardware";
    case 0x6u: return "device software";
    case 0x7u: return "additional modules";
    case 0x8u: return "monitoring";
    case 0x9u: return "external error";
    case 0xFu: return "additional functions";
    default: return "unknown";
    }
}

const char *drives_bus_state_name(can_bus_state_t s)
{
    switch (s) {
    case CAN_BUS_ACTIVE: return "error-active";
    case CAN_BUS_PASSIVE: return "error-passive";
    case CAN_BUS_OFF: return "bus-off";
    }
    return "?";
}

void drives_request_fault_reset(drives_t *dr, uint32_t for_us)
{
    dr->fault_reset_left_us = for_us;
}
