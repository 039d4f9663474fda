/* Scripted window input (see ui_input.h). One event per line:
 *   AT_S key NAME | shift down|up | ctrl down|up | cursor X Y | left down|up | right down|up |
 *   wheel STEPS */
#define GLFW_INCLUDE_NONE
#include "host/render/ui_input.h"

#include <GLFW/glfw3.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/tokens.h"

static const struct {
    const char *name;
    int code;
} KEYS[] = {
    {"1", GLFW_KEY_1},         {"2", GLFW_KEY_2},         {"3", GLFW_KEY_3},
    {"4", GLFW_KEY_4},         {"5", GLFW_KEY_5},         {"6", GLFW_KEY_6},
    {"B", GLFW_KEY_B},         {"C", GLFW_KEY_C},         {"TAB", GLFW_KEY_TAB},
    {"UP", GLFW_KEY_UP},       {"DOWN", GLFW_KEY_DOWN},   {"LEFT", GLFW_KEY_LEFT},
    {"RIGHT", GLFW_KEY_RIGHT}, {"PLUS", GLFW_KEY_EQUAL},  {"MINUS", GLFW_KEY_MINUS},
    {"ESC", GLFW_KEY_ESCAPE},  {"I", GLFW_KEY_I},         {"M", GLFW_KEY_M},         {"K", GLFW_KEY_K},
    {"P", GLFW_KEY_P},         {"Y", GLFW_KEY_Y},         {"Z", GLFW_KEY_Z},
    {"LBRACKET", GLFW_KEY_LEFT_BRACKET},                 {"RBRACKET", GLFW_KEY_RIGHT_BRACKET},
};

int ui_input_key_code(const char *name)
{
    for (size_t i = 0; i < sizeof(KEYS) / sizeof(KEYS[0]); i++)
        if (strcmp(KEYS[i].name, name) == 0)
            return KEYS[i].code;
    return -1;
}

void ui_input_init(ui_input_t *in)
{
    in->ev = NULL;
    in->count = 0;
    in->cap = 0;
}

void ui_input_free(ui_input_t *in)
{
    free(in->ev);
    ui_input_init(in);
}

static bool number(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !isfinite(v) || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

/* Empties in and returns code, with "line N: what 'word'" (no word: "line N: what") in err. */
static ui_input_err_t fail(ui_input_t *in, int line, ui_input_err_t code, const char *what,
                           const char *word, char *err, size_t err_len)
{
    snprintf(err, err_len, "line %d: %s%s%s%s", line, what, word ? " '" : "", word ? word : "",
             word ? "'" : "");
    ui_input_free(in);
    return code;
}

ui_input_err_t ui_input_parse(ui_input_t *in, const char *text, size_t len, char *err,
                              size_t err_len)
{
    ui_input_free(in);
    char buf[256];
    int line = 0;
    size_t pos = 0;
    double last_s = 0.0;
    while (pos < len) {
        line++;
        size_t end = pos;
        while (end < len && text[end] != '\n')
            end++;
        if (end - pos >= sizeof(buf))
            return fail(in, line, UI_INPUT_ERR_LINE_LONG, "line longer than 255 characters", NULL,
                        err, err_len);
        const size_t line_len = end - pos;
        memcpy(buf, text + pos, line_len);
        buf[line_len] = '\0';
        pos = end + 1;
        if (strlen(buf) != line_len)
            return fail(in, line, UI_INPUT_ERR_LINE_NUL, "NUL byte in the line", NULL, err,
                        err_len);
        char *hash = strchr(buf, '#');
        if (hash)
            *hash = '\0';
        char *w[5];
        const int n = (int)tokens_split(buf, sizeof(buf), " \t\r", '\0', w, 5);
        if (n == 0)
            continue;
        if (n > 4)
            return fail(in, line, UI_INPUT_ERR_WORDS, "too many words", NULL, err, err_len);
        ui_event_t e;
        memset(&e, 0, sizeof(e));
        e.line = line;
        if (!number(w[0], 0.0, 1e6, &e.at_s))
            return fail(in, line, UI_INPUT_ERR_TIME,
                        "time is not a number of seconds 0..1e6:", w[0], err, err_len);
        if (e.at_s < last_s)
            return fail(in, line, UI_INPUT_ERR_TIME_BACKWARDS, "time goes backwards:", w[0], err,
                        err_len);
        last_s = e.at_s;
        if (n < 2)
            return fail(in, line, UI_INPUT_ERR_EVENT_MISSING, "an event is missing after the time",
                        NULL, err, err_len);
        const char *ev = w[1];
        if (strcmp(ev, "key") == 0) {
            if (n != 3)
                return fail(in, line, UI_INPUT_ERR_KEY_ARGS, "key needs one NAME", NULL, err,
                            err_len);
            e.kind = UI_EV_KEY;
            e.code = ui_input_key_code(w[2]);
            if (e.code < 0)
                return fail(in, line, UI_INPUT_ERR_KEY, "unknown key", w[2], err, err_len);
        } else if (strcmp(ev, "shift") == 0 || strcmp(ev, "left") == 0 ||
                   strcmp(ev, "right") == 0 || strcmp(ev, "ctrl") == 0) {
            if (n != 3 || (strcmp(w[2], "down") != 0 && strcmp(w[2], "up") != 0))
                return fail(in, line, UI_INPUT_ERR_UP_DOWN, "needs down or up:", ev, err, err_len);
            e.kind = ev[0] == 's'   ? UI_EV_SHIFT
                     : ev[0] == 'c' ? UI_EV_CTRL
                     : ev[0] == 'l' ? UI_EV_LEFT
                                    : UI_EV_RIGHT;
            e.down = strcmp(w[2], "down") == 0;
        } else if (strcmp(ev, "cursor") == 0) {
            if (n != 4 || !number(w[2], -1e5, 1e5, &e.x) || !number(w[3], -1e5, 1e5, &e.y))
                return fail(in, line, UI_INPUT_ERR_CURSOR,
                            "cursor needs X Y in pixels (within 1e5)", NULL, err, err_len);
            e.kind = UI_EV_CURSOR;
        } else if (strcmp(ev, "wheel") == 0) {
            if (n != 3 || !number(w[2], -100, 100, &e.x))
                return fail(in, line, UI_INPUT_ERR_WHEEL, "wheel needs STEPS within -100..100",
                            NULL, err, err_len);
            e.kind = UI_EV_WHEEL;
        } else {
            return fail(in, line, UI_INPUT_ERR_EVENT, "unknown event", ev, err, err_len);
        }
        if (in->count == UI_INPUT_MAX_EVENTS)
            return fail(in, line, UI_INPUT_ERR_EVENTS_MAX, "more than 100000 events", NULL, err,
                        err_len);
        if (in->count == in->cap) {
            const size_t cap = in->cap ? 2 * in->cap : 64;
            ui_event_t *p = realloc(in->ev, cap * sizeof(*p));
            if (p == NULL) {
                ui_input_free(in);
                snprintf(err, err_len, "out of memory");
                return UI_INPUT_ERR_NOMEM;
            }
            in->ev = p;
            in->cap = cap;
        }
        in->ev[in->count++] = e;
    }
    return UI_INPUT_OK;
}

ui_input_err_t ui_input_load(ui_input_t *in, const char *path, char *err, size_t err_len)
{
    ui_input_init(in);
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        snprintf(err, err_len, "%s: cannot open: %s", path, strerror(errno));
        return UI_INPUT_ERR_IO;
    }
    char *text = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len == cap) {
            cap = cap ? 2 * cap : 4096;
            if (cap > ((size_t)16 << 20)) {
                free(text);
                fclose(f);
                snprintf(err, err_len, "%s: larger than 16 MiB", path);
                return UI_INPUT_ERR_FILE_SIZE;
            }
            char *p = realloc(text, cap);
            if (p == NULL) {
                free(text);
                fclose(f);
                snprintf(err, err_len, "%s: out of memory", path);
                return UI_INPUT_ERR_NOMEM;
            }
            text = p;
        }
        const size_t got = fread(text + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
    }
    const int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(text);
        snprintf(err, err_len, "%s: read error", path);
        return UI_INPUT_ERR_IO;
    }
    char perr[256];
    const ui_input_err_t rc = ui_input_parse(in, text, len, perr, sizeof(perr));
    free(text);
    if (rc != UI_INPUT_OK)
        snprintf(err, err_len, "%s: %s", path, perr);
    return rc;
}
