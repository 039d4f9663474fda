/* The board's 1 kHz tick: sense → kinematics → force mapping on the local window → local
 * window step → safety → actuate → telemetry. Fixed allocation: board_t holds everything. The
 * tick sees the world only through board_in_t / board_out_t; board_hal.c moves those through
 * the HAL. */
#ifndef ARGIL_BOARD_H
#define ARGIL_BOARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "drives.h"
#include "haptics.h"
#include "safety.h"
#include "shared/arm_kin.h"
#include "shared/canopen.h"
#include "shared/proto.h"
#include "window.h"

#define BOARD_LINK_TX_MAX 8192u        /* bytes of frames one tick may send */
#define BOARD_IMPULSE_FRAMES_MAX 4u    /* IMPULSE frames per flush; the rest waits a tick */

typedef struct {
    uint32_t tick_us;                  /* loop period (1000 at 1 kHz) */
    float max_force_n;                 /* hard limit on the force to the hand (3.3 N) */
    uint32_t impulse_period_us;        /* how often impulses go to the host (5 ms) */
    uint32_t heartbeat_period_us;      /* board heartbeat (10 ms) */
    uint32_t crossfade_ticks;          /* force cross-fade after a window swap */
    float velocity_filter;             /* 0…1: weight of the newest velocity sample */
    safety_cfg_t safety;
    drives_cfg_t drives;
    arm_desc_t arm;
    char name[PROTO_NAME_LEN];
} board_cfg_t;

typedef struct {
    const can_batch_t *can_rx;         /* frames from the drives since the last tick */
    uint32_t gpio_in;                  /* GPIO_IN_* levels */
    const uint8_t *link_rx;            /* whole frames from the host, back to back */
    size_t link_rx_len;
    uint32_t prev_compute_ns;          /* measured compute time of the previous tick */
} board_in_t;

typedef struct {
    can_batch_t can_tx;
    uint32_t gpio_out;                 /* GPIO_OUT_* levels */
    uint8_t link_tx[BOARD_LINK_TX_MAX];
    size_t link_tx_len;
} board_out_t;

typedef struct {
    uint32_t ticks;
    uint32_t deadline_misses;
    uint32_t worst_compute_ns;
    uint32_t link_frames_rx;
    uint32_t link_errors;              /* frames the decoder refused */
    uint32_t link_tx_dropped;          /* frames that did not fit in a tick's output */
    uint32_t windows_swapped;
    float peak_force_n;
    proto_err_t last_link_error;
} board_stats_t;

typedef struct {
    board_cfg_t cfg;
    safety_t safety;
    drives_t drives;
    window_t window;
    haptics_t haptics;
    msg_tool_t tool;
    bool tool_valid;
    float impulse_ns[ARGIL_WINDOW_SAMPLES_MAX]; /* accumulated ∫f dt per active window node */
    bool impulse_pending;
    uint32_t impulse_seq;
    uint32_t tx_seq;
    uint64_t time_us;
    uint32_t since_impulse_us;
    uint32_t since_heartbeat_us;
    bool hello_due;
    bool fault_reported;
    bool wdog_level;
    uint32_t host_window_version;      /* newest version the host says it sent */
    bool have_tip;
    vec3_t tip_device_m;
    vec3_t pos_m;                      /* tool, model space */
    vec3_t vel_m_s;
    vec3_t force_n;                    /* rendered this tick, model space */
    vec3_t fade_from_n;                /* force at the last window swap */
    uint32_t fade_left;
    bool contact;
    bool sculpting;
    board_stats_t stats;
    proto_msg_t scratch;               /* one decoded or outgoing message (a WINDOW chunk is ~1 KiB) */
} board_t;

void board_cfg_default(board_cfg_t *cfg);

/* Prepares the board; returns ARGIL_ERR_ARG for a configuration out of range. */
argil_err_t board_init(board_t *b, const board_cfg_t *cfg);

/* Runs one tick. Never blocks; bounded work. */
void board_tick(board_t *b, const board_in_t *in, board_out_t *out);

/* Model-space tool position from a device-space tip under the current tool transform. */
vec3_t board_device_to_model(const board_t *b, vec3_t device_m);

#endif
