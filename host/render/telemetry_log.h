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

/* Reads path. Columns are found by the header's names (time_s x_mm y_mm z_mm fx_n fy_n fz_n
 * force_n state are required; contact is read when present, as 0 or 1; others are skipped). ARGIL_ERR_PARSE with "<path>: line N: why",
 * ARGIL_ERR_IO, ARGIL_ERR_NOMEM; log is empty on error. */
argil_err_t telemetry_log_read(const char *path, telemetry_log_t *log, char *err, size_t err_len);

void telemetry_log_free(telemetry_log_t *log);

#endif
