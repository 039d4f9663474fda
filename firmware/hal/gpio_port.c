/* Named GPIO lines <-> GPIO_IN_* / GPIO_OUT_* words, through gpio_ops_t. */
#include "gpio_port.h"

#include <stdio.h>
#include <string.h>

#include "shared/gpio_lines.h"

#define CONSUMER "argil-board"

static const uint32_t in_bits[GPIO_IN_COUNT] = {GPIO_IN_ESTOP_N, GPIO_IN_DRIVE_FAULT_N,
                                                GPIO_IN_STYLUS_BTN1, GPIO_IN_STYLUS_BTN2};
static const uint32_t out_bits[GPIO_OUT_COUNT] = {GPIO_OUT_DRIVE_ENABLE, GPIO_OUT_STATUS_LED,
                                                  GPIO_OUT_WDOG_KICK};

static void release_all(gpio_port_t *p)
{
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++) {
        if (p->out[i]) {
            (void)p->ops->line_set(p->ctx, p->out[i], 0);
            p->ops->line_release(p->ctx, p->out[i]);
            p->out[i] = NULL;
        }
    }
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++) {
        if (p->in[i]) {
            p->ops->line_release(p->ctx, p->in[i]);
            p->in[i] = NULL;
        }
    }
    if (p->chip) {
        p->ops->chip_close(p->ctx, p->chip);
        p->chip = NULL;
    }
}

argil_err_t gpio_port_open(gpio_port_t *p, const gpio_ops_t *ops, void *ctx,
                           const gpio_names_t *names, char *err, size_t err_len)
{
    memset(p, 0, sizeof(*p));
    p->ops = ops;
    p->ctx = ctx;
    p->chip = ops->chip_open(ctx, names->chip);
    if (p->chip == NULL) {
        snprintf(err, err_len, "GPIO chip '%s' not found (check the gpio chip setting; "
                 "gpiodetect lists the chips)", names->chip);
        return ARGIL_ERR_IO;
    }
    for (uint32_t i = 0; i < GPIO_IN_COUNT + GPIO_OUT_COUNT; i++) {
        const bool is_in = i < GPIO_IN_COUNT;
        const char *name = is_in ? names->in[i] : names->out[i - GPIO_IN_COUNT];
        void *line = ops->line_find(ctx, p->chip, name);
        if (line == NULL) {
            snprintf(err, err_len, "GPIO line '%s' not found on chip '%s' (gpioinfo %s lists "
                     "its line names)", name, names->chip, names->chip);
            release_all(p);
            return ARGIL_ERR_IO;
        }
        const int rc = is_in ? ops->line_request_input(ctx, line, CONSUMER)
                             : ops->line_request_output(ctx, line, CONSUMER, 0);
        if (rc != 0) {
            snprintf(err, err_len, "GPIO line '%s' on chip '%s' cannot be requested as %s "
                     "(in use by another program?)", name, names->chip, is_in ? "input" : "output");
            ops->line_release(ctx, line);
            release_all(p);
            return ARGIL_ERR_IO;
        }
        if (is_in)
            p->in[i] = line;
        else
            p->out[i - GPIO_IN_COUNT] = line;
    }
    p->out_levels = 0;
    return ARGIL_OK;
}

uint32_t gpio_port_read(gpio_port_t *p)
{
    uint32_t levels = 0;
    for (uint32_t i = 0; i < GPIO_IN_COUNT; i++) {
        const int v = p->ops->line_get(p->ctx, p->in[i]);
        if (v < 0)
            p->read_errors++;
        else if (v > 0)
            levels |= in_bits[i];
    }
    return levels;
}

void gpio_port_write(gpio_port_t *p, uint32_t levels)
{
    for (uint32_t i = 0; i < GPIO_OUT_COUNT; i++) {
        const uint32_t bit = out_bits[i];
        if (((levels ^ p->out_levels) & bit) == 0)
            continue;
        if (p->ops->line_set(p->ctx, p->out[i], (levels & bit) ? 1 : 0) != 0)
            p->write_errors++;
        else
            p->out_levels = (p->out_levels & ~bit) | (levels & bit);
    }
}

void gpio_port_close(gpio_port_t *p)
{
    if (p->ops)
        release_all(p);
}
