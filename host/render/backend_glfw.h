/* A GLFW window with an OpenGL 3.3 core context (a real X display or Xvfb). libglfw is opened
 * at run time, so nothing links to it; the window may be hidden for screenshots. */
#ifndef ARGIL_BACKEND_GLFW_H
#define ARGIL_BACKEND_GLFW_H

#include <stdbool.h>
#include <stddef.h>

#include "host/render/gl_api.h"
#include "shared/argil_err.h"

#define GLFW_KEYS_QUEUED 32     /* key presses kept between two polls; more are dropped */

typedef struct {
    void *lib;          /* dlopen handle of libglfw.so.3 */
    void *window;       /* GLFWwindow */
    void *fns;          /* the GLFW entry points (backend-private) */
    double scroll_y;    /* wheel steps accumulated since the last glfw_window_take_scroll */
    int keys[GLFW_KEYS_QUEUED]; /* keys pressed (or repeated) since the last glfw_window_take_key */
    unsigned n_keys;
} glfw_window_t;

typedef struct {
    bool left_down;     /* left mouse button held */
    double cursor_x, cursor_y;  /* pixels from the top-left corner */
    bool escape;        /* Esc pressed */
    bool right_down;    /* right mouse button held */
    bool shift;         /* either Shift key held */
    bool ctrl;          /* either Control key held (Ctrl+Z undo in the live window) */
} glfw_input_t;

/* Opens a width × height window (hidden when !visible) with a current GL 3.3 core context,
 * samples-× multisampling asked for (0: none), and loads gl. ARGIL_ERR_STATE with a one-line
 * reason (no libglfw, no display, no 3.3 context). */
argil_err_t glfw_window_open(glfw_window_t *w, int width, int height, bool visible, int samples,
                             const char *title, gl_api_t *gl, char *err, size_t err_len);

/* Processes pending events and returns the mouse and keyboard state. */
void glfw_window_poll(glfw_window_t *w, glfw_input_t *in);

/* Processes pending events; when there are none, sleeps until one arrives, glfw_window_wake is
 * called or timeout_s passes (timeout_s <= 0: does not sleep). Main thread only. */
void glfw_window_wait(glfw_window_t *w, double timeout_s);

/* Makes a glfw_window_wait in progress (or the next one) return at once. Safe from any thread
 * while the window is open. */
void glfw_window_wake(glfw_window_t *w);

/* Takes the oldest key pressed since the last poll (a GLFW_KEY_* code); false when none. */
bool glfw_window_take_key(glfw_window_t *w, int *key);

/* Returns the wheel steps since the last call (positive: away from the person). */
double glfw_window_take_scroll(glfw_window_t *w);

/* True once the person closed the window. */
bool glfw_window_should_close(const glfw_window_t *w);

/* The framebuffer's size in pixels. */
void glfw_window_size(const glfw_window_t *w, int *width, int *height);

/* Shows the frame just drawn into the default framebuffer. */
void glfw_window_swap(glfw_window_t *w);

/* Destroys the window and terminates GLFW; safe on a zeroed or failed w. */
void glfw_window_close(glfw_window_t *w);

#endif
