/* The board's named GPIO lines on a Linux GPIO chip: looked up by name at start, read and
 * driven every tick as GPIO_IN_* / GPIO_OUT_* level words (shared/gpio_lines.h). The chip
 * access goes through gpio_ops_t so tests run the mapping against a fake chip; gpio_gpiod.c
 * is the libgpiod 1.6 implementation. Linux only (hosted). */
#ifndef ARGIL_GPIO_PORT_H
#define ARGIL_GPIO_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"

#define GPIO_NAME_LEN 32u
#define GPIO_IN_COUNT 4u               /* ESTOP_N, DRIVE_FAULT_N, STYLUS_BTN1, STYLUS_BTN2 */
#define GPIO_OUT_COUNT 3u              /* DRIVE_ENABLE, STATUS_LED, WDOG_KICK */

/* Line names, in the bit order of GPIO_IN_* and GPIO_OUT_*. */
typedef struct {
    char chip[GPIO_NAME_LEN];          /* "gpiochip0", "/dev/gpiochip0", a label or a number */
    char in[GPIO_IN_COUNT][GPIO_NAME_LEN];
    char out[GPIO_OUT_COUNT][GPIO_NAME_LEN];
} gpio_names_t;

/* Chip access. Handles are opaque; every call returns at once. */
typedef struct {
    void *(*chip_open)(void *ctx, const char *chip);
    void (*chip_close)(void *ctx, void *chip);
    void *(*line_find)(void *ctx, void *chip, const char *name);  /* NULL: no such line */
    int (*line_request_input)(void *ctx, void *line, const char *consumer);  /* 0 = ok */
    int (*line_request_output)(void *ctx, void *line, const char *consumer, int level);
    int (*line_get)(void *ctx, void *line);                      /* 0/1, < 0 error */
    int (*line_set)(void *ctx, void *line, int level);           /* 0 = ok */
    void (*line_release)(void *ctx, void *line);
} gpio_ops_t;

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

void gpio_names_default(gpio_names_t *n);

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

/* The libgpiod 1.6 implementation of gpio_ops_t (gpio_gpiod.c); ctx is unused. */
extern const gpio_ops_t gpio_ops_gpiod;

#endif
