/* The libusb link (host/link/link_usb.c) through unplug, bus rescans and replug, against a
 * fake libusb that keeps libusb-1.0's object lifetimes: a context owns its device objects, a
 * transfer holds a reference to the device it was last submitted on (libusb >= 1.0.25), a
 * device keeps a pointer to its context, libusb_close takes the handle's transfers off the
 * in-flight list but leaves them marked in flight. The fake records every misuse that crashes or
 * wedges the real library: a device destroyed after its context exited (what killed `argil
 * connect` with SIGSEGV in the HIL VM), a context torn down while a transfer still holds one of
 * its devices, a transfer freed while libusb is still processing it, submits on closed handles. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/link/link.h"
#include "host/link/link_usb_api.h"
#include "shared/proto.h"

#define FK_CTX 64
#define FK_DEV 256
#define FK_HANDLES 64
#define FK_XFERS 256

struct libusb_context {
    bool alive;
};

struct libusb_device {
    libusb_context *ctx;
    int refs;
    bool listed;     /* in its context's device list (holds one reference) */
    bool attached;   /* still on the bus */
    bool destroyed;
    bool board;      /* the argil board (else a root hub) */
    int gen;         /* which plug-in of the board this object stands for */
};

struct libusb_device_handle {
    libusb_device *dev;
    bool open;
};

typedef struct {
    struct libusb_transfer *t;
    libusb_device *dev;   /* the device of the last submit, referenced */
    bool listed;          /* on libusb's in-flight list: will be called back */
    bool in_flight;       /* libusb's IN_FLIGHT flag (survives libusb_close) */
    bool cancelled;
    bool stuck;           /* never called back (a controller that keeps the URB) */
} fk_xfer_t;

static struct {
    libusb_context ctx[FK_CTX];
    int n_ctx, exits;
    libusb_device dev[FK_DEV];
    int n_dev;
    libusb_device_handle h[FK_HANDLES];
    int n_h, closes;
    fk_xfer_t x[FK_XFERS];
    int n_x, frees;
    bool present;         /* the board is on the bus */
    int gen;
    bool stuck_on_unplug; /* in-flight transfers of an unplugged board never come back */
    uint32_t seq;
    size_t out_bytes;
    int violations;
    char first[200];
} fk;

static void fk_violation(const char *what)
{
    if (fk.violations++ == 0)
        snprintf(fk.first, sizeof(fk.first), "%s", what);
}

static void fk_unref(libusb_device *d)
{
    if (--d->refs > 0)
        return;
    if (d->refs < 0)
        fk_violation("device reference count below zero");
    if (!d->ctx->alive)
        fk_violation("a device destroyed after its context exited (libusb logs through the freed "
                     "context: SIGSEGV)");
    d->destroyed = true;
}

static libusb_device *fk_ref(libusb_device *d)
{
    if (d->destroyed)
        fk_violation("a destroyed device referenced again");
    d->refs++;
    return d;
}

static fk_xfer_t *fk_find(const struct libusb_transfer *t)
{
    for (int i = 0; i < fk.n_x; i++)
        if (fk.x[i].t == t)
            return &fk.x[i];
    fail_msg("unknown transfer %p", (const void *)t);
    return NULL;
}

static int fk_init(libusb_context **ctx)
{
    assert_true(fk.n_ctx < FK_CTX);
    libusb_context *c = &fk.ctx[fk.n_ctx++];
    c->alive = true;
    *ctx = c;
    return 0;
}

static void fk_exit(libusb_context *ctx)
{
    assert_true(ctx->alive);
    for (int i = 0; i < fk.n_h; i++)
        if (fk.h[i].open && fk.h[i].dev->ctx == ctx)
            fk_violation("libusb_exit with a device handle still open");
    for (int i = 0; i < fk.n_x; i++)
        if (fk.x[i].t && fk.x[i].dev && fk.x[i].dev->ctx == ctx)
            fk_violation("libusb_exit while a transfer still holds one of its devices");
    for (int i = 0; i < fk.n_dev; i++) {
        libusb_device *d = &fk.dev[i];
        if (d->ctx == ctx && d->listed) {
            d->listed = false;
            fk_unref(d);
        }
    }
    ctx->alive = false;
    fk.exits++;
}

/* The context's object for the board (current plug-in) or its root hub, made on first sight. */
static libusb_device *fk_device(libusb_context *ctx, bool board)
{
    for (int i = 0; i < fk.n_dev; i++) {
        libusb_device *d = &fk.dev[i];
        if (d->ctx == ctx && d->listed && d->board == board && (!board || d->gen == fk.gen))
            return d;
    }
    assert_true(fk.n_dev < FK_DEV);
    libusb_device *d = &fk.dev[fk.n_dev++];
    memset(d, 0, sizeof(*d));
    d->ctx = ctx;
    d->refs = 1;
    d->listed = d->attached = true;
    d->board = board;
    d->gen = fk.gen;
    return d;
}

static ssize_t fk_get_device_list(libusb_context *ctx, libusb_device ***list)
{
    if (!ctx->alive)
        fk_violation("device list of an exited context");
    libusb_device **l = calloc(3, sizeof(*l));
    assert_non_null(l);
    ssize_t n = 0;
    l[n++] = fk_ref(fk_device(ctx, false));
    if (fk.present)
        l[n++] = fk_ref(fk_device(ctx, true));
    *list = l;
    return n;
}

static void fk_free_device_list(libusb_device **list, int unref)
{
    for (int i = 0; unref && list[i]; i++)
        fk_unref(list[i]);
    free(list);
}

static int fk_get_device_descriptor(libusb_device *d, struct libusb_device_descriptor *dd)
{
    memset(dd, 0, sizeof(*dd));
    dd->idVendor = d->board ? 0x1209 : 0x1d6b;
    dd->idProduct = d->board ? 0x0001 : 0x0002;
    return 0;
}

static uint8_t fk_get_bus_number(libusb_device *d)
{
    (void)d;
    return 1;
}

static int fk_get_port_numbers(libusb_device *d, uint8_t *ports, int len)
{
    if (!d->board)
        return 0;
    assert_true(len >= 1);
    ports[0] = 1;
    return 1;
}

static int fk_open(libusb_device *d, libusb_device_handle **h)
{
    if (!d->attached)
        return LIBUSB_ERROR_NO_DEVICE;
    assert_true(fk.n_h < FK_HANDLES);
    libusb_device_handle *nh = &fk.h[fk.n_h++];
    nh->dev = fk_ref(d);
    nh->open = true;
    *h = nh;
    return 0;
}

static void fk_close(libusb_device_handle *h)
{
    assert_true(h->open);
    for (int i = 0; i < fk.n_x; i++) {
        fk_xfer_t *x = &fk.x[i];
        if (x->t && x->listed && x->t->dev_handle == h) {
            x->listed = false; /* libusb: off the list, IN_FLIGHT stays, dev_handle = NULL */
            x->t->dev_handle = NULL;
        }
    }
    h->open = false;
    fk_unref(h->dev);
    fk.closes++;
}

/* GET_DESCRIPTOR(CONFIGURATION): one vendor interface, bulk IN 0x81 and OUT 0x02 (as dummy_hcd
 * presents the gadget's endpoints). */
static int fk_control_transfer(libusb_device_handle *h, uint8_t type, uint8_t req, uint16_t value,
                               uint16_t index, unsigned char *data, uint16_t len,
                               unsigned int timeout_ms)
{
    (void)type, (void)req, (void)value, (void)index, (void)timeout_ms;
    static const uint8_t cfg[32] = {9, 2, 32, 0, 1, 1, 0, 0x80, 50,
                                    9, 4, 0, 0, 2, 0xff, 0, 0, 0,
                                    7, 5, 0x81, 2, 0, 2, 0,
                                    7, 5, 0x02, 2, 0, 2, 0};
    if (!h->open)
        fk_violation("control transfer on a closed handle");
    if (!h->dev->attached)
        return LIBUSB_ERROR_NO_DEVICE;
    const uint16_t n = len < sizeof(cfg) ? len : (uint16_t)sizeof(cfg);
    memcpy(data, cfg, n);
    return n;
}

static int fk_set_auto_detach(libusb_device_handle *h, int on)
{
    (void)h, (void)on;
    return 0;
}

static int fk_claim(libusb_device_handle *h, int iface)
{
    (void)iface;
    return h->dev->attached ? 0 : LIBUSB_ERROR_NO_DEVICE;
}

static int fk_alt(libusb_device_handle *h, int iface, int alt)
{
    (void)h, (void)iface, (void)alt;
    return 0;
}

static struct libusb_transfer *fk_alloc_transfer(int iso)
{
    assert_int_equal(iso, 0);
    assert_true(fk.n_x < FK_XFERS);
    fk_xfer_t *x = &fk.x[fk.n_x++];
    memset(x, 0, sizeof(*x));
    x->t = calloc(1, sizeof(struct libusb_transfer));
    assert_non_null(x->t);
    return x->t;
}

static void fk_free_transfer(struct libusb_transfer *t)
{
    fk_xfer_t *x = fk_find(t);
    if (x->listed)
        fk_violation("a transfer freed while libusb may still call it back");
    if (x->dev)
        fk_unref(x->dev);
    free(t);
    x->t = NULL;
    x->dev = NULL;
    fk.frees++;
}

static int fk_submit(struct libusb_transfer *t)
{
    fk_xfer_t *x = fk_find(t);
    if (x->in_flight)
        return LIBUSB_ERROR_BUSY;
    assert_non_null(t->dev_handle);
    if (!t->dev_handle->open)
        fk_violation("a transfer submitted on a closed handle");
    if (x->dev)
        fk_unref(x->dev); /* libusb_submit_transfer drops the previous submit's device */
    x->dev = fk_ref(t->dev_handle->dev);
    if (!x->dev->attached)
        return LIBUSB_ERROR_NO_DEVICE;
    x->listed = x->in_flight = true;
    x->cancelled = x->stuck = false;
    return 0;
}

static int fk_cancel(struct libusb_transfer *t)
{
    fk_xfer_t *x = fk_find(t);
    if (!x->listed)
        return LIBUSB_ERROR_NOT_FOUND;
    x->cancelled = true;
    return 0;
}

static size_t fk_heartbeat(uint8_t *buf, size_t cap)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HEARTBEAT;
    m.u.heartbeat.time_us = ++fk.seq;
    size_t len = 0;
    assert_int_equal(proto_encode(&m, fk.seq, buf, cap, &len), PROTO_OK);
    return len;
}

/* Calls back each transfer of this context once: board frames in, bytes out, NO_DEVICE for an
 * unplugged board, CANCELLED for a cancelled one. */
static int fk_handle_events(libusb_context *ctx, struct timeval *tv, int *completed)
{
    (void)tv, (void)completed;
    if (!ctx->alive)
        fk_violation("events handled on an exited context");
    int due[FK_XFERS], n = 0;
    for (int i = 0; i < fk.n_x; i++)
        if (fk.x[i].t && fk.x[i].listed && !fk.x[i].stuck && fk.x[i].dev->ctx == ctx)
            due[n++] = i;
    for (int k = 0; k < n; k++) {
        fk_xfer_t *x = &fk.x[due[k]];
        struct libusb_transfer *t = x->t;
        t->actual_length = 0;
        if (x->cancelled)
            t->status = LIBUSB_TRANSFER_CANCELLED;
        else if (!x->dev->attached)
            t->status = LIBUSB_TRANSFER_NO_DEVICE;
        else if (t->endpoint & LIBUSB_ENDPOINT_IN) {
            t->status = LIBUSB_TRANSFER_COMPLETED;
            t->actual_length = (int)fk_heartbeat(t->buffer, (size_t)t->length);
        } else {
            t->status = LIBUSB_TRANSFER_COMPLETED;
            t->actual_length = t->length;
            fk.out_bytes += (size_t)t->length;
        }
        x->listed = x->in_flight = false;
        t->callback(t);
    }
    return 0;
}

static int fk_has_capability(uint32_t cap)
{
    (void)cap;
    return 0; /* no hot-plug events: the link rescans with fresh contexts, as in the HIL VM */
}

static int fk_hotplug_register(libusb_context *ctx, int events, int flags, int vid, int pid,
                               int cls, libusb_hotplug_callback_fn cb, void *user,
                               libusb_hotplug_callback_handle *h)
{
    (void)ctx, (void)events, (void)flags, (void)vid, (void)pid, (void)cls, (void)cb, (void)user,
        (void)h;
    return LIBUSB_ERROR_NOT_SUPPORTED;
}

static void fk_hotplug_deregister(libusb_context *ctx, libusb_hotplug_callback_handle h)
{
    (void)ctx, (void)h;
}

static const char *fk_error_name(int code)
{
    (void)code;
    return "LIBUSB_ERROR";
}

static const usb_api_t FAKE_API = {
    NULL, fk_init, fk_exit, fk_get_device_list, fk_free_device_list, fk_get_device_descriptor,
    fk_get_bus_number, fk_get_port_numbers, fk_open, fk_close, fk_control_transfer,
    fk_set_auto_detach, fk_claim, fk_claim, fk_alt, fk_alloc_transfer, fk_free_transfer,
    fk_submit, fk_cancel, fk_handle_events, fk_has_capability, fk_hotplug_register,
    fk_hotplug_deregister, fk_error_name,
};

static void fk_unplug(void)
{
    fk.present = false;
    for (int i = 0; i < fk.n_dev; i++) {
        libusb_device *d = &fk.dev[i];
        if (!d->board || !d->attached)
            continue;
        d->attached = false;
        if (d->listed) { /* libusb's disconnect takes it off the context's list */
            d->listed = false;
            fk_unref(d);
        }
    }
    if (fk.stuck_on_unplug)
        for (int i = 0; i < fk.n_x; i++)
            if (fk.x[i].t && fk.x[i].listed && (fk.x[i].t->endpoint & LIBUSB_ENDPOINT_IN))
                fk.x[i].stuck = true;
}

static void fk_plug(void)
{
    fk.present = true;
    fk.gen++;
}

/* ---- the link over the fake ---- */

static uint64_t now_us;

/* Polls for ms milliseconds of link time (1 ms per poll); returns the frames received. */
static uint32_t run_ms(link_t *l, uint32_t ms)
{
    uint8_t buf[PROTO_FRAME_MAX];
    uint32_t frames = 0;
    for (uint32_t i = 0; i < ms; i++) {
        now_us += 1000u;
        link_poll(l, 1000u, now_us);
        while (link_recv(l, buf, sizeof(buf)) > 0)
            frames++;
    }
    return frames;
}

static void open_link(link_t *l)
{
    memset(&fk, 0, sizeof(fk));
    fk.present = true;
    now_us = 1000000u;
    memset(l, 0, sizeof(*l));
    assert_int_equal(link_spec_parse("usb", &l->spec), LINK_SPEC_OK);
    char err[256] = "";
    assert_int_equal(link_usb_open_api(l, &FAKE_API, err, sizeof(err)), ARGIL_OK);
}

static void send_one(link_t *l, argil_err_t want)
{
    uint8_t f[PROTO_FRAME_MAX];
    const size_t n = fk_heartbeat(f, sizeof(f));
    assert_int_equal(link_send(l, f, n), want);
}

static void close_and_audit(link_t *l)
{
    link_close(l);
    if (fk.violations)
        fail_msg("%d libusb misuse(s), first: %s", fk.violations, fk.first);
    assert_int_equal(fk.exits, fk.n_ctx);           /* every context torn down */
    assert_int_equal(fk.frees, fk.n_x);             /* every transfer freed */
    for (int i = 0; i < fk.n_h; i++)
        assert_false(fk.h[i].open);
    for (int i = 0; i < fk.n_dev; i++)
        assert_true(fk.dev[i].destroyed);       /* no device leaked */
}

/* Three unplug/replug cycles with bus rescans (fresh contexts) in between: lost while gone,
 * sends refused, reconnected with one resync each time, frames both ways, and no transfer ever
 * outlives the context of the device it holds. */
static void test_usb_unplug_rescan_replug(void **state)
{
    (void)state;
    link_t l;
    open_link(&l);
    assert_true(run_ms(&l, 20) >= 100); /* 8 IN transfers, one frame each per poll */
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    send_one(&l, ARGIL_OK);
    (void)run_ms(&l, 2);
    assert_true(fk.out_bytes > 0);
    for (int cycle = 1; cycle <= 3; cycle++) {
        fk_unplug();
        (void)run_ms(&l, 5);
        assert_int_equal(link_state(&l), LINK_LOST);
        assert_int_equal(fk.closes, cycle);
        send_one(&l, ARGIL_ERR_IO);
        const int ctx_before = fk.n_ctx;
        assert_int_equal(run_ms(&l, 1600), 0);
        assert_true(fk.n_ctx - ctx_before >= 3); /* rescanned every 500 ms with a new context */
        fk_plug();
        const size_t out_before = fk.out_bytes;
        assert_true(run_ms(&l, 600) >= 100);
        assert_int_equal(link_state(&l), LINK_CONNECTED);
        assert_true(link_take_resync(&l));
        assert_false(link_take_resync(&l));
        assert_int_equal(l.stats.reconnects, (uint32_t)cycle);
        send_one(&l, ARGIL_OK);
        (void)run_ms(&l, 2);
        assert_true(fk.out_bytes > out_before);
    }
    close_and_audit(&l);
}

/* A host controller that never returns the cancelled IN transfers of an unplugged board: the
 * link gives up after its bounded wait, closes the handle, and the board still comes back with
 * fresh transfers (re-using the old ones would fail with BUSY for ever). */
static void test_usb_unplug_transfers_never_return(void **state)
{
    (void)state;
    link_t l;
    open_link(&l);
    assert_true(run_ms(&l, 10) > 0);
    fk.stuck_on_unplug = true;
    fk_unplug();
    send_one(&l, ARGIL_OK);   /* queued; its submit finds the device gone */
    (void)run_ms(&l, 3);
    assert_int_equal(fk.closes, 1);
    assert_int_equal(link_state(&l), LINK_LOST);
    (void)run_ms(&l, 1000);
    fk.stuck_on_unplug = false;
    fk_plug();
    assert_true(run_ms(&l, 600) >= 100);
    assert_int_equal(link_state(&l), LINK_CONNECTED);
    assert_int_equal(l.stats.reconnects, 1);
    close_and_audit(&l);
}

/* No board on the bus at open: one line naming the ids, nothing left behind. */
static void test_usb_open_no_device(void **state)
{
    (void)state;
    memset(&fk, 0, sizeof(fk));
    link_t l;
    memset(&l, 0, sizeof(l));
    assert_int_equal(link_spec_parse("usb", &l.spec), LINK_SPEC_OK);
    char err[256] = "";
    assert_int_equal(link_usb_open_api(&l, &FAKE_API, err, sizeof(err)), ARGIL_ERR_IO);
    assert_non_null(strstr(err, "usb 1209:0001: no such device"));
    assert_int_equal(fk.violations, 0);
    assert_int_equal(fk.exits, fk.n_ctx);
    assert_int_equal(fk.n_x, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_usb_unplug_rescan_replug),
        cmocka_unit_test(test_usb_unplug_transfers_never_return),
        cmocka_unit_test(test_usb_open_no_device),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
