/* The host link's transports for the board daemon's link thread: UDP (one frame per datagram;
 * with a key each sealed and verified here, shared/link_envelope.h; only the host whose HELLO
 * started the core's session gets through, and gets the replies: link_bind.h) and a USB
 * FunctionFS gadget (vendor-class interface, one bulk OUT and one bulk IN endpoint; the same
 * frames back to back).
 * Linux only (hosted); nothing here runs in the fast loop. */
#ifndef ARGIL_LINK_IO_H
#define ARGIL_LINK_IO_H

#include <netinet/in.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "link_auth.h"
#include "link_bind.h"
#include "shared/argil_err.h"
#include "shared/link_framer.h"
#include "shared/proto.h"

#define LINK_USB_VID 0x1209u   /* pid.codes test VID */
#define LINK_USB_PID 0x0001u   /* pid.codes test PID */

/* ---- UDP ---- */

typedef struct {
    int fd;
    link_bind_t bind;            /* the session's host (bind.peer is link_udp_key of peer) */
    struct sockaddr_in peer;     /* its address, while bind.bound */
    uint32_t peer_changes;       /* hosts bound: a HELLO from a new address with no live session */
    uint32_t rx_datagrams;       /* datagrams passed on to the core */
    uint32_t rx_refused;         /* not starting with a frame header */
    uint32_t tx_datagrams;
    uint32_t tx_errors;
    uint32_t tx_unbound;         /* frames dropped: no host bound */
    bool keyed;                  /* every datagram sealed and verified with key (link_envelope.h) */
    link_key_t key;
    uint64_t nonce;              /* the bound session's nonce, drawn at each new session */
    uint32_t nonces;             /* nonces drawn */
    uint32_t bad_mac;            /* datagrams whose tag did not verify (keyed), or that carried
                                  * a trailer to this keyless link */
    uint32_t bad_nonce;          /* tag right, nonce not the session's (nor 0 on a HELLO) */
} link_udp_t;

/* The sender key of an IPv4 address and port (link_bind.h). */
uint64_t link_udp_key(const struct sockaddr_in *a);

/* The rule an "ADDR:PORT" text broke (link_udp_parse); LINK_UDP_ADDR_OK = 0. */
typedef enum {
    LINK_UDP_ADDR_OK = 0,
    LINK_UDP_ADDR_ERR_FORM = -1, /* no text, no ':' before the port, or nothing before it */
    LINK_UDP_ADDR_ERR_HOST = -2, /* ADDR is not an IPv4 dotted quad */
    LINK_UDP_ADDR_ERR_PORT = -3  /* PORT is not a whole number 1..65535 */
} link_udp_addr_err_t;

/* Parses "ADDR:PORT" (IPv4 dotted quad, port 1..65535) into *addr. */
link_udp_addr_err_t link_udp_parse(const char *spec, struct sockaddr_in *addr);

/* Binds a non-blocking UDP socket to spec ("ADDR:PORT"); one line into err on failure. */
argil_err_t link_udp_open(link_udp_t *u, const char *spec, char *err, size_t err_len);

/* From now on every datagram is sealed with key, and one whose tag or nonce is wrong is
 * dropped and counted (docs/protocol.md "Authenticated UDP"). Call before the first receive. */
void link_udp_set_key(link_udp_t *u, const link_key_t *key);

/* Takes the core's host session (hal_link_session, read on the link thread). */
void link_udp_session(link_udp_t *u, hal_session_state_t state, uint32_t epoch, uint64_t now_us);

/* Receives datagrams until one may reach the core; returns the length of its frames (a keyed
 * link's trailer taken off), 0 when none waits. A datagram that does not start with a frame
 * header, whose tag or nonce is wrong (keyed), that carries a trailer to a keyless link, or
 * that the session's binding refuses (another sender while the host's session lives; anything
 * but a host HELLO with no host), is dropped and counted. A new session's binding draws a new
 * nonce, as does a HELLO that restarts a lapsed session. */
size_t link_udp_receive(link_udp_t *u, uint8_t *buf, size_t cap, uint64_t now_us);

/* Sends each whole frame of buf[0..len) as its own datagram to the session's host (keyed:
 * sealed with the session's nonce).
 * ARGIL_ERR_STATE when no host is bound (counted), ARGIL_ERR_IO on a send failure. */
argil_err_t link_udp_send(link_udp_t *u, const uint8_t *buf, size_t len);

void link_udp_close(link_udp_t *u);

/* ---- USB FunctionFS ---- */

typedef struct {
    int ep0;
    int ep_out;                  /* host → board (bulk OUT, ep1 file) */
    int ep_in;                   /* board → host (bulk IN, ep2 file) */
    bool enabled;                /* the host configured the gadget (FUNCTIONFS_ENABLE) */
    uint32_t enables;
    uint32_t disables;
} link_ffs_t;

/* Writes the FunctionFS v2 descriptor blob (full- and high-speed: one vendor-class
 * interface, bulk OUT 0x01 and bulk IN 0x82) into buf; returns its size, 0 if cap is short. */
size_t link_ffs_descriptors(uint8_t *buf, size_t cap);
/* Writes the strings blob (English: the interface name) into buf; returns its size. */
size_t link_ffs_strings(uint8_t *buf, size_t cap);

/* Opens dir/ep0, writes descriptors and strings, opens dir/ep1 and dir/ep2. One line into err
 * on failure ("FunctionFS 'DIR' is not mounted…"). */
argil_err_t link_ffs_open(link_ffs_t *f, const char *dir, char *err, size_t err_len);
void link_ffs_close(link_ffs_t *f);

#endif
