/* SocketCAN raw socket: struct can_frame <-> can_frame_t, never blocking. */
#define _GNU_SOURCE /* recvmmsg, sendmmsg */
#include "can_socket.h"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "shared/can_err.h"

/* The core decodes error frames with its own copies of the kernel's constants. */
_Static_assert(ARGIL_CAN_ERR_FLAG == CAN_ERR_FLAG, "CAN_ERR_FLAG");
_Static_assert(ARGIL_CAN_ERR_CRTL == CAN_ERR_CRTL, "CAN_ERR_CRTL");
_Static_assert(ARGIL_CAN_ERR_BUSOFF == CAN_ERR_BUSOFF, "CAN_ERR_BUSOFF");
_Static_assert(ARGIL_CAN_ERR_RESTARTED == CAN_ERR_RESTARTED, "CAN_ERR_RESTARTED");
_Static_assert(ARGIL_CAN_CRTL_RX_PASSIVE == CAN_ERR_CRTL_RX_PASSIVE, "RX_PASSIVE");
_Static_assert(ARGIL_CAN_CRTL_TX_PASSIVE == CAN_ERR_CRTL_TX_PASSIVE, "TX_PASSIVE");
_Static_assert(ARGIL_CAN_CRTL_ACTIVE == CAN_ERR_CRTL_ACTIVE, "CRTL_ACTIVE");

argil_err_t can_socket_open(const char *ifname, int *fd, char *err, size_t err_len)
{
    *fd = -1;
    if (ifname == NULL || ifname[0] == '\0' || strlen(ifname) >= IFNAMSIZ) {
        snprintf(err, err_len, "CAN interface name '%s' is empty or longer than %d characters",
                 ifname ? ifname : "", IFNAMSIZ - 1);
        return ARGIL_ERR_ARG;
    }
    const int s = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (s < 0) {
        snprintf(err, err_len, "CAN interface '%s': cannot create a SocketCAN socket (%s)%s",
                 ifname, strerror(errno),
                 errno == EAFNOSUPPORT ? "; this kernel has no CAN support (modprobe can-raw)" : "");
        return ARGIL_ERR_IO;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof(ifr));
    memcpy(ifr.ifr_name, ifname, strlen(ifname));
    if (ioctl(s, SIOCGIFINDEX, &ifr) < 0) {
        snprintf(err, err_len, "CAN interface '%s' not found (%s)", ifname, strerror(errno));
        close(s);
        return ARGIL_ERR_IO;
    }
    const can_err_mask_t mask = CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_RESTARTED;
    if (setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof(mask)) < 0) {
        snprintf(err, err_len, "CAN interface '%s': cannot enable error frames (%s)", ifname,
                 strerror(errno));
        close(s);
        return ARGIL_ERR_IO;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(s, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        snprintf(err, err_len, "CAN interface '%s': bind failed (%s)", ifname, strerror(errno));
        close(s);
        return ARGIL_ERR_IO;
    }
    *fd = s;
    return ARGIL_OK;
}

/* One received frame into *f: 1 accepted, 2 refused (malformed, RTR, 29-bit: counted in
 * rx_dropped). */
static int decode_frame(const struct can_frame *cf, size_t len, can_frame_t *f,
                        can_socket_stats_t *st)
{
    if (len != sizeof(*cf) || cf->can_dlc > 8 || (cf->can_id & CAN_RTR_FLAG)) {
        st->rx_dropped++;
        return 2;
    }
    memset(f, 0, sizeof(*f));
    if (cf->can_id & CAN_ERR_FLAG) {
        f->id = cf->can_id & (CAN_ERR_FLAG | CAN_ERR_MASK);
        st->rx_error_frames++;
    } else if (cf->can_id & CAN_EFF_FLAG) {
        st->rx_dropped++; /* CANopen uses 11-bit identifiers only */
        return 2;
    } else {
        f->id = cf->can_id & CAN_SFF_MASK;
    }
    f->len = cf->can_dlc;
    memcpy(f->data, cf->data, f->len);
    st->rx_frames++;
    return 1;
}

/* msg[i] points at cf[i] through iov[i], for i < n: one frame per message. */
static void point_msgs(struct mmsghdr *msg, struct iovec *iov, struct can_frame *cf, uint32_t n)
{
    memset(msg, 0, n * sizeof(msg[0]));
    for (uint32_t i = 0; i < n; i++) {
        iov[i].iov_base = &cf[i];
        iov[i].iov_len = sizeof(cf[i]);
        msg[i].msg_hdr.msg_iov = &iov[i];
        msg[i].msg_hdr.msg_iovlen = 1;
    }
}

/* Up to max (<= CAN_BATCH_MAX) frames from fd in one recvmmsg: the accepted ones into out
 * (*accepted of them). Returns the frames read (accepted or refused), 0 when nothing was
 * waiting, -1 on an I/O error (st->last_errno). One system call for a tick's frames instead of
 * one per frame and one more to find the socket empty: under the HIL rig's emulation each cost
 * tens of microseconds. */
static int read_burst(int fd, can_frame_t *out, uint32_t max, uint32_t *accepted,
                      can_socket_stats_t *st)
{
    struct can_frame cf[CAN_BATCH_MAX];
    struct iovec iov[CAN_BATCH_MAX];
    struct mmsghdr msg[CAN_BATCH_MAX];
    *accepted = 0;
    if (max > CAN_BATCH_MAX)
        max = CAN_BATCH_MAX;
    point_msgs(msg, iov, cf, max);
    const int n = recvmmsg(fd, msg, max, MSG_DONTWAIT, NULL);
    if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)
            return 0;
        st->last_errno = errno;
        return -1;
    }
    for (int i = 0; i < n; i++) {
        const size_t len = (msg[i].msg_hdr.msg_flags & MSG_TRUNC) ? 0 : msg[i].msg_len;
        if (decode_frame(&cf[i], len, &out[*accepted], st) == 1)
            (*accepted)++;
    }
    return n;
}

argil_err_t can_socket_receive(int fd, can_batch_t *rx, can_socket_stats_t *st)
{
    uint32_t accepted = 0;
    const int r = read_burst(fd, rx->f, CAN_BATCH_MAX, &accepted, st);
    rx->n = (uint8_t)accepted;
    return r < 0 ? ARGIL_ERR_IO : ARGIL_OK;
}

static bool is_tpdo1(uint32_t id)
{
    return id > CANOPEN_COB_TPDO1 && id <= CANOPEN_COB_TPDO1 + 0x7Fu;
}

static bool fifo_full(const can_fifo_t *q)
{
    return q->n == CAN_RX_QUEUE_MAX;
}

static void fifo_push(can_fifo_t *q, const can_frame_t *f)
{
    q->f[(q->head + q->n) % CAN_RX_QUEUE_MAX] = *f;
    q->n++;
}

/* Moves frames from q into rx while both allow. */
static void fifo_pour(can_fifo_t *q, can_batch_t *rx)
{
    while (q->n > 0 && rx->n < CAN_BATCH_MAX) {
        (void)can_batch_push(rx, &q->f[q->head]);
        q->head = (q->head + 1u) % CAN_RX_QUEUE_MAX;
        q->n--;
    }
}

argil_err_t can_socket_receive_queued(int fd, can_rx_queue_t *q, can_batch_t *rx,
                                      can_socket_stats_t *st)
{
    rx->n = 0;
    argil_err_t err = ARGIL_OK;
    /* Bursts no larger than the room left in either queue: reading stops, as frame by frame,
     * when one of them is full, the socket is empty or 2 * CAN_RX_QUEUE_MAX frames were read. */
    uint32_t budget = 2u * CAN_RX_QUEUE_MAX;
    while (budget > 0 && !fifo_full(&q->tpdo) && !fifo_full(&q->event)) {
        uint32_t room = CAN_RX_QUEUE_MAX - (q->tpdo.n > q->event.n ? q->tpdo.n : q->event.n);
        room = room < budget ? room : budget;
        room = room < CAN_BATCH_MAX ? room : CAN_BATCH_MAX;
        can_frame_t f[CAN_BATCH_MAX];
        uint32_t accepted = 0;
        const int r = read_burst(fd, f, room, &accepted, st);
        if (r < 0) {
            err = ARGIL_ERR_IO;
            break;
        }
        for (uint32_t i = 0; i < accepted; i++)
            fifo_push(is_tpdo1(f[i].id) ? &q->tpdo : &q->event, &f[i]);
        if ((uint32_t)r < room)
            break; /* the socket ran empty */
        budget -= (uint32_t)r;
    }
    if (q->tpdo.n + q->event.n > st->rx_queue_peak)
        st->rx_queue_peak = q->tpdo.n + q->event.n;
    fifo_pour(&q->event, rx);
    fifo_pour(&q->tpdo, rx);
    return err;
}

argil_err_t can_socket_send(int fd, const can_batch_t *tx, can_socket_stats_t *st)
{
    const uint8_t n = tx->n <= CAN_BATCH_MAX ? tx->n : CAN_BATCH_MAX;
    struct can_frame cf[CAN_BATCH_MAX];
    struct iovec iov[CAN_BATCH_MAX];
    struct mmsghdr msg[CAN_BATCH_MAX];
    memset(cf, 0, n * sizeof(cf[0]));
    for (uint8_t i = 0; i < n; i++) {
        cf[i].can_id = tx->f[i].id & CAN_SFF_MASK;
        cf[i].can_dlc = tx->f[i].len <= 8 ? tx->f[i].len : 8;
        memcpy(cf[i].data, tx->f[i].data, cf[i].can_dlc);
    }
    point_msgs(msg, iov, cf, n);
    /* One sendmmsg for the batch (in order; it stops at the first frame the socket refuses,
     * and the next call reports why). At most n calls: each sends one frame or returns. */
    uint8_t done = 0;
    while (done < n) {
        const int w = sendmmsg(fd, &msg[done], n - done, MSG_DONTWAIT);
        if (w <= 0) {
            st->last_errno = w < 0 ? errno : EIO;
            if (w < 0 && (errno == ENOBUFS || errno == EAGAIN || errno == EWOULDBLOCK)) {
                st->tx_busy++;
                return ARGIL_ERR_FULL;
            }
            st->tx_errors++;
            return ARGIL_ERR_IO;
        }
        for (int i = 0; i < w; i++)
            if (msg[done + i].msg_len != sizeof(cf[0])) {
                st->last_errno = EIO;
                st->tx_errors++;
                return ARGIL_ERR_IO;
            }
        done = (uint8_t)(done + w);
        st->tx_frames += (uint32_t)w;
    }
    return ARGIL_OK;
}
