/* Scenario text → scenario_t (see scenario.h and docs/sim.md). Every refusal names its line. */
#include "scenario.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "shared/tokens.h"

#define WORDS_MAX 12u
#define WORD_LEN 40u

typedef struct {
    uint32_t n;
    char *w[WORDS_MAX];           /* into line; "" past n */
    char line[SCN_LINE_MAX + 1u]; /* the line, cut into words in place */
} words_t;

static const char *const action_names[SCN_ACTION_COUNT] = {
    "hand", "hand release", "button", "estop", "drive_fault_line", "emcy", "heartbeat",
    "encoder_jump", "can_drop", "can_delay", "bus_off", "bus_restart", "link lost",
    "link restore", "link delay", "link duplicate", "link reorder", "link garbage",
    "link nan_tool", "stranger", "overrun", "rearm"};

static const char *const stranger_names[SCN_STRANGER_COUNT] = {"replay", "forge", "flood"};

const char *scenario_stranger_name(scn_stranger_t k)
{
    return (unsigned)k < SCN_STRANGER_COUNT ? stranger_names[k] : "?";
}

static const char *const expect_names[SCN_EXP_COUNT] = {
    "torque_zero", "force_zero", "quick_stop", "fault", "enabled", "torque_nonzero",
    "no_torque_frames", "running", "safe", "heartbeat_supervised"};

const char *scenario_action_name(scn_action_t a)
{
    return (unsigned)a < SCN_ACTION_COUNT ? action_names[a] : "?";
}

const char *scenario_expect_name(scn_expect_kind_t k)
{
    return (unsigned)k < SCN_EXP_COUNT ? expect_names[k] : "?";
}

bool scenario_action_is_host_side(scn_action_t a)
{
    return a >= SCN_LINK_LOST && a <= SCN_REARM;
}

__attribute__((format(printf, 4, 5))) static scn_err_t
fail(scn_error_t *err, scn_err_t code, uint32_t line, const char *fmt, ...)
{
    err->code = code;
    err->line = line;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof(err->msg), fmt, ap);
    va_end(ap);
    return code;
}

/* Splits a line (len <= SCN_LINE_MAX) into blank-separated words up to a '#'; false when a word
 * or the count is too large. */
static bool split(const char *p, size_t len, words_t *w)
{
    memcpy(w->line, p, len);
    w->line[len] = '\0';
    char *hash = strchr(w->line, '#');
    if (hash != NULL)
        *hash = '\0';
    const size_t n = tokens_split(w->line, len + 1u, TOKENS_SPACE_TAB, '\0', w->w, WORDS_MAX);
    w->n = (uint32_t)(n < WORDS_MAX ? n : WORDS_MAX);
    for (size_t k = w->n; k < WORDS_MAX; k++)
        w->w[k] = &w->line[len];
    if (n > WORDS_MAX)
        return false;
    for (size_t k = 0; k < n; k++)
        if (strlen(w->w[k]) >= WORD_LEN)
            return false;
    return true;
}

/* A decimal number with at most 6 fraction digits, as an integer count of millionths; the
 * rest of the word is returned in *rest (the unit). */
static bool fixed6(const char *s, int64_t *out, const char **rest)
{
    bool neg = false;
    if (*s == '-' || *s == '+')
        neg = *s++ == '-';
    int64_t whole = 0, frac = 0;
    int digits = 0, fdigits = 0;
    while (*s >= '0' && *s <= '9') {
        if (whole > 100000000LL)
            return false;
        whole = whole * 10 + (*s++ - '0');
        digits++;
    }
    if (*s == '.') {
        s++;
        while (*s >= '0' && *s <= '9') {
            if (fdigits == 6)
                return false;
            frac = frac * 10 + (*s++ - '0');
            fdigits++;
        }
    }
    if (digits == 0 && fdigits == 0)
        return false;
    for (int k = fdigits; k < 6; k++)
        frac *= 10;
    *out = (whole * 1000000LL + frac) * (neg ? -1 : 1);
    *rest = s;
    return true;
}

/* A time in seconds (no unit): ≥ 0, at most an hour. */
static bool parse_time(const char *s, int64_t *us)
{
    const char *rest;
    return fixed6(s, us, &rest) && *rest == '\0' && *us >= 0 && *us <= SCN_TIME_MAX_US &&
           s[0] != '-' && s[0] != '+';
}

/* A duration with its unit: 500us, 10ms, 1.5s; ≥ 0, at most an hour, whole microseconds. */
static bool parse_duration(const char *s, int64_t *us)
{
    const char *unit;
    int64_t v;
    if (s[0] == '-' || s[0] == '+' || !fixed6(s, &v, &unit))
        return false;
    int64_t scale; /* v is in millionths of the unit */
    if (strcmp(unit, "us") == 0)
        scale = 1;
    else if (strcmp(unit, "ms") == 0)
        scale = 1000;
    else if (strcmp(unit, "s") == 0)
        scale = 1000000;
    else
        return false;
    if (v > SCN_TIME_MAX_US)
        return false;
    if ((v * scale) % 1000000 != 0)
        return false; /* finer than a microsecond */
    *us = v * scale / 1000000;
    return *us <= SCN_TIME_MAX_US;
}

/* An integer in [lo, hi]. */
static bool parse_int(const char *s, int64_t lo, int64_t hi, int32_t *out)
{
    int64_t v;
    const char *rest;
    if (!fixed6(s, &v, &rest) || *rest != '\0' || v % 1000000 != 0 || strchr(s, '.'))
        return false;
    v /= 1000000;
    if (v < lo || v > hi)
        return false;
    *out = (int32_t)v;
    return true;
}

static scn_err_t parse_node(const words_t *w, uint32_t at, uint32_t line, int32_t *node,
                            scn_error_t *err)
{
    if (at >= w->n)
        return fail(err, SCN_ERR_ARG, line, "missing drive node (1-3)");
    if (!parse_int(w->w[at], -1000000, 1000000, node))
        return fail(err, SCN_ERR_ARG, line, "'%s' is not a drive node (1-3)", w->w[at]);
    if (*node < 1 || *node > 3)
        return fail(err, SCN_ERR_NODE, line, "drive node '%s' is outside 1-3", w->w[at]);
    return SCN_OK;
}

#define TRY(x)                      \
    do {                            \
        const scn_err_t e_ = (x);   \
        if (e_ != SCN_OK)           \
            return e_;              \
    } while (0)

/* Picks one of two words: sets *v to 1 for yes, 0 for no. */
static scn_err_t parse_choice(const words_t *w, uint32_t at, uint32_t line, const char *yes,
                              const char *no, int32_t *v, scn_error_t *err)
{
    if (at >= w->n)
        return fail(err, SCN_ERR_ARG, line, "missing argument");
    if (strcmp(w->w[at], yes) == 0)
        *v = 1;
    else if (strcmp(w->w[at], no) == 0)
        *v = 0;
    else
        return fail(err, SCN_ERR_ARG, line, "unexpected '%s'", w->w[at]);
    return SCN_OK;
}

/* Parses the action words from w->w[at] into st; *used is one past the last word taken. */
static scn_err_t parse_action(const words_t *w, uint32_t at, uint32_t line, scn_step_t *st,
                              uint32_t *used, scn_error_t *err)
{
    if (at >= w->n)
        return fail(err, SCN_ERR_ACTION, line, "missing action after the time");
    const char *a = w->w[at];
    const char *next = at + 1 < w->n ? w->w[at + 1] : "";
    *used = at + 1;
    if (strcmp(a, "hand") == 0) {
        if (strcmp(next, "release") == 0) {
            st->action = SCN_HAND_RELEASE;
            *used = at + 2;
            return SCN_OK;
        }
        st->action = SCN_HAND;
        for (uint32_t k = 0; k < 3; k++) {
            int64_t v;
            const char *rest;
            if (at + 1 + k >= w->n)
                return fail(err, SCN_ERR_ARG, line, "hand needs X Y Z in mm");
            if (!fixed6(w->w[at + 1 + k], &v, &rest) || *rest != '\0' || v > 200000000LL ||
                v < -200000000LL)
                return fail(err, SCN_ERR_ARG, line, "hand coordinate '%s' is not mm within ±200",
                            w->w[at + 1 + k]);
            st->p_mm[k] = (float)((double)v * 1e-6);
        }
        *used = at + 4;
        st->dur_us = 0;
        if (*used < w->n && strcmp(w->w[*used], "over") == 0) {
            if (*used + 1 >= w->n || !parse_duration(w->w[*used + 1], &st->dur_us))
                return fail(err, SCN_ERR_DURATION, line, "'over' needs a duration like 500ms");
            *used += 2;
        }
        return SCN_OK;
    }
    if (strcmp(a, "button") == 0) {
        st->action = SCN_BUTTON;
        if (at + 1 >= w->n || !parse_int(next, 1, 2, &st->a))
            return fail(err, SCN_ERR_ARG, line, "button needs 1 or 2, got '%s'", next);
        TRY(parse_choice(w, at + 2, line, "down", "up", &st->b, err));
        *used = at + 3;
        return SCN_OK;
    }
    if (strcmp(a, "estop") == 0) {
        st->action = SCN_ESTOP;
        TRY(parse_choice(w, at + 1, line, "press", "release", &st->a, err));
        *used = at + 2;
        return SCN_OK;
    }
    if (strcmp(a, "drive_fault_line") == 0) {
        st->action = SCN_DRIVE_FAULT_LINE;
        TRY(parse_choice(w, at + 1, line, "low", "high", &st->a, err));
        *used = at + 2;
        return SCN_OK;
    }
    if (strcmp(a, "emcy") == 0) {
        st->action = SCN_EMCY;
        TRY(parse_node(w, at + 1, line, &st->a, err));
        *used = at + 2;
        return SCN_OK;
    }
    if (strcmp(a, "heartbeat") == 0) {
        st->action = SCN_HEARTBEAT;
        TRY(parse_node(w, at + 1, line, &st->a, err));
        TRY(parse_choice(w, at + 2, line, "resume", "stop", &st->b, err));
        *used = at + 3;
        return SCN_OK;
    }
    if (strcmp(a, "encoder_jump") == 0) {
        st->action = SCN_ENCODER_JUMP;
        TRY(parse_node(w, at + 1, line, &st->a, err));
        if (at + 2 >= w->n || !parse_int(w->w[at + 2], -1000000, 1000000, &st->b) || st->b == 0)
            return fail(err, SCN_ERR_ARG, line,
                        "encoder_jump needs counts, non-zero within ±1000000");
        *used = at + 3;
        return SCN_OK;
    }
    if (strcmp(a, "can_drop") == 0) {
        st->action = SCN_CAN_DROP;
        int64_t v;
        const char *rest;
        if (at + 1 >= w->n || !fixed6(next, &v, &rest) || strcmp(rest, "%") != 0 || v < 0 ||
            v > 100000000LL || next[0] == '-' || next[0] == '+')
            return fail(err, SCN_ERR_ARG, line, "can_drop needs a percentage 0%%-100%%, got '%s'",
                        next);
        st->ppm = (uint32_t)(v / 100); /* millionths of a percent → parts per million */
        st->seed = 1;
        *used = at + 2;
        if (*used < w->n && strcmp(w->w[*used], "seed") == 0) {
            int32_t seed;
            if (*used + 1 >= w->n || !parse_int(w->w[*used + 1], 1, 2147483647, &seed))
                return fail(err, SCN_ERR_ARG, line, "seed needs an integer 1-2147483647");
            st->seed = (uint32_t)seed;
            *used += 2;
        }
        return SCN_OK;
    }
    if (strcmp(a, "can_delay") == 0) {
        st->action = SCN_CAN_DELAY;
        if (at + 1 >= w->n || !parse_duration(next, &st->dur_us) || st->dur_us > 1000000)
            return fail(err, SCN_ERR_DURATION, line,
                        "can_delay needs a duration up to 1s like 500us, got '%s'", next);
        *used = at + 2;
        return SCN_OK;
    }
    if (strcmp(a, "bus_off") == 0) {
        st->action = SCN_BUS_OFF;
        return SCN_OK;
    }
    if (strcmp(a, "bus_restart") == 0) {
        st->action = SCN_BUS_RESTART;
        return SCN_OK;
    }
    if (strcmp(a, "rearm") == 0) {
        st->action = SCN_REARM;
        return SCN_OK;
    }
    if (strcmp(a, "overrun") == 0) {
        st->action = SCN_OVERRUN;
        if (at + 1 >= w->n || !parse_int(next, 1, 1000, &st->a))
            return fail(err, SCN_ERR_ARG, line, "overrun needs a tick count 1-1000, got '%s'",
                        next);
        *used = at + 2;
        return SCN_OK;
    }
    if (strcmp(a, "stranger") == 0) {
        st->action = SCN_STRANGER;
        st->a = -1;
        for (int k = 0; k < (int)SCN_STRANGER_COUNT; k++)
            if (strcmp(next, stranger_names[k]) == 0)
                st->a = k;
        if (st->a < 0)
            return fail(err, SCN_ERR_ARG, line,
                        "stranger needs replay, forge or flood, got '%s'", next);
        if (at + 3 >= w->n || strcmp(w->w[at + 2], "for") != 0 ||
            !parse_duration(w->w[at + 3], &st->dur_us) || st->dur_us > 10000000)
            return fail(err, SCN_ERR_DURATION, line,
                        "stranger %s needs 'for D' with D up to 10s, like 'for 500ms'", next);
        *used = at + 4;
        return SCN_OK;
    }
    if (strcmp(a, "link") == 0) {
        *used = at + 2;
        if (strcmp(next, "lost") == 0) {
            st->action = SCN_LINK_LOST;
        } else if (strcmp(next, "restore") == 0) {
            st->action = SCN_LINK_RESTORE;
        } else if (strcmp(next, "nan_tool") == 0) {
            st->action = SCN_LINK_NAN;
        } else if (strcmp(next, "delay") == 0) {
            st->action = SCN_LINK_DELAY;
            if (at + 2 >= w->n || !parse_duration(w->w[at + 2], &st->dur_us) ||
                st->dur_us > 1000000)
                return fail(err, SCN_ERR_DURATION, line,
                            "link delay needs a duration up to 1s like 30ms");
            *used = at + 3;
        } else if (strcmp(next, "duplicate") == 0 || strcmp(next, "reorder") == 0 ||
                   strcmp(next, "garbage") == 0) {
            st->action = next[0] == 'd' ? SCN_LINK_DUPLICATE
                         : next[0] == 'r' ? SCN_LINK_REORDER
                                          : SCN_LINK_GARBAGE;
            if (at + 2 >= w->n || !parse_int(w->w[at + 2], 1, 1024, &st->a))
                return fail(err, SCN_ERR_ARG, line, "link %s needs a count 1-1024", next);
            *used = at + 3;
        } else {
            return fail(err, SCN_ERR_ACTION, line, "unknown link fault '%s'", next);
        }
        return SCN_OK;
    }
    return fail(err, SCN_ERR_ACTION, line, "unknown action '%s'", a);
}

static scn_err_t parse_expect(const words_t *w, uint32_t line, scn_expect_t *e,
                              scn_error_t *err)
{
    if (w->n < 2 || strcmp(w->w[1], "at") != 0)
        return fail(err, SCN_ERR_EXPECT, line, "expected 'expect at T KIND ...'");
    if (w->n < 3 || !parse_time(w->w[2], &e->t_us))
        return fail(err, SCN_ERR_TIME, line, "'%s' is not a time in seconds",
                    w->n < 3 ? "" : w->w[2]);
    if (w->n < 4)
        return fail(err, SCN_ERR_EXPECT, line, "missing expectation kind");
    e->kind = SCN_EXP_COUNT;
    for (int k = 0; k < (int)SCN_EXP_COUNT; k++)
        if (strcmp(w->w[3], expect_names[k]) == 0)
            e->kind = (scn_expect_kind_t)k;
    if (e->kind == SCN_EXP_COUNT)
        return fail(err, SCN_ERR_EXPECT, line, "unknown expectation '%s'", w->w[3]);
    const bool needs_until = e->kind == SCN_EXP_NO_TORQUE_FRAMES || e->kind == SCN_EXP_RUNNING ||
                             e->kind == SCN_EXP_SAFE || e->kind == SCN_EXP_HEARTBEAT_SUPERVISED;
    if (w->n < 6)
        return fail(err, SCN_ERR_EXPECT, line, "'%s' needs 'within D' or 'until X'", w->w[3]);
    e->within_us = 0;
    e->until = SCN_UNTIL_NONE;
    e->until_us = 0;
    if (strcmp(w->w[4], "within") == 0) {
        if (needs_until)
            return fail(err, SCN_ERR_EXPECT, line, "'%s' takes 'until', not 'within'", w->w[3]);
        if (!parse_duration(w->w[5], &e->within_us))
            return fail(err, SCN_ERR_DURATION, line, "'%s' is not a duration like 10ms", w->w[5]);
    } else if (strcmp(w->w[4], "until") == 0) {
        if (strcmp(w->w[5], "rearm") == 0) {
            e->until = SCN_UNTIL_REARM;
        } else if (strcmp(w->w[5], "end") == 0) {
            e->until = SCN_UNTIL_END;
        } else if (parse_time(w->w[5], &e->until_us) && e->until_us > e->t_us) {
            e->until = SCN_UNTIL_TIME;
        } else {
            return fail(err, SCN_ERR_EXPECT, line,
                        "'until %s': expected rearm, end or a later time", w->w[5]);
        }
        if (!needs_until && e->kind != SCN_EXP_TORQUE_ZERO && e->kind != SCN_EXP_FORCE_ZERO &&
            e->kind != SCN_EXP_FAULT)
            return fail(err, SCN_ERR_EXPECT, line, "'%s' takes 'within', not 'until'", w->w[3]);
    } else {
        return fail(err, SCN_ERR_EXPECT, line, "expected 'within' or 'until', got '%s'", w->w[4]);
    }
    if (w->n > 6)
        return fail(err, SCN_ERR_TRAILING, line, "unexpected '%s' at the end", w->w[6]);
    return SCN_OK;
}

static void keep_text(char *dst, const char *p, size_t len)
{
    while (len > 0 && (*p == ' ' || *p == '\t')) {
        p++;
        len--;
    }
    const size_t n = len < SCN_TEXT_LEN - 1 ? len : SCN_TEXT_LEN - 1;
    memcpy(dst, p, n);
    dst[n] = '\0';
}

scn_err_t scenario_parse(scenario_t *s, const char *text, size_t len, scn_error_t *err)
{
    memset(s, 0, sizeof(*s));
    memset(err, 0, sizeof(*err));
    memcpy(s->name, "scenario", 9);
    s->duration_us = -1;
    int64_t last_at = 0;
    uint32_t line = 0, dur_line = 0;
    size_t pos = 0;
    words_t w;
    while (pos < len) {
        line++;
        size_t end = pos;
        while (end < len && text[end] != '\n')
            end++;
        size_t llen = end - pos;
        if (llen > 0 && text[pos + llen - 1] == '\r')
            llen--;
        const char *p = text + pos;
        pos = end + 1;
        if (llen > SCN_LINE_MAX)
            return fail(err, SCN_ERR_LINE_LONG, line, "line longer than 200 characters");
        bool comment = false; /* a comment may hold UTF-8 text; the rest is ASCII */
        for (size_t i = 0; i < llen; i++) {
            const unsigned char ch = (unsigned char)p[i];
            comment = comment || ch == '#';
            if ((ch < 0x20 && ch != '\t') || ch == 0x7F || (ch > 0x7F && !comment))
                return fail(err, SCN_ERR_CHAR, line, "control or non-ASCII byte");
        }
        if (!split(p, llen, &w))
            return fail(err, SCN_ERR_ARG, line, "too many words or a word over 39 characters");
        if (w.n == 0)
            continue;
        if (strcmp(w.w[0], "name") == 0) {
            if (w.n != 2 || strlen(w.w[1]) >= SCN_NAME_LEN)
                return fail(err, SCN_ERR_ARG, line, "name needs one word under 32 characters");
            memcpy(s->name, w.w[1], strlen(w.w[1]) + 1);
        } else if (strcmp(w.w[0], "duration") == 0) {
            if (dur_line != 0)
                return fail(err, SCN_ERR_NO_DURATION, line, "second 'duration' line");
            if (w.n < 2 || !parse_duration(w.w[1], &s->duration_us) || s->duration_us == 0)
                return fail(err, SCN_ERR_DURATION, line, "duration needs a time like 5s, got '%s'",
                            w.n < 2 ? "" : w.w[1]);
            if (w.n > 2)
                return fail(err, SCN_ERR_TRAILING, line, "unexpected '%s' at the end", w.w[2]);
            dur_line = line;
        } else if (strcmp(w.w[0], "at") == 0) {
            if (s->n_steps == SCN_STEPS_MAX)
                return fail(err, SCN_ERR_TOO_MANY, line, "more than 64 steps");
            scn_step_t *st = &s->step[s->n_steps];
            st->line = line;
            if (w.n < 2 || !parse_time(w.w[1], &st->t_us))
                return fail(err, SCN_ERR_TIME, line, "'%s' is not a time in seconds",
                            w.n < 2 ? "" : w.w[1]);
            if (st->t_us < last_at)
                return fail(err, SCN_ERR_ORDER, line, "time %s is before the previous step",
                            w.w[1]);
            uint32_t used = 0;
            TRY(parse_action(&w, 2, line, st, &used, err));
            if (used < w.n)
                return fail(err, SCN_ERR_TRAILING, line, "unexpected '%s' at the end", w.w[used]);
            keep_text(st->text, p, llen);
            last_at = st->t_us;
            s->n_steps++;
        } else if (strcmp(w.w[0], "expect") == 0) {
            if (s->n_expects == SCN_EXPECTS_MAX)
                return fail(err, SCN_ERR_TOO_MANY, line, "more than 32 expectations");
            scn_expect_t *e = &s->expect[s->n_expects];
            e->line = line;
            TRY(parse_expect(&w, line, e, err));
            keep_text(e->text, p, llen);
            s->n_expects++;
        } else {
            return fail(err, SCN_ERR_KEYWORD, line,
                        "unknown keyword '%s' (name, duration, at, expect)", w.w[0]);
        }
    }
    if (dur_line == 0)
        return fail(err, SCN_ERR_NO_DURATION, line == 0 ? 1 : line,
                    "no 'duration' line");
    for (uint32_t i = 0; i < s->n_steps; i++)
        if (s->step[i].t_us > s->duration_us)
            return fail(err, SCN_ERR_BEYOND, s->step[i].line, "step after the duration");
    for (uint32_t i = 0; i < s->n_expects; i++) {
        const scn_expect_t *e = &s->expect[i];
        if (e->t_us > s->duration_us || (e->until == SCN_UNTIL_TIME && e->until_us > s->duration_us))
            return fail(err, SCN_ERR_BEYOND, e->line, "expectation after the duration");
    }
    return SCN_OK;
}

scn_err_t scenario_load(scenario_t *s, const char *path, scn_error_t *err)
{
    static char buf[65537];
    memset(err, 0, sizeof(*err));
    FILE *f = fopen(path, "rb");
    if (f == NULL)
        return fail(err, SCN_ERR_IO, 0, "cannot open the file (%s)", strerror(errno));
    const size_t n = fread(buf, 1, sizeof(buf), f);
    const bool bad = ferror(f) != 0;
    fclose(f);
    if (bad)
        return fail(err, SCN_ERR_IO, 0, "read error");
    if (n == sizeof(buf))
        return fail(err, SCN_ERR_IO, 0, "file larger than 64 KiB");
    return scenario_parse(s, buf, n, err);
}

int64_t scenario_until_us(const scenario_t *s, const scn_expect_t *e)
{
    switch (e->until) {
    case SCN_UNTIL_TIME:
        return e->until_us;
    case SCN_UNTIL_END:
        return s->duration_us;
    default: /* until rearm, and the hold window of a `within` */
        for (uint32_t i = 0; i < s->n_steps; i++)
            if (s->step[i].action == SCN_REARM && s->step[i].t_us > e->t_us)
                return s->step[i].t_us;
        return s->duration_us;
    }
}
