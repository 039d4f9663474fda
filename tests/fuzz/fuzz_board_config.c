/* libFuzzer target: argil-board's INI parser must refuse any input with a reason and a line
 * number, never crash or read out of bounds. */
#include <stddef.h>
#include <stdint.h>

#include "firmware/board/board_config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    board_daemon_cfg_t c;
    board_config_default(&c);
    uint32_t line = 0;
    char why[160];
    why[0] = '\0';
    if (board_config_parse_ini(&c, (const char *)data, size, &line, why, sizeof(why)) ==
        BOARD_CONFIG_OK)
        (void)board_config_check(&c, why, sizeof(why));
    return 0;
}
