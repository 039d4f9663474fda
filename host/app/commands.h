/* The argil subcommands: each takes the arguments after its name and returns the exit status
 * (0 success, 1 the work failed, 2 a usage error, 130 interrupted). */
#ifndef ARGIL_COMMANDS_H
#define ARGIL_COMMANDS_H

#include <stdbool.h>

int cmd_sculpt(int argc, char **argv);
int cmd_mesh(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_fit(int argc, char **argv);
int cmd_view(int argc, char **argv);
int cmd_plot(int argc, char **argv);
int cmd_connect(int argc, char **argv);
int cmd_recover(int argc, char **argv);
int cmd_keygen(int argc, char **argv);

/* Before a session writes into dir: when dir holds an unfinished session's journal, says so in
 * one line and (interactive only) asks whether to recover, discard or quit; discard removes it.
 * Returns -1 to go on with the session, else the exit status to end with. */
int recover_offer(const char *dir, bool discard, bool interactive);

#endif
