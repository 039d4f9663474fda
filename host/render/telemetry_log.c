/* telemetry.csv reader (see telemetry_log.h). */
#include "host/render/telemetry_log.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Required columns, then the optional ones (COL_REQUIRED..COL_COUNT-1: -1 when absent). */
enum { COL_T, COL_X, COL_Y, COL_Z, COL_FX, COL_FY, COL_FZ, COL_F, COL_STATE, COL_CONTACT,
       COL_COUNT, COL_REQUIRED = COL_CONTACT };
enum { LINE_MAX_CHARS = 1024, FIELDS_MAX = 64 };

static const char *const COL_NAMES[COL_COUNT] = {"time_s", "x_mm", "y_mm", "z_mm", "fx_n",
                                                  "fy_n", "fz_n", "force_n", "state",
                                                  "contact"};

argil_err_t telemetry_err_argil(telemetry_err_t e)
{
    switch (e) {
    case TELEMETRY_OK: return ARGIL_OK;
    case TELEMETRY_ERR_IO: return ARGIL_ERR_IO;
    case TELEMETRY_ERR_NOMEM: return ARGIL_ERR_NOMEM;
    default: return ARGIL_ERR_PARSE;
    }
}

void telemetry_log_free(telemetry_log_t *log)
{
    free(log->time_s);
    free(log->pos_mm);
    free(log->force_n);
    free(log->force_mag_n);
    free(log->state);
    free(log->contact);
    memset(log, 0, sizeof(*log));
}

/* Splits line at commas in place (trailing CR/LF removed); returns the field count, or -1 when
 * there are more than FIELDS_MAX. */
static int split(char *line, char *fields[FIELDS_MAX])
{
    line[strcspn(line, "\r\n")] = '\0';
    int n = 0;
    char *p = line;
    for (;;) {
        if (n == FIELDS_MAX)
            return -1;
        fields[n++] = p;
        char *c = strchr(p, ',');
        if (c == NULL)
            return n;
        *c = '\0';
        p = c + 1;
    }
}

static argil_err_t grow(telemetry_log_t *log, size_t *cap, bool with_contact)
{
    const size_t nc = *cap ? *cap * 2 : 4096;
    double *t = realloc(log->time_s, nc * sizeof(*t));
    if (t) log->time_s = t;
    float *p = realloc(log->pos_mm, nc * 3 * sizeof(*p));
    if (p) log->pos_mm = p;
    float *f = realloc(log->force_n, nc * 3 * sizeof(*f));
    if (f) log->force_n = f;
    float *m = realloc(log->force_mag_n, nc * sizeof(*m));
    if (m) log->force_mag_n = m;
    uint8_t *s = realloc(log->state, nc);
    if (s) log->state = s;
    uint8_t *k = with_contact ? realloc(log->contact, nc) : NULL;
    if (k) log->contact = k;
    if (!t || !p || !f || !m || !s || (with_contact && !k))
        return ARGIL_ERR_NOMEM;
    *cap = nc;
    return ARGIL_OK;
}

static telemetry_err_t parse_row(telemetry_log_t *log, char **fields, const int col[COL_COUNT],
                                 const char *path, unsigned line_no, char *err, size_t err_len)
{
    float v[COL_STATE];
    double t = 0.0;
    for (int c = 0; c < COL_STATE; c++) {
        const char *s = fields[col[c]];
        char *end;
        errno = 0;
        const double d = strtod(s, &end);
        if (end == s || *end != '\0' || errno == ERANGE || !isfinite(d) ||
            (c != COL_T && fabs(d) > FLT_MAX)) {
            snprintf(err, err_len, "%s: line %u: %s is not a finite number: '%.32s'", path,
                     line_no, COL_NAMES[c], s);
            return TELEMETRY_ERR_NUMBER;
        }
        if (c == COL_T)
            t = d;
        v[c] = (float)d;
    }
    if (log->n > 0 && t < log->time_s[log->n - 1]) {
        snprintf(err, err_len, "%s: line %u: time_s goes backwards (%.6g after %.6g)", path,
                 line_no, t, log->time_s[log->n - 1]);
        return TELEMETRY_ERR_TIME_BACKWARDS;
    }
    const char *st = fields[col[COL_STATE]];
    if (st[0] == '\0' || strlen(st) >= sizeof(log->state_name[0])) {
        snprintf(err, err_len, "%s: line %u: state '%.32s' is empty or longer than %zu characters",
                 path, line_no, st, sizeof(log->state_name[0]) - 1);
        return TELEMETRY_ERR_STATE;
    }
    int si = 0;
    while (si < log->n_states && strcmp(log->state_name[si], st) != 0)
        si++;
    if (si == log->n_states) {
        if (log->n_states == TELEMETRY_STATES_MAX) {
            snprintf(err, err_len, "%s: line %u: more than %d different states (new: '%s')",
                     path, line_no, TELEMETRY_STATES_MAX, st);
            return TELEMETRY_ERR_STATES_MAX;
        }
        snprintf(log->state_name[si], sizeof(log->state_name[si]), "%s", st);
        log->n_states++;
    }
    if (log->contact != NULL) {
        const char *k = fields[col[COL_CONTACT]];
        if ((k[0] != '0' && k[0] != '1') || k[1] != '\0') {
            snprintf(err, err_len, "%s: line %u: contact is not 0 or 1: '%.32s'", path, line_no,
                     k);
            return TELEMETRY_ERR_CONTACT;
        }
    }
    const size_t i = log->n++;
    log->time_s[i] = t;
    for (int k = 0; k < 3; k++) {
        log->pos_mm[3 * i + (size_t)k] = v[COL_X + k];
        log->force_n[3 * i + (size_t)k] = v[COL_FX + k];
    }
    log->force_mag_n[i] = v[COL_F];
    log->state[i] = (uint8_t)si;
    if (log->contact != NULL)
        log->contact[i] = (uint8_t)(fields[col[COL_CONTACT]][0] - '0');
    return TELEMETRY_OK;
}

telemetry_err_t telemetry_log_read(const char *path, telemetry_log_t *log, char *err,
                                   size_t err_len)
{
    memset(log, 0, sizeof(*log));
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, err_len, "%s: cannot open: %s", path, strerror(errno));
        return TELEMETRY_ERR_IO;
    }
    char line[LINE_MAX_CHARS + 2];
    char *fields[FIELDS_MAX];
    int col[COL_COUNT];
    int n_header = 0;
    unsigned line_no = 0;
    size_t cap = 0;
    telemetry_err_t rc = TELEMETRY_OK;
    while (fgets(line, sizeof(line), f) != NULL) {
        line_no++;
        if (strchr(line, '\n') == NULL && !feof(f)) {
            snprintf(err, err_len, "%s: line %u: longer than %d characters", path, line_no,
                     LINE_MAX_CHARS);
            rc = TELEMETRY_ERR_LINE_LONG;
            break;
        }
        const int n = split(line, fields);
        if (line_no == 1) {
            n_header = n;
            for (int c = 0; c < COL_COUNT && rc == TELEMETRY_OK; c++) {
                col[c] = -1;
                for (int k = 0; k < n && col[c] < 0; k++)
                    if (strcmp(fields[k], COL_NAMES[c]) == 0)
                        col[c] = k;
                if (col[c] < 0 && c < COL_REQUIRED) {
                    snprintf(err, err_len, "%s: line 1: the header has no '%s' column (is this "
                                           "a telemetry.csv?)", path, COL_NAMES[c]);
                    rc = TELEMETRY_ERR_COLUMN;
                }
            }
            if (rc != TELEMETRY_OK)
                break;
            continue;
        }
        if (n == 1 && fields[0][0] == '\0')
            continue; /* a blank line */
        if (n != n_header) {
            snprintf(err, err_len, "%s: line %u: %d fields where the header has %d", path,
                     line_no, n < 0 ? FIELDS_MAX + 1 : n, n_header);
            rc = TELEMETRY_ERR_FIELDS;
            break;
        }
        if (log->n == cap && grow(log, &cap, col[COL_CONTACT] >= 0) != ARGIL_OK) {
            snprintf(err, err_len, "%s: out of memory at line %u", path, line_no);
            rc = TELEMETRY_ERR_NOMEM;
            break;
        }
        rc = parse_row(log, fields, col, path, line_no, err, err_len);
        if (rc != TELEMETRY_OK)
            break;
    }
    if (rc == TELEMETRY_OK && ferror(f)) {
        snprintf(err, err_len, "%s: read error: %s", path, strerror(errno));
        rc = TELEMETRY_ERR_IO;
    }
    fclose(f);
    if (rc == TELEMETRY_OK && line_no == 0) {
        snprintf(err, err_len, "%s: empty file (no header)", path);
        rc = TELEMETRY_ERR_EMPTY;
    } else if (rc == TELEMETRY_OK && log->n == 0) {
        snprintf(err, err_len, "%s: line %u: no data rows after the header", path, line_no);
        rc = TELEMETRY_ERR_NO_ROWS;
    }
    if (rc != TELEMETRY_OK)
        telemetry_log_free(log);
    return rc;
}
