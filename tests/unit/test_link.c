/* The host link without a device: device strings (every error branch), endpoint discovery from
 * descriptor blobs (the renumbered endpoints a UDC gives), the link state machine, the
 * transport-neutral link through a fake transport that unplugs and replugs, the UDP transport
 * against a "board" socket on 127.0.0.1 that restarts, and the in-process simulated board. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "firmware/core/safety.h"
#include "host/app/peer.h"
#include "host/link/link.h"
#include "host/link/link_usb_desc.h"
#include "host/model/grid.h"
#include "shared/proto.h"

/* ---- device strings ---- */

static void test_spec_accepts(void **state)
{
    (void)state;
    link_spec_t s;
    assert_int_equal(link_spec_parse("sim", &s), LINK_SPEC_OK);
    assert_int_equal(s.kind, LINK_KIND_SIM);
    assert_int_equal(s.sim_hand, LINK_SIM_HAND_STILL);
    assert_int_equal(link_spec_parse("sim:press", &s), LINK_SPEC_OK);
    assert_int_equal(s.kind, LINK_KIND_SIM);
    assert_int_equal(s.sim_hand, LINK_SIM_HAND_PRESS);
    assert_int_equal(link_spec_parse("udp:127.0.0.1:5000", &s), LINK_SPEC_OK);
    assert_int_equal(s.kind, LINK_KIND_UDP);
    assert_string_equal(s.host, "127.0.0.1");
    assert_int_equal(s.port, 5000);
    assert_int_equal(link_spec_parse("udp:board-1.local:65535", &s), LINK_SPEC_OK);
    assert_string_equal(s.host, "board-1.local");
    assert_int_equal(s.port, 65535);
    assert_int_equal(link_spec_parse("usb", &s), LINK_SPEC_OK);
    assert_int_equal(s.kind, LINK_KIND_USB);
    assert_int_equal(s.vid, 0x1209);
    assert_int_equal(s.pid, 0x0001);
    assert_false(s.by_path);
    assert_int_equal(link_spec_parse("usb:CAFE:b0b", &s), LINK_SPEC_OK);
    assert_int_equal(s.vid, 0xCAFE);
    assert_int_equal(s.pid, 0x0B0B);
    assert_int_equal(link_spec_parse("usb:3-1.4.2", &s), LINK_SPEC_OK);
    assert_true(s.by_path);
    assert_int_equal(s.bus, 3);
    assert_int_equal(s.n_ports, 3);
    assert_int_equal(s.ports[0], 1);
    assert_int_equal(s.ports[1], 4);
    assert_int_equal(s.ports[2], 2);
    assert_int_equal(link_spec_parse("usb:1-1.2.3.4.5.6.7", &s), LINK_SPEC_OK);
    assert_int_equal(s.n_ports, 7);
}

static void test_spec_errors(void **state)
{
    (void)state;
    static const struct {
        const char *s;
        link_spec_err_t e;
    } cases[] = {
        {NULL, LINK_SPEC_ERR_EMPTY},
        {"", LINK_SPEC_ERR_EMPTY},
        {"tcp:1.2.3.4:5", LINK_SPEC_ERR_KIND},
        {"simulator", LINK_SPEC_ERR_KIND},
        {"usbx", LINK_SPEC_ERR_KIND},
        {"sim:fast", LINK_SPEC_ERR_SIM_ARGS},
        {"sim:", LINK_SPEC_ERR_SIM_ARGS},
        {"sim:pressx", LINK_SPEC_ERR_SIM_ARGS},
        {"udp", LINK_SPEC_ERR_UDP_FORM},
        {"udp:", LINK_SPEC_ERR_UDP_FORM},
        {"udp:1.2.3.4", LINK_SPEC_ERR_UDP_FORM},
        {"udp::5000", LINK_SPEC_ERR_UDP_HOST},
        {"udp:bad host:5000", LINK_SPEC_ERR_UDP_HOST},
        {"udp:aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa:1",
         LINK_SPEC_ERR_UDP_HOST},
        {"udp:h:0", LINK_SPEC_ERR_UDP_PORT},
        {"udp:h:65536", LINK_SPEC_ERR_UDP_PORT},
        {"udp:h:", LINK_SPEC_ERR_UDP_PORT},
        {"udp:h:12x", LINK_SPEC_ERR_UDP_PORT},
        {"udp:h:-1", LINK_SPEC_ERR_UDP_PORT},
        {"usb:", LINK_SPEC_ERR_USB_FORM},
        {"usb:1209", LINK_SPEC_ERR_USB_FORM},
        {"usb:12345:1", LINK_SPEC_ERR_USB_ID},
        {"usb:1209:", LINK_SPEC_ERR_USB_ID},
        {"usb::1", LINK_SPEC_ERR_USB_ID},
        {"usb:12g9:0001", LINK_SPEC_ERR_USB_ID},
        {"usb:0-1", LINK_SPEC_ERR_USB_BUS},
        {"usb:256-1", LINK_SPEC_ERR_USB_BUS},
        {"usb:-1", LINK_SPEC_ERR_USB_BUS},
        {"usb:1-", LINK_SPEC_ERR_USB_PORT},
        {"usb:1-0", LINK_SPEC_ERR_USB_PORT},
        {"usb:1-2..3", LINK_SPEC_ERR_USB_PORT},
        {"usb:1-2.", LINK_SPEC_ERR_USB_PORT},
        {"usb:1-2-3", LINK_SPEC_ERR_USB_PORT},
        {"usb:1-1.2.3.4.5.6.7.8", LINK_SPEC_ERR_USB_DEPTH},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        link_spec_t s;
        const link_spec_err_t e = link_spec_parse(cases[i].s, &s);
        if (e != cases[i].e)
            fail_msg("'%s': got %d, want %d", cases[i].s ? cases[i].s : "(null)", e, cases[i].e);
        /* Every error has its own explanation. */
        assert_true(strlen(link_spec_err_text(e)) > 10);
    }
    assert_string_not_equal(link_spec_err_text(LINK_SPEC_ERR_USB_ID),
                            link_spec_err_text(LINK_SPEC_ERR_USB_FORM));
}

/* ---- descriptors ---- */

/* A configuration as the dummy_hcd UDC presents argil's FunctionFS gadget: a HID-like
 * interface 0 first (class 3, one interrupt IN), then the vendor interface 1 whose endpoints
 * came back renumbered (OUT 0x02, IN 0x81), with an unrelated class descriptor in between. */
static size_t make_config(uint8_t *b)
{
    static const uint8_t cfg[] = {
        9, 2, 0, 0, 2, 1, 0, 0x80, 50,                /* config, wTotalLength patched */
        9, 4, 0, 0, 1, 3, 0, 0, 0,                    /* interface 0: HID */
        9, 0x21, 0x11, 0x01, 0, 1, 0x22, 0x20, 0,     /* HID class descriptor */
        7, 5, 0x83, 3, 8, 0, 10,                      /* interrupt IN */
        9, 4, 1, 0, 2, 0xFF, 0, 0, 1,                 /* interface 1: vendor */
        7, 5, 0x02, 2, 0x00, 0x02, 0,                 /* bulk OUT 0x02, 512 */
        7, 5, 0x81, 2, 0x00, 0x02, 0,                 /* bulk IN 0x81, 512 */
    };
    memcpy(b, cfg, sizeof(cfg));
    b[2] = (uint8_t)sizeof(cfg);
    b[3] = 0;
    return sizeof(cfg);
}

static void test_desc_endpoints(void **state)
{
    (void)state;
    uint8_t b[128];
    const size_t n = make_config(b);
    usb_endpoints_t ep;
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_OK);
    assert_int_equal(ep.interface, 1);
    assert_int_equal(ep.alt_setting, 0);
    assert_int_equal(ep.ep_in, 0x81);
    assert_int_equal(ep.ep_out, 0x02);
    assert_int_equal(ep.in_max_packet, 512);
    assert_int_equal(ep.out_max_packet, 512);
    /* The gadget's declared numbering (full speed: 64-byte packets) reads just as well. */
    b[n - 14 + 2] = 0x01;
    b[n - 7 + 2] = 0x82;
    b[n - 14 + 4] = 64;
    b[n - 14 + 5] = 0;
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_OK);
    assert_int_equal(ep.ep_out, 0x01);
    assert_int_equal(ep.ep_in, 0x82);
    assert_int_equal(ep.out_max_packet, 64);
}

static void test_desc_errors(void **state)
{
    (void)state;
    uint8_t b[128];
    usb_endpoints_t ep;
    size_t n = make_config(b);
    assert_int_equal(usb_desc_find_endpoints(b, 8, &ep), USB_DESC_ERR_SHORT);
    assert_int_equal(usb_desc_find_endpoints(b, n - 1, &ep), USB_DESC_ERR_SHORT); /* total > len */
    b[1] = 1; /* a device descriptor, not a configuration */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_TYPE);
    n = make_config(b);
    b[9 + 9] = 0; /* the HID class descriptor's bLength */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_LENGTH);
    n = make_config(b);
    b[n - 7] = 20; /* the last endpoint runs past the end */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_LENGTH);
    n = make_config(b);
    b[9 + 9 + 9 + 7 + 5] = 0x08; /* the vendor interface becomes mass storage */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_NO_INTERFACE);
    n = make_config(b);
    b[n - 7 + 3] = 3; /* the IN endpoint is interrupt, not bulk */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_NO_INTERFACE);
    n = make_config(b);
    b[2] = 9; /* a configuration with no interfaces at all */
    assert_int_equal(usb_desc_find_endpoints(b, n, &ep), USB_DESC_ERR_NO_INTERFACE);
    assert_true(strlen(usb_desc_err_text(USB_DESC_ERR_NO_INTERFACE)) > 10);
}

static void test_desc_path_match(void **state)
{
    (void)state;
    link_spec_t s;
    assert_int_equal(link_spec_parse("usb:3-1.4", &s), LINK_SPEC_OK);
    const uint8_t p14[2] = {1, 4}, p15[2] = {1, 5}, p1[1] = {1};
    assert_true(usb_desc_path_match(&s, 3, p14, 2));
    assert_false(usb_desc_path_match(&s, 2, p14, 2));
    assert_false(usb_desc_path_match(&s, 3, p15, 2));
    assert_false(usb_desc_path_match(&s, 3, p1, 1));
    assert_int_equal(link_spec_parse("usb", &s), LINK_SPEC_OK);
    assert_false(usb_desc_path_match(&s, 3, p14, 2)); /* by VID:PID, not by path */
}

/* ---- the state machine ---- */

static void test_fsm(void **state)
{
    (void)state;
    link_fsm_t f;
    link_fsm_init(&f, 100000u, true);
    assert_int_equal(f.state, LINK_WAITING);
    link_fsm_tick(&f, 5000000u); /* waiting never times out into LOST */
    assert_int_equal(f.state, LINK_WAITING);
    link_fsm_frame(&f, 5000000u);
    assert_int_equal(f.state, LINK_CONNECTED);
    assert_false(link_fsm_take_resync(&f)); /* the first connection is not a RE-connection */
    link_fsm_frame(&f, 5050000u);
    link_fsm_tick(&f, 5150000u); /* 100 ms silence exactly: still connected */
    assert_int_equal(f.state, LINK_CONNECTED);
    link_fsm_tick(&f, 5150001u);
    assert_int_equal(f.state, LINK_LOST);
    assert_int_equal(f.losses, 1);
    link_fsm_frame(&f, 6000000u);
    assert_int_equal(f.state, LINK_CONNECTED);
    assert_int_equal(f.reconnects, 1);
    assert_true(link_fsm_take_resync(&f));
    assert_false(link_fsm_take_resync(&f)); /* once per reconnection */
    /* Unplug: lost at once; frames that were in flight do not reconnect a closed transport. */
    link_fsm_transport_down(&f);
    assert_int_equal(f.state, LINK_LOST);
    assert_int_equal(f.losses, 2);
    assert_int_equal(f.transport_drops, 1);
    link_fsm_transport_down(&f); /* a second report of the same unplug counts nothing */
    assert_int_equal(f.transport_drops, 1);
    assert_int_equal(f.losses, 2);
    link_fsm_frame(&f, 6010000u);
    assert_int_equal(f.state, LINK_LOST);
    link_fsm_transport_up(&f);
    assert_int_equal(f.state, LINK_LOST); /* reopened, but the board has not spoken yet */
    link_fsm_frame(&f, 7000000u);
    assert_int_equal(f.state, LINK_CONNECTED);
    assert_int_equal(f.reconnects, 2);
    assert_true(link_fsm_take_resync(&f));
    /* A transport lost before anything was heard: still waiting, no loss counted. */
    link_fsm_init(&f, 100000u, true);
    link_fsm_transport_down(&f);
    assert_int_equal(f.state, LINK_WAITING);
    assert_int_equal(f.losses, 0);
    assert_string_equal(link_state_name(LINK_LOST), "lost");
}

/* ---- the link through a fake transport (a USB device that is unplugged and replugged) ---- */

typedef struct {
    uint8_t frames[8][64];
    size_t lens[8];
    int n, at;
    bool plugged, unplug_now, replug_now;
    int sent;
    bool full;
} fake_t;

static argil_err_t fake_send(link_t *l, const uint8_t *frame, size_t len)
{
    fake_t *f = l->impl;
    (void)frame;
    (void)len;
    if (!f->plugged)
        return ARGIL_ERR_IO;
    if (f->full)
        return ARGIL_ERR_FULL;
    f->sent++;
    return ARGIL_OK;
}

static size_t fake_recv(link_t *l, uint8_t *buf, size_t cap)
{
    fake_t *f = l->impl;
    if (!f->plugged || f->at >= f->n || f->lens[f->at] > cap)
        return 0;
    memcpy(buf, f->frames[f->at], f->lens[f->at]);
    return f->lens[f->at++];
}

static void fake_poll(link_t *l, uint32_t wait_us, uint64_t now_us)
{
    (void)wait_us;
    (void)now_us;
    fake_t *f = l->impl;
    if (f->unplug_now) {
        f->unplug_now = false;
        f->plugged = false;
        f->n = f->at = 0;
        link_transport_down(l);
    }
    if (f->replug_now) {
        f->replug_now = false;
        f->plugged = true;
        link_transport_up(l);
    }
}

static const link_ops_t FAKE_OPS = {fake_send, fake_recv, fake_poll, NULL};

static size_t heartbeat_frame(uint8_t *buf, size_t cap, uint32_t seq)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HEARTBEAT;
    m.u.heartbeat.time_us = seq;
    size_t len = 0;
    assert_int_equal(proto_encode(&m, seq, buf, cap, &len), PROTO_OK);
    return len;
}

static void fake_queue(fake_t *f, uint32_t seq)
{
    f->lens[f->n] = heartbeat_frame(f->frames[f->n], sizeof(f->frames[0]), seq);
    f->n++;
}

static void test_link_fake_unplug_replug(void **state)
{
    (void)state;
    fake_t f;
    memset(&f, 0, sizeof(f));
    f.plugged = true;
    link_t l;
    memset(&l, 0, sizeof(l));
    link_attach(&l, &FAKE_OPS, &f, true);
    uint8_t buf[PROTO_FRAME_MAX];
    uint64_t t = 1000000u;
    link_poll(&l, 0, t);
    assert_int_equal(link_state(&l), LINK_WAITING);
    fake_queue(&f, 1);
    fake_queue(&f, 2);
    size_t n1 = link_recv(&l, buf, sizeof(buf));
    assert_int_equal(n1, 33); /* a HEARTBEAT frame */
    assert_int_equal(link_recv(&l, buf, sizeof(buf)), 33);
    assert_int_equal(link_recv(&l, buf, sizeof(buf)), 0);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_int_equal(l.stats.frames_rx, 2);
    assert_int_equal(l.stats.bytes_rx, 66);
    assert_int_equal(link_send(&l, buf, 33), ARGIL_OK);
    f.full = true;
    assert_int_equal(link_send(&l, buf, 33), ARGIL_ERR_FULL);
    f.full = false;
    assert_int_equal(l.stats.frames_tx, 1);
    assert_int_equal(l.stats.errors_tx, 1);
    /* A poll that returned late (the process was stopped): with a fresh clock the silence is
     * seen before the frames that end it, so they count as a reconnection. */
    link_poll(&l, 0, t);
    link_set_time(&l, t += 300000u);
    assert_int_equal(link_state(&l), LINK_LOST);
    fake_queue(&f, 9);
    assert_int_equal(link_recv(&l, buf, sizeof(buf)), 33);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_true(link_take_resync(&l));
    assert_int_equal(l.stats.reconnects, 1);
    /* Unplug: LOST at the next poll; sends fail; nothing is received. */
    f.unplug_now = true;
    link_poll(&l, 0, t += 1000u);
    assert_int_equal(link_state(&l), LINK_LOST);
    assert_int_equal(link_send(&l, buf, 33), ARGIL_ERR_IO);
    link_poll(&l, 0, t += 500000u);
    assert_int_equal(link_state(&l), LINK_LOST);
    assert_false(link_take_resync(&l));
    link_set_time(&l, t - 1000u); /* time never goes back */
    assert_true(l.now_us == t);
    /* Replug: still LOST until the board speaks, then CONNECTED and one resync. */
    f.replug_now = true;
    link_poll(&l, 0, t += 1000u);
    assert_int_equal(link_state(&l), LINK_LOST);
    fake_queue(&f, 3);
    assert_int_equal(link_recv(&l, buf, sizeof(buf)), 33);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_true(link_take_resync(&l));
    assert_false(link_take_resync(&l));
    assert_int_equal(l.stats.reconnects, 2);
    assert_int_equal(l.stats.frames_rx, 4);
}

/* ---- UDP against a board socket on 127.0.0.1 ---- */

static int board_socket(uint16_t *port)
{
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    assert_true(fd >= 0);
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    struct sockaddr_in a;
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(*port);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof(a)), 0);
    socklen_t al = sizeof(a);
    getsockname(fd, (struct sockaddr *)&a, &al);
    *port = ntohs(a.sin_port);
    struct timeval tv = {1, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    return fd;
}

/* Polls until a frame arrives (at most 1 s); returns its size. */
static size_t udp_wait_frame(link_t *l, uint8_t *buf, uint64_t *t)
{
    for (int k = 0; k < 1000; k++) {
        link_poll(l, 1000u, *t += 1000u);
        const size_t n = link_recv(l, buf, PROTO_FRAME_MAX);
        if (n > 0)
            return n;
    }
    return 0;
}

static void test_udp_frames_and_restart(void **state)
{
    (void)state;
    uint16_t port = 0;
    int bfd = board_socket(&port);
    char dev[64], err[512];
    snprintf(dev, sizeof(dev), "udp:127.0.0.1:%u", port);
    link_t l;
    assert_int_equal(link_open(&l, dev, err, sizeof(err)), ARGIL_OK);
    uint8_t f[PROTO_FRAME_MAX], buf[PROTO_FRAME_MAX * 3];
    const size_t fl = heartbeat_frame(f, sizeof(f), 7);
    /* Host → board: one frame, one datagram of exactly that frame. */
    assert_int_equal(link_send(&l, f, fl), ARGIL_OK);
    struct sockaddr_in host;
    socklen_t hl = sizeof(host);
    const ssize_t got = recvfrom(bfd, buf, sizeof(buf), 0, (struct sockaddr *)&host, &hl);
    assert_int_equal(got, (ssize_t)fl);
    assert_memory_equal(buf, f, fl);
    /* Board → host: a datagram of two frames, then a datagram of junk, then one frame. */
    memcpy(buf, f, fl);
    memcpy(buf + fl, f, fl);
    sendto(bfd, buf, 2 * fl, 0, (struct sockaddr *)&host, hl);
    sendto(bfd, "junk junk junk junk", 19, 0, (struct sockaddr *)&host, hl);
    sendto(bfd, f, fl, 0, (struct sockaddr *)&host, hl);
    uint64_t t = 1000000u;
    uint8_t in[PROTO_FRAME_MAX];
    assert_int_equal(udp_wait_frame(&l, in, &t), fl);
    assert_int_equal(udp_wait_frame(&l, in, &t), fl);
    assert_int_equal(udp_wait_frame(&l, in, &t), fl);
    assert_memory_equal(in, f, fl);
    assert_int_equal(l.stats.frames_rx, 3);
    assert_int_equal(l.stats.errors_rx, 1);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    /* The board restarts: silence (virtual 150 ms) → LOST; the new board on the same port
     * hears our next frame and answers → CONNECTED with one resync. */
    close(bfd);
    link_poll(&l, 0, t += 150000u);
    assert_int_equal(link_state(&l), LINK_LOST);
    (void)link_send(&l, f, fl); /* may be refused (port closed): that is counted, not fatal */
    bfd = board_socket(&port);
    assert_int_equal(link_send(&l, f, fl), ARGIL_OK);
    hl = sizeof(host);
    assert_int_equal(recvfrom(bfd, buf, sizeof(buf), 0, (struct sockaddr *)&host, &hl),
                     (ssize_t)fl);
    sendto(bfd, f, fl, 0, (struct sockaddr *)&host, hl);
    assert_int_equal(udp_wait_frame(&l, in, &t), fl);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_true(link_take_resync(&l));
    assert_int_equal(l.stats.reconnects, 1);
    link_close(&l);
    close(bfd);
}

/* ---- the simulated board ---- */

typedef struct {
    link_t *l;
    uint32_t frames, first_seq, last_seq;
    bool out_of_order;
    uint32_t hellos_sent;
} seq_probe_t;

/* The host's frames on their way to the link: every one's number must be the last one's + 1. */
static bool probe_send(void *ctx, const uint8_t *f, size_t len)
{
    seq_probe_t *p = ctx;
    assert_true(len >= PROTO_HEADER_SIZE);
    const uint32_t seq = (uint32_t)f[8] | (uint32_t)f[9] << 8 | (uint32_t)f[10] << 16 |
                         (uint32_t)f[11] << 24;
    if (p->frames == 0)
        p->first_seq = seq;
    else if (seq != p->last_seq + 1u)
        p->out_of_order = true;
    p->last_seq = seq;
    p->frames++;
    if (f[5] == MSG_HELLO)
        p->hellos_sent++;
    return link_send(p->l, f, len) == ARGIL_OK;
}

/* Runs the peer over the link for ms milliseconds of virtual time; returns board HELLOs seen. */
static uint32_t run_peer(link_t *l, peer_t *peer, int ms, uint64_t *t)
{
    uint8_t f[PROTO_FRAME_MAX];
    uint32_t hellos = 0;
    for (int i = 0; i < ms; i++) {
        link_poll(l, 0, *t += 1000u);
        size_t n;
        while ((n = link_recv(l, f, sizeof(f))) > 0) {
            hellos += f[5] == MSG_HELLO;
            peer_receive(peer, f, n);
        }
        peer_tick(peer, 1000);
    }
    return hellos;
}

/* The host's side of the board's session: the peer numbers every frame it sends (HELLO,
 * tool, window chunks, heartbeats) in one increasing sequence, across a second HELLO (a
 * reconnection starts a new session) too; the board, which refuses a repeated or old number,
 * refuses none of them (its RT_STATS says so), and arms. */
static void test_host_numbers_its_frames_in_one_sequence(void **state)
{
    (void)state;
    static link_t l;
    char err[256];
    assert_int_equal(link_open(&l, "sim", err, sizeof(err)), ARGIL_OK);
    static grid_t g;
    const int32_t dims[3] = {24, 24, 24};
    assert_int_equal(grid_init(&g, dims, 0.0025f, vec3(-0.03f, -0.03f, -0.03f)), ARGIL_OK);
    grid_fill_sphere(&g, vec3(0, 0, 0), 0.02f);
    seq_probe_t probe = {&l, 0, 0, 0, false, 0};
    static peer_t peer;
    peer_cfg_t pc;
    peer_cfg_default(&pc);
    assert_int_equal(peer_init(&peer, &pc, &g, probe_send, NULL, &probe), ARGIL_OK);
    msg_tool_t t;
    memset(&t, 0, sizeof(t));
    t.radius_m = 0.004f;
    t.axis[2] = 1.0f;
    t.contact_stiffness_n_per_m = 800.0f;
    t.max_force_n = 3.0f;
    t.model_scale = 1.0f;
    peer_set_tool(&peer, &t);
    peer_request_arm(&peer);
    uint64_t now = 1000u;
    /* nothing before a HELLO: the peer waits for the board, the board for a host */
    assert_int_equal(run_peer(&l, &peer, 50, &now), 0);
    assert_int_equal(probe.frames, 0);
    assert_true(peer_send_hello(&peer, "test"));
    assert_int_equal(run_peer(&l, &peer, 1100, &now), 1);
    assert_true(peer.stats.rt_stats_frames >= 1);
    assert_int_equal(peer.last_rt.link.sessions, 1);
    assert_true(peer.have_tm && peer.last_tm.state == SAFETY_ACTIVE);
    /* a reconnection: HELLO again, the board answers and resends nothing it need not */
    assert_true(peer_send_hello(&peer, "test"));
    assert_int_equal(run_peer(&l, &peer, 1100, &now), 1);
    assert_true(peer_send_command(&peer, PROTO_CMD_END));
    assert_int_equal(run_peer(&l, &peer, 1100, &now), 0);
    const proto_link_counts_t *c = &peer.last_rt.link;
    printf("  %u frames numbered %u..%u; board: sessions %u, refused duplicate %u, stale %u, "
           "no session %u\n", probe.frames, probe.first_seq, probe.last_seq, c->sessions,
           c->duplicate, c->stale, c->no_session);
    assert_false(probe.out_of_order);
    assert_true(probe.frames > 300);
    assert_int_equal(probe.hellos_sent, 2);
    assert_int_equal(c->sessions, 2);
    assert_int_equal(c->duplicate, 0);
    assert_int_equal(c->stale, 0);
    /* after END the peer's heartbeats find no session: refused, counted, and the arm is off */
    assert_true(c->no_session > 50);
    assert_int_equal(peer.last_tm.state, SAFETY_IDLE);
    peer_free(&peer);
    grid_free(&g);
    link_close(&l);
}

/* Opens the sim board on device and says HELLO to it as its host. */
static void open_sim_and_hello(link_t *l, const char *device)
{
    char err[256];
    assert_int_equal(link_open(l, device, err, sizeof(err)), ARGIL_OK);
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HELLO;
    m.u.hello.role = PROTO_ROLE_HOST;
    uint8_t f[PROTO_FRAME_MAX];
    size_t fl = 0;
    assert_int_equal(proto_encode(&m, 0, f, sizeof(f), &fl), PROTO_OK);
    assert_int_equal(link_send(l, f, fl), ARGIL_OK);
}

static void test_sim_board_answers(void **state)
{
    (void)state;
    link_t l;
    open_sim_and_hello(&l, "sim");
    proto_msg_t m;
    uint8_t f[PROTO_FRAME_MAX];
    /* 200 ms of virtual time (no sleeping: wait 0): the board answers HELLO, telemetry every
     * tick. */
    uint32_t hellos = 0, telemetry = 0, last_tick = 0;
    uint64_t t = 1000u;
    for (int ms = 0; ms < 200; ms++) {
        link_poll(&l, 0, t += 1000u);
        size_t n;
        while ((n = link_recv(&l, f, sizeof(f))) > 0) {
            size_t used = 0;
            assert_int_equal(proto_decode(f, n, &m, &used), PROTO_OK);
            assert_int_equal(used, n);
            if (m.type == MSG_HELLO)
                hellos++;
            if (m.type == MSG_TELEMETRY) {
                telemetry++;
                last_tick = m.u.telemetry.tick;
                assert_int_equal(m.u.telemetry.state, SAFETY_IDLE);
            }
        }
    }
    assert_int_equal(hellos, 1);
    assert_in_range(telemetry, 195, 200); /* one per 1 ms tick */
    assert_in_range(last_tick, 195, 200);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_int_equal(l.stats.errors_rx, 0);
    link_close(&l);
}

/* How many of 2 s of the sim board's telemetry rows show stylus button 1 held. */
static void sim_hand_buttons(const char *device, uint32_t *b1_rows, uint32_t *rows)
{
    link_t l;
    open_sim_and_hello(&l, device);
    proto_msg_t m;
    uint8_t f[PROTO_FRAME_MAX];
    *b1_rows = *rows = 0;
    uint64_t t = 1000u;
    for (int ms = 0; ms < 2000; ms++) {
        link_poll(&l, 0, t += 1000u);
        size_t n;
        while ((n = link_recv(&l, f, sizeof(f))) > 0) {
            size_t used = 0;
            assert_int_equal(proto_decode(f, n, &m, &used), PROTO_OK);
            if (m.type != MSG_TELEMETRY)
                continue;
            (*rows)++;
            *b1_rows += (m.u.telemetry.buttons & 1u) != 0;
        }
    }
    link_close(&l);
}

/* "sim" holds the stylus still with no button; "sim:press" holds button 1 for 1.4 s of every
 * 2 s (the board reports no position before it is armed, so the press itself, 4 mm into the
 * clay, is tested by tests/sys/test_connect_options.sh: the carve it makes is journaled). */
static void test_sim_board_hands(void **state)
{
    (void)state;
    uint32_t b1_rows, rows;
    sim_hand_buttons("sim", &b1_rows, &rows);
    assert_in_range(rows, 1990, 2000);
    assert_int_equal(b1_rows, 0);
    sim_hand_buttons("sim:press", &b1_rows, &rows);
    assert_in_range(rows, 1990, 2000);
    assert_in_range(b1_rows, 1380, 1420);
}

static void test_open_errors(void **state)
{
    (void)state;
    link_t l;
    char err[512];
    assert_int_equal(link_open(&l, "udp:1.2.3.4", err, sizeof(err)), ARGIL_ERR_PARSE);
    assert_non_null(strstr(err, "bad device 'udp:1.2.3.4'"));
    assert_null(strchr(err, '\n'));
    /* This machine has no argil board on USB (and perhaps no USB at all): one line, IO. */
    assert_int_equal(link_open(&l, "usb:1209:0001", err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "usb"));
    assert_null(strchr(err, '\n'));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spec_accepts),
        cmocka_unit_test(test_spec_errors),
        cmocka_unit_test(test_desc_endpoints),
        cmocka_unit_test(test_desc_errors),
        cmocka_unit_test(test_desc_path_match),
        cmocka_unit_test(test_fsm),
        cmocka_unit_test(test_link_fake_unplug_replug),
        cmocka_unit_test(test_udp_frames_and_restart),
        cmocka_unit_test(test_sim_board_answers),
        cmocka_unit_test(test_sim_board_hands),
        cmocka_unit_test(test_host_numbers_its_frames_in_one_sequence),
        cmocka_unit_test(test_open_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
