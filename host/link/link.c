/* The transport-neutral half of the host link: device strings to transports, counters and the
 * link state. */
#include "link.h"

#include <stdio.h>
#include <string.h>

argil_err_t link_open(link_t *l, const char *device, char *err, size_t err_len)
{
    return link_open_keyed(l, device, NULL, err, err_len);
}

argil_err_t link_open_keyed(link_t *l, const char *device, const uint8_t *key, char *err,
                            size_t err_len)
{
    memset(l, 0, sizeof(*l));
    const link_spec_err_t pe = link_spec_parse(device, &l->spec);
    if (pe != LINK_SPEC_OK) {
        snprintf(err, err_len, "bad device '%s': %s", device ? device : "",
                 link_spec_err_text(pe));
        return ARGIL_ERR_PARSE;
    }
    if (key && l->spec.kind != LINK_KIND_UDP) {
        snprintf(err, err_len, "device '%s': a link key is for udp: devices (USB is a cable to "
                 "one board and the sim board is in this process: neither needs one)", device);
        return ARGIL_ERR_ARG;
    }
    if (key) {
        l->keyed = true;
        memcpy(l->key, key, LINK_KEY_SIZE);
    }
    switch (l->spec.kind) {
    case LINK_KIND_SIM: return link_sim_open(l, l->spec.sim_hand, err, err_len);
    case LINK_KIND_UDP: return link_dgram_open(l, err, err_len);
    case LINK_KIND_USB: return link_usb_open(l, err, err_len);
    }
    snprintf(err, err_len, "bad device '%s'", device);
    return ARGIL_ERR_PARSE;
}

void link_attach(link_t *l, const link_ops_t *ops, void *impl, bool transport_up)
{
    l->ops = ops;
    l->impl = impl;
    link_fsm_init(&l->fsm, LINK_SILENCE_US, transport_up);
}

argil_err_t link_send(link_t *l, const uint8_t *frame, size_t len)
{
    const argil_err_t e = l->ops->send(l, frame, len);
    if (e == ARGIL_OK) {
        l->stats.frames_tx++;
        l->stats.bytes_tx += len;
    } else {
        l->stats.errors_tx++;
    }
    return e;
}

size_t link_recv(link_t *l, uint8_t *buf, size_t cap)
{
    const size_t n = l->ops->recv(l, buf, cap);
    if (n > 0) {
        l->stats.frames_rx++;
        l->stats.bytes_rx += n;
        link_fsm_frame(&l->fsm, l->now_us);
        l->stats.reconnects = l->fsm.reconnects;
    }
    return n;
}

void link_poll(link_t *l, uint32_t wait_us, uint64_t now_us)
{
    l->now_us = now_us;
    l->ops->poll(l, wait_us, now_us);
    link_fsm_tick(&l->fsm, now_us);
}

void link_set_time(link_t *l, uint64_t now_us)
{
    if (now_us > l->now_us)
        l->now_us = now_us;
    link_fsm_tick(&l->fsm, l->now_us);
}

bool link_take_resync(link_t *l)
{
    return link_fsm_take_resync(&l->fsm);
}

link_state_t link_state(const link_t *l)
{
    return l->fsm.state;
}

void link_close(link_t *l)
{
    if (l->ops && l->ops->close)
        l->ops->close(l);
    l->ops = NULL;
    l->impl = NULL;
}

void link_transport_down(link_t *l)
{
    link_fsm_transport_down(&l->fsm);
}

void link_transport_up(link_t *l)
{
    link_fsm_transport_up(&l->fsm);
}
