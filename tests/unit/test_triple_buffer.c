/* The triple buffer between the session and the window, and the window's command queue: slot
 * rotation, newest-wins, and threaded stress runs in which the reader must never see a torn
 * snapshot or a snapshot older than one it already saw. */
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "host/render/triple_buffer.h"
#include "host/render/ui_queue.h"

static void test_single_thread_rotation(void **state)
{
    (void)state;
    triple_buffer_t t;
    triple_buffer_init(&t);
    uint32_t slot = 99;
    assert_false(triple_buffer_has_fresh(&t));
    assert_false(triple_buffer_take(&t, &slot)); /* nothing published yet */
    assert_int_equal(slot, 2);
    const uint32_t b0 = triple_buffer_back(&t);
    const uint32_t b1 = triple_buffer_publish(&t);
    assert_int_not_equal(b0, b1);
    assert_int_not_equal(b1, 2); /* never the reader's slot */
    assert_true(triple_buffer_has_fresh(&t)); /* a peek does not take it */
    assert_true(triple_buffer_has_fresh(&t));
    assert_true(triple_buffer_take(&t, &slot));
    assert_int_equal(slot, b0);
    assert_false(triple_buffer_has_fresh(&t));
    assert_false(triple_buffer_take(&t, &slot)); /* taken once only */
    assert_int_equal(slot, b0);
    /* Three publishes without a take: the reader gets the newest, the writer never the
     * reader's slot. */
    uint32_t last = triple_buffer_back(&t);
    for (int i = 0; i < 3; i++) {
        last = triple_buffer_back(&t);
        const uint32_t next = triple_buffer_publish(&t);
        assert_int_not_equal(next, slot);
    }
    uint32_t got;
    assert_true(triple_buffer_take(&t, &got));
    assert_int_equal(got, last);
    assert_int_equal(t.published, 4);
    assert_int_equal(t.taken, 2);
}

enum { SNAP_WORDS = 251, STRESS_PUBLISHES = 50000 };

typedef struct {
    uint64_t seq;
    uint64_t words[SNAP_WORDS];   /* every word = seq * 7 + index: a torn copy shows */
} snap_t;

typedef struct {
    triple_buffer_t tb;
    snap_t slot[3];
    _Atomic int done;
    _Atomic uint64_t reader_fresh;    /* fresh snapshots the reader has checked */
    _Atomic uint64_t last_published;
} stress_t;

/* Publishes at least STRESS_PUBLISHES snapshots, and goes on (yielding now and then) until the
 * reader has checked 1000 of them, however the scheduler shares the cores. */
static void *writer_main(void *arg)
{
    stress_t *s = arg;
    uint64_t seq = 1;
    for (; seq <= STRESS_PUBLISHES || atomic_load(&s->reader_fresh) < 1000u; seq++) {
        snap_t *w = &s->slot[triple_buffer_back(&s->tb)];
        w->seq = seq;
        for (uint64_t i = 0; i < SNAP_WORDS; i++)
            w->words[i] = seq * 7u + i;
        triple_buffer_publish(&s->tb);
        if (seq > STRESS_PUBLISHES && seq % 256u == 0)
            sched_yield();
    }
    atomic_store(&s->last_published, seq - 1u);
    atomic_store(&s->done, 1);
    return NULL;
}

static void test_threaded_no_torn_snapshot(void **state)
{
    (void)state;
    static stress_t s;
    memset(&s, 0, sizeof(s));
    triple_buffer_init(&s.tb);
    atomic_init(&s.done, 0);
    atomic_init(&s.reader_fresh, 0u);
    atomic_init(&s.last_published, 0u);
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, writer_main, &s), 0);
    uint64_t last_seq = 0, torn = 0, backwards = 0, fresh = 0;
    for (;;) {
        const int finished = atomic_load(&s.done);
        uint32_t slot;
        if (triple_buffer_take(&s.tb, &slot)) {
            const snap_t *r = &s.slot[slot];
            fresh++;
            for (uint64_t i = 0; i < SNAP_WORDS; i++)
                if (r->words[i] != r->seq * 7u + i)
                    torn++;
            if (r->seq <= last_seq)
                backwards++;
            last_seq = r->seq;
            atomic_store(&s.reader_fresh, fresh);
        }
        if (finished && !triple_buffer_take(&s.tb, &slot))
            break;
        if (finished) { /* one more fresh slot was there: check it too */
            const snap_t *r = &s.slot[slot];
            for (uint64_t i = 0; i < SNAP_WORDS; i++)
                if (r->words[i] != r->seq * 7u + i)
                    torn++;
            last_seq = r->seq;
            break;
        }
    }
    pthread_join(th, NULL);
    assert_int_equal(torn, 0);
    assert_int_equal(backwards, 0);
    /* The newest snapshot always arrives; the reader saw a real share of them. */
    assert_int_equal(last_seq, atomic_load(&s.last_published));
    assert_true(last_seq >= STRESS_PUBLISHES);
    assert_true(fresh >= 1000);
    assert_true(s.tb.taken == fresh || s.tb.taken == fresh + 1);
}

enum { QUEUE_CMDS = 300000 };

typedef struct {
    ui_queue_t q;
    uint64_t pushed;
} qstress_t;

static void *producer_main(void *arg)
{
    qstress_t *s = arg;
    for (int32_t i = 0; i < QUEUE_CMDS;) {
        ui_cmd_t c;
        memset(&c, 0, sizeof(c));
        c.kind = UI_CMD_PARAM;
        c.arg = i;
        c.value = (float)(i % 1000);
        c.origin_m[0] = (float)(i % 777);
        if (ui_queue_push(&s->q, &c))
            i++;
    }
    return NULL;
}

static void test_queue_order_under_threads(void **state)
{
    (void)state;
    static qstress_t s;
    ui_queue_init(&s.q);
    ui_cmd_t c;
    assert_false(ui_queue_pop(&s.q, &c));
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, producer_main, &s), 0);
    int32_t expect = 0;
    uint64_t wrong = 0;
    while (expect < QUEUE_CMDS) {
        if (!ui_queue_pop(&s.q, &c))
            continue;
        if (c.kind != UI_CMD_PARAM || c.arg != expect || c.value != (float)(expect % 1000) ||
            c.origin_m[0] != (float)(expect % 777))
            wrong++;
        expect++;
    }
    pthread_join(th, NULL);
    assert_int_equal(wrong, 0);
    assert_false(ui_queue_pop(&s.q, &c));
}

static void test_queue_full_drops(void **state)
{
    (void)state;
    static ui_queue_t q;
    ui_queue_init(&q);
    ui_cmd_t c;
    memset(&c, 0, sizeof(c));
    c.kind = UI_CMD_TOOL;
    for (uint32_t i = 0; i < UI_QUEUE_CAP; i++)
        assert_true(ui_queue_push(&q, &c));
    assert_false(ui_queue_push(&q, &c));
    assert_false(ui_queue_push(&q, &c));
    assert_int_equal(atomic_load(&q.dropped), 2);
    assert_true(ui_queue_pop(&q, &c));
    assert_true(ui_queue_push(&q, &c)); /* room again */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_single_thread_rotation),
        cmocka_unit_test(test_threaded_no_torn_snapshot),
        cmocka_unit_test(test_queue_order_under_threads),
        cmocka_unit_test(test_queue_full_drops),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
