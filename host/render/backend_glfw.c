/* GLFW window backend (see backend_glfw.h). */
#define GLFW_INCLUDE_NONE
#include "host/render/backend_glfw.h"

#include <GLFW/glfw3.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The GLFW prototypes give the pointer types; the functions are only ever called through these. */
#define GLFW_FUNCS(X)                                                                            \
    X(glfwInit)                                                                                  \
    X(glfwTerminate)                                                                             \
    X(glfwGetError)                                                                              \
    X(glfwDefaultWindowHints)                                                                    \
    X(glfwWindowHint)                                                                            \
    X(glfwCreateWindow)                                                                          \
    X(glfwDestroyWindow)                                                                         \
    X(glfwMakeContextCurrent)                                                                    \
    X(glfwGetProcAddress)                                                                        \
    X(glfwSwapBuffers)                                                                           \
    X(glfwSwapInterval)                                                                          \
    X(glfwPollEvents)                                                                            \
    X(glfwWaitEventsTimeout)                                                                     \
    X(glfwPostEmptyEvent)                                                                        \
    X(glfwWindowShouldClose)                                                                     \
    X(glfwGetFramebufferSize)                                                                    \
    X(glfwGetCursorPos)                                                                          \
    X(glfwGetMouseButton)                                                                        \
    X(glfwGetKey)                                                                                \
    X(glfwSetScrollCallback)                                                                     \
    X(glfwSetKeyCallback)


#define GLFW_FIELD(name) __typeof__(&name) name;
typedef struct {
    GLFW_FUNCS(GLFW_FIELD)
} glfw_fns_t;
#undef GLFW_FIELD

static gl_proc_t glfw_get_proc(const char *name, void *ctx)
{
    const glfw_fns_t *f = ctx;
    return (gl_proc_t)f->glfwGetProcAddress(name);
}

/* GLFW's scroll callback carries only the GLFWwindow, and reaching the user pointer needs the
 * dlopen'ed table: so the one open window is remembered here (argil opens one window at most). */
static glfw_window_t *g_scroll_window;

static void on_scroll(GLFWwindow *win, double dx, double dy)
{
    (void)win;
    (void)dx;
    if (g_scroll_window != NULL)
        g_scroll_window->scroll_y += dy;
}

static argil_err_t fail(glfw_window_t *w, const char *what, char *err, size_t err_len)
{
    const glfw_fns_t *f = w->fns;
    const char *why = NULL;
    if (f != NULL && f->glfwGetError != NULL)
        f->glfwGetError(&why);
    snprintf(err, err_len, "OpenGL window (GLFW): %s%s%s", what, why ? ": " : "", why ? why : "");
    glfw_window_close(w);
    return ARGIL_ERR_STATE;
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)win;
    (void)scancode;
    (void)mods;
    glfw_window_t *w = g_scroll_window;
    if (w != NULL && (action == GLFW_PRESS || action == GLFW_REPEAT) && w->n_keys < GLFW_KEYS_QUEUED)
        w->keys[w->n_keys++] = key;
}

argil_err_t glfw_window_open(glfw_window_t *w, int width, int height, bool visible, int samples,
                             const char *title, gl_api_t *gl, char *err, size_t err_len)
{
    memset(w, 0, sizeof(*w));
    if (g_scroll_window != NULL) {
        snprintf(err, err_len, "OpenGL window (GLFW): a window is already open");
        return ARGIL_ERR_STATE;
    }
    const argil_err_t st = gl_lib_open("libglfw.so.3", "OpenGL window", "libglfw3",
                                       sizeof(glfw_fns_t), &w->lib, &w->fns, err, err_len);
    if (st != ARGIL_OK)
        return st;
    glfw_fns_t *f = w->fns;
#define GLFW_LOAD(name)                                                                          \
    {                                                                                            \
        void *p = dlsym(w->lib, #name);                                                          \
        if (p == NULL)                                                                           \
            return fail(w, "libglfw has no " #name, err, err_len);                               \
        memcpy(&f->name, &p, sizeof(p));                                                         \
    }
    GLFW_FUNCS(GLFW_LOAD)
#undef GLFW_LOAD
    if (!f->glfwInit())
        return fail(w, "cannot initialise (no X display?)", err, err_len);
    f->glfwDefaultWindowHints();
    f->glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    f->glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    f->glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    f->glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    f->glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    f->glfwWindowHint(GLFW_SAMPLES, samples);
    GLFWwindow *win = f->glfwCreateWindow(width, height, title, NULL, NULL);
    if (win == NULL)
        return fail(w, "cannot create a window with an OpenGL 3.3 core context", err, err_len);
    w->window = win;
    f->glfwMakeContextCurrent(win);
    f->glfwSwapInterval(1);
    g_scroll_window = w;
    f->glfwSetScrollCallback(win, on_scroll);
    f->glfwSetKeyCallback(win, on_key);
    const argil_err_t rc = gl_api_load(gl, glfw_get_proc, f, err, err_len);
    if (rc != ARGIL_OK) {
        glfw_window_close(w);
        return rc;
    }
    return ARGIL_OK;
}

void glfw_window_poll(glfw_window_t *w, glfw_input_t *in)
{
    const glfw_fns_t *f = w->fns;
    f->glfwPollEvents();
    in->left_down = f->glfwGetMouseButton(w->window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    f->glfwGetCursorPos(w->window, &in->cursor_x, &in->cursor_y);
    in->escape = f->glfwGetKey(w->window, GLFW_KEY_ESCAPE) == GLFW_PRESS;
    in->right_down = f->glfwGetMouseButton(w->window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    in->shift = f->glfwGetKey(w->window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                f->glfwGetKey(w->window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    in->ctrl = f->glfwGetKey(w->window, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
               f->glfwGetKey(w->window, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
}

void glfw_window_wait(glfw_window_t *w, double timeout_s)
{
    const glfw_fns_t *f = w->fns;
    if (timeout_s > 0.0)
        f->glfwWaitEventsTimeout(timeout_s);
    else
        f->glfwPollEvents();
}

void glfw_window_wake(glfw_window_t *w)
{
    const glfw_fns_t *f = w->fns;
    f->glfwPostEmptyEvent();
}

bool glfw_window_take_key(glfw_window_t *w, int *key)
{
    if (w->n_keys == 0)
        return false;
    *key = w->keys[0];
    w->n_keys--;
    memmove(w->keys, w->keys + 1, w->n_keys * sizeof(w->keys[0]));
    return true;
}

double glfw_window_take_scroll(glfw_window_t *w)
{
    const double s = w->scroll_y;
    w->scroll_y = 0.0;
    return s;
}

bool glfw_window_should_close(const glfw_window_t *w)
{
    const glfw_fns_t *f = w->fns;
    return f->glfwWindowShouldClose(w->window) != 0;
}

void glfw_window_size(const glfw_window_t *w, int *width, int *height)
{
    const glfw_fns_t *f = w->fns;
    f->glfwGetFramebufferSize(w->window, width, height);
}

void glfw_window_swap(glfw_window_t *w)
{
    const glfw_fns_t *f = w->fns;
    f->glfwSwapBuffers(w->window);
}

void glfw_window_close(glfw_window_t *w)
{
    glfw_fns_t *f = w->fns;
    if (f != NULL && f->glfwTerminate != NULL) {
        if (w->window != NULL)
            f->glfwDestroyWindow(w->window);
        f->glfwTerminate();
    }
    if (g_scroll_window == w)
        g_scroll_window = NULL;
    free(f);
    /* libglfw stays loaded: the GL driver it pulled in may run exit handlers from it. */
    memset(w, 0, sizeof(*w));
}
