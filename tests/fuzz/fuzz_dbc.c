/* libFuzzer target: the DBC reader of tests/unit/dbc_parser.h (and its candump-line reader) must
 * refuse any input with a reason and a line, never crash or read out of bounds; whatever it
 * accepts must decode every signal of a frame within the frame. */
#include <stddef.h>
#include <stdint.h>

#include "tests/unit/dbc_parser.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static dbc_t d;
    uint32_t line = 0;
    if (dbc_parse(&d, (const char *)data, size, &line) == DBC_OK) {
        const uint8_t frame[8] = {0x27, 0x00, 0xE8, 0x03, 0x00, 0x00, 0xF4, 0x01};
        for (uint32_t i = 0; i < d.n_messages; i++) {
            const dbc_message_t *m = &d.msg[i];
            if (m->dlc > 8u || m->n_signals > DBC_SIGNALS_MAX)
                __builtin_trap();
            for (uint8_t j = 0; j < m->n_signals; j++) {
                if (m->sig[j].start_bit + m->sig[j].length > m->dlc * 8u)
                    __builtin_trap();
                (void)dbc_physical(&m->sig[j], frame);
            }
        }
    } else if (line == 0) {
        __builtin_trap(); /* an error always names its line */
    }
    can_frame_t f;
    if (dbc_candump_line((const char *)data, size, &f) == DBC_OK && f.len > 8u)
        __builtin_trap();
    return 0;
}
