/* The UDP link's pre-shared key file (docs/link.md "Link key"): text, one line of 64 hex digits
 * (32 bytes), '#' comments and blank lines allowed; readable by its owner only. The board
 * (argil-board --key) and the host (argil connect --key, argil keygen) read the same format and
 * judge it by the same rules, here; each side only opens, fstats and reads the file
 * (firmware/hal/link_key.c, host/link/link_key_file.c). Freestanding: returns which rule was
 * broken and one line naming the fix; never prints, holds no copy of the key. */
#ifndef ARGIL_LINK_KEY_TEXT_H
#define ARGIL_LINK_KEY_TEXT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/link_envelope.h"

#define LINK_KEY_FILE_MAX 4096u  /* bytes; a key file is one line and a few comments */
#define LINK_KEY_TEXT_MAX 256u   /* bytes of a new key file's text (link_key_format) */

typedef enum {
    LINK_KEY_OK = 0,
    LINK_KEY_ERR_NO_KEY = -1,    /* no key line (empty, or only comments) */
    LINK_KEY_ERR_HEX = -2,       /* a character on the key line that is not a hex digit */
    LINK_KEY_ERR_SHORT = -3,     /* fewer than 64 hex digits (a truncated key) */
    LINK_KEY_ERR_LONG = -4,      /* more than 64 hex digits */
    LINK_KEY_ERR_EXTRA = -5,     /* a second key line */
    LINK_KEY_ERR_OPEN = -6,      /* cannot open or read the file (errno in the message) */
    LINK_KEY_ERR_NOT_FILE = -7,  /* not a regular file (a directory, a device, a FIFO) */
    LINK_KEY_ERR_MODE = -8,      /* group or others may read or write it (st_mode & 077) */
    LINK_KEY_ERR_BIG = -9,       /* larger than LINK_KEY_FILE_MAX */
    LINK_KEY_ERR_EXISTS = -10,   /* creating: the file is there already */
    LINK_KEY_ERR_WRITE = -11     /* creating: cannot create or write it */
} link_key_err_t;

/* Parses a key file's text (len bytes, no NUL needed); key is written only on LINK_KEY_OK. On
 * an error *line is the 1-based line the rule was broken on (the last line for NO_KEY). */
link_key_err_t link_key_parse(const char *text, size_t len, link_key_t *key, uint32_t *line);

/* LINK_KEY_ERR_OPEN, with one line into err naming path and sys_text (the failed call's
 * strerror); at_open (the file could not be opened) adds how to make one. */
link_key_err_t link_key_open_failed(const char *path, const char *sys_text, bool at_open,
                                    char *err, size_t err_len);

/* The verdict on an open key file from what fstat says, before it is read: NOT_FILE, MODE (group
 * or others may read or write it: mode & 077), BIG; one line into err naming path and the fix. */
link_key_err_t link_key_check_file(const char *path, bool regular, uint32_t mode,
                                   uint64_t size_bytes, char *err, size_t err_len);

/* Parses the text read from path (at most LINK_KEY_FILE_MAX + 1 bytes: one more than the limit
 * is BIG, the file grew after its check); on an error one line into err naming path, the line
 * and the fix. */
link_key_err_t link_key_parse_file(const char *path, const char *text, size_t len,
                                   link_key_t *key, char *err, size_t err_len);

/* Writes a new key file's text for key into text: a comment line and the key as 64 lower-case
 * hex digits, each line ending in '\n'; returns its length (no NUL), 0 when cap is short. */
size_t link_key_format(const link_key_t *key, char *text, size_t cap);

/* What the rule is ("not 64 hex digits"). */
const char *link_key_err_text(link_key_err_t e);

#endif
