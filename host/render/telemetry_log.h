/* Reads a session's telemetry.csv (one row per board tick: time_s, x_mm, y_mm, z_mm, fx_n, fy_n,
 * fz_n, force_n, state, …) into columns for plotting and for placing the tool in a view. */
#ifndef ARGIL_TELEMETRY_LOG_H
#define ARGIL_TELEMETRY_LOG_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"

enum { TELEMETRY_STATES_MAX = 8 };

typedef struct {
    size_t n;                   /* rows */
    double *time_s;
    float *pos_mm;              /* x y z per row */
    float *force_n;             /* fx fy fz per row */
    float *force_mag_n;
    uint8_t *state;             /* index into state_name */
    uint8_t *contact;           /* the tool's contact flag, 0 or 1; NULL without the column */
    char state_name[TELEMETRY_STATES_MAX][16];
    int n_states;
} telemetry_log_t;

/* What telemetry_log_read returns: TELEMETRY_OK, the file cannot be opened or read (IO) or
 * memory ran out (NOMEM), or the rule a line broke. */
typedef enum {
    TELEMETRY_OK = 0,
    TELEMETRY_ERR_IO = -1,
    TELEMETRY_ERR_NOMEM = -2,
    TELEMETRY_ERR_EMPTY = -3,          /* no header line */
    TELEMETRY_ERR_COLUMN = -4,         /* the header lacks a required column */
    TELEMETRY_ERR_NO_ROWS = -5,        /* no data row after the header */
    TELEMETRY_ERR_LINE_LONG = -6,      /* a line longer than the reader takes */
    TELEMETRY_ERR_FIELDS = -7,         /* a row's field count differs from the header's */
    TELEMETRY_ERR_NUMBER = -8,         /* a numeric field not a finite float */
    TELEMETRY_ERR_TIME_BACKWARDS = -9, /* time_s below the previous row's */
    TELEMETRY_ERR_STATE = -10,         /* a state empty or longer than 15 characters */
    TELEMETRY_ERR_STATES_MAX = -11,    /* more than TELEMETRY_STATES_MAX different states */
    TELEMETRY_ERR_CONTACT = -12        /* contact neither 0 nor 1 */
} telemetry_err_t;

/* Reads path. Columns are found by the header's names (time_s x_mm y_mm z_mm fx_n fy_n fz_n
 * force_n state are required; contact is read when present, as 0 or 1; others are skipped).
 * Returns the rule a line broke with "<path>: line N: why" in err, IO or NOMEM; log is empty on
 * error. */
telemetry_err_t telemetry_log_read(const char *path, telemetry_log_t *log, char *err,
                                   size_t err_len);

/* The argil_err_t a command reports for e: OK, IO, NOMEM, or PARSE for a broken rule. */
argil_err_t telemetry_err_argil(telemetry_err_t e);

void telemetry_log_free(telemetry_log_t *log);

#endif
