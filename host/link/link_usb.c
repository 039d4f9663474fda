/* USB transport of the host link through libusb-1.0 (opened with dlopen, like the GL
 * libraries, so the rest of argil links and tests without it): finds the board by VID:PID or
 * bus/port path, claims its vendor interface, reads the endpoint addresses from the interface
 * descriptor, keeps several asynchronous bulk IN transfers in flight (the board's 1 kHz
 * telemetry never waits on the host) and one bulk OUT. The byte stream is cut into frames by
 * the framer the board uses too (shared/link_framer.c). Unplug → transport down (link LOST,
 * everything else kept); the device is looked for again (hot-plug events where libusb has
 * them, and a fresh scan every USB_RESCAN_US), reopened, and the link state machine asks the
 * host to resynchronise once frames flow.
 * Lifetimes: a libusb transfer holds a reference to the device it was last submitted on (libusb
 * ≥ 1.0.25), and the device points at its context. So the transfers live exactly as long as the
 * device handle: allocated at open, freed at close (after every callback, while the context is
 * still alive); a context is only ever torn down with no transfer left. */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <libusb-1.0/libusb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "host/link/link.h"
#include "host/link/link_usb_api.h"
#include "host/link/link_usb_desc.h"
#include "shared/link_framer.h"
#include "shared/wire.h"

#define USB_IN_TRANSFERS 8u          /* bulk IN transfers kept in flight */
#define USB_IN_BYTES 4096u           /* each */
#define USB_OUT_BYTES 16384u         /* one bulk OUT transfer: whole frames back to back */
#define USB_TXQ_BYTES 65536u         /* frames queued for the OUT endpoint */
#define USB_RXQ_BYTES 262144u        /* received bytes not yet cut into frames */
#define USB_RESCAN_US 500000u        /* while the device is gone, look for it this often */
#define USB_ERRORS_GONE 50u          /* consecutive transfer errors taken as an unplug */
#define USB_CTRL_TIMEOUT_MS 1000u

typedef struct {
    usb_api_t api;
    link_t *link;
    libusb_context *ctx;
    libusb_device_handle *h;
    bool open;                       /* h is open and the interface claimed */
    bool closing;                    /* cancelling: completed transfers are not resubmitted */
    bool gone;                       /* a transfer saw the device disappear */
    bool hotplug;                    /* hot-plug events registered */
    libusb_hotplug_callback_handle hp;
    volatile bool hp_arrived;        /* set by the hot-plug callback */
    volatile bool hp_left;
    uint64_t last_scan_us;
    usb_endpoints_t ep;
    uint8_t bus, ports[LINK_SPEC_PORTS_MAX];
    int n_ports;
    struct libusb_transfer *in[USB_IN_TRANSFERS]; /* allocated while h is open, else NULL */
    struct libusb_transfer *out;
    uint32_t in_flight;              /* IN transfers submitted and not yet called back */
    bool in_busy[USB_IN_TRANSFERS];  /* which of them */
    bool out_busy;
    uint32_t error_streak;
    uint8_t in_buf[USB_IN_TRANSFERS][USB_IN_BYTES];
    uint8_t out_buf[USB_OUT_BYTES];
    uint8_t txq[USB_TXQ_BYTES];
    size_t txq_len;
    uint8_t rxq[USB_RXQ_BYTES];      /* ring of received bytes */
    uint32_t rx_head, rx_tail;       /* free-running */
    link_framer_t framer;
} usb_t;

static const char *api_load(usb_api_t *a)
{
    a->lib = dlopen("libusb-1.0.so.0", RTLD_NOW | RTLD_LOCAL);
    if (!a->lib)
        return "libusb-1.0.so.0 not found: install Debian's libusb-1.0-0 (toolchain/install-deps.sh build)";
#define LOAD(f)                                                                                    \
    do {                                                                                           \
        *(void **)&a->f = dlsym(a->lib, "libusb_" #f);                                            \
        if (!a->f)                                                                                 \
            return "libusb-1.0.so.0 lacks libusb_" #f " (libusb 1.0.22 or newer is needed)";      \
    } while (0)
    LOAD(init);
    LOAD(exit);
    LOAD(get_device_list);
    LOAD(free_device_list);
    LOAD(get_device_descriptor);
    LOAD(get_bus_number);
    LOAD(get_port_numbers);
    LOAD(open);
    LOAD(close);
    LOAD(control_transfer);
    LOAD(set_auto_detach_kernel_driver);
    LOAD(claim_interface);
    LOAD(release_interface);
    LOAD(set_interface_alt_setting);
    LOAD(alloc_transfer);
    LOAD(free_transfer);
    LOAD(submit_transfer);
    LOAD(cancel_transfer);
    LOAD(handle_events_timeout_completed);
    LOAD(has_capability);
    LOAD(hotplug_register_callback);
    LOAD(hotplug_deregister_callback);
    LOAD(error_name);
#undef LOAD
    return NULL;
}

static const char *uerr(const usb_t *u, int rc)
{
    return u->api.error_name(rc);
}

/* "1209:0001" or "bus 1 port 2.1", for messages. */
static void describe(const link_spec_t *s, char *buf, size_t cap)
{
    if (!s->by_path) {
        snprintf(buf, cap, "%04x:%04x", s->vid, s->pid);
        return;
    }
    int n = snprintf(buf, cap, "%u-", s->bus);
    for (uint8_t i = 0; i < s->n_ports && n > 0 && (size_t)n < cap; i++)
        n += snprintf(buf + n, cap - (size_t)n, i ? ".%u" : "%u", s->ports[i]);
}

/* ---- transfers ---- */

static void rx_push(usb_t *u, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (u->rx_tail - u->rx_head == USB_RXQ_BYTES) {
            u->link->stats.errors_rx++; /* the host thread fell far behind: drop the rest */
            return;
        }
        u->rxq[u->rx_tail++ % USB_RXQ_BYTES] = p[i];
    }
}

static uint32_t in_index(const usb_t *u, const struct libusb_transfer *t)
{
    for (uint32_t i = 0; i < USB_IN_TRANSFERS; i++)
        if (u->in[i] == t)
            return i;
    return 0; /* cannot happen: only u->in[] are IN transfers */
}

static void submit_in(usb_t *u, struct libusb_transfer *t)
{
    if (!u->open || u->gone || u->closing)
        return;
    const int rc = u->api.submit_transfer(t);
    if (rc == 0) {
        u->in_flight++;
        u->in_busy[in_index(u, t)] = true;
    }
    else if (rc == LIBUSB_ERROR_NO_DEVICE)
        u->gone = true;
    else
        u->link->stats.errors_rx++;
}

static void LIBUSB_CALL in_done(struct libusb_transfer *t)
{
    usb_t *u = t->user_data;
    u->in_flight--;
    u->in_busy[in_index(u, t)] = false;
    switch (t->status) {
    case LIBUSB_TRANSFER_COMPLETED:
        u->error_streak = 0;
        rx_push(u, t->buffer, (size_t)t->actual_length);
        submit_in(u, t);
        break;
    case LIBUSB_TRANSFER_TIMED_OUT:
        submit_in(u, t);
        break;
    case LIBUSB_TRANSFER_CANCELLED:
        break;
    case LIBUSB_TRANSFER_NO_DEVICE:
        u->gone = true;
        break;
    default: /* ERROR, STALL, OVERFLOW */
        u->link->stats.errors_rx++;
        if (++u->error_streak >= USB_ERRORS_GONE)
            u->gone = true;
        else
            submit_in(u, t);
        break;
    }
}

static void LIBUSB_CALL out_done(struct libusb_transfer *t)
{
    usb_t *u = t->user_data;
    u->out_busy = false;
    if (t->status == LIBUSB_TRANSFER_NO_DEVICE)
        u->gone = true;
    else if (t->status != LIBUSB_TRANSFER_COMPLETED && t->status != LIBUSB_TRANSFER_CANCELLED)
        u->link->stats.errors_tx++;
}

/* Sends the queued whole frames that fit in one OUT transfer. */
static void submit_out(usb_t *u)
{
    if (!u->open || u->gone || u->out_busy || u->txq_len == 0)
        return;
    size_t n = 0;
    while (n < u->txq_len) {
        const size_t f = link_frame_size(u->txq + n, u->txq_len - n);
        if (f == 0 || n + f > USB_OUT_BYTES)
            break;
        n += f;
    }
    if (n == 0) { /* cannot happen: send() queues whole frames only */
        u->txq_len = 0;
        return;
    }
    memcpy(u->out_buf, u->txq, n);
    memmove(u->txq, u->txq + n, u->txq_len - n);
    u->txq_len -= n;
    libusb_fill_bulk_transfer(u->out, u->h, u->ep.ep_out, u->out_buf, (int)n, out_done, u, 0);
    /* A transfer of whole max-size packets ends with a zero-length packet, so the board's
     * read returns at once instead of waiting for the next transfer. */
    u->out->flags = LIBUSB_TRANSFER_ADD_ZERO_PACKET;
    const int rc = u->api.submit_transfer(u->out);
    if (rc == 0)
        u->out_busy = true;
    else if (rc == LIBUSB_ERROR_NO_DEVICE)
        u->gone = true;
    else
        u->link->stats.errors_tx++;
}

/* ---- device ---- */

/* Frees the transfers. Call only once none is in a libusb flying list: every callback came, or
 * libusb_close took the rest off the list. Each free drops the transfer's reference to the
 * device while its context is alive (freeing them after libusb_exit, or resubmitting them in a
 * new context, made libusb destroy the unplugged device through its freed context: SIGSEGV). */
static void transfers_free(usb_t *u)
{
    for (uint32_t i = 0; i < USB_IN_TRANSFERS; i++) {
        if (u->in[i])
            u->api.free_transfer(u->in[i]);
        u->in[i] = NULL;
        u->in_busy[i] = false;
    }
    if (u->out)
        u->api.free_transfer(u->out);
    u->out = NULL;
    u->out_busy = false;
    u->in_flight = 0;
}

static bool transfers_alloc(usb_t *u)
{
    for (uint32_t i = 0; i < USB_IN_TRANSFERS; i++)
        if (!(u->in[i] = u->api.alloc_transfer(0)))
            return false;
    return (u->out = u->api.alloc_transfer(0)) != NULL;
}

static void close_device(usb_t *u)
{
    if (!u->h)
        return;
    u->closing = true;
    for (uint32_t i = 0; i < USB_IN_TRANSFERS; i++)
        if (u->in_busy[i])
            (void)u->api.cancel_transfer(u->in[i]);
    if (u->out_busy)
        (void)u->api.cancel_transfer(u->out);
    /* Wait (bounded: 2 s) until libusb has called every transfer back. */
    for (int k = 0; k < 200 && (u->in_flight > 0 || u->out_busy); k++) {
        struct timeval tv = {0, 10000};
        (void)u->api.handle_events_timeout_completed(u->ctx, &tv, NULL);
    }
    if (u->open)
        (void)u->api.release_interface(u->h, u->ep.interface);
    /* A transfer the host controller has not returned within 2 s is not waited for any longer:
     * libusb_close takes it off libusb's in-flight list and closes the file descriptor (the
     * kernel discards its URBs), after which freeing it is safe. */
    u->api.close(u->h);
    u->h = NULL;
    transfers_free(u);
    u->open = false;
    u->closing = false;
    u->txq_len = 0;
    u->rx_head = u->rx_tail = 0;
    link_framer_init(&u->framer);
}

/* Reads the active configuration descriptor through GET_DESCRIPTOR and finds the endpoints. */
static argil_err_t read_endpoints(usb_t *u, char *err, size_t err_len, const char *who)
{
    uint8_t cfg[1024];
    int rc = u->api.control_transfer(u->h, LIBUSB_ENDPOINT_IN, LIBUSB_REQUEST_GET_DESCRIPTOR,
                                     (uint16_t)(LIBUSB_DT_CONFIG << 8), 0, cfg, 9,
                                     USB_CTRL_TIMEOUT_MS);
    if (rc == 9) {
        const uint16_t total = le_get_u16(cfg + 2);
        rc = u->api.control_transfer(u->h, LIBUSB_ENDPOINT_IN, LIBUSB_REQUEST_GET_DESCRIPTOR,
                                     (uint16_t)(LIBUSB_DT_CONFIG << 8), 0, cfg,
                                     total < sizeof(cfg) ? total : (uint16_t)sizeof(cfg),
                                     USB_CTRL_TIMEOUT_MS);
    }
    if (rc < 0) {
        snprintf(err, err_len, "usb %s: cannot read its configuration descriptor (%s)", who,
                 uerr(u, rc));
        return ARGIL_ERR_IO;
    }
    const usb_desc_err_t de = usb_desc_find_endpoints(cfg, (size_t)rc, &u->ep);
    if (de != USB_DESC_OK) {
        snprintf(err, err_len, "usb %s: not an argil board: %s", who, usb_desc_err_text(de));
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}

/* Finds, opens and claims the device; starts the IN transfers. */
static argil_err_t open_device(usb_t *u, char *err, size_t err_len)
{
    const link_spec_t *s = &u->link->spec;
    char who[64];
    describe(s, who, sizeof(who));
    libusb_device **list = NULL;
    const ssize_t n = u->api.get_device_list(u->ctx, &list);
    if (n < 0) {
        snprintf(err, err_len, "usb: cannot list USB devices (%s)", uerr(u, (int)n));
        return ARGIL_ERR_IO;
    }
    libusb_device *dev = NULL;
    for (ssize_t i = 0; i < n && !dev; i++) {
        if (s->by_path) {
            uint8_t ports[LINK_SPEC_PORTS_MAX];
            const int np = u->api.get_port_numbers(list[i], ports, (int)sizeof(ports));
            if (np > 0 && usb_desc_path_match(s, u->api.get_bus_number(list[i]), ports, np))
                dev = list[i];
        } else {
            struct libusb_device_descriptor dd;
            if (u->api.get_device_descriptor(list[i], &dd) == 0 && dd.idVendor == s->vid &&
                dd.idProduct == s->pid)
                dev = list[i];
        }
    }
    if (!dev) {
        u->api.free_device_list(list, 1);
        snprintf(err, err_len, "usb %s: no such device (is the board plugged in and its gadget "
                 "bound? 'lsusb' lists what is there)", who);
        return ARGIL_ERR_IO;
    }
    u->bus = u->api.get_bus_number(dev);
    u->n_ports = u->api.get_port_numbers(dev, u->ports, (int)sizeof(u->ports));
    int rc = u->api.open(dev, &u->h);
    u->api.free_device_list(list, 1);
    if (rc == LIBUSB_ERROR_ACCESS) {
        snprintf(err, err_len, "usb %s: permission denied; install the udev rule "
                 "(cp firmware/board/70-argil.rules /etc/udev/rules.d/ && udevadm control "
                 "--reload && udevadm trigger; see docs/link.md) and replug", who);
        u->h = NULL;
        return ARGIL_ERR_IO;
    }
    if (rc != 0) {
        snprintf(err, err_len, "usb %s: cannot open (%s)", who, uerr(u, rc));
        u->h = NULL;
        return ARGIL_ERR_IO;
    }
    argil_err_t e = read_endpoints(u, err, err_len, who);
    if (e == ARGIL_OK) {
        (void)u->api.set_auto_detach_kernel_driver(u->h, 1);
        rc = u->api.claim_interface(u->h, u->ep.interface);
        if (rc == 0 && u->ep.alt_setting != 0)
            rc = u->api.set_interface_alt_setting(u->h, u->ep.interface, u->ep.alt_setting);
        if (rc != 0) {
            snprintf(err, err_len, "usb %s: cannot claim interface %u (%s%s)", who,
                     u->ep.interface, uerr(u, rc),
                     rc == LIBUSB_ERROR_BUSY ? ": another program has it" : "");
            e = ARGIL_ERR_IO;
        }
    }
    if (e != ARGIL_OK) {
        u->api.close(u->h);
        u->h = NULL;
        return e;
    }
    if (!transfers_alloc(u)) {
        snprintf(err, err_len, "usb %s: out of memory for transfers", who);
        transfers_free(u);
        (void)u->api.release_interface(u->h, u->ep.interface);
        u->api.close(u->h);
        u->h = NULL;
        return ARGIL_ERR_NOMEM;
    }
    u->open = true;
    u->gone = false;
    u->error_streak = 0;
    for (uint32_t i = 0; i < USB_IN_TRANSFERS; i++) {
        libusb_fill_bulk_transfer(u->in[i], u->h, u->ep.ep_in, u->in_buf[i], (int)USB_IN_BYTES,
                                  in_done, u, 0);
        submit_in(u, u->in[i]);
    }
    if (u->in_flight == 0) {
        snprintf(err, err_len, "usb %s: cannot start bulk IN transfers on endpoint 0x%02x", who,
                 u->ep.ep_in);
        close_device(u);
        return ARGIL_ERR_IO;
    }
    return ARGIL_OK;
}

static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *dev,
                                  libusb_hotplug_event ev, void *user)
{
    (void)ctx;
    (void)dev;
    usb_t *u = user;
    if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED)
        u->hp_arrived = true;
    else
        u->hp_left = true;
    return 0;
}

static void hotplug_start(usb_t *u)
{
    u->hotplug = false;
    if (!u->api.has_capability(LIBUSB_CAP_HAS_HOTPLUG))
        return;
    const link_spec_t *s = &u->link->spec;
    const int rc = u->api.hotplug_register_callback(
        u->ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT, 0,
        s->by_path ? LIBUSB_HOTPLUG_MATCH_ANY : s->vid,
        s->by_path ? LIBUSB_HOTPLUG_MATCH_ANY : s->pid, LIBUSB_HOTPLUG_MATCH_ANY, on_hotplug, u,
        &u->hp);
    u->hotplug = rc == 0;
}

static argil_err_t context_start(usb_t *u, char *err, size_t err_len)
{
    const int rc = u->api.init(&u->ctx);
    if (rc != 0) {
        snprintf(err, err_len, "usb: cannot start libusb (%s; is /dev/bus/usb there?)",
                 uerr(u, rc));
        u->ctx = NULL;
        return ARGIL_ERR_IO;
    }
    hotplug_start(u);
    return ARGIL_OK;
}

static void context_stop(usb_t *u)
{
    if (!u->ctx)
        return;
    if (u->hotplug)
        u->api.hotplug_deregister_callback(u->ctx, u->hp);
    u->hotplug = false;
    u->api.exit(u->ctx);
    u->ctx = NULL;
}

/* ---- link operations ---- */

static argil_err_t usb_send(link_t *l, const uint8_t *frame, size_t len)
{
    usb_t *u = l->impl;
    if (!u->open || u->gone)
        return ARGIL_ERR_IO;
    if (len > USB_TXQ_BYTES - u->txq_len)
        return ARGIL_ERR_FULL;
    memcpy(u->txq + u->txq_len, frame, len);
    u->txq_len += len;
    submit_out(u);
    return ARGIL_OK;
}

static size_t usb_recv(link_t *l, uint8_t *buf, size_t cap)
{
    usb_t *u = l->impl;
    for (;;) {
        const size_t f = link_framer_next(&u->framer, buf, cap);
        if (f > 0)
            return f;
        if (u->framer.len == sizeof(u->framer.buf))
            link_framer_init(&u->framer); /* cannot happen with frames ≤ PROTO_FRAME_MAX */
        if (u->rx_head == u->rx_tail)
            return 0;
        uint8_t chunk[512];
        size_t n = 0;
        const size_t room = sizeof(u->framer.buf) - u->framer.len;
        while (n < sizeof(chunk) && n < room && u->rx_head != u->rx_tail)
            chunk[n++] = u->rxq[u->rx_head++ % USB_RXQ_BYTES];
        (void)link_framer_feed(&u->framer, chunk, n);
    }
}

static void usb_poll(link_t *l, uint32_t wait_us, uint64_t now_us)
{
    usb_t *u = l->impl;
    if (u->open) {
        submit_out(u);
        struct timeval tv = {(time_t)(wait_us / 1000000u), (long)(wait_us % 1000000u)};
        const int rc = u->api.handle_events_timeout_completed(u->ctx, &tv, NULL);
        if (rc == LIBUSB_ERROR_NO_DEVICE)
            u->gone = true;
        submit_out(u);
        if (u->gone || u->hp_left) {
            /* A left event may be for another device with the same ids: the transfers'
             * NO_DEVICE decides; a left event only makes us look. */
            if (u->gone) {
                close_device(u);
                link_transport_down(l);
                u->last_scan_us = now_us;
            }
            u->hp_left = false;
        }
        return;
    }
    if (u->ctx) {
        struct timeval tv = {0, (long)(wait_us < 999999u ? wait_us : 999999u)};
        (void)u->api.handle_events_timeout_completed(u->ctx, &tv, NULL);
    }
    if (!u->hp_arrived && now_us - u->last_scan_us < USB_RESCAN_US)
        return;
    u->last_scan_us = now_us;
    /* A fresh context rescans the bus: libusb's device list follows udev's hot-plug events,
     * which a machine without udevd (the HIL VM) never sends. */
    if (!u->hp_arrived || !u->ctx) {
        context_stop(u);
        char ignored[256];
        if (context_start(u, ignored, sizeof(ignored)) != ARGIL_OK)
            return;
    }
    u->hp_arrived = false;
    char why[512];
    if (open_device(u, why, sizeof(why)) == ARGIL_OK)
        link_transport_up(l);
}

static void usb_close(link_t *l)
{
    usb_t *u = l->impl;
    if (!u)
        return;
    close_device(u); /* frees the transfers: none outlives the context */
    context_stop(u);
    if (u->api.lib)
        dlclose(u->api.lib);
    free(u);
}

static const link_ops_t USB_OPS = {usb_send, usb_recv, usb_poll, usb_close};

argil_err_t link_usb_open_api(link_t *l, const usb_api_t *api, char *err, size_t err_len)
{
    usb_t *u = calloc(1, sizeof(*u));
    if (!u) {
        snprintf(err, err_len, "out of memory for the USB link");
        if (api->lib)
            dlclose(api->lib);
        return ARGIL_ERR_NOMEM;
    }
    u->api = *api;
    u->link = l;
    link_framer_init(&u->framer);
    l->impl = u;
    l->ops = &USB_OPS;
    argil_err_t e = context_start(u, err, err_len);
    if (e == ARGIL_OK)
        e = open_device(u, err, err_len);
    if (e != ARGIL_OK) {
        usb_close(l);
        l->impl = NULL;
        l->ops = NULL;
        return e;
    }
    link_attach(l, &USB_OPS, u, true);
    return ARGIL_OK;
}

argil_err_t link_usb_open(link_t *l, char *err, size_t err_len)
{
    usb_api_t api;
    memset(&api, 0, sizeof(api));
    const char *why = api_load(&api);
    if (why) {
        snprintf(err, err_len, "usb: %s", why);
        if (api.lib)
            dlclose(api.lib);
        return ARGIL_ERR_IO;
    }
    return link_usb_open_api(l, &api, err, err_len);
}
