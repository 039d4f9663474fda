/* The argil subcommands: each takes the arguments after its name and returns the exit status
 * (0 success, 1 the work failed, 2 a usage error, 130 interrupted). */
#ifndef ARGIL_COMMANDS_H
#define ARGIL_COMMANDS_H

int cmd_sculpt(int argc, char **argv);

#endif
