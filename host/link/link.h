/* The host's link to the board: one interface over three transports — the in-process
 * simulated board ("sim"), UDP ("udp:HOST:PORT", one frame per datagram) and USB bulk through
 * libusb ("usb", "usb:VID:PID", "usb:BUS-PORT.PORT"; a byte stream cut into frames). Whole
 * frames in and out, never blocking longer than the poll's wait; counters and a link state.
 * All calls on one link come from one thread (the connect command's link thread). */
#ifndef ARGIL_LINK_H
#define ARGIL_LINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/link/link_spec.h"
#include "host/link/link_state.h"
#include "shared/argil_err.h"

typedef struct {
    uint32_t frames_rx, frames_tx;
    uint64_t bytes_rx, bytes_tx;
    uint32_t errors_rx;        /* datagrams or stream bytes that were not a frame; IN transfer errors */
    uint32_t errors_tx;        /* frames the transport refused or could not queue */
    uint32_t reconnects;       /* the board came back after the link was lost */
    uint32_t auth_refused;     /* keyed UDP: datagrams whose tag did not verify (another key, or
                                * a board without one) */
} link_stats_t;

#define LINK_KEY_SIZE 32u      /* the UDP link key (shared/link_envelope.h, docs/link.md) */

typedef struct link_s link_t;

/* What a transport provides. send queues one whole frame without blocking (ARGIL_ERR_FULL when
 * it cannot take it now, ARGIL_ERR_IO when the transport is down); recv moves the next whole
 * received frame into buf (0 when none); poll moves bytes for up to wait_us. */
typedef struct {
    argil_err_t (*send)(link_t *l, const uint8_t *frame, size_t len);
    size_t (*recv)(link_t *l, uint8_t *buf, size_t cap);
    void (*poll)(link_t *l, uint32_t wait_us, uint64_t now_us);
    void (*close)(link_t *l);
} link_ops_t;

struct link_s {
    const link_ops_t *ops;
    void *impl;                /* the transport's own state */
    link_spec_t spec;
    link_fsm_t fsm;
    link_stats_t stats;
    uint64_t now_us;           /* of the last poll */
    bool keyed;                /* udp: every datagram sealed and verified with key */
    uint8_t key[LINK_KEY_SIZE];
};

/* Opens the link named by device. ARGIL_ERR_PARSE for a bad device string, ARGIL_ERR_IO when
 * the transport cannot be opened (no such device, permission, no USB library); one line
 * (without the program's name) in err. */
argil_err_t link_open(link_t *l, const char *device, char *err, size_t err_len);
/* As link_open; with a key (not NULL) a udp: device seals every datagram and drops those from the
 * board whose tag does not verify (docs/protocol.md "Authenticated UDP"). ARGIL_ERR_ARG when a
 * key is given for a device other than udp: (USB and sim need none). */
argil_err_t link_open_keyed(link_t *l, const char *device, const uint8_t *key, char *err,
                            size_t err_len);

/* Wraps a transport the caller built (tests use a fake). */
void link_attach(link_t *l, const link_ops_t *ops, void *impl, bool transport_up);

/* Queues one whole frame; counts it. */
argil_err_t link_send(link_t *l, const uint8_t *frame, size_t len);
/* The next whole frame from the board, or 0. */
size_t link_recv(link_t *l, uint8_t *buf, size_t cap);
/* Moves bytes for up to wait_us, then updates the link state for the time now_us. */
void link_poll(link_t *l, uint32_t wait_us, uint64_t now_us);
/* Updates the link state for the time now_us (call it with a fresh clock after a poll that
 * may have waited, before link_recv, so silence is judged before the frames that end it). */
void link_set_time(link_t *l, uint64_t now_us);
/* True once after each reconnection: say HELLO again. */
bool link_take_resync(link_t *l);
link_state_t link_state(const link_t *l);
void link_close(link_t *l);

/* For transports: the transport went away / came back. */
void link_transport_down(link_t *l);
void link_transport_up(link_t *l);

/* Transport constructors (link_open calls them). */
argil_err_t link_sim_open(link_t *l, link_sim_hand_t hand, char *err, size_t err_len);
argil_err_t link_dgram_open(link_t *l, char *err, size_t err_len);
argil_err_t link_usb_open(link_t *l, char *err, size_t err_len);

#endif
