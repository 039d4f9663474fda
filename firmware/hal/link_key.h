/* The board's reading of the UDP link's key file (argil-board --key; docs/link.md "Link key"):
 * open, fstat and read here, every rule and message in shared/link_key_text.h, the same as the
 * host's (host/link/link_key_file.h). Library code: never prints. */
#ifndef ARGIL_LINK_KEY_H
#define ARGIL_LINK_KEY_H

#include <stddef.h>

#include "link_auth.h"
#include "shared/link_key_text.h"

/* Reads and parses path; refuses a file that is not regular, that group or others may read or
 * write, or that is too large. One line into err naming the file and the fix. */
link_key_err_t link_key_load(const char *path, link_key_t *key, char *err, size_t err_len);

#endif
