/* libFuzzer target for the autosave-journal reader: any bytes either replay or stop with one line
 * naming the journal and the byte; scanning and replaying agree; replay never writes outside the
 * grid nor leaves a density outside [0, 1] or a painted material value grid_mat_valid refuses
 * (replayed onto a whole grid too, so type-2 records reach the channels and type-3 records the
 * colour). Every record carries a
 * CRC-32C, so the input is read
 * as it is, then once more with the header and record checksums recomputed, which lets mutated
 * records reach the decoder. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "host/io/io_util.h"
#include "host/io/journal.h"
#include "shared/crc32c.h"
#include "shared/wire.h"
#include "tests/unit/grid_view.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_SAMPLES_MAX ((size_t)1 << 16) /* replay into a model only up to this size */

static void check_one(const uint8_t *data, size_t size)
{
    static const char name[] = "fuzz.journal";
    journal_info_t scan, play;
    char err[512] = "", err2[512] = "";
    const journal_err_t e = journal_replay(data, size, name, NULL, 0, &scan, err, sizeof(err));
    if (e != JOURNAL_OK) {
        if (journal_err_argil(e) != ARGIL_ERR_PARSE ||
            strncmp(err, "fuzz.journal: byte ", 19) != 0 || strchr(err, '\n') != NULL)
            abort();
    } else if (scan.good_bytes + scan.torn_bytes != size) {
        abort(); /* a clean walk accounts for every byte */
    }
    if (scan.good_bytes > size || scan.torn_bytes > size)
        abort();
    /* With a model of the header's size: same verdict, same records, densities stay valid. */
    if (scan.dims[0] < 1 || scan.dims[1] < 1 || scan.dims[2] < 1)
        return;
    const size_t n = (size_t)scan.dims[0] * (size_t)scan.dims[1] * (size_t)scan.dims[2];
    if (n > FUZZ_SAMPLES_MAX)
        return;
    float *density = malloc(n * sizeof(float));
    if (density == NULL)
        return;
    for (size_t i = 0; i < n; i++)
        density[i] = 0.5f;
    const journal_err_t e2 =
        journal_replay(data, size, name, density, n, &play, err2, sizeof(err2));
    if (e2 != e || play.records != scan.records || play.last_seq != scan.last_seq ||
        play.good_bytes != scan.good_bytes || strcmp(err, err2) != 0)
        abort();
    for (size_t i = 0; i < n; i++)
        if (!isfinite(density[i]) || density[i] < 0.0f || density[i] > 1.0f)
            abort();
    free(density);
    /* Onto a whole grid: the same verdict, densities and channels stay valid. */
    grid_t g;
    if (grid_init(&g, scan.dims, 0.001f, vec3(0, 0, 0)) != ARGIL_OK)
        return;
    for (size_t i = 0; i < n; i++)
        gv_set(&g, GRID_DENSITY, i, 0.5f);
    journal_info_t grid_play;
    char err3[512] = "";
    const journal_err_t e3 =
        journal_replay_grid(data, size, name, &g, &grid_play, err3, sizeof(err3));
    if (e3 != e || grid_play.records != scan.records || grid_play.mat_samples != scan.mat_samples ||
        grid_play.rgb_samples != scan.rgb_samples || strcmp(err, err3) != 0)
        abort();
    /* Type-3 records paint the grid's colour: present only when a colour run was replayed (a run
     * of the clay's own grey leaves the sparse grid without colour arrays). */
    if (grid_rgb_any(&g) && grid_play.rgb_samples == 0)
        abort();
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        for (size_t i = 0; grid_mat_painted(&g, (grid_mat_t)ch) && i < n; i++)
            if (!grid_mat_valid((grid_mat_t)ch, gv_mat(&g, ch, i)))
                abort();
    grid_free(&g);
}

/* Recomputes the header CRC and every whole record's CRC; true when anything changed. */
static bool fix_checksums(uint8_t *b, size_t n)
{
    if (n < JOURNAL_HEADER_BYTES)
        return false;
    bool changed = false;
    const uint32_t hc = crc32c(0, b, JOURNAL_HEADER_BYTES - 4);
    changed = le_get_u32(b + JOURNAL_HEADER_BYTES - 4) != hc;
    le_put_u32(b + JOURNAL_HEADER_BYTES - 4, hc);
    size_t at = JOURNAL_HEADER_BYTES;
    while (n - at >= 8) {
        const uint64_t payload = le_get_u32(b + at);
        if (payload + 8 > n - at)
            break;
        const uint32_t c = crc32c(0, b + at, 4 + (size_t)payload);
        changed = changed || le_get_u32(b + at + 4 + payload) != c;
        le_put_u32(b + at + 4 + payload, c);
        at += 8 + (size_t)payload;
    }
    return changed;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    check_one(data, size);
    if (size < JOURNAL_HEADER_BYTES)
        return 0;
    uint8_t *fixed = malloc(size);
    if (fixed == NULL)
        return 0;
    memcpy(fixed, data, size);
    if (fix_checksums(fixed, size))
        check_one(fixed, size);
    free(fixed);
    return 0;
}
