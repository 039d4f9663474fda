/* Compile-time bounds shared by the board and the host: a port changes one line here. */
#ifndef ARGIL_LIMITS_H
#define ARGIL_LIMITS_H

#define ARGIL_DRIVES 3                /* joints of the arm, one CiA 402 drive each */
#define ARGIL_WINDOW_MAX 32           /* samples per axis of the local density window */
#define ARGIL_WINDOW_SAMPLES_MAX (ARGIL_WINDOW_MAX * ARGIL_WINDOW_MAX * ARGIL_WINDOW_MAX)
#define ARGIL_TICK_US_DEFAULT 1000u   /* 1 kHz haptic loop */

#endif
