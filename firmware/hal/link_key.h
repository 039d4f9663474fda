/* The UDP link's pre-shared key file (docs/link.md "Link key"): text, one line of 64 hex digits
 * (32 bytes), '#' comments and blank lines allowed; readable by its owner only. The board
 * (argil-board --key) and the host (argil connect --key, argil keygen) read the same format.
 * Library code: returns which rule was broken and one line naming the fix; never prints. */
#ifndef ARGIL_LINK_KEY_H
#define ARGIL_LINK_KEY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "link_auth.h"

#define LINK_KEY_FILE_MAX 4096u  /* bytes; a key file is one line and a few comments */

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
    LINK_KEY_ERR_EXISTS = -10,   /* link_key_create: the file is there already */
    LINK_KEY_ERR_WRITE = -11     /* link_key_create: cannot create or write it */
} link_key_err_t;

/* Parses a key file's text (len bytes, no NUL needed). On an error *line is the 1-based line
 * the rule was broken on (the last line for NO_KEY). */
link_key_err_t link_key_parse(const char *text, size_t len, link_key_t *key, uint32_t *line);

/* Reads and parses path; refuses a file that is not regular, that group or others may read or
 * write, or that is too large. One line into err naming the file and the fix. */
link_key_err_t link_key_load(const char *path, link_key_t *key, char *err, size_t err_len);

/* As link_key_load, for the file named by the environment variable var (the test hosts'
 * ARGIL_LINK_KEY); *found false and LINK_KEY_OK when var is unset or empty. Starts libsodium. */
link_key_err_t link_key_load_env(const char *var, link_key_t *key, bool *found, char *err,
                                 size_t err_len);

/* Makes a new key file at path from 32 random bytes (libsodium): created with O_EXCL and mode
 * 0600, never over an existing file. One line into err on failure. */
link_key_err_t link_key_create(const char *path, char *err, size_t err_len);

/* What the rule is ("not 64 hex digits"). */
const char *link_key_err_text(link_key_err_t e);

#endif
