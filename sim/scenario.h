/* Scenario files (hil/scenarios/NAME.scn, format in docs/sim.md): a time-stamped script of what the
 * hand does, which faults are injected, and what must be observed within which time bound. One
 * format for the in-process SIL rig, argil-sim on a real bus and the log checker. */
#ifndef ARGIL_SCENARIO_H
#define ARGIL_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SCN_STEPS_MAX 64u
#define SCN_EXPECTS_MAX 32u
#define SCN_LINE_MAX 200u          /* characters per line, without the newline */
#define SCN_TIME_MAX_US 3600000000LL /* one hour */
#define SCN_NAME_LEN 32u
#define SCN_TEXT_LEN 80u           /* a step's source text kept for logs */

/* Which rule a scenario text broke. */
typedef enum {
    SCN_OK = 0,
    SCN_ERR_LINE_LONG = -1,        /* a line longer than SCN_LINE_MAX */
    SCN_ERR_CHAR = -2,             /* a control or non-ASCII byte */
    SCN_ERR_KEYWORD = -3,          /* a line that starts with no known keyword */
    SCN_ERR_TIME = -4,             /* a time that is not seconds ≥ 0 with ≤ 6 decimals */
    SCN_ERR_ORDER = -5,            /* an `at` time earlier than the one before it */
    SCN_ERR_ACTION = -6,           /* an unknown action after `at T` */
    SCN_ERR_ARG = -7,              /* a missing, malformed or out-of-range argument */
    SCN_ERR_TRAILING = -8,         /* words left over at the end of a line */
    SCN_ERR_DURATION = -9,         /* a duration without a unit (us, ms, s) or out of range */
    SCN_ERR_EXPECT = -10,          /* an unknown expectation or a bad within/until clause */
    SCN_ERR_TOO_MANY = -11,        /* more than SCN_STEPS_MAX steps or SCN_EXPECTS_MAX expects */
    SCN_ERR_NO_DURATION = -12,     /* no `duration` line, or two of them */
    SCN_ERR_BEYOND = -13,          /* a step or expectation after the scenario's end */
    SCN_ERR_NODE = -14,            /* a drive node outside 1..3 */
    SCN_ERR_IO = -15               /* the file could not be read (scenario_load only) */
} scn_err_t;

typedef enum {
    SCN_HAND = 0,       /* move the hand's target to p_mm (relative to home) over dur_us */
    SCN_HAND_RELEASE,   /* let go of the stylus */
    SCN_BUTTON,         /* a = 1 or 2, b = 1 down / 0 up */
    SCN_ESTOP,          /* a = 1 pressed / 0 released */
    SCN_DRIVE_FAULT_LINE, /* a = 1 pulled low (fault) / 0 released */
    SCN_EMCY,           /* drive node a trips: EMCY + FAULT + DRIVE_FAULT_N low */
    SCN_HEARTBEAT,      /* drive node a: b = 0 heartbeat stops, 1 resumes */
    SCN_ENCODER_JUMP,   /* drive node a: position counts jump by b */
    SCN_CAN_DROP,       /* drop frames both ways with probability ppm; seed */
    SCN_CAN_DELAY,      /* hold frames both ways for dur_us */
    SCN_BUS_OFF,        /* the device goes silent, the board gets a bus-off error frame */
    SCN_BUS_RESTART,    /* the bus is back: a "restarted" error frame, frames flow again */
    SCN_LINK_LOST,      /* host side: the link carries nothing either way */
    SCN_LINK_RESTORE,   /* host side: the link works again (clears lost/delay/dup/reorder) */
    SCN_LINK_DELAY,     /* host side: host → board frames arrive dur_us late */
    SCN_LINK_DUPLICATE, /* host side: the next a frames to the board are sent twice */
    SCN_LINK_REORDER,   /* host side: the next a pairs of frames to the board swap places */
    SCN_LINK_GARBAGE,   /* host side: a bytes (1..1024, one frame at most) of noise */
    SCN_LINK_NAN,       /* host side: a TOOL frame with a NaN field (valid CRC) */
    SCN_STRANGER,       /* host side: a hostile sender for dur_us, a = scn_stranger_t */
    SCN_OVERRUN,        /* host side: the next a board ticks overrun their 1 ms deadline */
    SCN_REARM,          /* host side: the host sends ARM */
    SCN_ACTION_COUNT
} scn_action_t;

/* What a hostile sender on the host's network does (`at T stranger KIND for D`). */
typedef enum {
    SCN_STRANGER_REPLAY = 0, /* resends the host's captured frames, from another address and
                                from the host's own (spoofed) */
    SCN_STRANGER_FORGE = 1,  /* CRC-valid commands (HELLO, DISARM, END, a stiffer TOOL) with no
                                or a wrong authentication tag, from both addresses */
    SCN_STRANGER_FLOOD = 2,  /* junk datagrams as fast as it can, from another address */
    SCN_STRANGER_COUNT
} scn_stranger_t;

const char *scenario_stranger_name(scn_stranger_t k);

/* True for the steps the host side of a rig performs (link, overrun, rearm); argil-sim does
 * only the others. */
bool scenario_action_is_host_side(scn_action_t a);
const char *scenario_action_name(scn_action_t a);

typedef struct {
    uint32_t line;
    int64_t t_us;
    scn_action_t action;
    float p_mm[3];
    int64_t dur_us;
    int32_t a, b;
    uint32_t ppm;           /* CAN drop probability, parts per million */
    uint32_t seed;
    char text[SCN_TEXT_LEN]; /* the line as written (truncated), for event logs */
} scn_step_t;

typedef enum {
    SCN_EXP_TORQUE_ZERO = 0, /* every RPDO target torque is 0 from some instant on */
    SCN_EXP_FORCE_ZERO,      /* same observable on the bus: the force reaches the hand as torque */
    SCN_EXP_QUICK_STOP,      /* every drive got controlword QUICK_STOP */
    SCN_EXP_FAULT,           /* drives commanded off (controlword 0/2, torque 0) and
                                DRIVE_ENABLE low when GPIO is observed, and it stays so */
    SCN_EXP_ENABLED,         /* every drive got ENABLE_OPERATION and DRIVE_ENABLE is high */
    SCN_EXP_TORQUE_NONZERO,  /* some RPDO carries a non-zero target torque */
    SCN_EXP_NO_TORQUE_FRAMES,/* no RPDO with a non-zero target torque (until …) */
    SCN_EXP_RUNNING,         /* drives stay enabled, no DRIVE_ENABLE drop (until …) */
    SCN_EXP_SAFE,            /* once a drive is commanded off or DRIVE_ENABLE drops, no
                                non-zero torque follows (until …): the fault latches */
    SCN_EXP_HEARTBEAT_SUPERVISED, /* the drive heartbeat consumer as required, judged from the
                                heartbeats on the bus: drives stay enabled while every drive's
                                last heartbeat is within the consumer time, are off once one is
                                surely past it, and stay off (until …) */
    SCN_EXP_COUNT
} scn_expect_kind_t;

typedef enum {
    SCN_UNTIL_NONE = 0,      /* a `within` expectation */
    SCN_UNTIL_REARM,         /* the next rearm step after the expectation's time */
    SCN_UNTIL_END,
    SCN_UNTIL_TIME
} scn_until_t;

typedef struct {
    uint32_t line;
    int64_t t_us;
    scn_expect_kind_t kind;
    int64_t within_us;       /* bound (within) */
    scn_until_t until;
    int64_t until_us;        /* SCN_UNTIL_TIME */
    char text[SCN_TEXT_LEN];
} scn_expect_t;

typedef struct {
    char name[SCN_NAME_LEN];
    int64_t duration_us;
    uint32_t n_steps;
    scn_step_t step[SCN_STEPS_MAX];
    uint32_t n_expects;
    scn_expect_t expect[SCN_EXPECTS_MAX];
} scenario_t;

typedef struct {
    scn_err_t code;
    uint32_t line;           /* 1-based; 0 for a file that could not be read */
    char msg[128];           /* one line, no newline, without the file name */
} scn_error_t;

/* Parses a whole scenario text (len bytes, no terminator needed). On error fills err (line and
 * reason) and returns its code; s is then unspecified. */
scn_err_t scenario_parse(scenario_t *s, const char *text, size_t len, scn_error_t *err);

/* Reads and parses a file (at most 64 KiB). */
scn_err_t scenario_load(scenario_t *s, const char *path, scn_error_t *err);

const char *scenario_expect_name(scn_expect_kind_t k);

/* The end of an `until` window of expectation e: the rearm after it, the end, or its time. */
int64_t scenario_until_us(const scenario_t *s, const scn_expect_t *e);

#endif
