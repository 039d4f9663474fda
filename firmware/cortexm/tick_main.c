/* Runs the fixed tick sequence and prints one line per tick (semihosting on the MCU, stdout
 * on the host): tick state fault can_frames gpio_out torque0..2 (‰) force x y z (N, %.9g)
 * link_bytes. The same file is the host reference and the Cortex-M image's main. */
#include <stdio.h>

#include "tick_script.h"

static tick_script_t script; /* ~1.2 MiB: static, never on the stack */

int main(void)
{
    if (tick_script_init(&script) != ARGIL_OK) {
        printf("tick script: board_init refused the configuration\n");
        return 1;
    }
    float peak = 0.0f;
    uint32_t active = 0;
    for (uint32_t i = 0; i < TICK_SCRIPT_TICKS; i++) {
        tick_result_t r;
        tick_script_step(&script, &r);
        printf("%u %u %u %u %u %d %d %d %.9g %.9g %.9g %u\n", (unsigned)r.tick, r.state, r.fault,
               r.can_tx, (unsigned)r.gpio_out, r.torque_permille[0], r.torque_permille[1],
               r.torque_permille[2], (double)r.force_n[0], (double)r.force_n[1],
               (double)r.force_n[2], (unsigned)r.link_tx_bytes);
        const float f2 = r.force_n[0] * r.force_n[0] + r.force_n[1] * r.force_n[1] +
                         r.force_n[2] * r.force_n[2];
        if (f2 > peak)
            peak = f2;
        active += r.state == SAFETY_ACTIVE;
    }
    printf("done: %u ticks, %u ACTIVE, peak |F|^2 %.6g N^2, window swaps %u\n",
           (unsigned)TICK_SCRIPT_TICKS, (unsigned)active, (double)peak,
           (unsigned)script.board.stats.windows_swapped);
    return 0;
}
