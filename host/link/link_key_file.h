/* The host's copy of the UDP link's key file (argil connect --key, argil keygen, the test hosts'
 * ARGIL_LINK_KEY; docs/link.md "Link key"): open, fstat, read and create here, every rule and
 * message in shared/link_key_text.h, the same as the board's (firmware/hal/link_key.h).
 * Library code: never prints. */
#ifndef ARGIL_LINK_KEY_FILE_H
#define ARGIL_LINK_KEY_FILE_H

#include <stdbool.h>
#include <stddef.h>

#include "shared/link_key_text.h"

/* Reads and parses path; refuses a file that is not regular, that group or others may read or
 * write, or that is too large. One line into err naming the file and the fix. */
link_key_err_t link_key_file_load(const char *path, link_key_t *key, char *err, size_t err_len);

/* As link_key_file_load, for the file named by the environment variable var (the test hosts'
 * ARGIL_LINK_KEY); *found false and LINK_KEY_OK when var is unset or empty. Starts libsodium. */
link_key_err_t link_key_file_load_env(const char *var, link_key_t *key, bool *found, char *err,
                                      size_t err_len);

/* Makes a new key file at path from 32 random bytes (libsodium): created with O_EXCL and mode
 * 0600, never over an existing file. One line into err on failure. */
link_key_err_t link_key_file_create(const char *path, char *err, size_t err_len);

#endif
