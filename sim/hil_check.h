/* The log checker behind argil-hil-check: reads what a rig recorded — a candump -l log of the
 * CAN bus and argil-sim's event log (injections and the board's DRIVE_ENABLE output, on
 * CLOCK_REALTIME) — and decides each expectation of a scenario from those timestamps alone.
 * The SIL fault matrix feeds the same checker, so SIL and the VM judge by one rule. */
#ifndef ARGIL_HIL_CHECK_H
#define ARGIL_HIL_CHECK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/canopen.h"
#include "sim/scenario.h"

typedef struct {
    int64_t t_us;
    can_frame_t f;
} hil_frame_t;

typedef struct {
    int64_t t_us;                  /* the sample that saw the new level */
    int64_t prev_us;               /* the sample before, which still saw the old one; −1 when
                                      not logged: the edge lies in (prev_us, t_us] */
    bool drive_enable;
} hil_gpio_t;

#define HIL_MARKS_MAX (2u * SCN_EXPECTS_MAX + 1u) /* expectation times, until times, the end */

/* What a run recorded. Arrays grow on the heap; free with hil_obs_free. */
typedef struct {
    hil_frame_t *frame;
    size_t n_frames, cap_frames;
    size_t n_syncs;                /* SYNC frames among them: the board's ticks */
    hil_gpio_t *gpio;              /* DRIVE_ENABLE changes, in time order */
    size_t n_gpio, cap_gpio;
    bool have_start;
    int64_t start_us;              /* scenario time 0 */
    bool step_seen[SCN_STEPS_MAX];
    int64_t step_us[SCN_STEPS_MAX]; /* when each scenario step was injected */
    uint32_t heartbeat_ticks;      /* the board's drive heartbeat consumer time in ticks
                                      (hil_obs_init: ARGIL_DRIVE_HEARTBEAT_CONSUMER_US) */
    uint32_t link_ticks;           /* set by the caller: board ticks the host link may take to
                                      deliver a host-side step (UDP, link thread, ring); added
                                      to the bounds of expectations anchored on one */
    uint32_t n_marks;              /* "mark at T": when the rig's scenario clock passed T */
    int64_t mark_t_us[HIL_MARKS_MAX];
    int64_t mark_us[HIL_MARKS_MAX];
    uint32_t mark_sync[HIL_MARKS_MAX]; /* "sync=N": the rig's clock passed T at the N-th SYNC
                                          after the start line (0: not said) */
} hil_obs_t;

typedef enum {
    HIL_OK = 0,
    HIL_ERR_SYNTAX = -1,   /* not "(SECONDS.MICROS) IFACE ID#DATA" / "(SECONDS.MICROS) EVENT …" */
    HIL_ERR_FRAME = -2,    /* bad identifier, odd or too many data digits, RTR or CAN FD */
    HIL_ERR_ORDER = -3,    /* a timestamp earlier than the line before */
    HIL_ERR_EVENT = -4,    /* an event log line naming no known event, or a step not in the
                              scenario */
    HIL_ERR_MEMORY = -5,
    HIL_ERR_NO_START = -6, /* the event log has no start line */
    HIL_ERR_SCENARIO = -7  /* its start line names another scenario */
} hil_err_t;

void hil_obs_init(hil_obs_t *o);
void hil_obs_free(hil_obs_t *o);
hil_err_t hil_obs_push_frame(hil_obs_t *o, int64_t t_us, const can_frame_t *f);
hil_err_t hil_obs_push_gpio(hil_obs_t *o, int64_t t_us, bool drive_enable);
/* The same with the time of the sample before (the edge lies between the two). */
hil_err_t hil_obs_push_gpio_sampled(hil_obs_t *o, int64_t prev_us, int64_t t_us,
                                    bool drive_enable);

/* One candump -l / -L line "(1700000000.123456) vcan0 201#0F00E803": the time in µs and the
 * frame (standard 3-digit ids, or 8-digit ids carrying CAN_ERR_FLAG for error frames). */
hil_err_t hil_candump_line(const char *line, size_t len, int64_t *t_us, can_frame_t *f);

/* Adds every line of a candump log (blank lines skipped); on error *err_line is 1-based. */
hil_err_t hil_obs_add_candump(hil_obs_t *o, const char *text, size_t len, uint32_t *err_line);

/* Adds an argil-sim event log: "(T) start …", "(T) inject line=N …", "(T) gpio_out
 * DRIVE_ENABLE=0|1 [prev=(SECONDS.MICROS)]" (prev: the sample before), "(T) mark at
 * S.UUUUUU [sync=N] …", "(T) note …", "(T) end …". Injections are
 * matched to s's steps by line; a mark says when the rig's scenario clock passed scenario time
 * S (argil-sim's clock follows the board's ticks), so an expectation at S with no step at S is
 * anchored there instead of at start + S (the first mark of a time counts); with " sync=N" at
 * the N-th SYNC of the CAN log after the start line, when the log has that many. */
hil_err_t hil_obs_add_events(hil_obs_t *o, const scenario_t *s, const char *text, size_t len,
                             uint32_t *err_line);

/* A scenario's time bounds are for a 1 kHz board: "within 3ms" allows 3 ticks. When the log
 * holds SYNC frames (one per board tick) a bound is asserted in ticks — SYNCs after the
 * expectation's time up to the observation — so a slow rig (an emulated VM at 200-700
 * ticks/s) is judged by what the board did per tick; without SYNCs, in wall-clock µs. */
#define HIL_TICK_US 1000

typedef struct {
    bool pass;
    int64_t observed_us;           /* latency from the expectation's time, −1 when not seen */
    int64_t observed_ticks;        /* the same in board ticks (SYNCs), −1 when not counted */
    uint32_t tolerated;            /* heartbeat_supervised: heartbeat gaps longer than one
                                      producer period that the board rode through */
    char msg[256];                 /* one line: what was seen */
} hil_result_t;

/* Decides expectation i of s from o. */
void hil_check_expect(const scenario_t *s, const hil_obs_t *o, uint32_t i, hil_result_t *r);

const char *hil_err_name(hil_err_t e);

#endif
