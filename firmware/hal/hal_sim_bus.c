/* The sim bus of the Linux board backend (hal_sim_bus.h): the in-process simulated arm in place
 * of SocketCAN and libgpiod. The only file of firmware/ that includes sim/. */
#include "hal_sim_bus.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/gpio_lines.h"
#include "sim/sim_device.h"

/* The simulated arm as a GPIO chip with the default line names. */
typedef struct {
    const char *name;
    uint32_t bit;
    bool output;
} sim_line_t;

static const sim_line_t sim_lines[] = {
    {"ESTOP_N", GPIO_IN_ESTOP_N, false},         {"DRIVE_FAULT_N", GPIO_IN_DRIVE_FAULT_N, false},
    {"STYLUS_BTN1", GPIO_IN_STYLUS_BTN1, false}, {"STYLUS_BTN2", GPIO_IN_STYLUS_BTN2, false},
    {"DRIVE_ENABLE", GPIO_OUT_DRIVE_ENABLE, true}, {"STATUS_LED", GPIO_OUT_STATUS_LED, true},
    {"WDOG_KICK", GPIO_OUT_WDOG_KICK, true},
};
#define SIM_CHIP "argil-sim"

static void *sim_chip_open(void *ctx, const char *chip)
{
    return strcmp(chip, SIM_CHIP) == 0 || strcmp(chip, "gpiochip0") == 0 ? ctx : NULL;
}

static void sim_chip_close(void *ctx, void *chip)
{
    (void)ctx;
    (void)chip;
}

static void *sim_line_find(void *ctx, void *chip, const char *name)
{
    (void)ctx;
    (void)chip;
    for (size_t i = 0; i < sizeof(sim_lines) / sizeof(sim_lines[0]); i++)
        if (strcmp(sim_lines[i].name, name) == 0)
            return (void *)&sim_lines[i];
    return NULL;
}

static int sim_request_in(void *ctx, void *line, const char *consumer)
{
    (void)ctx;
    (void)consumer;
    return ((const sim_line_t *)line)->output ? -1 : 0;
}

static int sim_request_out(void *ctx, void *line, const char *consumer, int level)
{
    (void)consumer;
    const sim_line_t *l = line;
    if (!l->output)
        return -1;
    hal_t *h = ctx;
    h->sim_gpio_out = level ? (h->sim_gpio_out | l->bit) : (h->sim_gpio_out & ~l->bit);
    return 0;
}

static int sim_get(void *ctx, void *line)
{
    hal_t *h = ctx;
    return (sim_device_gpio_in(h->sim) & ((const sim_line_t *)line)->bit) ? 1 : 0;
}

static int sim_set(void *ctx, void *line, int level)
{
    return sim_request_out(ctx, line, NULL, level);
}

static void sim_release(void *ctx, void *line)
{
    (void)ctx;
    (void)line;
}

static const gpio_ops_t sim_gpio_ops = {sim_chip_open, sim_chip_close, sim_line_find,
                                        sim_request_in, sim_request_out, sim_get,
                                        sim_set, sim_release};

argil_err_t hal_linux_open_sim(hal_t *h, const gpio_names_t *names, uint32_t tick_us, char *err,
                               size_t err_len)
{
    argil_err_t rc = hal_linux_reset(h, HAL_BUS_SIM);
    if (rc != ARGIL_OK)
        return rc;
    h->tick_us = tick_us;
    h->sim = calloc(1, sizeof(*h->sim));
    if (h->sim == NULL) {
        snprintf(err, err_len, "simulated arm: out of memory");
        return ARGIL_ERR_NOMEM;
    }
    sim_params_t sp;
    sim_params_default(&sp);
    sim_device_init(h->sim, &sp);
    sim_device_release_hand(h->sim);
    rc = gpio_port_open(&h->gpio, &sim_gpio_ops, h, names, err, err_len);
    if (rc != ARGIL_OK) {
        free(h->sim);
        h->sim = NULL;
    }
    return rc;
}

void hal_sim_bus_close(hal_t *h)
{
    free(h->sim);
    h->sim = NULL;
}

void hal_sim_bus_step(hal_t *h, can_batch_t *rx)
{
    sim_device_step(h->sim, &h->sim_from_board, h->sim_gpio_out, rx, h->tick_us);
    h->sim_from_board.n = 0;
}
