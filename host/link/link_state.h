/* The state of the host link as the person sees it — waiting for the board, connected, or
 * lost — and when the host must resynchronise (say HELLO again, resend its window). Pure: time
 * is passed in, so the same machine runs under every transport and in tests. */
#ifndef ARGIL_LINK_STATE_H
#define ARGIL_LINK_STATE_H

#include <stdbool.h>
#include <stdint.h>

#define LINK_SILENCE_US 100000u  /* no frame for this long: the board is lost (it sends 1 kHz) */

typedef enum { LINK_WAITING = 0, LINK_CONNECTED = 1, LINK_LOST = 2 } link_state_t;

typedef struct {
    link_state_t state;
    uint32_t silence_us;       /* frames stop for this long → LOST */
    uint64_t last_rx_us;
    bool ever_connected;
    bool transport_up;         /* the socket / USB handle is open */
    bool resync_due;           /* a reconnection the host has not yet acted on */
    uint32_t reconnects;       /* LOST → CONNECTED transitions */
    uint32_t losses;           /* CONNECTED → LOST transitions */
    uint32_t transport_drops;  /* the transport itself went away (USB unplug) */
} link_fsm_t;

void link_fsm_init(link_fsm_t *f, uint32_t silence_us, bool transport_up);
/* A whole frame arrived at now_us. */
void link_fsm_frame(link_fsm_t *f, uint64_t now_us);
/* The transport went away (USB unplugged): LOST until it is back and frames flow. */
void link_fsm_transport_down(link_fsm_t *f);
/* The transport is back (USB replugged and reopened); the state changes with the first frame. */
void link_fsm_transport_up(link_fsm_t *f);
/* Advances time: a connected link that heard nothing for silence_us becomes LOST. */
void link_fsm_tick(link_fsm_t *f, uint64_t now_us);
/* True once per reconnection: the caller says HELLO and resends its window and tool. */
bool link_fsm_take_resync(link_fsm_t *f);

const char *link_state_name(link_state_t s);

#endif
