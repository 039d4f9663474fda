/* libFuzzer target: the session-script parser must refuse any malformed text with a message
 * naming the line, and whatever it accepts must play to the end within its stated duration. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/script.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    script_t s;
    script_init(&s);
    char err[256] = "";
    const script_err_t e = script_parse(&s, (const char *)data, size, err, sizeof(err));
    if (script_err_argil(e) == ARGIL_ERR_PARSE && strncmp(err, "line ", 5) != 0)
        abort(); /* every refusal names its line */
    if (e == SCRIPT_OK) {
        const float total = script_duration_s(&s);
        if (!(total >= 0.0f) || total > SCRIPT_MAX_SECONDS)
            abort();
        if (total < 5.0f) {
            /* Play it: it must finish within its duration (plus one tick per command). */
            script_player_t p;
            script_player_init(&p, &s, vec3(0, 0, 0));
            const long limit = (long)(total * 1000.0f) + (long)s.count + 2;
            long ticks = 0;
            while (!script_player_step(&p, 0.001f)) {
                if (++ticks > limit)
                    abort();
                /* The session's part of the contract: an undo or redo the player reached is
                 * done or refused before the next step (here: refused at once). */
                p.history_op = 0;
            }
        }
    }
    script_free(&s);
    return 0;
}
