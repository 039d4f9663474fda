/* Wait-free triple buffer (see triple_buffer.h). The exchange on `middle` orders everything the
 * writer stored into a slot before the reader's loads from it (release on publish, acquire on
 * take). */
#include "host/render/triple_buffer.h"

void triple_buffer_init(triple_buffer_t *t)
{
    t->back = 0;
    atomic_init(&t->middle, 1u);
    t->front = 2;
    t->published = 0;
    t->taken = 0;
}

uint32_t triple_buffer_back(const triple_buffer_t *t)
{
    return t->back;
}

uint32_t triple_buffer_publish(triple_buffer_t *t)
{
    /* Sequentially consistent, so a reader that announced it is going to sleep and then found
     * nothing fresh is seen by the writer's next look at that announcement (sculpt_window.c). */
    const uint32_t old = atomic_exchange_explicit(&t->middle, t->back | TRIPLE_BUFFER_FRESH,
                                                  memory_order_seq_cst);
    t->back = old & 3u;
    t->published++;
    return t->back;
}

bool triple_buffer_has_fresh(const triple_buffer_t *t)
{
    return (atomic_load_explicit(&t->middle, memory_order_seq_cst) & TRIPLE_BUFFER_FRESH) != 0u;
}

bool triple_buffer_take(triple_buffer_t *t, uint32_t *slot)
{
    if ((atomic_load_explicit(&t->middle, memory_order_relaxed) & TRIPLE_BUFFER_FRESH) == 0u) {
        *slot = t->front;
        return false;
    }
    /* Only the writer can change `middle` meanwhile, and only to another fresh slot. */
    const uint32_t old = atomic_exchange_explicit(&t->middle, t->front, memory_order_acq_rel);
    t->front = old & 3u;
    t->taken++;
    *slot = t->front;
    return true;
}
