/* Names of the safety states and fault codes, for status lines and logs on both sides. */
#include "safety_codes.h"

const char *safety_state_name(safety_state_t st)
{
    switch (st) {
    case SAFETY_BOOT: return "BOOT";
    case SAFETY_IDLE: return "IDLE";
    case SAFETY_ARMED: return "ARMED";
    case SAFETY_ACTIVE: return "ACTIVE";
    case SAFETY_FAULT: return "FAULT";
    case SAFETY_ESTOP: return "ESTOP";
    }
    return "?";
}

const char *safety_fault_name(fault_code_t f)
{
    switch (f) {
    case FAULT_NONE: return "none";
    case FAULT_HOST_LOST: return "host heartbeat lost";
    case FAULT_DRIVE_HEARTBEAT: return "drive heartbeat lost";
    case FAULT_DRIVE_EMCY: return "drive emergency";
    case FAULT_DRIVE_LINE: return "drive fault line";
    case FAULT_DEADLINE: return "deadline overrun streak";
    case FAULT_NONFINITE: return "non-finite value";
    case FAULT_FORCE_LIMIT: return "force limit exceeded";
    case FAULT_BUS: return "CAN bus error";
    case FAULT_ESTOP: return "e-stop";
    case FAULT_VELOCITY_LIMIT: return "velocity limit exceeded";
    }
    return "?";
}
