/* The command lines of the argil commands: option values more than one command takes (each
 * value parser returns false for a value outside its set, and the command prints its one-line
 * error ending in the matching CLI_*_EXPECTS text), and the reading of a whole command line of
 * flags, numbers, -o FILE and inputs, whose errors are said as "argil <command>: ..." on stderr. */
#ifndef ARGIL_CLI_OPTS_H
#define ARGIL_CLI_OPTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "host/app/peer.h"
#include "shared/argil_err.h"

#define CLI_GLOBAL_SOLVE_EXPECTS "'bspline' or 'springs'"
#define CLI_KNOT_RATIO_EXPECTS "1, 2 or 4 (grid samples per knot span)"
#define CLI_AUTOSAVE_EXPECTS "seconds in 0.001..3600"

/* --global-solve: "bspline" or "springs". */
bool cli_global_solve(const char *v, peer_global_solve_t *out);

/* --knot-ratio: "1", "2" or "4". */
bool cli_knot_ratio(const char *v, int *out);

#define CLI_RATE_HZ_EXPECTS "1000, 2000 or 4000 (the board's loop rate, Hz)"
/* --rate-hz: "1000", "2000" or "4000"; *out the loop period in microseconds. */
bool cli_rate_hz(const char *v, uint32_t *tick_us);

/* --autosave-s, --checkpoint-s: a number of seconds in 0.001 … 3600. */
bool cli_autosave_s(const char *v, float *out);

/* --undo-mb: a whole number of MiB in 0 … SESSION_UNDO_MB_MAX. */
bool cli_undo_mb(const char *v, uint32_t *mb);

/* The summary's words for a global solve ("B-spline model (implicit)", ...). */
const char *cli_global_solve_text(peer_global_solve_t gs);

/* How a command's own option parser took one word of its command line. */
typedef enum {
    CLI_OPT_TAKEN, /* understood; the index moved past any value it took */
    CLI_OPT_OTHER, /* not one of its options */
    CLI_OPT_BAD,   /* refused; one line on stderr said why */
} cli_opt_t;

/* Where the session options argil sculpt and argil connect share go; a NULL place: the command
 * has no such option. */
typedef struct {
    peer_global_solve_t *global_solve;
    bool *global_solve_given;     /* set when --global-solve is given (may be NULL) */
    int *knot_ratio;
    uint32_t *tick_us;            /* --rate-hz */
    float *autosave_s, *checkpoint_s;
    uint32_t *undo_mb;
} cli_session_t;

/* Takes argv[*i] when it is --global-solve, --knot-ratio, --rate-hz, --autosave-s,
 * --checkpoint-s or --undo-mb with a place in s, moving *i past its value. */
cli_opt_t cli_session_option(const char *cmd, const cli_session_t *s, int argc, char **argv,
                             int *i);

/* argv[*i]'s value, moving *i past it; NULL when none is left (said on stderr as
 * "argil <cmd>: <option> needs <needs> (see --help)"). */
const char *cli_value(const char *cmd, const char *needs, int argc, char **argv, int *i);

/* A flag: its word sets the bool at offset at of the options to value. */
typedef struct {
    const char *name;
    size_t at;
    bool value;
} cli_flag_t;

/* An option of count numbers in lo … hi, into the doubles at offset at of the options; whole
 * numbers only when whole. */
typedef struct {
    const char *name;
    double lo, hi;
    size_t at;
    int count;
    bool whole;
} cli_number_t;

/* Takes the option argv[*i] as n says (its name matched) into opts, moving *i past its numbers;
 * a bad one is said on stderr. */
cli_opt_t cli_numbers(const char *cmd, const cli_number_t *n, void *opts, int argc, char **argv,
                      int *i);

/* An option whose value is taken as it is, into the const char * at offset at of the options. */
typedef struct {
    const char *name;
    size_t at;
} cli_word_t;

/* A command line as cli_parse reads it into a command's options struct: -h/--help, the flags,
 * numbers and words of the tables, -o FILE, the command's other options and at most one input. */
typedef struct {
    const char *name;               /* "fit": every message starts "argil fit: " */
    void (*usage)(FILE *f);         /* the text of --help */
    const cli_flag_t *flags;
    size_t n_flags;
    const cli_number_t *numbers;
    size_t n_numbers;
    const cli_word_t *words;
    size_t n_words;
    /* The command's other options (NULL: none): argv[*i], moving *i past any value taken. */
    cli_opt_t (*option)(void *opts, int argc, char **argv, int *i);
    const char *out_needs;          /* -o FILE is an option when set: what it lacks without one */
    size_t out;                     /* where -o's value goes (a const char *) */
    bool inputs;                    /* a word that is no option is the input (else unknown) */
    size_t input;                   /* where it goes (a const char *) */
    bool dash_is_input;             /* a lone "-" is an input, not an unknown option */
    /* Says on stderr why a second input a is refused after first (NULL: "more than one
     * input ('a')"). */
    void (*second_input)(const char *first, const char *a);
} cli_cmd_t;

/* Reads argv into opts as cmd says. Sets *done after -h or --help (the usage printed on stdout,
 * exit status 0) and after a usage error (said in one line on stderr, exit status 2,
 * ARGIL_ERR_ARG); otherwise the command goes on. */
argil_err_t cli_parse(const cli_cmd_t *cmd, void *opts, int argc, char **argv, bool *done,
                      int *exit_status);

#endif
