/* The board's named GPIO lines as bits of one input and one output word (levels, not meanings:
 * ESTOP_N and DRIVE_FAULT_N are active low, so bit set = line high = released / healthy). */
#ifndef ARGIL_GPIO_LINES_H
#define ARGIL_GPIO_LINES_H

#define GPIO_IN_ESTOP_N (1u << 0)
#define GPIO_IN_DRIVE_FAULT_N (1u << 1)
#define GPIO_IN_STYLUS_BTN1 (1u << 2)
#define GPIO_IN_STYLUS_BTN2 (1u << 3)

#define GPIO_OUT_DRIVE_ENABLE (1u << 0)
#define GPIO_OUT_STATUS_LED (1u << 1)
#define GPIO_OUT_WDOG_KICK (1u << 2)

#endif
