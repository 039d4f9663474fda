/* libFuzzer target for the link key file's parser (shared/link_key_text.c): arbitrary bytes as a
 * key file's text. Checked: it never reads past the text; a refusal names a line within it;
 * an accepted key, written back as one line of hex, parses to the same 32 bytes. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/link_key_text.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(int ok)
{
    if (!ok)
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* a copy of exactly size bytes, so ASan sees any read past the text */
    char *text = malloc(size ? size : 1u);
    check(text != NULL);
    memcpy(text, data, size);
    link_key_t key;
    uint32_t line = 0;
    const link_key_err_t e = link_key_parse(text, size, &key, &line);
    size_t lines = 1;
    for (size_t i = 0; i < size; i++)
        lines += text[i] == '\n';
    check(line >= 1 && line <= lines);
    if (e == LINK_KEY_OK) {
        char hex[2u * LINK_KEY_BYTES + 2u];
        for (unsigned i = 0; i < LINK_KEY_BYTES; i++)
            snprintf(hex + 2u * i, 3, "%02x", key.k[i]);
        hex[2u * LINK_KEY_BYTES] = '\n';
        link_key_t again;
        check(link_key_parse(hex, 2u * LINK_KEY_BYTES + 1u, &again, &line) == LINK_KEY_OK);
        check(memcmp(again.k, key.k, LINK_KEY_BYTES) == 0);
    } else {
        check(e == LINK_KEY_ERR_NO_KEY || e == LINK_KEY_ERR_HEX || e == LINK_KEY_ERR_SHORT ||
              e == LINK_KEY_ERR_LONG || e == LINK_KEY_ERR_EXTRA);
    }
    free(text);
    return 0;
}
