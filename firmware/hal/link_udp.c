/* UDP transport of the host link: one frame per datagram, never blocking; with a key every
 * datagram sealed and verified here, in the link thread (shared/link_envelope.h with
 * link_auth.h's MAC); only the session's host gets through (link_bind.h). */
#include <arpa/inet.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "link_io.h"

#define LINK_UDP_REFUSED_PER_CALL 256u

link_udp_addr_err_t link_udp_parse(const char *spec, struct sockaddr_in *addr)
{
    char host[64];
    const char *colon = spec ? strrchr(spec, ':') : NULL;
    if (colon == NULL || colon == spec)
        return LINK_UDP_ADDR_ERR_FORM;
    if ((size_t)(colon - spec) >= sizeof(host))
        return LINK_UDP_ADDR_ERR_HOST;
    memcpy(host, spec, (size_t)(colon - spec));
    host[colon - spec] = '\0';
    char *end = NULL;
    errno = 0;
    const long port = strtol(colon + 1, &end, 10);
    if (errno != 0 || end == colon + 1 || *end != '\0' || port < 1 || port > 65535)
        return LINK_UDP_ADDR_ERR_PORT;
    memset(addr, 0, sizeof(*addr));
    addr->sin_family = AF_INET;
    addr->sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, host, &addr->sin_addr) != 1)
        return LINK_UDP_ADDR_ERR_HOST;
    return LINK_UDP_ADDR_OK;
}

argil_err_t link_udp_open(link_udp_t *u, const char *spec, char *err, size_t err_len)
{
    memset(u, 0, sizeof(*u));
    link_bind_init(&u->bind);
    u->fd = -1;
    struct sockaddr_in addr;
    if (link_udp_parse(spec, &addr) != LINK_UDP_ADDR_OK) {
        snprintf(err, err_len, "host link 'udp:%s': expected udp:ADDR:PORT with an IPv4 "
                 "address and a port 1-65535", spec);
        return ARGIL_ERR_ARG;
    }
    const int s = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (s < 0) {
        snprintf(err, err_len, "host link 'udp:%s': socket failed (%s)", spec, strerror(errno));
        return ARGIL_ERR_IO;
    }
    if (bind(s, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        snprintf(err, err_len, "host link 'udp:%s': cannot bind (%s)", spec, strerror(errno));
        close(s);
        return ARGIL_ERR_IO;
    }
    u->fd = s;
    return ARGIL_OK;
}

void link_udp_set_key(link_udp_t *u, const link_key_t *key)
{
    u->keyed = true;
    u->key = *key;
}

uint64_t link_udp_key(const struct sockaddr_in *a)
{
    return (uint64_t)ntohl(a->sin_addr.s_addr) << 16 | ntohs(a->sin_port);
}

void link_udp_session(link_udp_t *u, hal_session_state_t state, uint32_t epoch, uint64_t now_us)
{
    link_bind_session(&u->bind, state, epoch, now_us);
}

size_t link_udp_receive(link_udp_t *u, uint8_t *buf, size_t cap, uint64_t now_us)
{
    /* Bounded: a flood of refused datagrams gives the thread back to its other work. */
    for (uint32_t k = 0; k < LINK_UDP_REFUSED_PER_CALL; k++) {
        struct sockaddr_in from;
        socklen_t flen = sizeof(from);
        const ssize_t n =
            recvfrom(u->fd, buf, cap, MSG_DONTWAIT, (struct sockaddr *)&from, &flen);
        if (n <= 0)
            return 0;
        const size_t first = link_frame_size(buf, (size_t)n);
        if (first == 0) {
            u->rx_refused++;
            continue;
        }
        size_t len = (size_t)n;
        uint64_t nonce = 0;
        if (u->keyed) {
            if (link_auth_open(link_auth_mac, &u->key, LINK_AUTH_HOST_TO_BOARD, buf, (size_t)n,
                               &len, &nonce) != LINK_AUTH_OK) {
                u->bad_mac++;
                continue;
            }
            if (!link_auth_nonce_ok(u->bind.bound ? u->nonce : 0u, nonce, buf, len)) {
                u->bad_nonce++;
                continue;
            }
        } else if ((size_t)n == first + LINK_AUTH_TRAILER_BYTES) {
            u->bad_mac++; /* a keyed host's datagram: this board has no key to check it */
            continue;
        }
        const uint64_t key = link_udp_key(&from);
        const uint32_t binds = u->bind.binds;
        const bool lapsed = u->bind.bound && !u->bind.pending &&
                            u->bind.state == HAL_SESSION_LAPSED;
        if (!link_bind_admit(&u->bind, key, buf, len, now_us))
            continue; /* counted by the binding */
        if (u->bind.binds != binds) {
            u->peer = from;
            u->peer_changes++;
        }
        /* A new session gets a new nonce, so no frame of an earlier one is accepted in it: at a
         * new binding, and at a HELLO that restarts the bound host's lapsed session (the core
         * restarts its sequence window there). */
        if (u->keyed && (u->bind.binds != binds || (lapsed && nonce == 0u))) {
            u->nonce = link_auth_new_nonce();
            u->nonces++;
        }
        u->rx_datagrams++;
        return len;
    }
    return 0;
}

argil_err_t link_udp_send(link_udp_t *u, const uint8_t *buf, size_t len)
{
    if (!u->bind.bound) {
        u->tx_unbound++;
        return ARGIL_ERR_STATE;
    }
    size_t at = 0;
    argil_err_t rc = ARGIL_OK;
    while (at < len) {
        size_t size = link_frame_size(buf + at, len - at);
        if (size == 0 || size > len - at)
            size = len - at; /* not a frame boundary: send the rest as it is */
        const uint8_t *dgram = buf + at;
        size_t dlen = size;
        uint8_t sealed[LINK_AUTH_DGRAM_MAX];
        if (u->keyed) {
            dlen = link_auth_seal(link_auth_mac, &u->key, LINK_AUTH_BOARD_TO_HOST, u->nonce,
                                  buf + at, size, sealed, sizeof(sealed));
            dgram = sealed;
        }
        const ssize_t w = dlen == 0 ? -1
                                    : sendto(u->fd, dgram, dlen, MSG_DONTWAIT,
                                             (const struct sockaddr *)&u->peer, sizeof(u->peer));
        if (w != (ssize_t)dlen || dlen == 0) {
            u->tx_errors++;
            rc = ARGIL_ERR_IO;
        } else {
            u->tx_datagrams++;
        }
        at += size;
    }
    return rc;
}

void link_udp_close(link_udp_t *u)
{
    if (u->fd >= 0)
        close(u->fd);
    u->fd = -1;
}
