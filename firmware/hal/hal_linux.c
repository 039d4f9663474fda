/* HAL backend for the Linux board: SocketCAN, libgpiod (through gpio_port), SPSC link rings,
 * CLOCK_MONOTONIC; or the simulated arm in place of CAN and GPIO (hal_sim_bus.c). */
#define _POSIX_C_SOURCE 200809L
#include "hal_linux.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hal_sim_bus.h"

argil_err_t hal_linux_reset(hal_t *h, hal_bus_t bus)
{
    memset(h, 0, offsetof(hal_t, link_rx_mem));
    h->bus = bus;
    h->can_fd = -1;
    if (spsc_init(&h->link_rx, h->link_rx_mem, HAL_LINUX_RX_RING_BYTES) != ARGIL_OK ||
        spsc_init(&h->link_tx, h->link_tx_mem, HAL_LINUX_TX_RING_BYTES) != ARGIL_OK)
        return ARGIL_ERR_ARG;
    return ARGIL_OK;
}

argil_err_t hal_linux_open(hal_t *h, const char *can_if, const gpio_names_t *names, char *err,
                           size_t err_len)
{
    argil_err_t rc = hal_linux_reset(h, HAL_BUS_SOCKETCAN);
    if (rc != ARGIL_OK)
        return rc;
    rc = can_socket_open(can_if, &h->can_fd, err, err_len);
    if (rc != ARGIL_OK)
        return rc;
    rc = gpio_port_open(&h->gpio, &gpio_ops_gpiod, NULL, names, err, err_len);
    if (rc != ARGIL_OK) {
        close(h->can_fd);
        h->can_fd = -1;
    }
    return rc;
}

void hal_linux_close(hal_t *h)
{
    gpio_port_close(&h->gpio);
    if (h->can_fd >= 0)
        close(h->can_fd);
    h->can_fd = -1;
    hal_sim_bus_close(h);
}

argil_err_t hal_linux_can_flush(hal_t *h, const can_batch_t *tx)
{
    return hal_can_send(h, tx);
}

/* ---- hal.h ---- */

argil_err_t hal_can_receive(hal_t *h, can_batch_t *rx)
{
    if (h->bus == HAL_BUS_SIM) {
        hal_sim_bus_step(h, rx);
        return ARGIL_OK;
    }
    return can_socket_receive_queued(h->can_fd, &h->can_rx, rx, &h->can);
}

argil_err_t hal_can_send(hal_t *h, const can_batch_t *tx)
{
    if (h->bus == HAL_BUS_SIM) {
        for (uint8_t i = 0; i < tx->n && i < CAN_BATCH_MAX; i++)
            if (can_batch_push(&h->sim_from_board, &tx->f[i]) != ARGIL_OK)
                return ARGIL_ERR_FULL;
        return ARGIL_OK;
    }
    return can_socket_send(h->can_fd, tx, &h->can);
}

uint32_t hal_gpio_read(hal_t *h)
{
    return gpio_port_read(&h->gpio);
}

void hal_gpio_write(hal_t *h, uint32_t levels)
{
    gpio_port_write(&h->gpio, levels);
}

size_t hal_link_receive(hal_t *h, uint8_t *buf, size_t cap)
{
    size_t n = 0;
    for (;;) {
        const size_t next = spsc_peek_len(&h->link_rx);
        if (next == 0)
            break;
        if (next > cap) {
            /* Can never fit (the link thread frames records to ≤ PROTO_FRAME_MAX, so this is
             * a bug elsewhere): drop it rather than stall the queue. */
            spsc_skip(&h->link_rx);
            h->link_rx_too_big++;
            continue;
        }
        if (n + next > cap)
            break;
        size_t got = 0;
        if (spsc_pop(&h->link_rx, buf + n, cap - n, &got) != ARGIL_OK)
            break;
        n += got;
    }
    return n;
}

argil_err_t hal_link_send(hal_t *h, const uint8_t *buf, size_t len)
{
    return spsc_push(&h->link_tx, buf, len);
}

void hal_link_session(hal_t *h, hal_session_state_t state, uint32_t epoch)
{
    atomic_store_explicit(&h->link_session, (uint32_t)state | epoch << 2, memory_order_release);
}

void hal_link_refusals(hal_t *h, hal_link_refusals_t *r)
{
    r->wrong_source = atomic_load_explicit(&h->link_refused_source, memory_order_relaxed);
    r->no_session = atomic_load_explicit(&h->link_refused_no_session, memory_order_relaxed);
    r->bad_mac = atomic_load_explicit(&h->link_refused_bad_mac, memory_order_relaxed);
    r->bad_nonce = atomic_load_explicit(&h->link_refused_bad_nonce, memory_order_relaxed);
}

void hal_linux_link_session_get(hal_t *h, hal_session_state_t *state, uint32_t *epoch)
{
    const uint32_t w = atomic_load_explicit(&h->link_session, memory_order_acquire);
    *state = (hal_session_state_t)(w & 3u);
    *epoch = w >> 2;
}

void hal_linux_link_refusals_set(hal_t *h, const hal_link_refusals_t *r)
{
    atomic_store_explicit(&h->link_refused_source, r->wrong_source, memory_order_relaxed);
    atomic_store_explicit(&h->link_refused_no_session, r->no_session, memory_order_relaxed);
    atomic_store_explicit(&h->link_refused_bad_mac, r->bad_mac, memory_order_relaxed);
    atomic_store_explicit(&h->link_refused_bad_nonce, r->bad_nonce, memory_order_relaxed);
}

uint64_t hal_compute_clock_ns(hal_t *h)
{
    (void)h;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

uint64_t hal_compute_preemptions(hal_t *h)
{
    (void)h;
    return 0; /* wall time: a preempted tick is late, and its lateness counts */
}
