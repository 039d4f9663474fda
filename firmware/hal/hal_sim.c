/* HAL backend for the in-process simulator: everything is a queue in memory. */
#define _GNU_SOURCE /* RUSAGE_THREAD */
#include "hal_sim.h"

#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "shared/wire.h"

void hal_sim_init(hal_t *h)
{
    memset(h, 0, sizeof(*h));
    link_bind_init(&h->bind);
    h->tick_us = 1000u;
}

void hal_sim_set_tick_us(hal_t *h, uint32_t tick_us)
{
    h->tick_us = tick_us;
}

static uint32_t fifo_used(const hal_sim_fifo_t *q)
{
    return q->tail - q->head;
}

static void fifo_compact(hal_sim_fifo_t *q)
{
    if (q->head == 0)
        return;
    memmove(q->bytes, q->bytes + q->head, q->tail - q->head);
    q->tail -= q->head;
    q->head = 0;
}

/* Appends one record (u16 length + bytes); false when it does not fit. */
static bool fifo_put(hal_sim_fifo_t *q, const uint8_t *data, size_t len)
{
    if (len > 0xFFFFu)
        return false;
    if (q->tail + 2u + len > HAL_SIM_LINK_BYTES)
        fifo_compact(q);
    if (q->tail + 2u + len > HAL_SIM_LINK_BYTES)
        return false;
    le_put_u16(q->bytes + q->tail, (uint16_t)len);
    memcpy(q->bytes + q->tail + 2u, data, len);
    q->tail += 2u + (uint32_t)len;
    return true;
}

/* Copies whole records' bytes into buf while they fit; returns the bytes copied. */
static size_t fifo_get(hal_sim_fifo_t *q, uint8_t *buf, size_t cap)
{
    size_t n = 0;
    while (fifo_used(q) >= 2u) {
        const uint32_t len = le_get_u16(q->bytes + q->head);
        if (n + len > cap)
            break;
        memcpy(buf + n, q->bytes + q->head + 2u, len);
        n += len;
        q->head += 2u + len;
    }
    if (q->head == q->tail)
        q->head = q->tail = 0;
    return n;
}

argil_err_t hal_can_receive(hal_t *h, can_batch_t *rx)
{
    *rx = h->to_board;
    h->to_board.n = 0;
    return ARGIL_OK;
}

argil_err_t hal_can_send(hal_t *h, const can_batch_t *tx)
{
    for (uint8_t i = 0; i < tx->n && i < CAN_BATCH_MAX; i++)
        if (can_batch_push(&h->from_board, &tx->f[i]) != ARGIL_OK)
            return ARGIL_ERR_FULL;
    return ARGIL_OK;
}

uint32_t hal_gpio_read(hal_t *h)
{
    return h->gpio_in;
}

void hal_gpio_write(hal_t *h, uint32_t levels)
{
    h->gpio_out = levels;
}

size_t hal_link_receive(hal_t *h, uint8_t *buf, size_t cap)
{
    return fifo_get(&h->link_to_board, buf, cap);
}

argil_err_t hal_link_send(hal_t *h, const uint8_t *buf, size_t len)
{
    if (!fifo_put(&h->link_from_board, buf, len)) {
        h->link_dropped++;
        return ARGIL_ERR_FULL;
    }
    return ARGIL_OK;
}

uint64_t hal_compute_clock_ns(hal_t *h)
{
    (void)h;
    /* Thread CPU time: the tick's own compute, not the time other processes took the core. */
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

uint64_t hal_compute_preemptions(hal_t *h)
{
    (void)h;
    struct rusage ru;
    if (getrusage(RUSAGE_THREAD, &ru) != 0)
        return 0;
    return (uint64_t)ru.ru_nivcsw;
}

void hal_sim_take_from_board(hal_t *h, can_batch_t *out)
{
    *out = h->from_board;
    h->from_board.n = 0;
}

void hal_sim_put_to_board(hal_t *h, const can_batch_t *in)
{
    for (uint8_t i = 0; i < in->n && i < CAN_BATCH_MAX; i++)
        (void)can_batch_push(&h->to_board, &in->f[i]);
}

void hal_sim_set_gpio_in(hal_t *h, uint32_t levels)
{
    h->gpio_in = levels;
}

uint32_t hal_sim_gpio_out(const hal_t *h)
{
    return h->gpio_out;
}

void hal_link_session(hal_t *h, hal_session_state_t state, uint32_t epoch)
{
    h->link_now_us += h->tick_us;
    link_bind_session(&h->bind, state, epoch, h->link_now_us);
}

void hal_link_refusals(hal_t *h, hal_link_refusals_t *r)
{
    r->wrong_source = h->bind.refused_source;
    r->no_session = h->bind.refused_no_session;
    r->bad_mac = 0; /* the simulated link has no envelope */
    r->bad_nonce = 0;
}

argil_err_t hal_sim_host_send(hal_t *h, const uint8_t *frame, size_t len)
{
    return hal_sim_host_send_from(h, HAL_SIM_HOST, frame, len);
}

argil_err_t hal_sim_host_send_from(hal_t *h, uint64_t sender, const uint8_t *frame, size_t len)
{
    if (!link_bind_admit(&h->bind, sender, frame, len, h->link_now_us))
        return ARGIL_OK; /* delivered to the board's transport, which dropped it */
    if (!fifo_put(&h->link_to_board, frame, len)) {
        h->link_dropped++;
        return ARGIL_ERR_FULL;
    }
    return ARGIL_OK;
}

size_t hal_sim_host_receive(hal_t *h, uint8_t *buf, size_t cap)
{
    return fifo_get(&h->link_from_board, buf, cap);
}
