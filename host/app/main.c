/* argil: the desktop program's entry point; each subcommand lives in its own cmd_*.c
 * (commands.h), e.g. `argil sculpt` in cmd_sculpt.c. */
#include <stdio.h>
#include <string.h>

#include "host/app/commands.h"

/* Every subcommand: one line here and one declaration in commands.h. */
static const struct {
    const char *name;
    argil_err_t (*run)(int argc, char **argv, int *exit_status);
    const char *summary;
} COMMANDS[] = {
    {"sculpt", cmd_sculpt, "run a sculpting session (see 'argil sculpt --help')"},
    {"fit", cmd_fit, "fit a point cloud, mesh or volume into a model (see 'argil fit --help')"},
    {"mesh", cmd_mesh, "write a model's surface as PLY, STL or OBJ (see 'argil mesh --help')"},
    {"info", cmd_info, "describe a model, mesh, point cloud or volume file"},
    {"plot", cmd_plot, "draw a session's telemetry.csv as a PNG chart (see 'argil plot --help')"},
    {"view", cmd_view, "render a mesh to a PNG or show it in a window (see 'argil view --help')"},
    {"connect", cmd_connect, "a live session with a board over USB, UDP or sim (see 'argil connect --help')"},
    {"recover", cmd_recover, "restore an unfinished session from its journal (see 'argil recover --help')"},
    {"keygen", cmd_keygen, "make a UDP link key file for board and host (see 'argil keygen --help')"},
};

/* The text of `argil --help`: the commands with their one-line summaries. */
static void usage_main(FILE *f)
{
    fprintf(f, "usage: argil COMMAND [OPTIONS]\n\n"
               "argil is a haptic virtual-clay sculpting system.\n\n"
               "commands:\n");
    for (size_t i = 0; i < sizeof(COMMANDS) / sizeof(COMMANDS[0]); i++)
        fprintf(f, "  %-9s %s\n", COMMANDS[i].name, COMMANDS[i].summary);
    fprintf(f, "  %-9s %s\n", "help", "show this text");
}

/* Runs the command argv[1] names; the process ends with the exit status it set. */
int main(int argc, char **argv)
{
    if (argc < 2) {
        usage_main(stderr);
        return 2;
    }
    for (size_t i = 0; i < sizeof(COMMANDS) / sizeof(COMMANDS[0]); i++)
        if (strcmp(argv[1], COMMANDS[i].name) == 0) {
            /* The command has said what went wrong; its exit status is the process's. */
            int exit_status = 1;
            (void)COMMANDS[i].run(argc - 2, argv + 2, &exit_status);
            return exit_status;
        }
    if (strcmp(argv[1], "help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "--help") == 0) {
        usage_main(stdout);
        return 0;
    }
    fprintf(stderr, "argil: unknown command '%s' (see 'argil --help')\n", argv[1]);
    return 2;
}
