/* A Linux GPIO chip's lines by name, for every program that drives a real one: the board's
 * named lines (their default names and the bit order of shared/gpio_lines.h) and the chip
 * access, through gpio_ops_t so tests run against a fake chip; gpio_gpiod.c is the libgpiod 1.6
 * implementation. Linux only (hosted): argil-board's HAL and argil-sim use it. */
#ifndef ARGIL_GPIO_CHIP_H
#define ARGIL_GPIO_CHIP_H

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

/* The board's line names as the rigs wire them: chip gpiochip0, ESTOP_N … WDOG_KICK. */
void gpio_names_default(gpio_names_t *n);

/* The libgpiod 1.6 implementation of gpio_ops_t (gpio_gpiod.c); ctx is unused. */
extern const gpio_ops_t gpio_ops_gpiod;

#endif
