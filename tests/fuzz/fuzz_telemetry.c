/* libFuzzer target for the telemetry CSV reader behind `argil plot`: any bytes as a file; a
 * refusal is one line naming the file, an accepted log holds finite, time-ordered rows whose
 * contact flags, when the column is there, are 0 or 1, and whose chatter figure is finite. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "host/render/chatter.h"
#include "host/render/telemetry_log.h"
#include "tests/fuzz/fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (fuzz_write_temp(data, size, "telemetry", path)) {
        telemetry_log_t log;
        char err[512];
        err[0] = '\0';
        const telemetry_err_t e = telemetry_log_read(path, &log, err, sizeof(err));
        if (e == TELEMETRY_OK) {
            for (size_t i = 0; i < log.n; i++) {
                if (!isfinite(log.time_s[i]) || !isfinite(log.force_mag_n[i]))
                    abort();
                for (int k = 0; k < 3; k++)
                    if (!isfinite(log.pos_mm[3 * i + k]) || !isfinite(log.force_n[3 * i + k]))
                        abort();
                if (log.state[i] >= log.n_states)
                    abort();
                if (log.contact != NULL && log.contact[i] > 1)
                    abort();
            }
            /* The chatter figure of any accepted log is finite and counts within the log. */
            chatter_t ch;
            if (chatter_measure(&log, &ch, NULL) == ARGIL_OK &&
                (!isfinite(ch.rms_n) || ch.contact_ticks > log.n ||
                 ch.steps + ch.first_contact_steps >= log.n ||
                 ch.rows_per_window < 1 || ch.rows_per_window > log.n))
                abort();
            telemetry_log_free(&log);
        }
        else if (!fuzz_error_names_file(err, path))
            abort(); /* every error is one line naming the file */
    }
    unlink(path);
    return 0;
}
