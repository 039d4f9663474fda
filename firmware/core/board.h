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
#include "host_session.h"
#include "passivity.h"
#include "rt_stats.h"
#include "velocity.h"
#include "safety.h"
#include "shared/arm_kin.h"
#include "shared/canopen.h"
#include "shared/proto.h"
#include "window.h"

#define BOARD_LINK_TX_MAX 8192u        /* bytes of frames one tick may send */
#define BOARD_IMPULSE_FRAMES_MAX 4u    /* IMPULSE frames per flush; the rest waits a tick */
#define BOARD_IMPULSE_LOG 4096u        /* sent impulses remembered until the host's window has them */
#define BOARD_SUBSTEPS_MAX 8u          /* adaptive step halving: at most 3 halvings */
#define BOARD_DEFER_FRAMES 2u          /* WINDOW frames a tick that sends impulses puts off */
#define BOARD_STALE_POSITION_TICKS 20u /* ticks without a new position before the arm counts as still */
#define BOARD_SETTLE_TICKS 100u        /* the window's springs run this long after the last push */

/* How long a host's ARM waits in FAULT/IDLE for the drives' fault reset to clear a drive trip
 * (EMCY, DRIVE_FAULT_N low); the fault causes are re-checked every tick meanwhile. */
#define BOARD_REARM_WAIT_US 500000u

typedef struct {
    uint32_t tick_us;                  /* loop period (1000 at 1 kHz) */
    float max_force_n;                 /* hard limit on the force to the hand (3.3 N) */
    uint32_t impulse_period_us;        /* how often impulses go to the host (5 ms) */
    uint32_t heartbeat_period_us;      /* board heartbeat (10 ms) */
    uint32_t rt_stats_period_us;       /* RT_STATS to the host (1 s) */
    uint32_t swap_fade_ticks;          /* a window swap's force step fades in over about this
                                        * many ticks: Guo et al.'s exponential weighted average
                                        * with α = 1 − 1/ticks (0: no fade) */
    float contact_damping_n_s_per_m;   /* velocity damping while in contact, b0 */
    float contact_damping_s;           /* … plus this many seconds × the contact stiffness
                                          (board.c shape_force) */
    uint32_t io_delay_ticks;           /* ticks from a force to the motion it acts on (2: CiA 402) */
    float slew_n_per_s;                /* largest change of the force per second */
    bool passivity;                    /* passivity observer + controller (Hannaford & Ryu) */
    float pc_max_damping_n_s_per_m;    /* the passivity controller's largest damping */
    float pc_deadband_j;               /* generated energy tolerated before it damps */
    float joint_margin_rad;            /* soft workspace limit starts this far from a joint limit */
    float joint_limit_stiffness_nm_per_rad;
    float accel_limit;                 /* density-spring |acceleration| (1/s²) that halves the step */
    float velocity_filter;             /* 0…1: weight of the newest velocity sample */
    float velocity_tolerance_m;        /* > 0: the velocity by adaptive windowing (velocity.h),
                                          positions trusted to this; 0: the backward
                                          difference over the last new position */
    float max_velocity_m_s;            /* tool speed (device space) that is a fault; 0 = none */
    bool refuse_arm;                   /* the link cannot tell who sent a frame (UDP without a
                                        * key): ARM commands are refused and counted */
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
    uint32_t prev_wake_ns;             /* its wake-up latency (0 when the caller does not
                                        * sleep on a clock, as in the lockstep simulation) */
    bool prev_compute_preempted;       /* the platform preempted that compute on a clock that
                                        * charged it time not its own (hal_compute_preemptions):
                                        * not timed, counted in stats.preempted_ticks */
    uint32_t link_refused_source;      /* the transport's own refusals so far: datagrams from an
                                        * address other than the session host's (UDP), */
    uint32_t link_refused_no_session;  /* … datagrams with no session to belong to, */
    uint32_t link_refused_bad_mac;     /* … datagrams whose tag did not verify (keyed UDP), */
    uint32_t link_refused_bad_nonce;   /* … and those with another session's nonce */
} board_in_t;

typedef struct {
    can_batch_t can_tx;
    uint32_t gpio_out;                 /* GPIO_OUT_* levels */
    uint8_t link_tx[BOARD_LINK_TX_MAX];
    size_t link_tx_len;
} board_out_t;

#define BOARD_PREEMPTED_KEPT 8u

typedef struct {
    uint32_t ticks;
    uint32_t deadline_misses;          /* timed ticks whose wake-up plus compute passed the period */
    uint32_t deadline_miss_tick[BOARD_PREEMPTED_KEPT]; /* the first ones' tick numbers: a real
                                        * overrun repeats at the same tick in a rerun, a machine
                                        * that held the vCPU does not */
    uint32_t worst_compute_ns;         /* of the timed ticks */
    uint32_t preempted_ticks;          /* ticks not timed (board_in_t.prev_compute_preempted) */
    uint32_t preempted_over_period;    /* … of them charged past the period: a real overrun
                                        * among them repeats at the same tick in a rerun */
    uint32_t preempted_over_tick[BOARD_PREEMPTED_KEPT]; /* the first ones' tick numbers */
    uint32_t link_frames_rx;
    uint32_t link_errors;              /* frames the decoder refused */
    uint32_t refused_no_session;       /* decoded host frames with no session (not a HELLO) */
    uint32_t refused_duplicate;        /* … whose sequence number the session had accepted */
    uint32_t refused_stale;            /* … older than the session's window */
    uint32_t transport_refused_source; /* board_in_t's counts, as of the last tick */
    uint32_t transport_refused_no_session;
    uint32_t transport_refused_bad_mac;
    uint32_t transport_refused_bad_nonce;
    uint32_t refused_arm;              /* ARM commands refused (cfg.refuse_arm) */
    uint32_t link_tx_dropped;          /* frames that did not fit in a tick's output */
    uint32_t windows_swapped;
    uint32_t window_frames_deferred;   /* decoded a tick late: they came with an impulse flush */
    uint32_t impulses_reapplied;       /* unacknowledged impulses carried into a new window */
    uint32_t impulse_log_overflow;     /* sent impulses forgotten before the host acknowledged them */
    uint32_t max_substeps;             /* most spring sub-steps one tick needed */
    uint32_t rt_stats_sent;            /* RT_STATS frames sent */
    float peak_force_n;
    proto_err_t last_link_error;
} board_stats_t;

typedef struct {
    board_cfg_t cfg;
    safety_t safety;
    drives_t drives;
    window_t window;
    haptics_t haptics;
    host_session_t session;            /* the host whose frames may act */
    msg_tool_t tool;
    bool tool_valid;
    float impulse_ns[ARGIL_WINDOW_SAMPLES_MAX]; /* accumulated ∫f dt per active window node */
    bool impulse_pending;
    int32_t impulse_lo[3];             /* node box [lo, hi] holding every nonzero impulse_ns */
    int32_t impulse_hi[3];             /* … (lo > hi: none); the flush scans only this box */
    uint32_t impulse_seq;
    uint32_t tx_seq;
    uint64_t time_us;
    uint32_t since_impulse_us;
    uint32_t since_heartbeat_us;
    uint32_t since_rt_stats_us;
    rt_stats_t rt;                     /* every previous tick's latency and compute time */
    bool hello_due;
    bool fault_reported;
    uint32_t arm_pending_us;           /* the host's ARM waits this long for drive faults to clear */
    bool wdog_level;
    uint32_t host_window_version;      /* newest version the host says it sent */
    uint32_t host_impulse_ack;         /* newest impulse batch the host says it applied */
    bool have_tip;
    vec3_t tip_device_m;
    uint32_t tpdos_seen[ARGIL_DRIVES]; /* each drive's TPDO count when the tip was last sampled */
    uint32_t stale_ticks;              /* ticks since then without a new position */
    vec3_t pos_m;                      /* tool, model space */
    vec3_t vel_m_s;
    velocity_window_t vel_window;      /* the positions the velocity is fitted to */
    uint32_t sense_ticks;              /* ticks sense_tool has seen (the window's clock) */
    vec3_t force_n;                    /* rendered this tick, model space */
    vec3_t swap_offset_n;              /* force step of the last window swap, decaying */
    bool swapped;                      /* a window was swapped in this tick */
    passivity_t passivity;
    float spring_max_accel;            /* last step's largest |acceleration| */
    uint32_t settle_left;              /* ticks the window's springs still run */
    vec3_t work_m;                     /* where the tool last worked the clay */
    float work_radius_m;
    uint32_t log_head;                 /* next slot of the impulse log */
    uint32_t log_count;
    uint32_t log_seq[BOARD_IMPULSE_LOG];
    vec3_t log_pos_m[BOARD_IMPULSE_LOG];   /* model-space node position */
    float log_impulse_ns[BOARD_IMPULSE_LOG];
    bool contact;
    bool sculpting;
    board_stats_t stats;
    proto_msg_t scratch;               /* one decoded or outgoing message (a WINDOW chunk is ~1 KiB) */
    /* WINDOW frames that arrived on a tick that sends impulses, decoded first on the next tick
     * (the two together were the worst tick: see docs/board.md "Worst tick"). */
    uint8_t deferred[BOARD_DEFER_FRAMES][PROTO_FRAME_MAX];
    uint16_t deferred_len[BOARD_DEFER_FRAMES];
    uint32_t deferred_n;
} board_t;

void board_cfg_default(board_cfg_t *cfg);

/* Prepares the board; returns ARGIL_ERR_ARG for a configuration out of range. */
argil_err_t board_init(board_t *b, const board_cfg_t *cfg);

/* Runs one tick. Never blocks; bounded work. */
void board_tick(board_t *b, const board_in_t *in, board_out_t *out);

/* The RT_STATS message of the ticks so far (the board sends one every rt_stats_period_us;
 * a daemon may send one more when it stops). */
void board_rt_stats_msg(const board_t *b, proto_msg_t *m);

/* The host frames refused so far, by reason (the board's own and its transport's). */
void board_link_counts(const board_t *b, proto_link_counts_t *c);

/* Model-space tool position from a device-space tip under the current tool transform. */
vec3_t board_device_to_model(const board_t *b, vec3_t device_m);

#endif
