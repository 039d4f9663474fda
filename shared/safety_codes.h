/* The board's safety states and fault codes and their names (DESIGN.md "Safety states"): the
 * board reports them in its status frames and the host shows them, so both build this file. */
#ifndef ARGIL_SAFETY_CODES_H
#define ARGIL_SAFETY_CODES_H

typedef enum {
    SAFETY_BOOT = 0,
    SAFETY_IDLE = 1,    /* drives off */
    SAFETY_ARMED = 2,   /* drives on, zero torque */
    SAFETY_ACTIVE = 3,  /* forces on */
    SAFETY_FAULT = 4,   /* latched, torque off */
    SAFETY_ESTOP = 5    /* latched until the line is released and the host re-arms */
} safety_state_t;

typedef enum {
    FAULT_NONE = 0,
    FAULT_HOST_LOST = 1,
    FAULT_DRIVE_HEARTBEAT = 2,
    FAULT_DRIVE_EMCY = 3,
    FAULT_DRIVE_LINE = 4,      /* DRIVE_FAULT_N low */
    FAULT_DEADLINE = 5,        /* overrun streak */
    FAULT_NONFINITE = 6,       /* NaN/Inf in a position, window or gain */
    FAULT_FORCE_LIMIT = 7,     /* the controller itself asked for more than the limit */
    FAULT_BUS = 8,             /* CAN bus-off or frames could not be sent */
    FAULT_ESTOP = 9,
    FAULT_VELOCITY_LIMIT = 10  /* the tool moved faster than the configured limit */
} fault_code_t;

/* The state's upper-case name ("ACTIVE"); "?" for a value outside the enum. */
const char *safety_state_name(safety_state_t st);
/* The fault's name in words ("host heartbeat lost"); "?" for a value outside the enum. */
const char *safety_fault_name(fault_code_t f);

#endif
