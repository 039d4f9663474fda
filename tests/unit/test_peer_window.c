/* Painted stiffness reaches the board: the peer sends its window with one channel
 * (densities) while nothing in it is painted, and with two (densities, then each node's spring
 * stiffness = base × painted scale) once a paint reaches it; the board's window takes the
 * second channel as its per-node stiffness. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/core/window.h"
#include "host/app/peer.h"
#include "host/model/grid.h"

#define EDGE 16
#define NODES (EDGE * EDGE * EDGE)

typedef struct {
    grid_t grid;
    peer_t peer;
    window_t board;             /* the board's window, fed with every chunk the peer sends */
    uint32_t chunks;            /* WINDOW chunks seen */
    uint32_t windows;           /* windows the board completed */
    uint8_t channels;           /* of the newest chunk */
    uint16_t chunk_count;
    uint32_t first_tick, last_tick; /* ticks (1-based) of the newest window's first and last chunk */
    uint32_t tick;
    float base_stiffness;       /* head.stiffness of the newest chunk */
} rig_t;

static bool capture(void *ctx, const uint8_t *frame, size_t len)
{
    rig_t *r = ctx;
    proto_msg_t m;
    size_t flen = 0;
    assert_int_equal(proto_decode(frame, len, &m, &flen), PROTO_OK);
    if (m.type != MSG_WINDOW)
        return true;
    const msg_window_t *w = &m.u.window;
    if (w->chunk_index == 0)
        r->first_tick = r->tick;
    r->last_tick = r->tick;
    r->chunks++;
    r->channels = w->channels;
    r->chunk_count = w->chunk_count;
    r->base_stiffness = w->stiffness;
    assert_int_equal(window_feed_decoded(&r->board, w), PROTO_OK);
    if (window_pending(&r->board)) {
        window_swap(&r->board);
        r->windows++;
    }
    return true;
}

static rig_t *rig_new(peer_global_solve_t solve)
{
    rig_t *r = calloc(1, sizeof(*r));
    assert_non_null(r);
    const int32_t dims[3] = {40, 40, 40};
    assert_int_equal(grid_init(&r->grid, dims, 1e-3f, vec3(-0.02f, -0.02f, -0.02f)), ARGIL_OK);
    grid_fill_sphere(&r->grid, vec3(0, 0, 0), 0.012f);
    window_init(&r->board);
    peer_cfg_t cfg;
    peer_cfg_default(&cfg);
    cfg.window_edge = EDGE;
    cfg.global_solve = solve;
    assert_int_equal(peer_init(&r->peer, &cfg, &r->grid, capture, NULL, r), ARGIL_OK);
    return r;
}

static void rig_free(rig_t *r)
{
    peer_free(&r->peer);
    grid_free(&r->grid);
    free(r);
}

/* The board says HELLO: the peer answers with a fresh window (around the origin: no telemetry). */
static void board_hello(rig_t *r)
{
    proto_msg_t m;
    memset(&m, 0, sizeof(m));
    m.type = MSG_HELLO;
    m.u.hello.role = PROTO_ROLE_BOARD;
    m.u.hello.drives = 3;
    m.u.hello.window_max = ARGIL_WINDOW_MAX;
    m.u.hello.tick_hz = 1000;
    uint8_t buf[PROTO_FRAME_MAX];
    size_t len = 0;
    assert_int_equal(proto_encode(&m, 1, buf, sizeof(buf), &len), PROTO_OK);
    peer_receive(&r->peer, buf, len);
}

static void run_ms(rig_t *r, uint32_t ms)
{
    for (uint32_t i = 0; i < ms; i++) {
        r->tick++;
        peer_tick(&r->peer, 1000);
    }
}

/* Stiffness the board uses at the node nearest x. */
static float board_stiffness_at(const rig_t *r, vec3_t x)
{
    const window_buf_t *b = window_active(&r->board);
    assert_non_null(b);
    int32_t c[3];
    const float u[3] = {(x.x - b->origin_m.x) / b->spacing_m, (x.y - b->origin_m.y) / b->spacing_m,
                        (x.z - b->origin_m.z) / b->spacing_m};
    for (int a = 0; a < 3; a++)
        c[a] = (int32_t)lrintf(u[a]);
    const int32_t i = window_index(b, c[0], c[1], c[2]);
    assert_true(i >= 0);
    return window_node_stiffness(b, i);
}

static void test_unpainted_window_has_one_channel(void **st)
{
    (void)st;
    rig_t *r = rig_new(PEER_SOLVE_BSPLINE);
    board_hello(r);
    run_ms(r, 30);
    assert_int_equal(r->windows, 1);
    assert_int_equal(r->channels, 1);
    assert_int_equal(r->chunk_count, 19); /* ⌈4096 / 224⌉ */
    /* two chunks a millisecond: the whole window in 10 ms */
    assert_int_equal(r->last_tick - r->first_tick + 1, 10);
    const window_buf_t *b = window_active(&r->board);
    assert_null(b->node_stiffness);
    assert_float_equal(board_stiffness_at(r, vec3(0, 0, 0.003f)), 2.0f, 1e-6f);
    rig_free(r);
}

static void test_painted_window_carries_node_stiffness(void **st)
{
    (void)st;
    rig_t *r = rig_new(PEER_SOLVE_BSPLINE);
    board_hello(r);
    run_ms(r, 30);
    assert_int_equal(r->windows, 1);
    /* Paint 4× stiffer, 5 mm round (0, 0, 3 mm): inside the window (about ±8 mm round the
     * origin, where the tool is before any telemetry). */
    const vec3_t c = vec3(0, 0, 0.003f);
    assert_int_equal(peer_paint_material(&r->peer, PEER_MAT_STIFFNESS, c, 0.005f, 4.0f), ARGIL_OK);
    run_ms(r, 60);
    assert_int_equal(r->windows, 2); /* sent again once painted */
    assert_int_equal(r->channels, 2);
    assert_int_equal(r->chunk_count, 37); /* ⌈2 · 4096 / 224⌉ */
    assert_int_equal(r->last_tick - r->first_tick + 1, 19);
    assert_float_equal(r->base_stiffness, 2.0f, 1e-6f); /* the header keeps the base material */
    const window_buf_t *b = window_active(&r->board);
    assert_non_null(b->node_stiffness);
    /* base 2 × scale: 4× at the centre, 2.8× 2 mm out (1 + 3 · 0.6), the base beyond 5 mm */
    assert_float_equal(board_stiffness_at(r, c), 8.0f, 1e-4f);
    assert_float_equal(board_stiffness_at(r, vec3(0, 0, 0.005f)), 5.6f, 1e-3f);
    assert_float_equal(board_stiffness_at(r, vec3(0, 0, -0.003f)), 2.0f, 1e-6f);
    assert_float_equal(b->max_stiffness, 8.0f, 1e-4f);
    /* what the board feels matches the host's model at every node */
    for (int32_t z = 0; z < EDGE; z++)
        for (int32_t y = 0; y < EDGE; y++)
            for (int32_t x = 0; x < EDGE; x++) {
                const vec3_t q = window_node_pos(b, x, y, z);
                const float k = peer_material_at(&r->peer, PEER_MAT_STIFFNESS, q) * 2.0f;
                assert_float_equal(window_node_stiffness(b, window_index(b, x, y, z)), k, 1e-5f);
            }
    rig_free(r);
}

static void test_paint_outside_the_window_keeps_one_channel(void **st)
{
    (void)st;
    rig_t *r = rig_new(PEER_SOLVE_BSPLINE);
    board_hello(r);
    run_ms(r, 30);
    /* The window covers about ±8 mm round the origin; paint 2 mm round a point 15 mm out. */
    assert_int_equal(peer_paint_material(&r->peer, PEER_MAT_STIFFNESS, vec3(0.015f, 0.015f, 0),
                                         0.002f, 4.0f), ARGIL_OK);
    assert_false(r->peer.field_dirty);
    run_ms(r, 60);
    assert_int_equal(r->windows, 1); /* nothing the hand feels changed: no new window */
    board_hello(r);                  /* a fresh window anyway */
    run_ms(r, 30);
    assert_int_equal(r->windows, 2);
    assert_int_equal(r->channels, 1);
    assert_int_equal(r->chunk_count, 19);
    rig_free(r);
}

static void test_springs_solve_sends_one_channel(void **st)
{
    (void)st;
    rig_t *r = rig_new(PEER_SOLVE_SPRINGS);
    board_hello(r);
    run_ms(r, 30);
    assert_int_equal(peer_paint_material(&r->peer, PEER_MAT_STIFFNESS, vec3(0, 0, 0.003f), 0.005f,
                                         4.0f), ARGIL_ERR_STATE);
    assert_int_equal(r->windows, 1);
    assert_int_equal(r->channels, 1);
    rig_free(r);
}

/* Sends a two-channel 16³ window of version v to the board's window, chunks in reverse order;
 * node `peak` gets stiffness peak_k, the rest base_k. */
static void feed_reversed(window_t *w, uint32_t v, int32_t peak, float base_k, float peak_k)
{
    static float all[2 * NODES];
    for (int32_t i = 0; i < NODES; i++) {
        all[i] = 0.5f;
        all[NODES + i] = i == peak ? peak_k : base_k;
    }
    msg_window_t head;
    memset(&head, 0, sizeof(head));
    head.version = v;
    head.dims[0] = head.dims[1] = head.dims[2] = EDGE;
    head.channels = 2;
    head.spacing_m = 1e-3f;
    head.iso = 0.5f;
    head.node_mass = 1.0f;
    head.stiffness = base_k;
    head.damping = 40.0f;
    head.chunk_count = window_chunk_count(head.dims, head.channels);
    static msg_window_t c;
    for (int k = head.chunk_count - 1; k >= 0; k--) {
        assert_int_equal(window_chunk_fill(&head, all, (uint16_t)k, &c), PROTO_OK);
        assert_int_equal(window_feed(w, &c), PROTO_OK);
        if (k > 0) /* a duplicate never disturbs the assembly */
            assert_int_equal(window_feed(w, &c), PROTO_OK);
    }
    assert_true(window_pending(w));
    window_swap(w);
}

/* The board keeps the largest node stiffness (its springs' stability bound) chunk by chunk, so
 * no tick scans a whole window: right whatever order the chunks come in, and a new window's
 * own, never the last one's. */
static void test_board_tracks_the_largest_node_stiffness_chunk_by_chunk(void **st)
{
    (void)st;
    window_t *w = calloc(1, sizeof(*w));
    assert_non_null(w);
    window_init(w);
    feed_reversed(w, 1, NODES - 1, 2.0f, 50.0f); /* the peak in the last chunk, fed first */
    assert_float_equal(window_active(w)->max_stiffness, 50.0f, 0.0f);
    feed_reversed(w, 2, 0, 2.0f, 8.0f);         /* the peak in the first stiffness chunk */
    assert_float_equal(window_active(w)->max_stiffness, 8.0f, 0.0f);
    feed_reversed(w, 3, 5, 3.0f, 1.0f);         /* all below the header's base stiffness */
    assert_float_equal(window_active(w)->max_stiffness, 3.0f, 0.0f);
    free(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unpainted_window_has_one_channel),
        cmocka_unit_test(test_painted_window_carries_node_stiffness),
        cmocka_unit_test(test_paint_outside_the_window_keeps_one_channel),
        cmocka_unit_test(test_springs_solve_sends_one_channel),
        cmocka_unit_test(test_board_tracks_the_largest_node_stiffness_chunk_by_chunk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
