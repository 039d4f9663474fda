/* The argil subcommands: each takes the arguments after its name and returns the exit status
 * (0 success, 1 the work failed, 2 a usage error, 130 interrupted). */
#ifndef ARGIL_COMMANDS_H
#define ARGIL_COMMANDS_H

int cmd_sculpt(int argc, char **argv);
int cmd_mesh(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_fit(int argc, char **argv);
int cmd_view(int argc, char **argv);
int cmd_plot(int argc, char **argv);

#endif
