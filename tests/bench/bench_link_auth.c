/* The UDP link envelope's cost per frame (shared/link_envelope.c with the board's libsodium MAC,
 * firmware/hal/link_auth.c), for make bench: median ns
 * per seal and per open of a 33-byte HEARTBEAT, an 80-byte TELEMETRY and a 1024-byte WINDOW
 * frame (the largest), and what the link thread spends on it per 1 ms tick at 1 kHz. With
 * "once SIZE" it seals and opens one frame of SIZE bytes 1000 times (for callgrind). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "firmware/hal/link_auth.h"
#include "shared/proto.h"

#define BATCH 2000
#define BATCHES 31

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A frame of size bytes whose header's length field says so (the tag covers it as any bytes). */
static void make_frame(uint8_t *f, size_t size)
{
    for (size_t i = 0; i < size; i++)
        f[i] = (uint8_t)(i * 131u + 7u);
    memcpy(f, "ARGL", 4);
    f[4] = PROTO_VERSION;
    f[5] = MSG_WINDOW;
    const size_t payload = size - PROTO_HEADER_SIZE - PROTO_CRC_SIZE;
    f[6] = (uint8_t)payload;
    f[7] = (uint8_t)(payload >> 8);
}

/* Median ns per call of seal (open = 0) or open (open = 1) over BATCHES batches. */
static double median_ns(const link_key_t *k, size_t size, int open)
{
    static uint8_t f[PROTO_FRAME_MAX], d[LINK_AUTH_DGRAM_MAX];
    make_frame(f, size);
    const size_t n =
        link_auth_seal(link_auth_mac, k, LINK_AUTH_BOARD_TO_HOST, 42, f, size, d, sizeof(d));
    double per[BATCHES];
    volatile size_t sink = 0;
    for (int b = 0; b < BATCHES; b++) {
        const uint64_t t0 = now_ns();
        for (int i = 0; i < BATCH; i++) {
            if (open) {
                size_t fl;
                uint64_t nonce;
                sink += (size_t)link_auth_open(link_auth_mac, k, LINK_AUTH_BOARD_TO_HOST, d, n,
                                               &fl, &nonce);
            } else {
                sink += link_auth_seal(link_auth_mac, k, LINK_AUTH_BOARD_TO_HOST, (uint64_t)i, f,
                                       size, d, sizeof(d));
            }
        }
        per[b] = (double)(now_ns() - t0) / BATCH;
    }
    (void)sink;
    qsort(per, BATCHES, sizeof(per[0]), cmp_d);
    return per[BATCHES / 2];
}

int main(int argc, char **argv)
{
    if (!link_auth_init())
        return 1;
    link_key_t k;
    for (unsigned i = 0; i < LINK_KEY_BYTES; i++)
        k.k[i] = (uint8_t)i;
    if (argc == 3 && strcmp(argv[1], "once") == 0) {
        const size_t size = (size_t)atoi(argv[2]);
        static uint8_t f[PROTO_FRAME_MAX], d[LINK_AUTH_DGRAM_MAX];
        make_frame(f, size);
        for (int i = 0; i < 1000; i++) {
            const size_t n = link_auth_seal(link_auth_mac, &k, 2, 42, f, size, d, sizeof(d));
            size_t fl;
            uint64_t nonce;
            if (link_auth_open(link_auth_mac, &k, 2, d, n, &fl, &nonce) != LINK_AUTH_OK)
                return 1;
        }
        return 0;
    }
    static const struct { const char *name; size_t size; } frames[] = {
        {"HEARTBEAT", 33}, {"TELEMETRY", 80}, {"WINDOW", 1024}};
    double seal[3], open[3];
    for (int i = 0; i < 3; i++) {
        seal[i] = median_ns(&k, frames[i].size, 0);
        open[i] = median_ns(&k, frames[i].size, 1);
        printf("  %-9s %4zu-byte frame: seal %6.0f ns, open %6.0f ns (median of %d batches of %d; "
               "keyed BLAKE2b-128 over 17 + %zu bytes, + a copy on seal, a compare on open)\n",
               frames[i].name, frames[i].size, seal[i], open[i], BATCHES, BATCH, frames[i].size);
    }
    /* At 1 kHz the board seals one TELEMETRY per tick and a HEARTBEAT every 10 ms, and opens the
     * host's HEARTBEAT every 5 ms; a window upload adds about 19 WINDOW chunks now and then. */
    const double tick_ns = seal[1] + 0.1 * seal[0] + 0.2 * open[0];
    printf("  per 1 ms tick at 1 kHz, steady session: %.0f ns = %.3f %% of the tick, on the link "
           "thread (1 TELEMETRY sealed + 0.1 HEARTBEAT sealed + 0.2 HEARTBEAT opened; never in "
           "the fast loop)\n", tick_ns, tick_ns / 1e4);
    printf("  a 19-chunk window upload opened: %.0f us once, on the link thread\n",
           19.0 * open[2] / 1e3);
    return 0;
}
