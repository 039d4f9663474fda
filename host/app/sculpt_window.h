/* The live sculpting window: the session runs in its own thread (paced to real time, or as
 * fast as it can), publishes re-meshed clay, tool, force, window box and status through a
 * triple buffer, and the window (GLFW main thread) draws the newest at the display rate with a
 * heads-up line, takes tool-panel keys and mouse sculpting, and never waits on the session. */
#ifndef ARGIL_SCULPT_WINDOW_H
#define ARGIL_SCULPT_WINDOW_H

#include <stdbool.h>
#include <stddef.h>

#include "host/app/session.h"

typedef struct {
    bool fast;                    /* run the session as fast as it can (default: real time) */
    bool mouse;                   /* no script: the mouse drives the hand until the window closes */
    int width, height;            /* window size in pixels */
    double screenshot_every_s;    /* > 0: a PNG of the window every this much simulated time */
    const char *frames_dir;       /* where those go (frame_MMMMMM.png, simulated ms) */
    const char *screenshot_path;  /* NULL, or the last frame's PNG once the session has ended */
    const char *input_path;       /* NULL, or scripted input (docs/render.md) */
    double linger_s;              /* the window stays this long (wall time) after the session */
    bool report;                  /* print the frame-time and latency figures at the end */
    float iso2;                   /* > 0: show the second iso-surface at this level from the start */
    int colour;                   /* colour_map_t shown on the clay from the start */
} sculpt_window_opts_t;

void sculpt_window_opts_default(sculpt_window_opts_t *o);

/* Opens the window and runs the session behind it (so->hook is set here). Returns
 * ARGIL_ERR_STATE with *window_failed when no window could be opened (nothing ran: the caller
 * may run headless); otherwise the session's result, with err as session_run gives it. */
argil_err_t sculpt_window_run(session_opts_t *so, const sculpt_window_opts_t *wo,
                              session_summary_t *sum, bool *window_failed, char *err,
                              size_t err_len);

#endif
