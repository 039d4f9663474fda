/* The board's default line names (bus/gpio_chip.h). */
#include "gpio_chip.h"

#include <string.h>

/* Copies src into a GPIO_NAME_LEN field, cut to fit and NUL-filled. */
static void set_name(char *dst, const char *src)
{
    memset(dst, 0, GPIO_NAME_LEN);
    memcpy(dst, src, strlen(src) < GPIO_NAME_LEN ? strlen(src) : GPIO_NAME_LEN - 1u);
}

void gpio_names_default(gpio_names_t *n)
{
    set_name(n->chip, "gpiochip0");
    set_name(n->in[0], "ESTOP_N");
    set_name(n->in[1], "DRIVE_FAULT_N");
    set_name(n->in[2], "STYLUS_BTN1");
    set_name(n->in[3], "STYLUS_BTN2");
    set_name(n->out[0], "DRIVE_ENABLE");
    set_name(n->out[1], "STATUS_LED");
    set_name(n->out[2], "WDOG_KICK");
}
