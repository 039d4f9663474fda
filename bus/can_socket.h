/* SocketCAN raw socket for the drives' bus: open by interface name, non-blocking receive of
 * data and error frames into a can_batch_t, send a batch. Linux only (hosted). */
#ifndef ARGIL_CAN_SOCKET_H
#define ARGIL_CAN_SOCKET_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"
#include "shared/canopen.h"

typedef struct {
    uint32_t rx_frames;
    uint32_t rx_error_frames;
    uint32_t rx_dropped;          /* malformed or not CANopen (29-bit) */
    uint32_t rx_queue_peak;       /* most frames held in a can_rx_queue_t between ticks */
    uint32_t tx_frames;
    uint32_t tx_busy;             /* sends refused: the queue is full (ENOBUFS/EAGAIN) */
    uint32_t tx_errors;           /* sends refused for other reasons (ENETDOWN…) */
    int last_errno;
} can_socket_stats_t;

/* Opens a raw CAN socket bound to ifname, non-blocking, with error frames for bus-off,
 * controller state and restarts enabled. On failure writes one line into err (no newline)
 * naming the interface and the cause, and returns ARGIL_ERR_IO (or ARGIL_ERR_ARG for a bad
 * name). */
argil_err_t can_socket_open(const char *ifname, int *fd, char *err, size_t err_len);

/* Reads every frame waiting on fd (up to CAN_BATCH_MAX) into rx without blocking. Error
 * frames keep their CAN_ERR_FLAG id (firmware/core/drives.h decodes them). */
argil_err_t can_socket_receive(int fd, can_batch_t *rx, can_socket_stats_t *st);

/* The board's receive queue: what the socket held beyond one tick's batch waits here, in
 * order, instead of in the socket, whose queue overflowed after a stalled tick and lost frames
 * (a drive heartbeat among them latched "drive heartbeat lost"). TPDOs and everything else
 * (heartbeats, EMCY, NMT, error frames) queue apart. */
#define CAN_RX_QUEUE_MAX 1024u
typedef struct {
    can_frame_t f[CAN_RX_QUEUE_MAX];
    uint32_t head, n;
} can_fifo_t;
typedef struct {
    can_fifo_t tpdo, event;
} can_rx_queue_t;

/* The board's read: drains fd into q without blocking (until q is full), then hands rx the
 * queued events first, then TPDOs in arrival order, CAN_BATCH_MAX at most: a backlog reaches
 * the core a batch a tick, as it would have from the socket, and a heartbeat or EMCY behind
 * it reaches the core in the first tick. q starts zeroed. */
argil_err_t can_socket_receive_queued(int fd, can_rx_queue_t *q, can_batch_t *rx,
                                      can_socket_stats_t *st);

/* Writes every frame of tx without blocking; ARGIL_ERR_FULL when the kernel queue is full,
 * ARGIL_ERR_IO for another failure (the rest of the batch is not sent). */
argil_err_t can_socket_send(int fd, const can_batch_t *tx, can_socket_stats_t *st);

#endif
