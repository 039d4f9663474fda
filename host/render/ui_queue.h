/* Commands from the window (render thread) to the running session (session thread): a
 * lock-free single-producer single-consumer queue of fixed-size records. The window never waits:
 * when the queue is full the command is dropped and counted. */
#ifndef ARGIL_UI_QUEUE_H
#define ARGIL_UI_QUEUE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#define UI_QUEUE_CAP 256u         /* records; a power of two */

typedef enum {
    UI_CMD_TOOL = 1,              /* arg: tool_kind_t */
    UI_CMD_FILTER,                /* arg: beta_filter_t */
    UI_CMD_PARAM,                 /* arg: script_param_t, value: the new value */
    UI_CMD_INVERT,                /* arg: 1 while the invert key is held, 0 on release */
    UI_CMD_MOUSE,                 /* arg: 1 while the left button is held; ray in model space */
    UI_CMD_STOP,                  /* end the session (window closed) */
    UI_CMD_ISO2,                  /* arg: 1 shows the second iso-surface at level value, 0 hides */
    UI_CMD_COLOUR,                /* arg: colour_map_t, the material shown on the clay */
    UI_CMD_REFINE,                /* knot insertion in the B-spline model (peer_refine) */
    UI_CMD_UNDO                   /* arg: 1 undo, 2 redo (host/app/session_undo.h) */
} ui_cmd_kind_t;

typedef struct {
    uint8_t kind;                 /* ui_cmd_kind_t */
    int32_t arg;
    float value;
    float origin_m[3], dir[3];    /* UI_CMD_MOUSE: the cursor's ray, dir unit */
} ui_cmd_t;

typedef struct {
    ui_cmd_t rec[UI_QUEUE_CAP];
    _Atomic uint32_t head;        /* free-running read index (consumer writes) */
    _Atomic uint32_t tail;        /* free-running write index (producer writes) */
    _Atomic uint32_t dropped;
} ui_queue_t;

void ui_queue_init(ui_queue_t *q);

/* Producer: appends c; false (and one more drop counted) when the queue is full. */
bool ui_queue_push(ui_queue_t *q, const ui_cmd_t *c);

/* Consumer: takes the oldest record into *c; false when empty. */
bool ui_queue_pop(ui_queue_t *q, ui_cmd_t *c);

#endif
