/* The board's named GPIO lines on a Linux GPIO chip: looked up by name at start, read and
 * driven every tick as GPIO_IN_* / GPIO_OUT_* level words (shared/gpio_lines.h). The chip
 * access goes through bus/gpio_chip.h's gpio_ops_t. Linux only (hosted). */
#ifndef ARGIL_GPIO_PORT_H
#define ARGIL_GPIO_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bus/gpio_chip.h"
#include "shared/argil_err.h"

typedef struct {
    const gpio_ops_t *ops;
    void *ctx;
    void *chip;
    void *in[GPIO_IN_COUNT];
    void *out[GPIO_OUT_COUNT];
    uint32_t out_levels;               /* last levels written */
    uint32_t read_errors;
    uint32_t write_errors;
} gpio_port_t;

/* Opens the chip and requests every line by name: inputs as inputs, outputs as outputs driven
 * low (drives disabled, LED off). On failure writes one line into err naming the chip or line
 * and returns ARGIL_ERR_IO; nothing stays requested. */
argil_err_t gpio_port_open(gpio_port_t *p, const gpio_ops_t *ops, void *ctx,
                           const gpio_names_t *names, char *err, size_t err_len);

/* Input levels as GPIO_IN_* bits. A line that cannot be read reads low, which for ESTOP_N and
 * DRIVE_FAULT_N means "pressed" / "faulted": a broken read is never taken as healthy. */
uint32_t gpio_port_read(gpio_port_t *p);

/* Drives the outputs to GPIO_OUT_* levels (only lines whose level changed are written). */
void gpio_port_write(gpio_port_t *p, uint32_t levels);

/* Drives every output low and releases every line. */
void gpio_port_close(gpio_port_t *p);

#endif
