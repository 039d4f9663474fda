/* A small reader for the parts of a Vector DBC file that say how to decode a frame: the BO_
 * (message) and SG_ (signal) lines, and a candump log line. Every other DBC section is skipped.
 * Used by tests/unit/test_dbc.c (firmware/argil.dbc against shared/canopen.c) and fuzzed by
 * tests/fuzz/fuzz_dbc.c. Header-only: both are single-file programs. */
#ifndef ARGIL_TEST_DBC_PARSER_H
#define ARGIL_TEST_DBC_PARSER_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "shared/canopen.h"
#include "shared/hex_digit.h"

#define DBC_MESSAGES_MAX 64u
#define DBC_SIGNALS_MAX 16u
#define DBC_NAME_MAX 48u
#define DBC_UNIT_MAX 16u

/* Which rule the input broke. */
typedef enum {
    DBC_OK = 0,
    DBC_ERR_SYNTAX = -1,      /* a token is missing or malformed */
    DBC_ERR_RANGE = -2,       /* id > 0x7FF (extended ids unused), dlc > 8, length 0 or > 64 */
    DBC_ERR_FULL = -3,        /* more messages or signals than the compile-time bounds */
    DBC_ERR_ORPHAN = -4,      /* an SG_ line before any BO_ line */
    DBC_ERR_LAYOUT = -5,      /* a signal reaches past the frame's dlc, or overlaps another */
    DBC_ERR_DUPLICATE = -6,   /* two messages with one id, or two signals with one name */
    DBC_ERR_UNSUPPORTED = -7, /* big-endian (@0) or multiplexed signals: argil uses neither */
    DBC_ERR_TOO_LONG = -8     /* a name, unit or number longer than its buffer */
} dbc_err_t;

typedef struct {
    char name[DBC_NAME_MAX];
    uint16_t start_bit;       /* Intel (little-endian) start bit: the signal's LSB */
    uint8_t length;           /* bits, 1..64 */
    bool is_signed;
    double factor, offset;    /* physical = raw * factor + offset */
    double min, max;
    char unit[DBC_UNIT_MAX];
} dbc_signal_t;

typedef struct {
    uint32_t id;
    char name[DBC_NAME_MAX];
    uint8_t dlc;
    uint8_t n_signals;
    dbc_signal_t sig[DBC_SIGNALS_MAX];
} dbc_message_t;

typedef struct {
    uint32_t n_messages;
    dbc_message_t msg[DBC_MESSAGES_MAX];
} dbc_t;

/* A cursor over one line (not NUL-terminated). */
typedef struct {
    const char *p;
    const char *end;
} dbc_cur_t;

static inline void dbc_skip_space(dbc_cur_t *c)
{
    while (c->p < c->end && (*c->p == ' ' || *c->p == '\t' || *c->p == '\r'))
        c->p++;
}

static inline bool dbc_is_ident_char(char ch)
{
    return (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
           ch == '_';
}

/* Reads a C identifier into out (NUL-terminated). */
static inline dbc_err_t dbc_ident(dbc_cur_t *c, char *out, size_t cap)
{
    dbc_skip_space(c);
    const char *s = c->p;
    if (s >= c->end || !dbc_is_ident_char(*s) || (*s >= '0' && *s <= '9'))
        return DBC_ERR_SYNTAX;
    while (c->p < c->end && dbc_is_ident_char(*c->p))
        c->p++;
    const size_t n = (size_t)(c->p - s);
    if (n >= cap)
        return DBC_ERR_TOO_LONG;
    memcpy(out, s, n);
    out[n] = '\0';
    return DBC_OK;
}

/* Expects the character ch (after optional spaces). */
static inline dbc_err_t dbc_expect(dbc_cur_t *c, char ch)
{
    dbc_skip_space(c);
    if (c->p >= c->end || *c->p != ch)
        return DBC_ERR_SYNTAX;
    c->p++;
    return DBC_OK;
}

/* Reads an unsigned decimal integer no larger than max. */
static inline dbc_err_t dbc_uint(dbc_cur_t *c, uint64_t max, uint64_t *out)
{
    dbc_skip_space(c);
    if (c->p >= c->end || *c->p < '0' || *c->p > '9')
        return DBC_ERR_SYNTAX;
    uint64_t v = 0;
    while (c->p < c->end && *c->p >= '0' && *c->p <= '9') {
        v = v * 10u + (uint64_t)(*c->p - '0');
        if (v > max)
            return DBC_ERR_RANGE;
        c->p++;
    }
    *out = v;
    return DBC_OK;
}

/* Reads a decimal floating-point number (sign, digits, point, exponent); must be finite. */
static inline dbc_err_t dbc_real(dbc_cur_t *c, double *out)
{
    dbc_skip_space(c);
    char buf[40];
    size_t n = 0;
    while (c->p + n < c->end && n < sizeof(buf) &&
           ((c->p[n] >= '0' && c->p[n] <= '9') || c->p[n] == '-' || c->p[n] == '+' ||
            c->p[n] == '.' || c->p[n] == 'e' || c->p[n] == 'E'))
        n++;
    if (n == sizeof(buf))
        return DBC_ERR_TOO_LONG;
    if (n == 0)
        return DBC_ERR_SYNTAX;
    memcpy(buf, c->p, n);
    buf[n] = '\0';
    char *stop = NULL;
    const double v = strtod(buf, &stop);
    if (stop != buf + n || !isfinite(v))
        return DBC_ERR_SYNTAX;
    c->p += n;
    *out = v;
    return DBC_OK;
}

/* Reads a double-quoted string without escapes. */
static inline dbc_err_t dbc_quoted(dbc_cur_t *c, char *out, size_t cap)
{
    dbc_err_t e = dbc_expect(c, '"');
    if (e != DBC_OK)
        return e;
    const char *s = c->p;
    while (c->p < c->end && *c->p != '"')
        c->p++;
    if (c->p >= c->end)
        return DBC_ERR_SYNTAX;
    const size_t n = (size_t)(c->p - s);
    c->p++;
    if (n >= cap)
        return DBC_ERR_TOO_LONG;
    memcpy(out, s, n);
    out[n] = '\0';
    return DBC_OK;
}

/* True when the line starts (after indentation) with keyword followed by a blank. */
static inline bool dbc_keyword(dbc_cur_t *c, const char *kw)
{
    dbc_skip_space(c);
    const size_t n = strlen(kw);
    if ((size_t)(c->end - c->p) <= n || memcmp(c->p, kw, n) != 0 ||
        (c->p[n] != ' ' && c->p[n] != '\t'))
        return false;
    c->p += n;
    return true;
}

#define DBC_TRY(expr)                  \
    do {                               \
        const dbc_err_t dbc_e_ = (expr); \
        if (dbc_e_ != DBC_OK)          \
            return dbc_e_;             \
    } while (0)

/* BO_ <id> <name>: <dlc> <sender> */
static inline dbc_err_t dbc_parse_message(dbc_t *d, dbc_cur_t *c)
{
    if (d->n_messages >= DBC_MESSAGES_MAX)
        return DBC_ERR_FULL;
    dbc_message_t *m = &d->msg[d->n_messages];
    memset(m, 0, sizeof(*m));
    uint64_t v = 0;
    DBC_TRY(dbc_uint(c, 0xFFFFFFFFu, &v));
    if (v > 0x7FFu)
        return DBC_ERR_RANGE;
    m->id = (uint32_t)v;
    DBC_TRY(dbc_ident(c, m->name, sizeof(m->name)));
    DBC_TRY(dbc_expect(c, ':'));
    DBC_TRY(dbc_uint(c, 0xFFu, &v));
    if (v > 8u)
        return DBC_ERR_RANGE;
    m->dlc = (uint8_t)v;
    char sender[DBC_NAME_MAX];
    DBC_TRY(dbc_ident(c, sender, sizeof(sender)));
    dbc_skip_space(c);
    if (c->p != c->end)
        return DBC_ERR_SYNTAX;
    for (uint32_t i = 0; i < d->n_messages; i++)
        if (d->msg[i].id == m->id)
            return DBC_ERR_DUPLICATE;
    d->n_messages++;
    return DBC_OK;
}

/* SG_ <name> : <start>|<length>@<order><sign> (<factor>,<offset>) [<min>|<max>] "<unit>" <rx> */
static inline dbc_err_t dbc_parse_signal(dbc_t *d, dbc_cur_t *c)
{
    if (d->n_messages == 0)
        return DBC_ERR_ORPHAN;
    dbc_message_t *m = &d->msg[d->n_messages - 1u];
    if (m->n_signals >= DBC_SIGNALS_MAX)
        return DBC_ERR_FULL;
    dbc_signal_t *s = &m->sig[m->n_signals];
    memset(s, 0, sizeof(*s));
    DBC_TRY(dbc_ident(c, s->name, sizeof(s->name)));
    dbc_skip_space(c);
    if (c->p < c->end && (*c->p == 'M' || *c->p == 'm'))
        return DBC_ERR_UNSUPPORTED;
    DBC_TRY(dbc_expect(c, ':'));
    uint64_t v = 0;
    DBC_TRY(dbc_uint(c, 0xFFFFu, &v));
    const uint64_t start = v;
    DBC_TRY(dbc_expect(c, '|'));
    DBC_TRY(dbc_uint(c, 0xFFFFu, &v));
    if (v == 0 || v > 64u)
        return DBC_ERR_RANGE;
    s->length = (uint8_t)v;
    DBC_TRY(dbc_expect(c, '@'));
    if (c->p >= c->end || (*c->p != '0' && *c->p != '1'))
        return DBC_ERR_SYNTAX;
    const bool big_endian = *c->p == '0';
    c->p++;
    if (c->p >= c->end || (*c->p != '+' && *c->p != '-'))
        return DBC_ERR_SYNTAX;
    s->is_signed = *c->p == '-';
    c->p++;
    if (big_endian)
        return DBC_ERR_UNSUPPORTED;
    DBC_TRY(dbc_expect(c, '('));
    DBC_TRY(dbc_real(c, &s->factor));
    DBC_TRY(dbc_expect(c, ','));
    DBC_TRY(dbc_real(c, &s->offset));
    DBC_TRY(dbc_expect(c, ')'));
    DBC_TRY(dbc_expect(c, '['));
    DBC_TRY(dbc_real(c, &s->min));
    DBC_TRY(dbc_expect(c, '|'));
    DBC_TRY(dbc_real(c, &s->max));
    DBC_TRY(dbc_expect(c, ']'));
    DBC_TRY(dbc_quoted(c, s->unit, sizeof(s->unit)));
    /* receivers: one or more node names separated by commas */
    char rx[DBC_NAME_MAX];
    DBC_TRY(dbc_ident(c, rx, sizeof(rx)));
    dbc_skip_space(c);
    while (c->p < c->end && *c->p == ',') {
        c->p++;
        DBC_TRY(dbc_ident(c, rx, sizeof(rx)));
        dbc_skip_space(c);
    }
    if (c->p != c->end)
        return DBC_ERR_SYNTAX;
    if (start + s->length > (uint64_t)m->dlc * 8u)
        return DBC_ERR_LAYOUT;
    s->start_bit = (uint16_t)start;
    for (uint8_t i = 0; i < m->n_signals; i++) {
        const dbc_signal_t *o = &m->sig[i];
        if (strcmp(o->name, s->name) == 0)
            return DBC_ERR_DUPLICATE;
        if (s->start_bit < o->start_bit + o->length && o->start_bit < s->start_bit + s->length)
            return DBC_ERR_LAYOUT;
    }
    m->n_signals++;
    return DBC_OK;
}

/* Parses a whole DBC text (len bytes, no terminator needed). On error *err_line is the 1-based
 * line that broke the rule. */
static inline dbc_err_t dbc_parse(dbc_t *d, const char *text, size_t len, uint32_t *err_line)
{
    memset(d, 0, sizeof(*d));
    *err_line = 0;
    const char *p = text;
    const char *end = text + len;
    uint32_t line = 0;
    while (p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (eol == NULL)
            eol = end;
        line++;
        dbc_cur_t c = {p, eol};
        dbc_err_t e = DBC_OK;
        if (dbc_keyword(&c, "BO_"))
            e = dbc_parse_message(d, &c);
        else if (dbc_keyword(&c, "SG_"))
            e = dbc_parse_signal(d, &c);
        if (e != DBC_OK) {
            *err_line = line;
            return e;
        }
        p = eol < end ? eol + 1 : end;
    }
    return DBC_OK;
}

static inline const dbc_message_t *dbc_find(const dbc_t *d, uint32_t id)
{
    for (uint32_t i = 0; i < d->n_messages; i++)
        if (d->msg[i].id == id)
            return &d->msg[i];
    return NULL;
}

static inline const dbc_signal_t *dbc_signal(const dbc_message_t *m, const char *name)
{
    for (uint8_t i = 0; i < m->n_signals; i++)
        if (strcmp(m->sig[i].name, name) == 0)
            return &m->sig[i];
    return NULL;
}

/* The signal's raw value, sign-extended when signed (Intel byte order: bit k of the signal is
 * bit (start + k) of the frame, counting bit 0 of byte 0 first). */
static inline int64_t dbc_raw(const dbc_signal_t *s, const uint8_t data[8])
{
    uint64_t v = 0;
    for (uint8_t k = 0; k < s->length; k++) {
        const unsigned bit = s->start_bit + k;
        if (bit >= 64u)
            break;
        if ((data[bit / 8u] >> (bit % 8u)) & 1u)
            v |= (uint64_t)1 << k;
    }
    if (s->is_signed && s->length < 64u && ((v >> (s->length - 1u)) & 1u) != 0)
        v |= ~(uint64_t)0 << s->length;
    return (int64_t)v;
}

/* The signal's physical value (raw * factor + offset). */
static inline double dbc_physical(const dbc_signal_t *s, const uint8_t data[8])
{
    const int64_t raw = dbc_raw(s, data);
    const double r = s->is_signed ? (double)raw : (double)(uint64_t)raw;
    return r * s->factor + s->offset;
}

/* One line of `candump -L` / `candump -l` output: "(SECONDS) IFACE ID#DATA", standard ids only
 * (3 hex digits), up to 8 data bytes as hex pairs. */
static inline dbc_err_t dbc_candump_line(const char *line, size_t len, can_frame_t *f)
{
    dbc_cur_t c = {line, line + len};
    memset(f, 0, sizeof(*f));
    DBC_TRY(dbc_expect(&c, '('));
    double ts = 0.0;
    DBC_TRY(dbc_real(&c, &ts));
    DBC_TRY(dbc_expect(&c, ')'));
    char iface[DBC_NAME_MAX];
    DBC_TRY(dbc_ident(&c, iface, sizeof(iface)));
    dbc_skip_space(&c);
    uint32_t id = 0;
    int digits = 0;
    while (c.p < c.end && *c.p != '#') {
        const int h = hex_digit_value(*c.p);
        if (h < 0)
            return DBC_ERR_SYNTAX;
        if (++digits > 3)
            return DBC_ERR_RANGE;
        id = id * 16u + (uint32_t)h;
        c.p++;
    }
    if (digits == 0 || id > 0x7FFu)
        return digits == 0 ? DBC_ERR_SYNTAX : DBC_ERR_RANGE;
    DBC_TRY(dbc_expect(&c, '#'));
    uint8_t n = 0;
    while (c.p < c.end && hex_digit_value(*c.p) >= 0) {
        if (c.p + 1 >= c.end || hex_digit_value(c.p[1]) < 0)
            return DBC_ERR_SYNTAX;
        if (n >= 8u)
            return DBC_ERR_RANGE;
        f->data[n++] = (uint8_t)(hex_digit_value(c.p[0]) * 16 + hex_digit_value(c.p[1]));
        c.p += 2;
    }
    while (c.p < c.end && (*c.p == ' ' || *c.p == '\t' || *c.p == '\r' || *c.p == '\n'))
        c.p++;
    if (c.p != c.end)
        return DBC_ERR_SYNTAX;
    f->id = id;
    f->len = n;
    return DBC_OK;
}

#endif
