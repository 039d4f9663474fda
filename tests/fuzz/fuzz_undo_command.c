/* libFuzzer target: the command lines `argil connect` reads on its standard input (undo, redo;
 * session_undo_feed): every byte is taken, an answer is one of the four kinds, and a bad line's
 * text is printable, terminated and within its buffer. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/app/session_undo.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    session_undo_lines_t l;
    memset(&l, 0, sizeof(l));
    for (size_t i = 0; i < size; i++) {
        const session_undo_cmd_t c = session_undo_feed(&l, (char)data[i]);
        if (c != SESSION_UNDO_CMD_BAD && c != SESSION_UNDO_CMD_NONE && c != SESSION_UNDO_CMD_UNDO &&
            c != SESSION_UNDO_CMD_REDO)
            abort();
        if (l.len > sizeof(l.buf))
            abort();
        if (c == SESSION_UNDO_CMD_BAD) {
            const size_t n = strnlen(l.bad, sizeof(l.bad));
            if (n == 0 || n == sizeof(l.bad))
                abort();
            for (size_t k = 0; k < n; k++)
                if (l.bad[k] < 0x20 || l.bad[k] > 0x7e)
                    abort();
        }
        if ((c == SESSION_UNDO_CMD_UNDO || c == SESSION_UNDO_CMD_REDO) && data[i] != '\n')
            abort();
    }
    return 0;
}
