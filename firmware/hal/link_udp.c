/* UDP transport of the host link: one frame per datagram, never blocking; only the session's
 * host gets through (link_bind.h). */
#include <arpa/inet.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "link_io.h"

#define LINK_UDP_REFUSED_PER_CALL 256u

argil_err_t link_udp_parse(const char *spec, struct sockaddr_in *addr)
{
    char host[64];
    const char *colon = spec ? strrchr(spec, ':') : NULL;
    if (colon == NULL || colon == spec || (size_t)(colon - spec) >= sizeof(host))
        return ARGIL_ERR_PARSE;
    memcpy(host, spec, (size_t)(colon - spec));
    host[colon - spec] = '\0';
    char *end = NULL;
    errno = 0;
    const long port = strtol(colon + 1, &end, 10);
    if (errno != 0 || end == colon + 1 || *end != '\0' || port < 1 || port > 65535)
        return ARGIL_ERR_PARSE;
    memset(addr, 0, sizeof(*addr));
    addr->sin_family = AF_INET;
    addr->sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, host, &addr->sin_addr) != 1)
        return ARGIL_ERR_PARSE;
    return ARGIL_OK;
}

argil_err_t link_udp_open(link_udp_t *u, const char *spec, char *err, size_t err_len)
{
    memset(u, 0, sizeof(*u));
    link_bind_init(&u->bind);
    u->fd = -1;
    struct sockaddr_in addr;
    if (link_udp_parse(spec, &addr) != ARGIL_OK) {
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
        if (link_frame_size(buf, (size_t)n) == 0) {
            u->rx_refused++;
            continue;
        }
        const uint64_t key = link_udp_key(&from);
        const uint32_t binds = u->bind.binds;
        if (!link_bind_admit(&u->bind, key, buf, (size_t)n, now_us))
            continue; /* counted by the binding */
        if (u->bind.binds != binds) {
            u->peer = from;
            u->peer_changes++;
        }
        u->rx_datagrams++;
        return (size_t)n;
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
        const ssize_t w = sendto(u->fd, buf + at, size, MSG_DONTWAIT,
                                 (const struct sockaddr *)&u->peer, sizeof(u->peer));
        if (w != (ssize_t)size) {
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
