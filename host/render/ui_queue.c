/* SPSC command queue (see ui_queue.h): the producer publishes a record by storing tail with
 * release order after writing it; the consumer frees it by storing head after reading it. */
#include "host/render/ui_queue.h"

#include <string.h>

_Static_assert((UI_QUEUE_CAP & (UI_QUEUE_CAP - 1u)) == 0u, "UI_QUEUE_CAP: power of two");

void ui_queue_init(ui_queue_t *q)
{
    memset(q->rec, 0, sizeof(q->rec));
    atomic_init(&q->head, 0u);
    atomic_init(&q->tail, 0u);
    atomic_init(&q->dropped, 0u);
}

bool ui_queue_push(ui_queue_t *q, const ui_cmd_t *c)
{
    const uint32_t tail = atomic_load_explicit(&q->tail, memory_order_relaxed);
    const uint32_t head = atomic_load_explicit(&q->head, memory_order_acquire);
    if (tail - head >= UI_QUEUE_CAP) {
        atomic_fetch_add_explicit(&q->dropped, 1u, memory_order_relaxed);
        return false;
    }
    q->rec[tail & (UI_QUEUE_CAP - 1u)] = *c;
    atomic_store_explicit(&q->tail, tail + 1u, memory_order_release);
    return true;
}

bool ui_queue_pop(ui_queue_t *q, ui_cmd_t *c)
{
    const uint32_t head = atomic_load_explicit(&q->head, memory_order_relaxed);
    const uint32_t tail = atomic_load_explicit(&q->tail, memory_order_acquire);
    if (head == tail)
        return false;
    *c = q->rec[head & (UI_QUEUE_CAP - 1u)];
    atomic_store_explicit(&q->head, head + 1u, memory_order_release);
    return true;
}
