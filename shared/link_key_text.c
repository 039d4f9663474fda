/* The link key file's rules and messages (link_key_text.h): the parser, the verdict on what
 * fstat says, and a new file's text. */
#include "shared/link_key_text.h"

#include <string.h>

#include "shared/hex_digit.h"

static const char HEX_DIGITS[] = "0123456789abcdef";

/* A message being written into a caller's buffer, cut (always NUL-terminated) where it is full. */
typedef struct {
    char *buf;
    size_t cap;
    size_t len;
} say_t;

/* An empty message in buf[0 … cap). */
static say_t say_into(char *buf, size_t cap)
{
    say_t s = {buf, cap, 0};
    if (cap > 0)
        buf[0] = '\0';
    return s;
}

/* Appends text, as much of it as fits. */
static void say(say_t *s, const char *text)
{
    for (; *text != '\0'; text++)
        if (s->len + 1u < s->cap)
            s->buf[s->len++] = *text;
    if (s->cap > 0)
        s->buf[s->len] = '\0';
}

/* Appends v in base 8 or 10 with at least min_digits digits (zeros in front; at most 11). */
static void say_uint(say_t *s, uint32_t v, uint32_t base, unsigned min_digits)
{
    char digits[12];
    size_t n = sizeof(digits) - 1u;
    digits[n] = '\0';
    do {
        digits[--n] = HEX_DIGITS[v % base];
        v /= base;
        min_digits = min_digits > 0 ? min_digits - 1u : 0u;
    } while ((v != 0 || min_digits > 0) && n > 0);
    say(s, digits + n);
}

/* True for the blanks a line may have around its content. */
static bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

/* The content [*a, *b) of the line text[at … end): up to a '#', without blanks around it. */
static void line_content(const char *text, size_t at, size_t end, size_t *a, size_t *b)
{
    *a = at;
    *b = end;
    for (size_t i = at; i < end; i++)
        if (text[i] == '#') {
            *b = i;
            break;
        }
    while (*a < *b && is_blank(text[*a]))
        (*a)++;
    while (*b > *a && is_blank(text[*b - 1u]))
        (*b)--;
}

/* The rule the key line text[a … b) breaks (have: a key line came before it), or LINK_KEY_OK. */
static link_key_err_t check_key_line(const char *text, size_t a, size_t b, bool have)
{
    for (size_t i = a; i < b; i++)
        if (hex_digit_value(text[i]) < 0)
            return LINK_KEY_ERR_HEX;
    if (have)
        return LINK_KEY_ERR_EXTRA;
    if (b - a > 2u * LINK_KEY_BYTES)
        return LINK_KEY_ERR_LONG;
    if (b - a < 2u * LINK_KEY_BYTES)
        return LINK_KEY_ERR_SHORT;
    return LINK_KEY_OK;
}

link_key_err_t link_key_parse(const char *text, size_t len, link_key_t *key, uint32_t *line)
{
    size_t key_at = 0; /* where the key line's 64 digits start */
    bool have = false;
    uint32_t ln = 1;
    link_key_err_t rc = LINK_KEY_OK;
    for (size_t at = 0; at < len;) {
        size_t end = at;
        while (end < len && text[end] != '\n')
            end++;
        size_t a, b;
        line_content(text, at, end, &a, &b);
        if (a < b) {
            rc = check_key_line(text, a, b, have);
            if (rc != LINK_KEY_OK)
                break;
            have = true;
            key_at = a;
        }
        at = end + 1u;
        if (end < len)
            ln++;
    }
    if (rc == LINK_KEY_OK && !have)
        rc = LINK_KEY_ERR_NO_KEY;
    *line = ln;
    if (rc == LINK_KEY_OK)
        for (size_t i = 0; i < LINK_KEY_BYTES; i++)
            key->k[i] = (uint8_t)((hex_digit_value(text[key_at + 2u * i]) << 4) |
                                  hex_digit_value(text[key_at + 2u * i + 1u]));
    return rc;
}

link_key_err_t link_key_open_failed(const char *path, const char *sys_text, bool at_open,
                                    char *err, size_t err_len)
{
    say_t s = say_into(err, err_len);
    say(&s, "key file '");
    say(&s, path);
    say(&s, "': ");
    say(&s, sys_text);
    if (at_open) {
        say(&s, " (make one with 'argil keygen ");
        say(&s, path);
        say(&s, "')");
    }
    return LINK_KEY_ERR_OPEN;
}

/* BIG, with its line: path is larger than LINK_KEY_FILE_MAX. */
static link_key_err_t say_too_big(const char *path, char *err, size_t err_len)
{
    say_t s = say_into(err, err_len);
    say(&s, "key file '");
    say(&s, path);
    say(&s, "' is larger than ");
    say_uint(&s, LINK_KEY_FILE_MAX, 10u, 1u);
    say(&s, " bytes: not a key file");
    return LINK_KEY_ERR_BIG;
}

link_key_err_t link_key_check_file(const char *path, bool regular, uint32_t mode,
                                   uint64_t size_bytes, char *err, size_t err_len)
{
    say_t s = say_into(err, err_len);
    if (!regular) {
        say(&s, "key file '");
        say(&s, path);
        say(&s, "' is not a regular file (make one with 'argil keygen FILE')");
        return LINK_KEY_ERR_NOT_FILE;
    }
    if ((mode & 077u) != 0) {
        say(&s, "key file '");
        say(&s, path);
        say(&s, "' may be read or written by group or others (mode ");
        say_uint(&s, mode & 07777u, 8u, 4u);
        say(&s, "): chmod 600 ");
        say(&s, path);
        return LINK_KEY_ERR_MODE;
    }
    if (size_bytes > LINK_KEY_FILE_MAX)
        return say_too_big(path, err, err_len);
    return LINK_KEY_OK;
}

link_key_err_t link_key_parse_file(const char *path, const char *text, size_t len,
                                   link_key_t *key, char *err, size_t err_len)
{
    if (len > LINK_KEY_FILE_MAX)
        return say_too_big(path, err, err_len);
    uint32_t line = 0;
    const link_key_err_t rc = link_key_parse(text, len, key, &line);
    if (rc != LINK_KEY_OK) {
        say_t s = say_into(err, err_len);
        say(&s, "key file '");
        say(&s, path);
        say(&s, "':");
        say_uint(&s, line, 10u, 1u);
        say(&s, ": ");
        say(&s, link_key_err_text(rc));
        say(&s, " (a key file is one line of 64 hex digits; make a new one with 'argil keygen "
                "FILE')");
    }
    return rc;
}

size_t link_key_format(const link_key_t *key, char *text, size_t cap)
{
    static const char head[] = "# argil link key (docs/link.md): the board's and the host's copy "
                               "must match; keep it mode 0600\n";
    const size_t len = sizeof(head) - 1u + 2u * LINK_KEY_BYTES + 1u;
    if (cap < len)
        return 0;
    memcpy(text, head, sizeof(head) - 1u);
    char *hex = text + sizeof(head) - 1u;
    for (size_t i = 0; i < LINK_KEY_BYTES; i++) {
        hex[2u * i] = HEX_DIGITS[key->k[i] >> 4];
        hex[2u * i + 1u] = HEX_DIGITS[key->k[i] & 0x0fu];
    }
    hex[2u * LINK_KEY_BYTES] = '\n';
    return len;
}

const char *link_key_err_text(link_key_err_t e)
{
    switch (e) {
    case LINK_KEY_OK: return "ok";
    case LINK_KEY_ERR_NO_KEY: return "no key line";
    case LINK_KEY_ERR_HEX: return "a character that is not a hex digit";
    case LINK_KEY_ERR_SHORT: return "fewer than 64 hex digits (truncated)";
    case LINK_KEY_ERR_LONG: return "more than 64 hex digits";
    case LINK_KEY_ERR_EXTRA: return "a second key line";
    case LINK_KEY_ERR_OPEN: return "cannot be read";
    case LINK_KEY_ERR_NOT_FILE: return "not a regular file";
    case LINK_KEY_ERR_MODE: return "readable or writable by group or others";
    case LINK_KEY_ERR_BIG: return "too large";
    case LINK_KEY_ERR_EXISTS: return "exists already";
    case LINK_KEY_ERR_WRITE: return "cannot be written";
    }
    return "?";
}
