/* Compile-time bounds shared by the board and the host: a port changes one line here. */
#ifndef ARGIL_LIMITS_H
#define ARGIL_LIMITS_H

#define ARGIL_DRIVES 3                /* joints of the arm, one CiA 402 drive each */
#define ARGIL_WINDOW_MAX 32           /* samples per axis of the local density window */
#define ARGIL_WINDOW_SAMPLES_MAX (ARGIL_WINDOW_MAX * ARGIL_WINDOW_MAX * ARGIL_WINDOW_MAX)
#define ARGIL_TICK_US_DEFAULT 1000u   /* 1 kHz haptic loop */
/* Drive heartbeats (CiA 301): the drives produce every 100 ms (0x1017); the board's consumer
 * time (0x1016) is two producer periods plus 50 ms, so one lost heartbeat never faults and two
 * in a row do, 250 ms after the last one received and before the third is due. */
#define ARGIL_DRIVE_HEARTBEAT_PERIOD_US 100000u
#define ARGIL_DRIVE_HEARTBEAT_CONSUMER_US 250000u

#endif
