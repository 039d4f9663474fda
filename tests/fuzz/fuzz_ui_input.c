/* libFuzzer target: the live window's scripted-input parser refuses malformed text with a
 * message naming the line, and what it accepts is in time order with values in range. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/render/ui_input.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ui_input_t in;
    ui_input_init(&in);
    char err[256] = "";
    const ui_input_err_t e = ui_input_parse(&in, (const char *)data, size, err, sizeof(err));
    if (e <= UI_INPUT_ERR_LINE_LONG && strncmp(err, "line ", 5) != 0)
        abort();
    if (e != UI_INPUT_OK && in.count != 0)
        abort(); /* nothing half-parsed is kept */
    double last = 0.0;
    for (size_t i = 0; i < in.count; i++) {
        const ui_event_t *ev = &in.ev[i];
        if (!(ev->at_s >= last) || !isfinite(ev->x) || !isfinite(ev->y) ||
            fabs(ev->x) > 1e5 || fabs(ev->y) > 1e5)
            abort();
        last = ev->at_s;
    }
    ui_input_free(&in);
    return 0;
}
