/* When the live window starts its next frame (host/app/sculpt_window.c): at once for a snapshot
 * with a new mesh and for input that changes the view; other snapshots (the tool, the HUD) at
 * most every display period, and while a change is on its way to a mesh that frame waits for it
 * a little, so the frame in progress does not delay the change; with nothing new, now and then
 * for the HUD. Time is passed in; nothing here sleeps. */
#ifndef ARGIL_FRAME_PACER_H
#define ARGIL_FRAME_PACER_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    uint64_t display_period_ns;   /* routine frames at most this often, start to start */
    uint64_t hold_ns;             /* a routine frame waits up to this long after the last swap
                                   * while a change is on its way */
    uint64_t idle_period_ns;      /* with nothing new, a frame this often (the HUD's rates) */
} frame_pacer_cfg_t;

typedef struct {
    bool any;                     /* a frame was drawn */
    uint64_t last_start_ns;       /* when the last frame started */
    uint64_t last_swap_ns;        /* when its swap returned */
} frame_pacer_t;

typedef struct {
    bool undrawn;                 /* a snapshot is taken that no frame has shown */
    bool urgent;                  /* it holds a new mesh or a change not shown yet */
    bool input;                   /* input changed the view (camera, keys, size) */
    bool inflight;                /* the session has an impulse on its way to a mesh */
} frame_pacer_in_t;

/* 60 Hz routine frames, a 12 ms hold (one 10 ms solve step and its mesh), 4 Hz when idle. */
void frame_pacer_cfg_default(frame_pacer_cfg_t *c);

void frame_pacer_init(frame_pacer_t *p);

/* True when a frame should start at now_ns. Otherwise *due_ns is when one will be due if nothing
 * else happens (a new mesh or input makes it due sooner). */
bool frame_pacer_due(const frame_pacer_t *p, const frame_pacer_cfg_t *c,
                     const frame_pacer_in_t *in, uint64_t now_ns, uint64_t *due_ns);

/* Records a frame that started at start_ns and whose swap returned at swap_ns. */
void frame_pacer_drawn(frame_pacer_t *p, uint64_t start_ns, uint64_t swap_ns);

#endif
