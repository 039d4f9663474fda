/* The scenario clock of a rig whose board may tick slower than 1 kHz (an emulated VM): one tick
 * of 1 ms per SYNC the board sends, so the arm, the scripted hand and the host-side steps
 * advance with the board's own clock and every tick sees the motion of 1 ms, as on a real
 * board; while the bus carries no SYNC for longer than SCN_CLOCK_SILENCE_US (bus-off, a
 * stopped board) the clock follows the wall clock. On a board that holds its 1 kHz both
 * agree. argil-sim and hil-host keep one each. */
#ifndef ARGIL_SCN_CLOCK_H
#define ARGIL_SCN_CLOCK_H

#include <stdbool.h>
#include <stdint.h>

#include "shared/canopen.h"

#define SCN_CLOCK_TICK_US 1000u        /* one board tick at the nominal 1 kHz */
#define SCN_CLOCK_SILENCE_US 400000    /* no SYNC this long: follow the wall clock (longer
                                          than a stall of the emulated board: 250 ms seen) */
#define SCN_CLOCK_MAX_STEP_US 20000u   /* longest step taken on the wall clock */

typedef struct {
    bool ticks;              /* true: SYNC-driven; false: always the wall clock */
    int64_t now_us;          /* scenario time */
    int64_t last_wall_us;    /* wall time of the last step (or of the start) */
    bool silent;             /* following the wall clock until the next SYNC */
    bool bus_off;            /* the scenario holds the bus off: the wall clock only */
    uint32_t syncs;          /* SYNCs counted */
    uint32_t wall_steps;     /* steps taken on the wall clock */
} scn_clock_t;

/* A frame that is one board tick on this clock (and in the HIL checker's counts): a SYNC, with
 * or without CiA 301's counter byte. */
bool scn_clock_is_tick(const can_frame_t *f);

/* Starts at scenario time 0, wall time wall_us; ticks: SYNC-driven, else wall clock only. */
void scn_clock_init(scn_clock_t *c, bool ticks, int64_t wall_us);

/* A SYNC seen at wall_us: returns the step (SCN_CLOCK_TICK_US) the clock took, 0 on a
 * wall-clock-only clock. */
uint32_t scn_clock_sync(scn_clock_t *c, int64_t wall_us);

/* Nothing (more) on the bus at wall_us: returns the step the clock takes now on the wall clock
 * (the wall time it has not taken yet, 1..SCN_CLOCK_MAX_STEP_US per call, so a silence is
 * counted whole, from the last SYNC), or 0 while it waits for the next SYNC (SYNC-driven and
 * silent for at most SCN_CLOCK_SILENCE_US) or is up to date. */
uint32_t scn_clock_idle(scn_clock_t *c, int64_t wall_us);

/* While the scenario itself holds the bus off (bus_off until bus_restart: the board's
 * controller sends no SYNC), scenario time is the wall time, from the last SYNC on: SYNCs the
 * board still sends before it sees the bus-off step nothing, idle calls step the wall time. A
 * SYNC-driven clock waited SCN_CLOCK_SILENCE_US for the silence and then caught up, and each
 * late SYNC started the wait again: under TCG a restart timed 300 ms after the bus-off came
 * 530-560 ms after it, past the board's 500 ms recovery bound. Off again, SYNCs drive it. */
void scn_clock_wall_while_bus_off(scn_clock_t *c, bool bus_off);

#endif
