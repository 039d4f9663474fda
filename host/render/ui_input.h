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

/* Parses input text (need not be NUL-terminated). ARGIL_ERR_PARSE with "line N: what is wrong"
 * in err; ARGIL_ERR_NOMEM. Times must not decrease. */
argil_err_t ui_input_parse(ui_input_t *in, const char *text, size_t len, char *err,
                           size_t err_len);

/* Reads and parses a file; err names the file. */
argil_err_t ui_input_load(ui_input_t *in, const char *path, char *err, size_t err_len);

/* The key name's GLFW_KEY_* code, or -1 for a name the file format does not know. */
int ui_input_key_code(const char *name);

#endif
