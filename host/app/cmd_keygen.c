/* argil keygen FILE: a new UDP link key file (host/link/link_key_file.h, docs/link.md "Link key")
 * for argil-board --key and argil connect --key. */
#include <stdio.h>
#include <string.h>

#include "host/app/commands.h"
#include "host/link/link_key_file.h"

/* The text of `argil keygen --help`. */
static void usage_keygen(FILE *f)
{
    fprintf(f,
            "usage: argil keygen FILE\n"
            "\n"
            "Makes a new pre-shared key for the UDP link between argil-board and argil connect:\n"
            "32 random bytes (libsodium) as one line of 64 hex digits, in FILE created with mode\n"
            "0600 (only its owner may read it). FILE must not exist: a key is never overwritten.\n"
            "Give the same file to the board and to every host that may command it:\n"
            "  argil keygen argil.key\n"
            "  scp -p argil.key board:/etc/argil/argil.key   (keep it mode 0600 there)\n"
            "  argil-board --key /etc/argil/argil.key ...    (or [link] key = ... in its INI)\n"
            "  argil connect --device udp:board:7700 --key argil.key ...\n"
            "Every datagram then carries a keyed BLAKE2b tag, and the board refuses any without\n"
            "a valid one. A key file that group or others may read or write is refused: chmod\n"
            "600 FILE. USB needs no key. See docs/link.md.\n"
            "\n"
            "exit status: 0 written; 1 FILE exists or cannot be written; 2 a usage error.\n");
}

/* argil keygen FILE: writes a random link key into FILE, which must not exist yet. */
argil_err_t cmd_keygen(int argc, char **argv, int *exit_status)
{
    if (argc == 1 && (strcmp(argv[0], "--help") == 0 || strcmp(argv[0], "-h") == 0)) {
        usage_keygen(stdout);
        return cmd_end(exit_status, 0, ARGIL_OK);
    }
    if (argc != 1 || argv[0][0] == '-') {
        fprintf(stderr, "argil keygen: expected one FILE to create (see 'argil keygen --help')\n");
        return cmd_end(exit_status, 2, ARGIL_ERR_ARG);
    }
    char err[512];
    if (link_key_file_create(argv[0], err, sizeof(err)) != LINK_KEY_OK) {
        fprintf(stderr, "argil keygen: %s\n", err);
        return cmd_end(exit_status, 1, ARGIL_ERR_IO);
    }
    printf("argil keygen: wrote a new link key to %s (mode 0600): give the same file to "
           "argil-board --key and argil connect --key\n", argv[0]);
    return cmd_end(exit_status, 0, ARGIL_OK);
}
