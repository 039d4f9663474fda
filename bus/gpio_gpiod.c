/* gpio_ops_t on libgpiod 1.6 (the v1 API Debian 12 ships). */
#include <gpiod.h>
#include <stddef.h>

#include "gpio_chip.h"

static void *chip_open(void *ctx, const char *chip)
{
    (void)ctx;
    return gpiod_chip_open_lookup(chip);
}

static void chip_close(void *ctx, void *chip)
{
    (void)ctx;
    gpiod_chip_close(chip);
}

static void *line_find(void *ctx, void *chip, const char *name)
{
    (void)ctx;
    return gpiod_chip_find_line(chip, name);
}

static int line_request_input(void *ctx, void *line, const char *consumer)
{
    (void)ctx;
    return gpiod_line_request_input(line, consumer);
}

static int line_request_output(void *ctx, void *line, const char *consumer, int level)
{
    (void)ctx;
    return gpiod_line_request_output(line, consumer, level);
}

static int line_get(void *ctx, void *line)
{
    (void)ctx;
    return gpiod_line_get_value(line);
}

static int line_set(void *ctx, void *line, int level)
{
    (void)ctx;
    return gpiod_line_set_value(line, level);
}

static void line_release(void *ctx, void *line)
{
    (void)ctx;
    if (gpiod_line_is_requested(line))
        gpiod_line_release(line);
}

const gpio_ops_t gpio_ops_gpiod = {chip_open,  chip_close, line_find, line_request_input,
                                   line_request_output, line_get, line_set, line_release};
