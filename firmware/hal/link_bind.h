/* Which sender a datagram transport (UDP, and the simulated link) lets through to the core: the
 * host whose HELLO started the core's session, and no one else while that session lives. A
 * sender is a 64-bit key (UDP: IPv4 address << 16 | port). Pure: no sockets, time passed in. */
#ifndef ARGIL_LINK_BIND_H
#define ARGIL_LINK_BIND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal.h"

/* How long a binding made on a HELLO waits for the core to start its session before it is
 * dropped (the core takes frames every tick; the HELLO may have been lost on the way in). */
#define LINK_BIND_PENDING_US 500000u
/* How long a lapsed host keeps its place (the core faulted it, host lost): a host that stalled
 * or whose link dropped for a moment comes back to its own session; only after this may
 * another sender's HELLO take over. A restarted host (a new port) waits this long at most. */
#define LINK_BIND_TAKEOVER_US 1000000u

typedef struct {
    bool bound;
    uint64_t peer;               /* the bound host's key */
    bool pending;                /* bound on a HELLO the core has not started a session for yet */
    uint32_t pending_epoch;      /* the core's session epoch when it was bound */
    uint64_t pending_since_us;
    hal_session_state_t state;   /* the core's session, as last told */
    uint32_t epoch;
    uint64_t lapsed_since_us;    /* when it was first told the session lapsed */
    uint32_t binds;              /* hosts bound */
    uint32_t refused_source;     /* datagrams from another sender than the bound host */
    uint32_t refused_no_session; /* datagrams with no binding that were not a host HELLO */
} link_bind_t;

void link_bind_init(link_bind_t *lb);

/* Takes the core's session (hal_link_session); a binding whose session ended (END, or a HELLO
 * the core never took up) is dropped. */
void link_bind_session(link_bind_t *lb, hal_session_state_t state, uint32_t epoch,
                       uint64_t now_us);

/* True when the datagram from sender may reach the core; a host HELLO (its first frame, CRC
 * checked) binds its sender when no host is bound, or the bound host's session ended or has
 * been lapsed for LINK_BIND_TAKEOVER_US. Each refusal is counted by reason. */
bool link_bind_admit(link_bind_t *lb, uint64_t sender, const uint8_t *dgram, size_t len,
                     uint64_t now_us);

#endif
