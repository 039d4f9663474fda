/* The daemon's Linux side against fakes: SocketCAN frames through a SOCK_SEQPACKET socketpair
 * (the same one-frame-per-read semantics as a raw CAN socket), the GPIO mapping against a fake
 * chip, the UDP link on 127.0.0.1, the stream framer, FunctionFS descriptors, the SPSC ring,
 * and the configuration parser's every refusal. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "firmware/board/board_config.h"
#include "firmware/core/drives.h"
#include "bus/can_socket.h"
#include "firmware/hal/gpio_port.h"
#include "firmware/hal/link_io.h"
#include "shared/gpio_lines.h"
#include "shared/spsc_ring.h"

static void test_can_socket_frames_and_error_frames(void **st)
{
    (void)st;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    struct can_frame cf;
    memset(&cf, 0, sizeof(cf));
    cf.can_id = 0x182;
    cf.can_dlc = 8;
    cf.data[0] = 0x37;
    assert_int_equal(write(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
    memset(&cf, 0, sizeof(cf));
    cf.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
    cf.can_dlc = CAN_ERR_DLC;
    assert_int_equal(write(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
    memset(&cf, 0, sizeof(cf));
    cf.can_id = CAN_EFF_FLAG | 0x1234567; /* 29-bit: not CANopen, dropped */
    assert_int_equal(write(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
    can_batch_t rx;
    can_socket_stats_t stats = {0};
    assert_int_equal(can_socket_receive(sv[0], &rx, &stats), ARGIL_OK);
    assert_int_equal(rx.n, 2);
    assert_int_equal(rx.f[0].id, 0x182);
    assert_int_equal(rx.f[0].data[0], 0x37);
    assert_int_equal(rx.f[1].id, ARGIL_CAN_ERR_FLAG | ARGIL_CAN_ERR_BUSOFF);
    assert_int_equal(stats.rx_error_frames, 1);
    assert_int_equal(stats.rx_dropped, 1);
    /* The core sees bus-off from it in the same tick. */
    drives_t dr;
    drives_cfg_t cfg;
    drives_cfg_default(&cfg);
    drives_init(&dr);
    drives_receive(&dr, &rx);
    assert_true(drives_bus_error(&dr, &cfg));
    /* Nothing waiting: returns at once with no frames (never blocks). */
    assert_int_equal(can_socket_receive(sv[0], &rx, &stats), ARGIL_OK);
    assert_int_equal(rx.n, 0);
    /* Send: each frame arrives whole with 11-bit id and its length. */
    can_batch_t tx = {0};
    can_frame_t f;
    canopen_rpdo_encode(&f, 2, CIA402_CW_ENABLE_OP, -250);
    (void)can_batch_push(&tx, &f);
    canopen_sync_encode(&f);
    (void)can_batch_push(&tx, &f);
    assert_int_equal(can_socket_send(sv[0], &tx, &stats), ARGIL_OK);
    assert_int_equal(read(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
    assert_int_equal(cf.can_id, 0x202);
    assert_int_equal(cf.can_dlc, 4);
    assert_int_equal(cf.data[0], 0x0F);
    assert_int_equal(read(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
    assert_int_equal(cf.can_id, 0x080);
    assert_int_equal(cf.can_dlc, 0);
    close(sv[0]);
    close(sv[1]);
}

/* After a stalled tick the board's socket holds a backlog: 40 ticks of the three drives' TPDOs
 * with a heartbeat and an EMCY among them. The board's read takes the whole backlog out of the
 * socket at once (whose queue would overflow and lose frames), hands the core the heartbeat and
 * the EMCY in the first tick, and the TPDOs in their order, a batch a tick. */
static void test_can_board_read_queues_a_backlog(void **st)
{
    (void)st;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    struct can_frame cf;
    for (int k = 0; k < 40; k++) {
        for (int n = 1; n <= 3; n++) {
            memset(&cf, 0, sizeof(cf));
            cf.can_id = 0x180u + (uint32_t)n;
            cf.can_dlc = 8;
            cf.data[2] = (uint8_t)k; /* position: the tick it was sent in */
            assert_int_equal(write(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
        }
        if (k == 20 || k == 30) {
            memset(&cf, 0, sizeof(cf));
            cf.can_id = k == 20 ? 0x702u : 0x083u; /* drive 2's heartbeat, drive 3's EMCY */
            cf.can_dlc = k == 20 ? 1 : 8;
            cf.data[0] = k == 20 ? 0x05 : 0x10;
            assert_int_equal(write(sv[1], &cf, sizeof(cf)), (ssize_t)sizeof(cf));
        }
    }
    static can_rx_queue_t q;
    can_batch_t rx;
    can_socket_stats_t stats = {0};
    assert_int_equal(can_socket_receive_queued(sv[0], &q, &rx, &stats), ARGIL_OK);
    assert_int_equal(stats.rx_frames, 122); /* the socket is empty after one read */
    assert_int_equal(rx.n, CAN_BATCH_MAX);
    assert_int_equal(rx.f[0].id, 0x702);
    assert_int_equal(rx.f[1].id, 0x083);
    int tpdos = 0, last[4] = {-1, -1, -1, -1};
    for (int tick = 0; tick < 5; tick++) {
        if (tick > 0)
            assert_int_equal(can_socket_receive_queued(sv[0], &q, &rx, &stats), ARGIL_OK);
        for (uint8_t i = 0; i < rx.n; i++) {
            const uint32_t id = rx.f[i].id;
            if (id < 0x181 || id > 0x183)
                continue;
            assert_int_equal(rx.f[i].data[2], last[id - 0x180] + 1); /* in order, none lost */
            last[id - 0x180] = rx.f[i].data[2];
            tpdos++;
        }
    }
    assert_int_equal(tpdos, 120);
    assert_int_equal(stats.rx_queue_peak, 122);
    assert_int_equal(can_socket_receive_queued(sv[0], &q, &rx, &stats), ARGIL_OK);
    assert_int_equal(rx.n, 0);
    close(sv[0]);
    close(sv[1]);
}

static void test_can_open_errors_are_one_line(void **st)
{
    (void)st;
    int fd;
    char err[200];
    assert_int_equal(can_socket_open("", &fd, err, sizeof(err)), ARGIL_ERR_ARG);
    assert_int_equal(can_socket_open("a_name_far_too_long", &fd, err, sizeof(err)), ARGIL_ERR_ARG);
    assert_int_equal(can_socket_open("nocan9", &fd, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "'nocan9'"));
    assert_null(strchr(err, '\n'));
    assert_int_equal(fd, -1);
}

/* ---- a fake GPIO chip ---- */
typedef struct {
    const char *names[8];
    int level[8];
    bool requested[8];
    bool is_out[8];
    int refuse;                /* index whose request fails, -1 none */
    int opened;
} fake_chip_t;

static void *f_open(void *ctx, const char *chip)
{
    fake_chip_t *c = ctx;
    if (strcmp(chip, "fake0") != 0)
        return NULL;
    c->opened++;
    return c;
}
static void f_close(void *ctx, void *chip) { (void)chip; ((fake_chip_t *)ctx)->opened--; }
static void *f_find(void *ctx, void *chip, const char *name)
{
    (void)chip;
    fake_chip_t *c = ctx;
    for (intptr_t i = 0; i < 8 && c->names[i]; i++)
        if (strcmp(c->names[i], name) == 0)
            return (void *)(i + 1);
    return NULL;
}
static int f_req_in(void *ctx, void *line, const char *who)
{
    (void)who;
    fake_chip_t *c = ctx;
    const intptr_t i = (intptr_t)line - 1;
    if (i == c->refuse)
        return -1;
    c->requested[i] = true;
    return 0;
}
static int f_req_out(void *ctx, void *line, const char *who, int level)
{
    fake_chip_t *c = ctx;
    const int rc = f_req_in(ctx, line, who);
    if (rc == 0) {
        c->is_out[(intptr_t)line - 1] = true;
        c->level[(intptr_t)line - 1] = level;
    }
    return rc;
}
static int f_get(void *ctx, void *line) { return ((fake_chip_t *)ctx)->level[(intptr_t)line - 1]; }
static int f_set(void *ctx, void *line, int level)
{
    ((fake_chip_t *)ctx)->level[(intptr_t)line - 1] = level;
    return 0;
}
static void f_release(void *ctx, void *line) { ((fake_chip_t *)ctx)->requested[(intptr_t)line - 1] = false; }
static const gpio_ops_t fake_ops = {f_open, f_close, f_find, f_req_in, f_req_out, f_get, f_set, f_release};

static fake_chip_t fake_chip(void)
{
    fake_chip_t c;
    memset(&c, 0, sizeof(c));
    const char *n[7] = {"ESTOP_N", "DRIVE_FAULT_N", "STYLUS_BTN1", "STYLUS_BTN2",
                        "DRIVE_ENABLE", "STATUS_LED", "WDOG_KICK"};
    memcpy(c.names, n, sizeof(n));
    c.refuse = -1;
    return c;
}

static void test_gpio_mapping_by_name(void **st)
{
    (void)st;
    fake_chip_t c = fake_chip();
    gpio_names_t names;
    gpio_names_default(&names);
    memcpy(names.chip, "fake0", 6);
    gpio_port_t p;
    char err[200];
    assert_int_equal(gpio_port_open(&p, &fake_ops, &c, &names, err, sizeof(err)), ARGIL_OK);
    for (int i = 4; i < 7; i++)
        assert_true(c.is_out[i] && c.level[i] == 0); /* outputs start low: drives disabled */
    c.level[0] = 1; /* e-stop released */
    c.level[1] = 1; /* no drive fault */
    c.level[3] = 1; /* button 2 pressed */
    assert_int_equal(gpio_port_read(&p), GPIO_IN_ESTOP_N | GPIO_IN_DRIVE_FAULT_N | GPIO_IN_STYLUS_BTN2);
    c.level[0] = 0; /* e-stop pressed: the bit drops, the core sees it this tick */
    assert_int_equal(gpio_port_read(&p) & GPIO_IN_ESTOP_N, 0);
    gpio_port_write(&p, GPIO_OUT_DRIVE_ENABLE | GPIO_OUT_WDOG_KICK);
    assert_int_equal(c.level[4], 1);
    assert_int_equal(c.level[5], 0);
    assert_int_equal(c.level[6], 1);
    gpio_port_write(&p, GPIO_OUT_DRIVE_ENABLE);
    assert_int_equal(c.level[6], 0); /* the watchdog line toggles */
    gpio_port_close(&p);
    assert_int_equal(c.level[4], 0); /* closing drops DRIVE_ENABLE */
    for (int i = 0; i < 7; i++)
        assert_false(c.requested[i]);
    assert_int_equal(c.opened, 0);
}

static void test_gpio_errors_name_the_line(void **st)
{
    (void)st;
    fake_chip_t c = fake_chip();
    gpio_names_t names;
    gpio_names_default(&names);
    gpio_port_t p;
    char err[200];
    assert_int_equal(gpio_port_open(&p, &fake_ops, &c, &names, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "GPIO chip 'gpiochip0' not found"));
    memcpy(names.chip, "fake0", 6);
    memcpy(names.out[1], "LED_TYPO", 9);
    assert_int_equal(gpio_port_open(&p, &fake_ops, &c, &names, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "GPIO line 'LED_TYPO' not found"));
    for (int i = 0; i < 7; i++)
        assert_false(c.requested[i]); /* nothing stays requested */
    assert_int_equal(c.opened, 0);
    gpio_names_default(&names);
    memcpy(names.chip, "fake0", 6);
    c.refuse = 2;
    assert_int_equal(gpio_port_open(&p, &fake_ops, &c, &names, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "'STYLUS_BTN1'"));
    assert_non_null(strstr(err, "cannot be requested as input"));
}

/* Each malformed "ADDR:PORT" is refused with the code of the rule it broke. */
static void test_udp_address_rules(void **st)
{
    (void)st;
    static const struct {
        link_udp_addr_err_t want;
        const char *specs[6]; /* NULL ends */
    } rules[] = {
        {LINK_UDP_ADDR_ERR_FORM, {"", "127.0.0.1", ":7700"}},
        {LINK_UDP_ADDR_ERR_HOST,
         {"localhost:7700", "127.0.0.256:7700", "::1:7700",
          "1111111111111111111111111111111111111111111111111111111111111111:7700"}},
        {LINK_UDP_ADDR_ERR_PORT,
         {"127.0.0.1:", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:77a",
          "127.0.0.1:99999999999999999999"}},
    };
    struct sockaddr_in a;
    assert_int_equal(link_udp_parse(NULL, &a), LINK_UDP_ADDR_ERR_FORM);
    for (size_t r = 0; r < sizeof(rules) / sizeof(rules[0]); r++)
        for (size_t i = 0; i < 6 && rules[r].specs[i] != NULL; i++) {
            const link_udp_addr_err_t got = link_udp_parse(rules[r].specs[i], &a);
            if (got != rules[r].want)
                fail_msg("'%s': %d, expected %d", rules[r].specs[i], got, rules[r].want);
        }
    assert_int_equal(link_udp_parse("10.1.2.3:65535", &a), LINK_UDP_ADDR_OK);
    assert_int_equal(ntohs(a.sin_port), 65535);
    assert_int_equal(ntohl(a.sin_addr.s_addr), 0x0a010203u);
}

static void test_udp_link_loopback(void **st)
{
    (void)st;
    link_udp_t u;
    char err[200];
    assert_int_equal(link_udp_open(&u, "127.0.0.1:0", err, sizeof(err)), ARGIL_ERR_ARG);
    assert_int_equal(link_udp_open(&u, "localhost:7700", err, sizeof(err)), ARGIL_ERR_ARG);
    assert_int_equal(link_udp_open(&u, "127.0.0.1:47311", err, sizeof(err)), ARGIL_OK);
    uint8_t frame[PROTO_FRAME_MAX], buf[2 * PROTO_FRAME_MAX];
    assert_int_equal(link_udp_send(&u, frame, 10), ARGIL_ERR_STATE); /* no host yet */
    const int h = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in to;
    assert_int_equal(link_udp_parse("127.0.0.1:47311", &to), LINK_UDP_ADDR_OK);
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HELLO;
    m.u.hello.role = PROTO_ROLE_HOST;
    size_t len = 0;
    assert_int_equal(proto_encode(&m, 7, frame, sizeof(frame), &len), PROTO_OK);
    assert_int_equal(sendto(h, "junk", 4, 0, (struct sockaddr *)&to, sizeof(to)), 4);
    assert_int_equal(sendto(h, frame, len, 0, (struct sockaddr *)&to, sizeof(to)), (ssize_t)len);
    usleep(20000);
    assert_int_equal(link_udp_receive(&u, buf, sizeof(buf), 0), len); /* junk refused first */
    assert_int_equal(u.rx_refused, 1);
    assert_true(u.bind.bound);
    /* Two frames back to back go out as two datagrams to that host. */
    memcpy(buf, frame, len);
    memcpy(buf + len, frame, len);
    assert_int_equal(link_udp_send(&u, buf, 2 * len), ARGIL_OK);
    usleep(20000);
    assert_int_equal(recv(h, buf, sizeof(buf), MSG_DONTWAIT), (ssize_t)len);
    assert_int_equal(recv(h, buf, sizeof(buf), MSG_DONTWAIT), (ssize_t)len);
    assert_int_equal(u.tx_datagrams, 2);
    close(h);
    link_udp_close(&u);
}

/* A UDP socket on 127.0.0.1 with an ephemeral port; its address in *a. */
static int udp_peer(struct sockaddr_in *a)
{
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    assert_true(fd >= 0);
    struct sockaddr_in any = {.sin_family = AF_INET};
    inet_pton(AF_INET, "127.0.0.1", &any.sin_addr);
    assert_int_equal(bind(fd, (struct sockaddr *)&any, sizeof(any)), 0);
    socklen_t len = sizeof(*a);
    assert_int_equal(getsockname(fd, (struct sockaddr *)a, &len), 0);
    return fd;
}

static size_t frame_of(uint8_t type, uint8_t command, uint32_t seq, uint8_t *buf)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = type;
    m.u.hello.role = PROTO_ROLE_HOST;
    if (type == MSG_HEARTBEAT)
        m.u.heartbeat.command = command;
    size_t len = 0;
    assert_int_equal(proto_encode(&m, seq, buf, PROTO_FRAME_MAX, &len), PROTO_OK);
    return len;
}

/* Sends a frame from fd to the link and returns what one receive call gives the core (after
 * the datagram has crossed loopback). */
static size_t udp_deliver(link_udp_t *u, int fd, const struct sockaddr_in *to, uint8_t type,
                          uint8_t command, uint32_t seq, uint64_t now_us)
{
    uint8_t f[PROTO_FRAME_MAX], buf[2 * PROTO_FRAME_MAX];
    const size_t len = frame_of(type, command, seq, f);
    assert_int_equal(sendto(fd, f, len, 0, (const struct sockaddr *)to, sizeof(*to)),
                     (ssize_t)len);
    usleep(5000);
    return link_udp_receive(u, buf, sizeof(buf), now_us);
}

/* Whether fd got a datagram from the link (drains it). */
static bool udp_got(int fd)
{
    uint8_t b[2 * PROTO_FRAME_MAX];
    usleep(5000);
    bool any = false;
    while (recv(fd, b, sizeof(b), MSG_DONTWAIT) > 0)
        any = true;
    return any;
}

/* The binding over real sockets: the host whose HELLO came first is served until its session
 * lapses or ends; a stranger's frames (another port) never reach the core, the board's frames
 * never reach the stranger, and every refusal is counted by reason. */
static void test_udp_link_serves_its_session_host_only(void **st)
{
    (void)st;
    link_udp_t u;
    char err[200];
    assert_int_equal(link_udp_open(&u, "127.0.0.1:47313", err, sizeof(err)), ARGIL_OK);
    struct sockaddr_in to, ha, sa;
    assert_int_equal(link_udp_parse("127.0.0.1:47313", &to), LINK_UDP_ADDR_OK);
    const int host = udp_peer(&ha), stranger = udp_peer(&sa);
    uint8_t f[PROTO_FRAME_MAX];
    const size_t flen = frame_of(MSG_HEARTBEAT, 0, 0, f);
    uint64_t t = 1000000u;

    /* no session: only a host's HELLO gets through */
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HEARTBEAT, PROTO_CMD_DISARM, 9, t), 0);
    assert_int_equal(u.bind.refused_no_session, 1);
    assert_int_equal(link_udp_send(&u, f, flen), ARGIL_ERR_STATE);
    assert_true(udp_deliver(&u, host, &to, MSG_HELLO, 0, 1, t) > 0);
    link_udp_session(&u, HAL_SESSION_LIVE, 1, t += 1000u); /* the core took the HELLO */
    assert_int_equal(u.peer_changes, 1);

    /* live: the stranger's HELLO and disarm are refused; the host's heartbeat passes */
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HELLO, 0, 50, t), 0);
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HEARTBEAT, PROTO_CMD_DISARM, 51, t), 0);
    assert_int_equal(u.bind.refused_source, 2);
    assert_true(udp_deliver(&u, host, &to, MSG_HEARTBEAT, 0, 2, t) > 0);
    assert_int_equal(link_udp_send(&u, f, flen), ARGIL_OK);
    assert_true(udp_got(host));
    assert_false(udp_got(stranger));

    /* the host went quiet (lapsed): its place is kept for a while, then another host's HELLO
     * takes over and the first is refused */
    link_udp_session(&u, HAL_SESSION_LAPSED, 1, t += 60000u);
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HELLO, 0, 52, t), 0);
    t += LINK_BIND_TAKEOVER_US - 1u;
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HELLO, 0, 53, t), 0);
    link_udp_session(&u, HAL_SESSION_LAPSED, 1, t += 1u);
    assert_true(udp_deliver(&u, stranger, &to, MSG_HELLO, 0, 54, t) > 0);
    assert_int_equal(u.peer_changes, 2);
    /* until the core has started its session, no third host may take it */
    const int third = udp_peer(&ha);
    assert_int_equal(udp_deliver(&u, third, &to, MSG_HELLO, 0, 1, t), 0);
    link_udp_session(&u, HAL_SESSION_LIVE, 2, t += 1000u);
    assert_int_equal(udp_deliver(&u, host, &to, MSG_HEARTBEAT, 0, 3, t), 0);
    assert_int_equal(u.bind.refused_source, 6);
    assert_int_equal(link_udp_send(&u, f, flen), ARGIL_OK);
    assert_true(udp_got(stranger));
    assert_false(udp_got(host));

    /* END: no host is bound any more; nothing goes out, nothing but a HELLO comes in */
    link_udp_session(&u, HAL_SESSION_NONE, 2, t += 1000u);
    assert_int_equal(link_udp_send(&u, f, flen), ARGIL_ERR_STATE);
    assert_int_equal(udp_deliver(&u, stranger, &to, MSG_HEARTBEAT, 0, 55, t), 0);
    assert_int_equal(u.bind.refused_no_session, 2);

    /* a HELLO the core never takes up (lost on the way in) binds for a bounded time only */
    assert_true(udp_deliver(&u, host, &to, MSG_HELLO, 0, 4, t) > 0);
    link_udp_session(&u, HAL_SESSION_NONE, 2, t += LINK_BIND_PENDING_US / 2u);
    assert_true(u.bind.bound);
    link_udp_session(&u, HAL_SESSION_NONE, 2, t += LINK_BIND_PENDING_US);
    assert_false(u.bind.bound);
    close(host);
    close(stranger);
    close(third);
    link_udp_close(&u);
}

static void test_framer_splits_a_stream(void **st)
{
    (void)st;
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HEARTBEAT;
    uint8_t a[64], out[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, 1, a, sizeof(a), &len), PROTO_OK);
    link_framer_t fr;
    link_framer_init(&fr);
    const uint8_t junk[3] = {1, 2, 3};
    link_framer_feed(&fr, junk, 3);
    link_framer_feed(&fr, a, 5);                /* a torn frame: wait */
    assert_int_equal(link_framer_next(&fr, out, sizeof(out)), 0);
    link_framer_feed(&fr, a + 5, len - 5);
    link_framer_feed(&fr, a, len);
    assert_int_equal(link_framer_next(&fr, out, sizeof(out)), len);
    assert_memory_equal(out, a, len);
    assert_int_equal(link_framer_next(&fr, out, sizeof(out)), len);
    assert_int_equal(link_framer_next(&fr, out, sizeof(out)), 0);
    assert_int_equal(fr.skipped_bytes, 3);
}

static void test_ffs_descriptors(void **st)
{
    (void)st;
    uint8_t b[128];
    const size_t n = link_ffs_descriptors(b, sizeof(b));
    assert_int_equal(n, 66);                     /* header 12 + counts 8 + 2 × 23 */
    assert_int_equal(b[0], 3);                   /* FUNCTIONFS_DESCRIPTORS_MAGIC_V2 */
    assert_int_equal(b[4], 66);
    assert_int_equal(b[20 + 5], 0xFF);           /* vendor-class interface */
    assert_int_equal(b[20 + 9 + 2], 0x01);       /* bulk OUT */
    assert_int_equal(b[20 + 16 + 2], 0x82);      /* bulk IN */
    assert_int_equal(b[20 + 9 + 4] | (b[20 + 9 + 5] << 8), 64);   /* full speed */
    assert_int_equal(b[43 + 9 + 4] | (b[43 + 9 + 5] << 8), 512);  /* high speed */
    assert_int_equal(link_ffs_descriptors(b, 10), 0);
    link_ffs_t f;
    char err[300];
    assert_int_equal(link_ffs_open(&f, "/nonexistent/ffs-argil", err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "is FunctionFS mounted"));
}

static void test_spsc_ring_wraps_and_refuses(void **st)
{
    (void)st;
    static uint8_t mem[64];
    spsc_ring_t r;
    assert_int_equal(spsc_init(&r, mem, 48), ARGIL_ERR_ARG);
    assert_int_equal(spsc_init(&r, mem, 64), ARGIL_OK);
    uint8_t in[40], out[40];
    size_t n;
    for (int i = 0; i < 40; i++)
        in[i] = (uint8_t)i;
    for (int round = 0; round < 10; round++) { /* crosses the end of storage many times */
        assert_int_equal(spsc_push(&r, in, 25), ARGIL_OK);
        assert_int_equal(spsc_push(&r, in, 25), ARGIL_OK);
        assert_int_equal(spsc_push(&r, in, 25), ARGIL_ERR_FULL);
        assert_int_equal(spsc_pop(&r, out, 10, &n), ARGIL_ERR_FULL); /* too small: stays */
        assert_int_equal(spsc_pop(&r, out, sizeof(out), &n), ARGIL_OK);
        assert_int_equal(n, 25);
        assert_memory_equal(out, in, 25);
        assert_true(spsc_skip(&r));
        assert_int_equal(spsc_pop(&r, out, sizeof(out), &n), ARGIL_ERR_EMPTY);
    }
    assert_int_equal(r.dropped, 10);
}

/* Seals a frame with key (NULL: sends it bare) and nonce, sends it from fd to the link and
 * returns what one receive call gives the core. */
static size_t udp_deliver_sealed(link_udp_t *u, int fd, const struct sockaddr_in *to,
                                 const link_key_t *key, uint64_t nonce, uint8_t type,
                                 uint32_t seq, uint64_t now_us)
{
    uint8_t f[PROTO_FRAME_MAX], d[LINK_AUTH_DGRAM_MAX], buf[2 * PROTO_FRAME_MAX];
    size_t len = frame_of(type, 0, seq, f);
    const uint8_t *out = f;
    if (key) {
        len = link_auth_seal(link_auth_mac, key, LINK_AUTH_HOST_TO_BOARD, nonce, f, len, d,
                             sizeof(d));
        out = d;
    }
    assert_int_equal(sendto(fd, out, len, 0, (const struct sockaddr *)to, sizeof(*to)),
                     (ssize_t)len);
    usleep(5000);
    return link_udp_receive(u, buf, sizeof(buf), now_us);
}

/* The board's next datagram to fd, verified with key: its nonce (fails if none or a bad tag). */
static uint64_t udp_board_nonce(int fd, const link_key_t *key)
{
    uint8_t b[2 * PROTO_FRAME_MAX];
    usleep(5000);
    const ssize_t n = recv(fd, b, sizeof(b), MSG_DONTWAIT);
    assert_true(n > 0);
    size_t flen = 0;
    uint64_t nonce = 0;
    assert_int_equal(
        link_auth_open(link_auth_mac, key, LINK_AUTH_BOARD_TO_HOST, b, (size_t)n, &flen, &nonce),
        LINK_AUTH_OK);
    (void)udp_got(fd); /* drain */
    return nonce;
}

/* A keyed link over real sockets: only datagrams with the key's tag reach the core, every other
 * one is counted; a session's frames carry its nonce, and a frame of an earlier session (a
 * replay, whatever its sequence number) is refused once a new session has started, also when
 * the same host restarts a lapsed one. */
static void test_udp_link_with_a_key(void **st)
{
    (void)st;
    assert_true(link_auth_init());
    link_udp_t u;
    char err[200];
    assert_int_equal(link_udp_open(&u, "127.0.0.1:47317", err, sizeof(err)), ARGIL_OK);
    link_key_t key, other;
    for (unsigned i = 0; i < LINK_KEY_BYTES; i++) {
        key.k[i] = (uint8_t)(3u * i + 1u);
        other.k[i] = key.k[i];
    }
    other.k[31] ^= 1u;
    link_udp_set_key(&u, &key);
    struct sockaddr_in to, ha;
    assert_int_equal(link_udp_parse("127.0.0.1:47317", &to), LINK_UDP_ADDR_OK);
    const int host = udp_peer(&ha);
    uint8_t f[PROTO_FRAME_MAX], g[PROTO_FRAME_MAX];
    const size_t flen = frame_of(MSG_HEARTBEAT, 0, 0, f);
    uint64_t t = 1000000u;

    /* another key, no tag at all, a heartbeat with no session's nonce: refused, counted */
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &other, 0, MSG_HELLO, 1, t), 0);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, NULL, 0, MSG_HELLO, 2, t), 0);
    assert_int_equal(u.bad_mac, 2);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, 0, MSG_HEARTBEAT, 3, t), 0);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, 99, MSG_HEARTBEAT, 4, t), 0);
    assert_int_equal(u.bad_nonce, 2);
    assert_false(u.bind.bound);

    /* the HELLO with the key binds the host and draws the session's nonce; the core gets the
     * frame without the trailer; the board's datagrams carry that nonce under a valid tag */
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, 0, MSG_HELLO, 5, t),
                     frame_of(MSG_HELLO, 0, 5, g));
    link_udp_session(&u, HAL_SESSION_LIVE, 1, t += 1000u);
    const uint64_t n1 = u.nonce;
    assert_true(n1 != 0);
    assert_int_equal(link_udp_send(&u, f, flen), ARGIL_OK);
    assert_true(udp_board_nonce(host, &key) == n1);
    assert_true(udp_deliver_sealed(&u, host, &to, &key, n1, MSG_HEARTBEAT, 6, t) > 0);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, n1 + 1u, MSG_HEARTBEAT, 7, t), 0);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &other, n1, MSG_HEARTBEAT, 8, t), 0);
    assert_int_equal(u.bad_nonce, 3);
    assert_int_equal(u.bad_mac, 3);

    /* END, then a new session (its numbers start lower): the earlier session's frame, numbered
     * above them, is refused by its nonce */
    link_udp_session(&u, HAL_SESSION_NONE, 1, t += 1000u);
    assert_true(udp_deliver_sealed(&u, host, &to, &key, 0, MSG_HELLO, 1, t) > 0);
    link_udp_session(&u, HAL_SESSION_LIVE, 2, t += 1000u);
    const uint64_t n2 = u.nonce;
    assert_true(n2 != 0 && n2 != n1);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, n1, MSG_HEARTBEAT, 9, t), 0);
    assert_int_equal(u.bad_nonce, 4);
    assert_true(udp_deliver_sealed(&u, host, &to, &key, n2, MSG_HEARTBEAT, 2, t) > 0);
    /* the live host's HELLO again (a reconnection) keeps the session and its nonce */
    assert_true(udp_deliver_sealed(&u, host, &to, &key, 0, MSG_HELLO, 3, t) > 0);
    assert_true(u.nonce == n2);

    /* lapsed, and the same host restarts it with a HELLO: a new nonce as well */
    link_udp_session(&u, HAL_SESSION_LAPSED, 2, t += 60000u);
    assert_true(udp_deliver_sealed(&u, host, &to, &key, 0, MSG_HELLO, 4, t) > 0);
    const uint64_t n3 = u.nonce;
    assert_true(n3 != n2 && n3 != 0);
    assert_int_equal(udp_deliver_sealed(&u, host, &to, &key, n2, MSG_HEARTBEAT, 100, t), 0);
    assert_int_equal(u.bad_nonce, 5);
    assert_int_equal(u.nonces, 3);
    close(host);
    link_udp_close(&u);

    /* a board without a key drops a keyed host's datagram (counted), not parts of it */
    assert_int_equal(link_udp_open(&u, "127.0.0.1:47317", err, sizeof(err)), ARGIL_OK);
    const int h2 = udp_peer(&ha);
    assert_int_equal(udp_deliver_sealed(&u, h2, &to, &key, 0, MSG_HELLO, 1, t), 0);
    assert_int_equal(u.bad_mac, 1);
    assert_true(udp_deliver_sealed(&u, h2, &to, NULL, 0, MSG_HELLO, 2, t) > 0);
    close(h2);
    link_udp_close(&u);
}

typedef struct {
    const char *text;
    uint32_t line;
    board_config_err_t want;
    const char *says;
} ini_refusal_t;

/* Each text is refused, at its line, with the code of the rule it broke and words that say why. */
static void expect_ini_refusals(const ini_refusal_t *bad, size_t n)
{
    board_daemon_cfg_t c;
    uint32_t line = 0;
    char why[200];
    for (size_t i = 0; i < n; i++) {
        board_config_default(&c);
        why[0] = '\0';
        const board_config_err_t got =
            board_config_parse_ini(&c, bad[i].text, strlen(bad[i].text), &line, why, sizeof(why));
        if (got != bad[i].want || line != bad[i].line || strstr(why, bad[i].says) == NULL)
            fail_msg("case %zu: %d at line %u '%s', expected %d at line %u saying '%s'", i, got,
                     line, why, bad[i].want, bad[i].line, bad[i].says);
    }
}

static void test_config_ini_and_refusals(void **st)
{
    (void)st;
    board_daemon_cfg_t c;
    board_config_default(&c);
    char why[200];
    uint32_t line = 0;
    const char *ok = "; comment\n[can]\ninterface = can1\n[gpio]\nestop = EMERG ; inline\n"
                     "[link]\nhost = ffs:/dev/ffs-argil\nrt_priority = 79\n[loop]\nrate_hz=4000\n"
                     "cpu = 1\n"
                     "[transform]\noffset_m = 0.01,-0.02,0.5\n";
    assert_int_equal(board_config_parse_ini(&c, ok, strlen(ok), &line, why, sizeof(why)),
                     BOARD_CONFIG_OK);
    assert_string_equal(c.can_if, "can1");
    assert_string_equal(c.gpio.in[0], "EMERG");
    assert_int_equal(c.link, BOARD_LINK_FFS);
    assert_string_equal(c.link_target, "/dev/ffs-argil");
    assert_int_equal(c.rate_hz, 4000);
    assert_int_equal(c.link_rt_priority, 79);
    assert_float_equal(c.model_offset_m[1], -0.02f, 1e-7f);
    static const ini_refusal_t bad[] = {
        {"x = 1\n", 1, BOARD_CONFIG_ERR_NO_SECTION, "outside any [section]"},
        {"[loop\n", 1, BOARD_CONFIG_ERR_SECTION, "expected [section]"},
        {"[loop]\nrate_hz\n", 2, BOARD_CONFIG_ERR_NO_VALUE, "expected key = value"},
        {"[loop]\nrate_hz = 3000\n", 2, BOARD_CONFIG_ERR_VALUE, "rate_hz '3000'"},
        {"[loop]\nrt_priority = 100\n", 2, BOARD_CONFIG_ERR_VALUE, "expected 0-99"},
        {"[link]\nrt_priority = -1\n", 2, BOARD_CONFIG_ERR_VALUE, "link.rt_priority '-1'"},
        {"[loop]\nbogus = 1\n", 2, BOARD_CONFIG_ERR_UNKNOWN, "unknown setting 'loop.bogus'"},
        {"[can]\nbus = vcan\n", 2, BOARD_CONFIG_ERR_VALUE, "expected socketcan or sim"},
        {"[limits]\nmax_force_n = nan\n", 2, BOARD_CONFIG_ERR_VALUE, "max_force_n"},
        {"[transform]\noffset_m = 1,2\n", 2, BOARD_CONFIG_ERR_VALUE, "expected X,Y,Z"},
        {"[link]\nhost = tcp:1\n", 2, BOARD_CONFIG_ERR_VALUE, "udp:ADDR:PORT or ffs:DIR"},
        {"[gpio]\nestop = two words\n", 2, BOARD_CONFIG_ERR_VALUE, "gpio.estop"},
        {"[link]\ninsecure = maybe\n", 2, BOARD_CONFIG_ERR_VALUE, "expected yes or no"},
        {"[link]\nkey =\n", 2, BOARD_CONFIG_ERR_VALUE, "link.key"},
    };
    expect_ini_refusals(bad, sizeof(bad) / sizeof(bad[0]));
}

/* libinih reads the file; argil's rules on top of it: every line stands alone (an indented line
 * is no continuation), a line has a length limit and never a NUL, nothing follows a section's
 * ']', only len bytes are read, and a refused file leaves the settings as they were. */
static void test_config_ini_rules_over_libinih(void **st)
{
    (void)st;
    board_daemon_cfg_t c;
    char why[200];
    uint32_t line = 0;

    /* indented keys are settings of their own (libinih alone reads "cpu = 1" as rate_hz's
     * second line) */
    board_config_default(&c);
    const char *indented = "[loop]\n  rate_hz = 2000\n\tcpu = 1\n";
    assert_int_equal(board_config_parse_ini(&c, indented, strlen(indented), &line, why,
                                            sizeof(why)), BOARD_CONFIG_OK);
    assert_int_equal(c.rate_hz, 2000);
    assert_int_equal(c.cpu, 1);

    /* what libinih accepts beyond the old reader: a UTF-8 BOM, key: value, ';' after ']' */
    board_config_default(&c);
    const char *forms = "\xEF\xBB\xBF[loop] ; the fast loop\r\nrate_hz: 4000\r\n"
                        "[can]\r\ninterface = can1 ; inline\r\n";
    assert_int_equal(board_config_parse_ini(&c, forms, strlen(forms), &line, why, sizeof(why)),
                     BOARD_CONFIG_OK);
    assert_int_equal(c.rate_hz, 4000);
    assert_string_equal(c.can_if, "can1");

    /* the text is len bytes, not a C string: what lies past len is not read */
    board_config_default(&c);
    const char *cut = "[loop]\nrate_hz = 2000\ncpu = 5";
    assert_int_equal(board_config_parse_ini(&c, cut, strlen("[loop]\nrate_hz = 2000\n"), &line,
                                            why, sizeof(why)), BOARD_CONFIG_OK);
    assert_int_equal(c.rate_hz, 2000);
    assert_int_equal(c.cpu, -1);

    /* a NUL byte is refused, not taken as the end of its line ("2000" alone would pass) */
    board_config_default(&c);
    const char nul[] = "[loop]\ncpu = 1\nrate_hz = 2000" "\0" "x\n";
    assert_int_equal(board_config_parse_ini(&c, nul, sizeof(nul) - 1u, &line, why, sizeof(why)),
                     BOARD_CONFIG_ERR_NUL);
    assert_int_equal(line, 3);
    assert_non_null(strstr(why, "NUL byte"));

    /* 197 characters fit libinih's 200-byte line with "\r\n" and its NUL; one more is refused
     * at its own line number, never split into two lines */
    char text[400];
    for (size_t n = 197; n <= 198; n++) {
        const size_t head = strlen("[loop]\n");
        memcpy(text, "[loop]\n", head);
        memset(text + head, 'x', n);
        text[head] = ';';
        memcpy(text + head + n, "\r\nrate_hz = 2000\n", strlen("\r\nrate_hz = 2000\n") + 1u);
        board_config_default(&c);
        why[0] = '\0';
        const board_config_err_t rc = board_config_parse_ini(&c, text, strlen(text), &line, why,
                                                             sizeof(why));
        if (n == 197) {
            assert_int_equal(rc, BOARD_CONFIG_OK);
            assert_int_equal(c.rate_hz, 2000);
        } else {
            assert_int_equal(rc, BOARD_CONFIG_ERR_LINE_LONG);
            assert_int_equal(line, 2);
            assert_non_null(strstr(why, "longer than 197 characters"));
        }
    }

    /* a refused file changes nothing, though libinih reads on past its own refusals */
    board_config_default(&c);
    const char *late = "[loop]\nrate_hz = 2000\n[can\ncpu = 3\n";
    assert_int_equal(board_config_parse_ini(&c, late, strlen(late), &line, why, sizeof(why)),
                     BOARD_CONFIG_ERR_SECTION);
    assert_int_equal(line, 3);
    assert_int_equal(c.rate_hz, 1000);
    assert_int_equal(c.cpu, -1);

    static const ini_refusal_t bad[] = {
        /* a setting on its section's line would otherwise be dropped without a word */
        {"[limits] max_force_n = 1\n", 1, BOARD_CONFIG_ERR_AFTER_SECTION,
         "after the section's ']'"},
        {"[loop]] ; x\n", 1, BOARD_CONFIG_ERR_AFTER_SECTION, "after the section's ']'"},
        {"\xEF\xBB\xBF [limits] max_force_n = 1\n", 1, BOARD_CONFIG_ERR_AFTER_SECTION,
         "after the section's ']'"},
        /* '#' is a comment at the start of a line only; the value says why it failed */
        {"[loop]\nrate_hz = 2000 # fast\n", 2, BOARD_CONFIG_ERR_VALUE,
         "inline comments start with ';'"},
        {"[]\nrate_hz = 2000\n", 2, BOARD_CONFIG_ERR_NO_SECTION, "outside any [section]"},
        {"[ loop ]\nrate_hz = 2000\n", 2, BOARD_CONFIG_ERR_UNKNOWN,
         "unknown setting ' loop .rate_hz'"},
        {"[a_section_name_longer_than_the_49_characters_libinih_keeps]\nk = 1\n", 2,
         BOARD_CONFIG_ERR_UNKNOWN, "unknown setting"},
        /* the first refusal is the one reported, libinih's or argil's */
        {"[loop\n[loop]\nbogus = 1\n", 1, BOARD_CONFIG_ERR_SECTION, "expected [section]"},
        {"[loop]\nrate_hz\nbogus = 1\n", 2, BOARD_CONFIG_ERR_NO_VALUE, "expected key = value"},
        {"\xEF\xBB\xBF[loop\n", 1, BOARD_CONFIG_ERR_SECTION, "expected [section]"},
        {"[loop]\n\t[link\n", 2, BOARD_CONFIG_ERR_SECTION, "expected [section]"},
    };
    expect_ini_refusals(bad, sizeof(bad) / sizeof(bad[0]));
}

/* Settings that parse alone but not together are refused by the check, each with its rule's
 * code; a command gets ARG for those and for an unknown setting, PARSE for every rule of the
 * text. */
static void test_config_check_rules(void **st)
{
    (void)st;
    board_daemon_cfg_t c;
    char why[200];
    board_config_default(&c);
    assert_int_equal(board_config_check(&c, why, sizeof(why)), BOARD_CONFIG_OK);
    static const struct {
        const char *set[2][3]; /* section, key, value */
        board_config_err_t want;
        const char *says;
    } cases[] = {
        {{{"link", "key", "k.key"}, {"link", "insecure", "yes"}}, BOARD_CONFIG_ERR_KEY_INSECURE,
         "link.key and link.insecure together"},
        {{{"link", "host", "ffs:/dev/ffs"}, {"link", "insecure", "yes"}},
         BOARD_CONFIG_ERR_USB_KEY, "link.insecure is for the UDP link"},
        {{{"link", "host", "ffs:/dev/ffs"}, {"link", "key", "k.key"}}, BOARD_CONFIG_ERR_USB_KEY,
         "link.key is for the UDP link"},
        {{{"link", "heartbeat_timeout_ms", "5"}, {"link", "fade_ms", "51"}},
         BOARD_CONFIG_ERR_FADE, "must not exceed ten host timeouts (50 ms)"},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        board_config_default(&c);
        for (size_t k = 0; k < 2; k++)
            assert_int_equal(board_config_set(&c, cases[i].set[k][0], cases[i].set[k][1],
                                              cases[i].set[k][2], why, sizeof(why)),
                             BOARD_CONFIG_OK);
        why[0] = '\0';
        const board_config_err_t got = board_config_check(&c, why, sizeof(why));
        if (got != cases[i].want || strstr(why, cases[i].says) == NULL)
            fail_msg("case %zu: %d '%s', expected %d saying '%s'", i, got, why, cases[i].want,
                     cases[i].says);
    }
    /* a drive heartbeat shorter than one tick (set directly: its setting's range keeps it
     * above the slowest tick) */
    board_config_default(&c);
    c.drive_heartbeat_ms = 0;
    assert_int_equal(board_config_check(&c, why, sizeof(why)), BOARD_CONFIG_ERR_HEARTBEAT);
    assert_non_null(strstr(why, "is shorter than one tick"));

    assert_int_equal(board_config_err_argil(BOARD_CONFIG_OK), ARGIL_OK);
    assert_int_equal(board_config_err_argil(BOARD_CONFIG_ERR_UNKNOWN), ARGIL_ERR_ARG);
    for (int e = BOARD_CONFIG_ERR_VALUE; e >= BOARD_CONFIG_ERR_READER; e--)
        assert_int_equal(board_config_err_argil((board_config_err_t)e), ARGIL_ERR_PARSE);
    for (int e = BOARD_CONFIG_ERR_KEY_INSECURE; e >= BOARD_CONFIG_ERR_HEARTBEAT; e--)
        assert_int_equal(board_config_err_argil((board_config_err_t)e), ARGIL_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_can_socket_frames_and_error_frames),
        cmocka_unit_test(test_can_board_read_queues_a_backlog),
        cmocka_unit_test(test_can_open_errors_are_one_line),
        cmocka_unit_test(test_gpio_mapping_by_name),
        cmocka_unit_test(test_gpio_errors_name_the_line),
        cmocka_unit_test(test_udp_address_rules),
        cmocka_unit_test(test_udp_link_loopback),
        cmocka_unit_test(test_udp_link_serves_its_session_host_only),
        cmocka_unit_test(test_udp_link_with_a_key),
        cmocka_unit_test(test_framer_splits_a_stream),
        cmocka_unit_test(test_ffs_descriptors),
        cmocka_unit_test(test_spsc_ring_wraps_and_refuses),
        cmocka_unit_test(test_config_ini_and_refusals),
        cmocka_unit_test(test_config_ini_rules_over_libinih),
        cmocka_unit_test(test_config_check_rules),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
