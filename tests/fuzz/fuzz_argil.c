/* libFuzzer target for the argil reader: the input bytes become a file it parses; an error must
 * name the file, and an accepted result must be consistent. Every CRC-32C (header, each section,
 * whole file) guards the decoders, so almost any mutation stops at a checksum: the input is
 * parsed as it is (the checks themselves), then once more with the declared length and every
 * checksum recomputed, which lets mutated sections (GRID, RBF3, OCTB, MTLS, ...) reach their
 * decoders. An accepted painted channel holds only values grid_mat_valid allows, and writing the
 * document back and reading it again gives the same channels bit for bit. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "host/io/argil_file.h"
#include "host/io/io_util.h"
#include "shared/crc32c.h"
#include "shared/wire.h"
#include "tests/fuzz/fuzz_file.h"
#include "tests/unit/grid_view.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes an accepted painted document back and reads it again: the channels survive. */
static void check_rewrite(const argil_doc_t *d, const char *path)
{
    char again[FUZZ_PATH_MAX + 8], err[512];
    snprintf(again, sizeof(again), "%s.again", path);
    argil_doc_t r;
    if (argil_file_write(again, d, err, sizeof(err)) != ARGIL_OK)
        return; /* e.g. a NaN in an RBF the reader does not check as strictly */
    if (argil_file_read(again, &r, err, sizeof(err)) != ARGIL_FILE_OK)
        abort();
    for (int ch = 0; ch < GRID_MAT_N; ch++)
        if (!grid_mat_equal(&r.grid, &d->grid, (grid_mat_t)ch))
            abort();
    argil_doc_free(&r);
    unlink(again);
}

static void parse_one(const uint8_t *data, size_t size)
{
    char path[FUZZ_PATH_MAX];
    if (!fuzz_write_temp(data, size, "argil", path))
        return;
    char err[512];
    err[0] = '\0';
    argil_doc_t d;
    const argil_file_err_t e = argil_file_read(path, &d, err, sizeof(err));
    if (e == ARGIL_FILE_OK) {
        if (grid_count(&d.grid) == 0 || (d.has_octree && (d.octree.n_nodes == 0 ||
                                                        d.octree.n_leaves == 0)))
            abort();
        if (d.has_octree) /* a decoded octree must evaluate without faults */
            (void)octfit_eval(&d.octree, vec3(d.octree.origin_m[0], d.octree.origin_m[1],
                                              d.octree.origin_m[2]));
        const size_t n = (size_t)d.grid.dims[0] * (size_t)d.grid.dims[1] * (size_t)d.grid.dims[2];
        bool painted = false;
        for (int ch = 0; ch < GRID_MAT_N; ch++) {
            if (!grid_mat_painted(&d.grid, (grid_mat_t)ch))
                continue;
            painted = true;
            if (d.file_version < ARGIL_FILE_VERSION_MTLS)
                abort();
            for (size_t i = 0; i < n; i++)
                if (!grid_mat_valid((grid_mat_t)ch, gv_mat(&d.grid, ch, i)))
                    abort();
        }
        if (painted)
            check_rewrite(&d, path);
        argil_doc_free(&d);
    } else if (!fuzz_error_names_file(err, path) || grid_count(&d.grid) > 0 || d.has_octree) {
        abort();
    }
    unlink(path);
}

/* Rewrites the declared length and the header, section and file checksums of b (as far as the
 * section heads can be followed); true when anything changed. */
static bool fix_checksums(uint8_t *b, size_t n)
{
    if (n < ARGIL_FILE_HEADER_BYTES + 4)
        return false;
    uint8_t before[ARGIL_FILE_HEADER_BYTES];
    memcpy(before, b, sizeof(before));
    const uint32_t old_file_crc = le_get_u32(b + n - 4);
    le_put_u64(b + 16, (uint64_t)n);
    le_put_u32(b + 28, crc32c(0, b, 28));
    bool changed = memcmp(before, b, sizeof(before)) != 0;
    const uint32_t n_sec = le_get_u32(b + 12);
    const size_t end = n - 4;
    size_t pos = ARGIL_FILE_HEADER_BYTES;
    for (uint32_t s = 0; s < n_sec && s < ARGIL_FILE_SECTIONS_MAX && end - pos >= 16; s++) {
        const uint64_t sl = le_get_u64(b + pos + 4);
        if (sl > (uint64_t)(end - pos - 16))
            break;
        const size_t crc_off = pos + 12 + (size_t)sl;
        const uint32_t crc = crc32c(0, b + pos, 12 + (size_t)sl);
        changed = changed || le_get_u32(b + crc_off) != crc;
        le_put_u32(b + crc_off, crc);
        pos = crc_off + 4;
    }
    const uint32_t file_crc = crc32c(0, b, n - 4);
    le_put_u32(b + n - 4, file_crc);
    return changed || file_crc != old_file_crc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    parse_one(data, size);
    if (size < ARGIL_FILE_HEADER_BYTES + 4)
        return 0;
    uint8_t *fixed = malloc(size);
    if (fixed == NULL)
        return 0;
    memcpy(fixed, data, size);
    if (fix_checksums(fixed, size))
        parse_one(fixed, size);
    free(fixed);
    return 0;
}
