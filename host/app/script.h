/* Session scripts: a line-based description of what the virtual hand does (docs/script.md). */
#ifndef ARGIL_SCRIPT_H
#define ARGIL_SCRIPT_H

#include <stddef.h>
#include <stdint.h>

#include "host/model/host_tool.h"
#include "shared/argil_err.h"
#include "shared/vec3.h"

typedef enum {
    SCRIPT_TOOL,      /* tool touch|push|pull|carve|probe|rope */
    SCRIPT_SHAPE,     /* shape point|curve|area */
    SCRIPT_FILTER,    /* filter constant|gaussian|spherical|cylindrical|conical */
    SCRIPT_AXIS,      /* axis X Y Z: the tool axis (curve and area orientation) */
    SCRIPT_SET,       /* set NAME VALUE */
    SCRIPT_MOVE,      /* move X_MM Y_MM Z_MM SECONDS */
    SCRIPT_PRESS,     /* press 1|2 */
    SCRIPT_RELEASE,   /* release 1|2 */
    SCRIPT_WAIT,      /* wait SECONDS */
    SCRIPT_PAINT,     /* paint stiffness|mass SCALE radius MM: at the hand (B-spline solve) */
    SCRIPT_REFINE,    /* refine: a knot in every span of the B-spline model (R halves) */
    SCRIPT_ACTION,    /* action NAME [strength S]: what carve does on the host (host_tool.h) */
    SCRIPT_ACTION_SHAPE, /* action_shape sphere|box|cylinder|torus */
    SCRIPT_MIRROR,    /* mirror none|x|y|z|xy|...: the host tool's mirror planes */
    SCRIPT_UNDO,      /* undo: the last stroke (host/app/session_undo.h); the player waits */
    SCRIPT_REDO       /* redo: the stroke undone last */
} script_op_t;

typedef enum { SCRIPT_PAINT_STIFFNESS = 0, SCRIPT_PAINT_MASS } script_paint_ch_t;
#define SCRIPT_PAINT_SCALE_MIN 0.05f
#define SCRIPT_PAINT_SCALE_MAX 50.0f
#define SCRIPT_PAINT_RADIUS_MIN_MM 0.5f
#define SCRIPT_PAINT_RADIUS_MAX_MM 100.0f
#define SCRIPT_PAINTS_PENDING_MAX 8  /* paints one player step hands over at most */

typedef enum {
    PARAM_RADIUS_MM,
    PARAM_ALPHA,
    PARAM_STIFFNESS_N_PER_MM,
    PARAM_MAX_FORCE_N,
    PARAM_LENGTH_MM,
    PARAM_YIELD_FORCE_N,
    PARAM_FRICTION,
    PARAM_ISO,
    PARAM_PROBE_GAIN,
    PARAM_ROPE_STIFFNESS_N_PER_MM,
    PARAM_CLAY_STIFFNESS,
    PARAM_CLAY_DAMPING,
    PARAM_PLASTIC_RATE_HZ,
    PARAM_COUNT
} script_param_t;

typedef struct {
    script_op_t op;
    int line;                 /* 1-based line in the file */
    int arg_int;              /* tool kind, shape, filter, button number, or param id */
    vec3_t target_m;          /* move: model space; axis: unit vector */
    float value;              /* set: value; move/wait: seconds; paint: scale */
    float radius_m;           /* paint */
} script_cmd_t;

/* A material paint the player reached, for the session to apply at the hand's position. */
typedef struct {
    int channel;              /* script_paint_ch_t */
    float scale;
    float radius_m;
    vec3_t pos_m;             /* model space */
} script_paint_t;

typedef struct {
    script_cmd_t *cmds;
    size_t count;
    size_t cap;
} script_t;

#define SCRIPT_MAX_COMMANDS 100000u
#define SCRIPT_MAX_SECONDS 3600.0f

void script_init(script_t *s);
void script_free(script_t *s);

/* What the script readers return: SCRIPT_OK, a failure outside the text (system call, memory),
 * or the rule a line broke. */
typedef enum {
    SCRIPT_OK = 0,
    SCRIPT_ERR_IO = -1,           /* the file cannot be opened or read */
    SCRIPT_ERR_NOMEM = -2,        /* an allocation failed */
    SCRIPT_ERR_FILE_SIZE = -3,    /* a file larger than 16 MiB */
    SCRIPT_ERR_LINE_LONG = -4,    /* a line longer than 511 characters */
    SCRIPT_ERR_LINE_NUL = -5,     /* a line holds a NUL byte */
    SCRIPT_ERR_WORDS = -6,        /* more words than any command takes */
    SCRIPT_ERR_COMMAND = -7,      /* an unknown command */
    SCRIPT_ERR_ARGS = -8,         /* a command given the wrong number or kind of words */
    SCRIPT_ERR_NAME = -9,         /* an unknown tool, shape, filter, parameter, action,
                                   * action_shape or mirror */
    SCRIPT_ERR_NUMBER = -10,      /* a word that is not a number (rgb: a whole number 0..255) */
    SCRIPT_ERR_RANGE = -11,       /* a number out of its range (parameter, move target or
                                   * duration, wait, paint scale or radius, strength) */
    SCRIPT_ERR_AXIS_ZERO = -12,   /* 'axis' the zero vector */
    SCRIPT_ERR_OPTION = -13,      /* an option the action does not take */
    SCRIPT_ERR_REPEATED = -14,    /* 'strength' or 'rgb' given twice */
    SCRIPT_ERR_DURATION = -15,    /* moves and waits longer than SCRIPT_MAX_SECONDS in all */
    SCRIPT_ERR_COMMANDS_MAX = -16 /* more than SCRIPT_MAX_COMMANDS commands */
} script_err_t;

/* The argil_err_t a command reports for e: IO and NOMEM as themselves, every rule (and a file too
 * large) ARGIL_ERR_PARSE. */
argil_err_t script_err_argil(script_err_t e);

/* Parses script text: the rule a line broke, with "line N: what is wrong" in err; NOMEM. Text
 * need not be NUL-terminated. */
script_err_t script_parse(script_t *s, const char *text, size_t len, char *err, size_t err_len);

/* Reads and parses a file; err names the file and line. */
script_err_t script_load(script_t *s, const char *path, char *err, size_t err_len);

/* The name a param is written with in scripts, and its default value. */
const char *script_param_name(script_param_t p);
float script_param_default(script_param_t p);

/* Total duration (s) of the moves and waits. */
float script_duration_s(const script_t *s);

/* Plays a script tick by tick: where the hand is and which buttons it holds. */
typedef struct {
    const script_t *script;
    size_t next;              /* next command to start */
    int active;               /* 1 while a move or wait runs */
    float elapsed_s;          /* in the running move/wait */
    float duration_s;
    vec3_t from_m, to_m;
    vec3_t pos_m;             /* hand target, model space */
    vec3_t vel_m_s;
    int buttons;              /* bit 0: button 1, bit 1: button 2 */
    int tool;                 /* tool_kind_t */
    int shape;                /* tool_shape_t */
    int filter;               /* beta_filter_t */
    vec3_t axis;              /* unit */
    float params[PARAM_COUNT];
    int params_changed;       /* set when tool or a param changed since the last call */
    script_paint_t paints[SCRIPT_PAINTS_PENDING_MAX]; /* reached by the last step: the */
    int paints_pending;       /* caller applies them before the next step (which drops them) */
    int refines_pending;      /* refine commands reached by the last step (the same rule) */
    host_tool_t host_tool;    /* action, action_shape, mirror (sets params_changed) */
    int history_op;           /* an undo (SCRIPT_UNDO) or redo reached: the player holds still
                               * until the caller clears it (done or refused) */
    int history_line;         /* its line */
} script_player_t;

/* The first paint command's line, or 0 when the script has none. */
int script_first_paint_line(const script_t *s);

/* The first action, action_shape or mirror command's line, or 0 when the script has none. */
int script_first_host_tool_line(const script_t *s);

/* The first undo or redo command's line, or 0 when the script has none. */
int script_first_history_line(const script_t *s);

/* The line of the nth (1-based) refine command, or 0 when the script has fewer. */
int script_refine_line(const script_t *s, int nth);

void script_player_init(script_player_t *p, const script_t *s, vec3_t start_m);
/* Advances by dt_s; returns 0 while running, 1 once every command has finished. */
int script_player_step(script_player_t *p, float dt_s);

#endif
