/* UDP transport of the host link: a connected, non-blocking socket to the board; every frame
 * is one datagram each way. With a key every datagram is sealed (the board's session nonce,
 * learned from each verified datagram of the board; 0 on a HELLO) and every datagram from the
 * board verified (shared/link_envelope.h, with libsodium's MAC: link_crypto.h). A board that
 * restarts on the same address is simply heard again (the link state machine turns that into a
 * reconnection). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "host/link/link.h"
#include "host/link/link_crypto.h"
#include "shared/link_envelope.h"
#include "shared/link_framer.h"

_Static_assert(LINK_KEY_SIZE == LINK_KEY_BYTES, "one key size");

typedef struct {
    int fd;
    uint8_t dgram[65536];      /* the datagram being handed out frame by frame */
    size_t len, at;
    bool keyed;
    link_auth_host_t auth;     /* keyed: the key and the board's session nonce */
    uint8_t sealed[LINK_AUTH_DGRAM_MAX];
} dgram_t;

static argil_err_t dgram_send(link_t *l, const uint8_t *frame, size_t len)
{
    dgram_t *d = l->impl;
    if (d->keyed) {
        /* none before the board told its session's nonce: it would refuse them (bad nonce) */
        len = link_auth_host_seal(&d->auth, frame, len, d->sealed, sizeof(d->sealed));
        if (len == 0)
            return ARGIL_ERR_STATE;
        frame = d->sealed;
    }
    ssize_t w = send(d->fd, frame, len, MSG_DONTWAIT | MSG_NOSIGNAL);
    /* ECONNREFUSED reports an earlier datagram that found the board's port closed (it was
     * restarting); this one may well pass: try it once more. */
    if (w < 0 && errno == ECONNREFUSED)
        w = send(d->fd, frame, len, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (w == (ssize_t)len)
        return ARGIL_OK;
    return w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) ? ARGIL_ERR_FULL : ARGIL_ERR_IO;
}

static size_t dgram_recv(link_t *l, uint8_t *buf, size_t cap)
{
    dgram_t *d = l->impl;
    for (;;) {
        if (d->at < d->len) {
            const size_t size = link_frame_size(d->dgram + d->at, d->len - d->at);
            if (size == 0 || size > d->len - d->at || size > cap) {
                /* Not a whole frame: drop the rest of this datagram. */
                l->stats.errors_rx++;
                d->at = d->len = 0;
                continue;
            }
            memcpy(buf, d->dgram + d->at, size);
            d->at += size;
            return size;
        }
        const ssize_t n = recv(d->fd, d->dgram, sizeof(d->dgram), MSG_DONTWAIT);
        if (n < 0) {
            if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR &&
                errno != ECONNREFUSED)
                l->stats.errors_rx++;
            return 0;
        }
        if (n == 0)
            return 0;
        d->len = (size_t)n;
        d->at = 0;
        size_t flen = 0;
        if (d->keyed && link_auth_host_open(&d->auth, d->dgram, d->len, &flen) != LINK_AUTH_OK) {
            l->stats.auth_refused = d->auth.refused;
            d->len = 0;
            continue;
        }
        if (d->keyed)
            d->len = flen; /* one frame, the trailer off */
    }
}

static void dgram_poll(link_t *l, uint32_t wait_us, uint64_t now_us)
{
    (void)now_us;
    dgram_t *d = l->impl;
    if (d->at < d->len || wait_us == 0)
        return;
    struct pollfd p = {.fd = d->fd, .events = POLLIN};
    const int ms = (int)((wait_us + 999u) / 1000u);
    (void)poll(&p, 1, ms);
}

static void dgram_close(link_t *l)
{
    dgram_t *d = l->impl;
    if (d) {
        close(d->fd);
        link_crypto_wipe(&d->auth, sizeof(d->auth));
        free(d);
    }
}

static const link_ops_t DGRAM_OPS = {dgram_send, dgram_recv, dgram_poll, dgram_close};

argil_err_t link_dgram_open(link_t *l, char *err, size_t err_len)
{
    char port[8];
    snprintf(port, sizeof(port), "%u", l->spec.port);
    struct addrinfo hints, *ai = NULL;
    memset(&hints, 0, sizeof(hints));
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    const int ge = getaddrinfo(l->spec.host, port, &hints, &ai);
    if (ge != 0 || !ai) {
        snprintf(err, err_len, "udp:%s:%u: cannot resolve '%s' (%s)", l->spec.host,
                 l->spec.port, l->spec.host, gai_strerror(ge));
        return ARGIL_ERR_IO;
    }
    dgram_t *d = calloc(1, sizeof(*d));
    if (!d) {
        freeaddrinfo(ai);
        snprintf(err, err_len, "out of memory for the UDP link");
        return ARGIL_ERR_NOMEM;
    }
    d->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (d->fd < 0 || connect(d->fd, ai->ai_addr, ai->ai_addrlen) != 0) {
        snprintf(err, err_len, "udp:%s:%u: %s", l->spec.host, l->spec.port, strerror(errno));
        if (d->fd >= 0)
            close(d->fd);
        free(d);
        freeaddrinfo(ai);
        return ARGIL_ERR_IO;
    }
    freeaddrinfo(ai);
    if (l->keyed) {
        link_key_t k;
        memcpy(k.k, l->key, sizeof(k.k));
        link_auth_host_init(&d->auth, &k, link_crypto_mac);
        link_crypto_wipe(&k, sizeof(k));
        d->keyed = true;
    }
    /* Room for a burst of telemetry and impulses while the link thread is descheduled. */
    const int rcvbuf = 1 << 20;
    (void)setsockopt(d->fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
    link_attach(l, &DGRAM_OPS, d, true);
    return ARGIL_OK;
}
