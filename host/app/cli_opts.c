/* The argil commands' command lines: option values argil sculpt and argil connect share, and
 * the reading of a command line by tables of flags, numbers and words. */
#include "host/app/cli_opts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/session_undo.h"

bool cli_global_solve(const char *v, peer_global_solve_t *out)
{
    if (!v || (strcmp(v, "bspline") != 0 && strcmp(v, "springs") != 0))
        return false;
    *out = v[0] == 'b' ? PEER_SOLVE_BSPLINE : PEER_SOLVE_SPRINGS;
    return true;
}

bool cli_knot_ratio(const char *v, int *out)
{
    if (!v || (strcmp(v, "1") != 0 && strcmp(v, "2") != 0 && strcmp(v, "4") != 0))
        return false;
    *out = v[0] - '0';
    return true;
}

bool cli_rate_hz(const char *v, uint32_t *tick_us)
{
    if (!v || (strcmp(v, "1000") != 0 && strcmp(v, "2000") != 0 && strcmp(v, "4000") != 0))
        return false;
    *tick_us = 1000000u / (uint32_t)atoi(v);
    return true;
}

bool cli_autosave_s(const char *v, float *out)
{
    char *end = NULL;
    const double sec = v ? strtod(v, &end) : 0.0;
    if (!v || end == v || *end != '\0' || !(sec >= 0.001 && sec <= 3600.0))
        return false;
    *out = (float)sec;
    return true;
}

const char *cli_global_solve_text(peer_global_solve_t gs)
{
    return gs == PEER_SOLVE_BSPLINE ? "B-spline model (implicit)" : "density springs (explicit)";
}

bool cli_undo_mb(const char *v, uint32_t *mb)
{
    char *end = NULL;
    const long n = v ? strtol(v, &end, 10) : -1;
    if (!v || v[0] == '\0' || *end != '\0' || n < 0 || n > (long)SESSION_UNDO_MB_MAX)
        return false;
    *mb = (uint32_t)n;
    return true;
}

cli_opt_t cli_session_option(const char *cmd, const cli_session_t *s, int argc, char **argv,
                             int *i)
{
    const char *a = argv[*i];
    const char *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    const char *expects = NULL, *tail = ""; /* a refused value: what the option needs */
    if (strcmp(a, "--global-solve") == 0 && s->global_solve) {
        if (!cli_global_solve(v, s->global_solve))
            expects = CLI_GLOBAL_SOLVE_EXPECTS;
        else if (s->global_solve_given)
            *s->global_solve_given = true;
    } else if (strcmp(a, "--knot-ratio") == 0 && s->knot_ratio) {
        if (!cli_knot_ratio(v, s->knot_ratio))
            expects = CLI_KNOT_RATIO_EXPECTS;
    } else if (strcmp(a, "--rate-hz") == 0 && s->tick_us) {
        if (!cli_rate_hz(v, s->tick_us))
            expects = CLI_RATE_HZ_EXPECTS;
    } else if ((strcmp(a, "--autosave-s") == 0 && s->autosave_s) ||
               (strcmp(a, "--checkpoint-s") == 0 && s->checkpoint_s)) {
        if (!cli_autosave_s(v, a[2] == 'a' ? s->autosave_s : s->checkpoint_s)) {
            expects = CLI_AUTOSAVE_EXPECTS;
            tail = " (see --help)";
        }
    } else if (strcmp(a, "--undo-mb") == 0 && s->undo_mb) {
        if (!cli_undo_mb(v, s->undo_mb)) {
            fprintf(stderr, "argil %s: --undo-mb needs MiB 0..%u (0: no undo)\n", cmd,
                    SESSION_UNDO_MB_MAX);
            return CLI_OPT_BAD;
        }
    } else {
        return CLI_OPT_OTHER;
    }
    if (expects) {
        fprintf(stderr, "argil %s: %s needs %s%s\n", cmd, a, expects, tail);
        return CLI_OPT_BAD;
    }
    (*i)++;
    return CLI_OPT_TAKEN;
}

const char *cli_value(const char *cmd, const char *needs, int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "argil %s: %s needs %s (see --help)\n", cmd, argv[*i], needs);
        return NULL;
    }
    return argv[++*i];
}

/* The member at offset at of the options struct opts. */
static void *member(void *opts, size_t at)
{
    return (char *)opts + at;
}

cli_opt_t cli_numbers(const char *cmd, const cli_number_t *n, void *opts, int argc, char **argv,
                      int *i)
{
    double *dst = member(opts, n->at);
    for (int j = 0; j < n->count; j++) {
        const char *v = *i + 1 + j < argc ? argv[*i + 1 + j] : NULL;
        char *end;
        const double d = v != NULL ? strtod(v, &end) : 0;
        if (v == NULL || end == v || *end != '\0' || !(d >= n->lo && d <= n->hi)) {
            fprintf(stderr, "argil %s: %s needs a number from %g to %g, got '%s'\n", cmd,
                    n->name, n->lo, n->hi, v != NULL ? v : "");
            return CLI_OPT_BAD;
        }
        dst[j] = d;
        if (n->whole && d != floor(d)) {
            fprintf(stderr, "argil %s: %s needs a whole number\n", cmd, n->name);
            return CLI_OPT_BAD;
        }
    }
    *i += n->count;
    return CLI_OPT_TAKEN;
}

/* Takes argv[*i] into opts when the tables of cmd name it; a bad value is said on stderr. */
static cli_opt_t take_table_option(const cli_cmd_t *cmd, void *opts, int argc, char **argv,
                                   int *i)
{
    const char *a = argv[*i];
    for (size_t k = 0; k < cmd->n_flags; k++)
        if (strcmp(a, cmd->flags[k].name) == 0) {
            *(bool *)member(opts, cmd->flags[k].at) = cmd->flags[k].value;
            return CLI_OPT_TAKEN;
        }
    for (size_t k = 0; k < cmd->n_words; k++)
        if (strcmp(a, cmd->words[k].name) == 0) {
            const char *v = cli_value(cmd->name, "a value", argc, argv, i);
            if (v == NULL)
                return CLI_OPT_BAD;
            *(const char **)member(opts, cmd->words[k].at) = v;
            return CLI_OPT_TAKEN;
        }
    for (size_t k = 0; k < cmd->n_numbers; k++)
        if (strcmp(a, cmd->numbers[k].name) == 0)
            return cli_numbers(cmd->name, &cmd->numbers[k], opts, argc, argv, i);
    return CLI_OPT_OTHER;
}

/* Takes argv[*i], which is no option of cmd's: the input into opts, or an unknown option
 * (said). */
static argil_err_t take_input(const cli_cmd_t *cmd, void *opts, const char *a)
{
    if (!cmd->inputs || (a[0] == '-' && !(cmd->dash_is_input && a[1] == '\0'))) {
        fprintf(stderr, "argil %s: unknown option '%s' (see --help)\n", cmd->name, a);
        return ARGIL_ERR_ARG;
    }
    const char **input = member(opts, cmd->input);
    if (*input == NULL) {
        *input = a;
        return ARGIL_OK;
    }
    if (cmd->second_input)
        cmd->second_input(*input, a);
    else
        fprintf(stderr, "argil %s: more than one input ('%s')\n", cmd->name, a);
    return ARGIL_ERR_ARG;
}

/* Takes the word argv[*i] of cmd's command line into opts, moving *i past any value. */
static argil_err_t take_word(const cli_cmd_t *cmd, void *opts, int argc, char **argv, int *i)
{
    const char *a = argv[*i];
    cli_opt_t r = CLI_OPT_OTHER;
    if (cmd->out_needs != NULL && strcmp(a, "-o") == 0) {
        const char **out = member(opts, cmd->out);
        *out = cli_value(cmd->name, cmd->out_needs, argc, argv, i);
        r = *out != NULL ? CLI_OPT_TAKEN : CLI_OPT_BAD;
    }
    if (r == CLI_OPT_OTHER)
        r = take_table_option(cmd, opts, argc, argv, i);
    if (r == CLI_OPT_OTHER && cmd->option != NULL)
        r = cmd->option(opts, argc, argv, i);
    if (r == CLI_OPT_OTHER)
        return take_input(cmd, opts, a);
    return r == CLI_OPT_BAD ? ARGIL_ERR_ARG : ARGIL_OK;
}

argil_err_t cli_parse(const cli_cmd_t *cmd, void *opts, int argc, char **argv, bool *done,
                      int *exit_status)
{
    *done = true;
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            cmd->usage(stdout);
            *exit_status = 0;
            return ARGIL_OK;
        }
        if (take_word(cmd, opts, argc, argv, &i) != ARGIL_OK) {
            *exit_status = 2;
            return ARGIL_ERR_ARG;
        }
    }
    *done = false;
    return ARGIL_OK;
}
