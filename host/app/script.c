/* Session script parser and player. */
#include "script.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/proto.h"
#include "shared/tokens.h"

/* Every tunable with its range and default: one row each (docs/script.md lists them). */
static const struct {
    const char *name;
    float min, max, def;
} PARAMS[PARAM_COUNT] = {
    [PARAM_RADIUS_MM] = {"radius_mm", 0.5f, 50.0f, 4.0f},
    [PARAM_ALPHA] = {"alpha", 0.0f, 1e7f, 30000.0f},
    [PARAM_STIFFNESS_N_PER_MM] = {"stiffness_n_per_mm", 0.01f, 10.0f, 0.8f},
    [PARAM_MAX_FORCE_N] = {"max_force_n", 0.1f, 10.0f, 3.3f},
    [PARAM_LENGTH_MM] = {"length_mm", 0.0f, 100.0f, 10.0f},
    [PARAM_YIELD_FORCE_N] = {"yield_force_n", 0.0f, 10.0f, 0.5f},
    [PARAM_FRICTION] = {"friction", 0.0f, 2.0f, 0.3f},
    [PARAM_ISO] = {"iso", 0.05f, 0.95f, 0.5f},
    [PARAM_PROBE_GAIN] = {"probe_gain", 0.0f, 100.0f, 0.02f},
    [PARAM_ROPE_STIFFNESS_N_PER_MM] = {"rope_stiffness_n_per_mm", 0.0f, 5.0f, 0.2f},
    [PARAM_CLAY_STIFFNESS] = {"clay_stiffness", 0.0f, 5000.0f, 2.0f},
    [PARAM_CLAY_DAMPING] = {"clay_damping", 0.1f, 1000.0f, 40.0f},
    [PARAM_PLASTIC_RATE_HZ] = {"plastic_rate_hz", 0.0f, 1000.0f, 20.0f},
};
static const char *const TOOL_NAMES[TOOL_KIND_COUNT] = {"touch", "push", "pull",
                                                        "carve", "probe", "rope"};
static const char *const SHAPE_NAMES[TOOL_SHAPE_COUNT] = {"point", "curve", "area"};
static const char *const FILTER_NAMES[BETA_FILTER_COUNT] = {"constant", "gaussian", "spherical",
                                                            "cylindrical", "conical"};

const char *script_param_name(script_param_t p)
{
    return (p >= 0 && p < PARAM_COUNT) ? PARAMS[p].name : "?";
}

float script_param_default(script_param_t p)
{
    return (p >= 0 && p < PARAM_COUNT) ? PARAMS[p].def : 0.0f;
}

/* Index of word in names[0..n), or -1. */
static int find_name(const char *word, const char *const *names, int n)
{
    for (int k = 0; k < n; k++)
        if (strcmp(word, names[k]) == 0)
            return k;
    return -1;
}

void script_init(script_t *s)
{
    s->cmds = NULL;
    s->count = 0;
    s->cap = 0;
}

void script_free(script_t *s)
{
    free(s->cmds);
    script_init(s);
}

static int parse_float(const char *w, float *out)
{
    char *end;
    errno = 0;
    const double v = strtod(w, &end);
    if (end == w || *end != '\0' || errno == ERANGE || !isfinite(v) || fabs(v) > 1e9)
        return 0;
    *out = (float)v;
    return 1;
}

static argil_err_t push_cmd(script_t *s, const script_cmd_t *c)
{
    if (s->count == s->cap) {
        const size_t cap = s->cap ? s->cap * 2 : 64;
        script_cmd_t *n = realloc(s->cmds, cap * sizeof(*n));
        if (!n)
            return ARGIL_ERR_NOMEM;
        s->cmds = n;
        s->cap = cap;
    }
    s->cmds[s->count++] = *c;
    return ARGIL_OK;
}

/* Writes the message into err and returns the rule code from the parser. */
#define FAIL(code, ...)                                                                        \
    do {                                                                                       \
        snprintf(err, err_len, __VA_ARGS__);                                                   \
        return code;                                                                           \
    } while (0)

/* The host tool's verbs (host/model/host_tool.h): action NAME [strength S], action_shape NAME,
 * mirror none|x|y|z|xy|... */
static script_err_t parse_host_tool(char **w, int n, int lineno, script_cmd_t *c, char *err,
                                    size_t err_len)
{
    const char *op = w[0];
    char list[160] = "";
    const bool act = strcmp(op, "action") == 0;
    if (strcmp(op, "mirror") == 0) {
        const int bits = n == 2 ? host_mirror_from_name(w[1]) : -1;
        if (n != 2)
            FAIL(SCRIPT_ERR_ARGS,
                 "line %d: 'mirror' takes one word: none, or the axes x, y, z (e.g. xz)", lineno);
        if (bits < 0)
            FAIL(SCRIPT_ERR_NAME,
                 "line %d: unknown mirror '%s' (none, x, y, z, or axes together such as xz)",
                 lineno, w[1]);
        c->op = SCRIPT_MIRROR;
        c->arg_int = bits;
        return SCRIPT_OK;
    }
    const int count = act ? HOST_ACT_COUNT : HOST_SHAPE_COUNT;
    for (int k = 0; k < count; k++) {
        strncat(list, act ? host_action_name((host_action_t)k) : host_shape_name((host_shape_t)k),
                sizeof(list) - strlen(list) - 1);
        if (k + 1 < count)
            strncat(list, ", ", sizeof(list) - strlen(list) - 1);
    }
    if (!act) {
        if (n != 2)
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'action_shape' takes one name (%s)", lineno, list);
        const int k = host_shape_from_name(w[1]);
        if (k < 0)
            FAIL(SCRIPT_ERR_NAME, "line %d: unknown action_shape '%s' (%s)", lineno, w[1], list);
        c->op = SCRIPT_ACTION_SHAPE;
        c->arg_int = k;
        return SCRIPT_OK;
    }
    if (n < 2)
        FAIL(SCRIPT_ERR_ARGS,
             "line %d: 'action' takes a name (%s) and optionally strength S (paint and "
             "soft-paint: rgb R G B)",
             lineno, list);
    const int k = host_action_from_name(w[1]);
    if (k < 0)
        FAIL(SCRIPT_ERR_NAME, "line %d: unknown action '%s' (%s)", lineno, w[1], list);
    const bool paints = host_action_paints((host_action_t)k);
    c->op = SCRIPT_ACTION;
    c->arg_int = k;
    c->value = host_action_default_strength((host_action_t)k);
    /* An action's paint colour rides in target_m (r, g, b as 0 … 255). */
    c->target_m = vec3(HOST_PAINT_R, HOST_PAINT_G, HOST_PAINT_B);
    bool have_strength = false, have_rgb = false;
    for (int i = 2; i < n;) {
        if (strcmp(w[i], "strength") == 0) {
            if (i + 1 >= n)
                FAIL(SCRIPT_ERR_ARGS,
                     "line %d: 'action' takes a name (%s) and optionally strength S", lineno, list);
            if (!host_action_has_strength((host_action_t)k))
                FAIL(SCRIPT_ERR_OPTION,
                     "line %d: 'action %s' takes no strength (it acts in full at once)", lineno,
                     w[1]);
            if (have_strength)
                FAIL(SCRIPT_ERR_REPEATED, "line %d: 'strength' given twice", lineno);
            if (!parse_float(w[i + 1], &c->value))
                FAIL(SCRIPT_ERR_NUMBER, "line %d: '%s' is not a number", lineno, w[i + 1]);
            if (!(c->value >= 0.0f && c->value <= HOST_STRENGTH_MAX))
                FAIL(SCRIPT_ERR_RANGE, "line %d: strength must be within 0 … %g, got %s", lineno,
                     (double)HOST_STRENGTH_MAX, w[i + 1]);
            have_strength = true;
            i += 2;
        } else if (strcmp(w[i], "rgb") == 0 && paints) {
            if (have_rgb)
                FAIL(SCRIPT_ERR_REPEATED, "line %d: 'rgb' given twice", lineno);
            if (i + 3 >= n)
                FAIL(SCRIPT_ERR_ARGS, "line %d: 'rgb' takes three whole numbers 0 … 255 (R G B)",
                     lineno);
            float v[3];
            for (int a = 0; a < 3; a++) {
                char *end;
                errno = 0;
                const long x = strtol(w[i + 1 + a], &end, 10);
                if (end == w[i + 1 + a] || *end != '\0' || errno == ERANGE || x < 0 || x > 255)
                    FAIL(SCRIPT_ERR_NUMBER,
                         "line %d: 'rgb' takes three whole numbers 0 … 255, got '%s'", lineno,
                         w[i + 1 + a]);
                v[a] = (float)x;
            }
            c->target_m = vec3(v[0], v[1], v[2]);
            have_rgb = true;
            i += 4;
        } else if (strcmp(w[i], "rgb") == 0) {
            FAIL(SCRIPT_ERR_OPTION,
                 "line %d: 'action %s' takes no colour (rgb is for paint and soft-paint)", lineno,
                 w[1]);
        } else if (paints) {
            FAIL(SCRIPT_ERR_OPTION, "line %d: 'action %s' takes NAME [rgb R G B]%s, not '%s'",
                 lineno, w[1], host_action_has_strength((host_action_t)k) ? " [strength S]" : "",
                 w[i]);
        } else {
            FAIL(SCRIPT_ERR_OPTION, "line %d: 'action' takes NAME [strength S], not '%s'", lineno,
                 w[i]);
        }
    }
    return SCRIPT_OK;
}

/* Parses one line's words into a command; returns 0 for a blank line, 1 for a command. */
static script_err_t parse_line(char **w, int n, int lineno, script_cmd_t *c, char *err,
                               size_t err_len)
{
    c->line = lineno;
    c->arg_int = 0;
    c->value = 0.0f;
    c->radius_m = 0.0f;
    c->target_m = vec3(0, 0, 0);
    const char *op = w[0];
    if (strcmp(op, "tool") == 0 || strcmp(op, "shape") == 0 || strcmp(op, "filter") == 0) {
        const char *const *names = op[0] == 't' ? TOOL_NAMES : op[0] == 's' ? SHAPE_NAMES : FILTER_NAMES;
        const int count = op[0] == 't' ? TOOL_KIND_COUNT : op[0] == 's' ? TOOL_SHAPE_COUNT
                                                                           : BETA_FILTER_COUNT;
        char list[128] = "";
        for (int k = 0; k < count; k++) {
            strncat(list, names[k], sizeof(list) - strlen(list) - 1);
            if (k + 1 < count)
                strncat(list, ", ", sizeof(list) - strlen(list) - 1);
        }
        if (n != 2)
            FAIL(SCRIPT_ERR_ARGS, "line %d: '%s' takes one name (%s)", lineno, op, list);
        const int k = find_name(w[1], names, count);
        if (k < 0)
            FAIL(SCRIPT_ERR_NAME, "line %d: unknown %s '%s' (%s)", lineno, op, w[1], list);
        c->op = op[0] == 't' ? SCRIPT_TOOL : op[0] == 's' ? SCRIPT_SHAPE : SCRIPT_FILTER;
        c->arg_int = k;
        return SCRIPT_OK;
    }
    if (strcmp(op, "axis") == 0) {
        float x, y, z;
        if (n != 4 || !parse_float(w[1], &x) || !parse_float(w[2], &y) || !parse_float(w[3], &z))
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'axis' takes three numbers X Y Z", lineno);
        const float len = sqrtf(x * x + y * y + z * z);
        if (!(len > 1e-6f) || !isfinite(len))
            FAIL(SCRIPT_ERR_AXIS_ZERO, "line %d: 'axis' must not be the zero vector", lineno);
        c->op = SCRIPT_AXIS;
        c->target_m = vec3(x / len, y / len, z / len);
        return SCRIPT_OK;
    }
    if (strcmp(op, "set") == 0) {
        if (n != 3)
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'set' takes a name and a value", lineno);
        for (int k = 0; k < PARAM_COUNT; k++) {
            if (strcmp(w[1], PARAMS[k].name) == 0) {
                if (!parse_float(w[2], &c->value))
                    FAIL(SCRIPT_ERR_NUMBER, "line %d: '%s' is not a number", lineno, w[2]);
                if (c->value < PARAMS[k].min || c->value > PARAMS[k].max)
                    FAIL(SCRIPT_ERR_RANGE, "line %d: %s must be within %g … %g, got %s", lineno,
                         PARAMS[k].name, (double)PARAMS[k].min, (double)PARAMS[k].max, w[2]);
                c->op = SCRIPT_SET;
                c->arg_int = k;
                return SCRIPT_OK;
            }
        }
        FAIL(SCRIPT_ERR_NAME, "line %d: unknown parameter '%s' (see docs/script.md)", lineno, w[1]);
    }
    if (strcmp(op, "move") == 0) {
        float x, y, z, t;
        if (n != 5)
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'move' takes X Y Z (mm, model space) and SECONDS",
                 lineno);
        if (!parse_float(w[1], &x) || !parse_float(w[2], &y) || !parse_float(w[3], &z) ||
            !parse_float(w[4], &t))
            FAIL(SCRIPT_ERR_NUMBER, "line %d: 'move' arguments must be numbers", lineno);
        if (fabsf(x) > 500.0f || fabsf(y) > 500.0f || fabsf(z) > 500.0f)
            FAIL(SCRIPT_ERR_RANGE, "line %d: move target beyond ±500 mm", lineno);
        if (t <= 0.0f || t > SCRIPT_MAX_SECONDS)
            FAIL(SCRIPT_ERR_RANGE, "line %d: move duration must be within 0 … %g s", lineno,
                 (double)SCRIPT_MAX_SECONDS);
        c->op = SCRIPT_MOVE;
        c->target_m = vec3(x * 1e-3f, y * 1e-3f, z * 1e-3f);
        c->value = t;
        return SCRIPT_OK;
    }
    if (strcmp(op, "press") == 0 || strcmp(op, "release") == 0) {
        if (n != 2 || (strcmp(w[1], "1") != 0 && strcmp(w[1], "2") != 0))
            FAIL(SCRIPT_ERR_ARGS, "line %d: '%s' takes a button number, 1 or 2", lineno, op);
        c->op = op[0] == 'p' ? SCRIPT_PRESS : SCRIPT_RELEASE;
        c->arg_int = w[1][0] - '0';
        return SCRIPT_OK;
    }
    if (strcmp(op, "wait") == 0) {
        if (n != 2 || !parse_float(w[1], &c->value))
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'wait' takes SECONDS", lineno);
        if (c->value < 0.0f || c->value > SCRIPT_MAX_SECONDS)
            FAIL(SCRIPT_ERR_RANGE, "line %d: wait must be within 0 … %g s", lineno,
                 (double)SCRIPT_MAX_SECONDS);
        c->op = SCRIPT_WAIT;
        return SCRIPT_OK;
    }
    if (strcmp(op, "paint") == 0) {
        float scale, radius_mm;
        if (n != 5 || (strcmp(w[1], "stiffness") != 0 && strcmp(w[1], "mass") != 0) ||
            strcmp(w[3], "radius") != 0)
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'paint' takes stiffness|mass SCALE radius MM", lineno);
        if (!parse_float(w[2], &scale) || !parse_float(w[4], &radius_mm))
            FAIL(SCRIPT_ERR_NUMBER, "line %d: 'paint' scale and radius must be numbers", lineno);
        if (!(scale >= SCRIPT_PAINT_SCALE_MIN && scale <= SCRIPT_PAINT_SCALE_MAX))
            FAIL(SCRIPT_ERR_RANGE, "line %d: paint scale must be within %g … %g, got %s", lineno,
                 (double)SCRIPT_PAINT_SCALE_MIN, (double)SCRIPT_PAINT_SCALE_MAX, w[2]);
        if (!(radius_mm >= SCRIPT_PAINT_RADIUS_MIN_MM && radius_mm <= SCRIPT_PAINT_RADIUS_MAX_MM))
            FAIL(SCRIPT_ERR_RANGE, "line %d: paint radius must be within %g … %g mm, got %s",
                 lineno, (double)SCRIPT_PAINT_RADIUS_MIN_MM, (double)SCRIPT_PAINT_RADIUS_MAX_MM,
                 w[4]);
        c->op = SCRIPT_PAINT;
        c->arg_int = w[1][0] == 's' ? SCRIPT_PAINT_STIFFNESS : SCRIPT_PAINT_MASS;
        c->value = scale;
        c->radius_m = radius_mm * 1e-3f;
        return SCRIPT_OK;
    }
    if (strcmp(op, "refine") == 0) {
        if (n != 1)
            FAIL(SCRIPT_ERR_ARGS, "line %d: 'refine' takes no arguments", lineno);
        c->op = SCRIPT_REFINE;
        return SCRIPT_OK;
    }
    if (strcmp(op, "undo") == 0 || strcmp(op, "redo") == 0) {
        if (n != 1)
            FAIL(SCRIPT_ERR_ARGS, "line %d: '%s' takes no arguments", lineno, op);
        c->op = op[0] == 'u' ? SCRIPT_UNDO : SCRIPT_REDO;
        return SCRIPT_OK;
    }
    if (strcmp(op, "action") == 0 || strcmp(op, "action_shape") == 0 || strcmp(op, "mirror") == 0)
        return parse_host_tool(w, n, lineno, c, err, err_len);
    FAIL(SCRIPT_ERR_COMMAND,
         "line %d: unknown command '%s' (tool, shape, filter, axis, set, move, press, release, "
         "wait, paint, refine, action, action_shape, mirror, undo, redo)",
         lineno, op);
}

script_err_t script_parse(script_t *s, const char *text, size_t len, char *err, size_t err_len)
{
    char line[512];
    int lineno = 0;
    size_t at = 0;
    float total_s = 0.0f;
    script_free(s);
    while (at < len) {
        size_t end = at;
        while (end < len && text[end] != '\n')
            end++;
        lineno++;
        size_t l = end - at;
        if (l > 0 && text[at + l - 1] == '\r')
            l--;
        if (l >= sizeof(line))
            FAIL(SCRIPT_ERR_LINE_LONG, "line %d: longer than %zu characters", lineno,
                 sizeof(line) - 1);
        memcpy(line, text + at, l);
        line[l] = '\0';
        if (memchr(line, '\0', l) != NULL)
            FAIL(SCRIPT_ERR_LINE_NUL, "line %d: contains a NUL byte", lineno);
        at = end + 1;
        char *w[9];
        /* words at any C-locale space; a word starting with '#' ends the line */
        const int n = (int)tokens_split(line, sizeof(line), TOKENS_C_SPACE, '#', w, 8);
        if (n == 0)
            continue;
        /* At most 5 words, but `action soft-paint rgb R G B strength S` takes 8. */
        if (n > 8 || (n > 5 && strcmp(w[0], "action") != 0))
            FAIL(SCRIPT_ERR_WORDS, "line %d: too many words", lineno);
        script_cmd_t c;
        const script_err_t e = parse_line(w, n, lineno, &c, err, err_len);
        if (e != SCRIPT_OK)
            return e;
        if (c.op == SCRIPT_MOVE || c.op == SCRIPT_WAIT) {
            total_s += c.value;
            if (total_s > SCRIPT_MAX_SECONDS)
                FAIL(SCRIPT_ERR_DURATION, "line %d: the script runs longer than %g s", lineno,
                     (double)SCRIPT_MAX_SECONDS);
        }
        if (s->count >= SCRIPT_MAX_COMMANDS)
            FAIL(SCRIPT_ERR_COMMANDS_MAX, "line %d: more than %u commands", lineno,
                 SCRIPT_MAX_COMMANDS);
        if (push_cmd(s, &c) != ARGIL_OK) {
            snprintf(err, err_len, "line %d: out of memory", lineno);
            return SCRIPT_ERR_NOMEM;
        }
    }
    return SCRIPT_OK;
}

argil_err_t script_err_argil(script_err_t e)
{
    switch (e) {
    case SCRIPT_OK: return ARGIL_OK;
    case SCRIPT_ERR_IO: return ARGIL_ERR_IO;
    case SCRIPT_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

script_err_t script_load(script_t *s, const char *path, char *err, size_t err_len)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_len, "%s: cannot open: %s", path, strerror(errno));
        return SCRIPT_ERR_IO;
    }
    const size_t max = 16u << 20;
    char *buf = malloc(max);
    if (!buf) {
        fclose(f);
        snprintf(err, err_len, "%s: out of memory", path);
        return SCRIPT_ERR_NOMEM;
    }
    const size_t n = fread(buf, 1, max, f);
    const int too_big = n == max && fgetc(f) != EOF;
    const int rd_err = ferror(f);
    fclose(f);
    if (rd_err || too_big) {
        free(buf);
        snprintf(err, err_len, "%s: %s", path, rd_err ? "read error" : "larger than 16 MiB");
        return rd_err ? SCRIPT_ERR_IO : SCRIPT_ERR_FILE_SIZE;
    }
    char msg[256];
    const script_err_t e = script_parse(s, buf, n, msg, sizeof(msg));
    free(buf);
    if (e != SCRIPT_OK)
        snprintf(err, err_len, "%s: %s", path, msg);
    return e;
}

float script_duration_s(const script_t *s)
{
    float t = 0.0f;
    for (size_t i = 0; i < s->count; i++)
        if (s->cmds[i].op == SCRIPT_MOVE || s->cmds[i].op == SCRIPT_WAIT)
            t += s->cmds[i].value;
    return t;
}

int script_first_paint_line(const script_t *s)
{
    for (size_t i = 0; i < s->count; i++)
        if (s->cmds[i].op == SCRIPT_PAINT)
            return s->cmds[i].line;
    return 0;
}

int script_first_host_tool_line(const script_t *s)
{
    for (size_t i = 0; i < s->count; i++)
        if (s->cmds[i].op == SCRIPT_ACTION || s->cmds[i].op == SCRIPT_ACTION_SHAPE ||
            s->cmds[i].op == SCRIPT_MIRROR)
            return s->cmds[i].line;
    return 0;
}

int script_first_history_line(const script_t *s)
{
    for (size_t i = 0; i < s->count; i++)
        if (s->cmds[i].op == SCRIPT_UNDO || s->cmds[i].op == SCRIPT_REDO)
            return s->cmds[i].line;
    return 0;
}

int script_refine_line(const script_t *s, int nth)
{
    int k = 0;
    for (size_t i = 0; i < s->count; i++)
        if (s->cmds[i].op == SCRIPT_REFINE && ++k == nth)
            return s->cmds[i].line;
    return 0;
}

void script_player_init(script_player_t *p, const script_t *s, vec3_t start_m)
{
    memset(p, 0, sizeof(*p));
    p->script = s;
    p->pos_m = start_m;
    p->from_m = start_m;
    p->to_m = start_m;
    p->tool = TOOL_TOUCH;
    p->shape = TOOL_SHAPE_POINT;
    p->filter = BETA_GAUSSIAN;
    p->axis = vec3(0, 0, 1);
    for (int k = 0; k < PARAM_COUNT; k++)
        p->params[k] = PARAMS[k].def;
    host_tool_default(&p->host_tool);
    p->params_changed = 1;
}

/* Applies a command that changes a tool setting (action, action_shape, mirror, tool, shape,
 * filter, axis, set) to the player. */
static void player_set(script_player_t *p, const script_cmd_t *c)
{
    switch (c->op) {
    case SCRIPT_ACTION:
        p->host_tool.action = (host_action_t)c->arg_int;
        p->host_tool.strength = c->value;
        p->host_tool.rgb[0] = (uint8_t)c->target_m.x;
        p->host_tool.rgb[1] = (uint8_t)c->target_m.y;
        p->host_tool.rgb[2] = (uint8_t)c->target_m.z;
        break;
    case SCRIPT_ACTION_SHAPE: p->host_tool.shape = (host_shape_t)c->arg_int; break;
    case SCRIPT_MIRROR: p->host_tool.mirror = (uint32_t)c->arg_int; break;
    case SCRIPT_TOOL: p->tool = c->arg_int; break;
    case SCRIPT_SHAPE: p->shape = c->arg_int; break;
    case SCRIPT_FILTER: p->filter = c->arg_int; break;
    case SCRIPT_AXIS: p->axis = c->target_m; break;
    case SCRIPT_SET: p->params[c->arg_int] = c->value; break;
    default: break;
    }
}

int script_player_step(script_player_t *p, float dt_s)
{
    /* Start commands until one takes time (bounded by the script's length); a paint waits for
     * the next step when this one already handed over SCRIPT_PAINTS_PENDING_MAX. The paints of
     * the previous step were the caller's to apply before this call. */
    p->paints_pending = 0;
    p->refines_pending = 0;
    while (!p->active && !p->history_op && p->next < p->script->count) {
        if (p->script->cmds[p->next].op == SCRIPT_PAINT &&
            p->paints_pending >= (int)SCRIPT_PAINTS_PENDING_MAX)
            return 0;
        const script_cmd_t *c = &p->script->cmds[p->next++];
        switch (c->op) {
        case SCRIPT_PAINT: {
            script_paint_t *pt = &p->paints[p->paints_pending++];
            pt->channel = c->arg_int;
            pt->scale = c->value;
            pt->radius_m = c->radius_m;
            pt->pos_m = p->pos_m;
            break;
        }
        case SCRIPT_REFINE:
            p->refines_pending++;
            break;
        case SCRIPT_UNDO:
        case SCRIPT_REDO:
            /* Waits (the hand holding still) until the session did it or refused it. */
            p->history_op = c->op;
            p->history_line = c->line;
            break;
        case SCRIPT_ACTION:
        case SCRIPT_ACTION_SHAPE:
        case SCRIPT_MIRROR:
        case SCRIPT_TOOL:
        case SCRIPT_SHAPE:
        case SCRIPT_FILTER:
        case SCRIPT_AXIS:
        case SCRIPT_SET:
            player_set(p, c);
            p->params_changed = 1;
            break;
        case SCRIPT_PRESS:
            p->buttons |= 1 << (c->arg_int - 1);
            break;
        case SCRIPT_RELEASE:
            p->buttons &= ~(1 << (c->arg_int - 1));
            break;
        case SCRIPT_MOVE:
        case SCRIPT_WAIT: /* a wait is a move to where the hand is */
            p->active = 1;
            p->elapsed_s = 0.0f;
            p->duration_s = c->value;
            p->from_m = p->pos_m;
            p->to_m = c->op == SCRIPT_MOVE ? c->target_m : p->pos_m;
            break;
        }
    }
    if (!p->active) {
        p->vel_m_s = vec3(0, 0, 0);
        return p->history_op ? 0 : 1;
    }
    p->elapsed_s += dt_s;
    /* Half a step of slack so float rounding never adds a tick to a move. */
    float t = p->elapsed_s / p->duration_s;
    if (t >= 1.0f || p->elapsed_s >= p->duration_s - 0.5f * dt_s)
        t = 1.0f;
    const vec3_t prev = p->pos_m;
    p->pos_m = vec3_add(p->from_m, vec3_scale(vec3_sub(p->to_m, p->from_m), t));
    p->vel_m_s = vec3_scale(vec3_sub(p->pos_m, prev), 1.0f / dt_s);
    if (t >= 1.0f)
        p->active = 0;
    return 0;
}
