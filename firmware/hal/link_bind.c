/* Sender binding of the datagram transports (link_bind.h). */
#include "link_bind.h"

#include <string.h>

#include "shared/proto.h"

void link_bind_init(link_bind_t *lb)
{
    memset(lb, 0, sizeof(*lb)); /* nothing bound, no session, nothing counted */
    lb->state = HAL_SESSION_NONE;
}

void link_bind_session(link_bind_t *lb, hal_session_state_t state, uint32_t epoch,
                       uint64_t now_us)
{
    if (state == HAL_SESSION_LAPSED && lb->state != HAL_SESSION_LAPSED)
        lb->lapsed_since_us = now_us;
    lb->state = state;
    lb->epoch = epoch;
    if (lb->pending &&
        (epoch != lb->pending_epoch || now_us - lb->pending_since_us >= LINK_BIND_PENDING_US))
        lb->pending = false;
    if (lb->bound && !lb->pending && state == HAL_SESSION_NONE)
        lb->bound = false;
}

/* True when the datagram's first frame is a valid HELLO from a host. */
static bool is_host_hello(const uint8_t *dgram, size_t len)
{
    if (len <= PROTO_HEADER_SIZE || dgram[5] != MSG_HELLO)
        return false;
    proto_msg_t m; /* ~1 KiB of stack: the link thread's, never the fast loop's */
    size_t used = 0;
    return proto_decode(dgram, len, &m, &used) == PROTO_OK && m.type == MSG_HELLO &&
           m.u.hello.role == PROTO_ROLE_HOST;
}

bool link_bind_admit(link_bind_t *lb, uint64_t sender, const uint8_t *dgram, size_t len,
                     uint64_t now_us)
{
    if (lb->bound && sender == lb->peer)
        return true;
    const bool lapsed_long = lb->state == HAL_SESSION_LAPSED &&
                             now_us - lb->lapsed_since_us >= LINK_BIND_TAKEOVER_US;
    const bool free =
        !lb->bound || (!lb->pending && (lb->state == HAL_SESSION_NONE || lapsed_long));
    if (free && is_host_hello(dgram, len)) {
        lb->bound = true;
        lb->peer = sender;
        lb->pending = true;
        lb->pending_epoch = lb->epoch;
        lb->pending_since_us = now_us;
        lb->binds++;
        return true;
    }
    if (lb->bound)
        lb->refused_source++;
    else
        lb->refused_no_session++;
    return false;
}
