/* A scripted input file for the live window (tests, demos): keys, the Shift key, the cursor,
 * the mouse buttons and the wheel, each at a simulated time (docs/render.md). */
#ifndef ARGIL_UI_INPUT_H
#define ARGIL_UI_INPUT_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"

#define UI_INPUT_MAX_EVENTS 100000u

typedef enum {
    UI_EV_KEY,                    /* code: a GLFW_KEY_* */
    UI_EV_SHIFT,                  /* down: held */
    UI_EV_CURSOR,                 /* x, y: pixels from the top-left */
    UI_EV_LEFT,                   /* down */
    UI_EV_RIGHT,                  /* down */
    UI_EV_WHEEL,                  /* x: steps */
    UI_EV_CTRL                    /* down: held (Ctrl+Z undo in the live window) */
} ui_ev_kind_t;

typedef struct {
    double at_s;                  /* simulated time at which it happens */
    ui_ev_kind_t kind;
    int code;
    int down;
    double x, y;
    int line;
} ui_event_t;

typedef struct {
    ui_event_t *ev;
    size_t count, cap;
} ui_input_t;

void ui_input_init(ui_input_t *in);
void ui_input_free(ui_input_t *in);

/* What the input readers return: UI_INPUT_OK, a failure outside the text (the file cannot be
 * opened or read: IO; out of memory: NOMEM; larger than 16 MiB: FILE_SIZE), or, in the order
 * the parser checks them, the rule a line broke. */
typedef enum {
    UI_INPUT_OK = 0,
    UI_INPUT_ERR_IO = -1,
    UI_INPUT_ERR_NOMEM = -2,
    UI_INPUT_ERR_FILE_SIZE = -3,
    UI_INPUT_ERR_LINE_LONG = -4,      /* a line longer than 255 characters */
    UI_INPUT_ERR_LINE_NUL = -5,       /* a line holds a NUL byte */
    UI_INPUT_ERR_WORDS = -6,          /* more than 4 words */
    UI_INPUT_ERR_TIME = -7,           /* the time is not a number of seconds 0..1e6 */
    UI_INPUT_ERR_TIME_BACKWARDS = -8, /* the time is before the previous line's */
    UI_INPUT_ERR_EVENT_MISSING = -9,  /* no event after the time */
    UI_INPUT_ERR_KEY_ARGS = -10,      /* key without exactly one NAME */
    UI_INPUT_ERR_KEY = -11,           /* a key name ui_input_key_code does not know */
    UI_INPUT_ERR_UP_DOWN = -12,       /* shift, ctrl, left or right without down or up */
    UI_INPUT_ERR_CURSOR = -13,        /* cursor without X Y in pixels within 1e5 */
    UI_INPUT_ERR_WHEEL = -14,         /* wheel without STEPS within -100..100 */
    UI_INPUT_ERR_EVENT = -15,         /* an unknown event */
    UI_INPUT_ERR_EVENTS_MAX = -16     /* more than UI_INPUT_MAX_EVENTS events */
} ui_input_err_t;

/* Parses input text (need not be NUL-terminated): the rule a line broke, with "line N: what is
 * wrong" in err; NOMEM. Times must not decrease. */
ui_input_err_t ui_input_parse(ui_input_t *in, const char *text, size_t len, char *err,
                              size_t err_len);

/* Reads and parses a file; err names the file. */
ui_input_err_t ui_input_load(ui_input_t *in, const char *path, char *err, size_t err_len);

/* The key name's GLFW_KEY_* code, or -1 for a name the file format does not know. */
int ui_input_key_code(const char *name);

#endif
