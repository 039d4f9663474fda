/* The .argil session file: model (density grid + optional painted colours), material, tool
 * settings, undo-independent state and an optional compact RBF or octree B-spline form. Versioned header, a CRC-32C
 * per section and over the whole file, written atomically so a crash mid-save keeps the previous
 * file. Layout byte by byte: docs/files.md. */
#ifndef ARGIL_ARGIL_FILE_H
#define ARGIL_ARGIL_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/fit/octree_fit.h"
#include "host/fit/rbf.h"
#include "host/model/grid.h"
#include "shared/argil_err.h"

/* The newest format this argil reads and writes. A file is written as version 1 unless it holds
 * painted material (section MTLS, version 2), so an older argil still reads an unpainted model
 * and refuses, rather than silently drops, a painted one. */
#define ARGIL_FILE_VERSION 2u
#define ARGIL_FILE_VERSION_MTLS 2u  /* first version with the painted-material section MTLS */
#define ARGIL_FILE_RUN_GAP 2u       /* unpainted samples bridged inside one MTLS run */
#define ARGIL_FILE_HEADER_BYTES 32u
#define ARGIL_FILE_SECTIONS_MAX 64u

#define ARGIL_FILE_PAINT_RATE_MAX 100.0f /* soft paint's blend rate, per second held */

typedef struct {
    uint32_t tool_kind;     /* the active tool (an app-level enum; 0 = none) */
    float radius_m;         /* tool radius */
    float strength;         /* 0..1 */
    uint8_t paint_rgb[3];   /* colour the paint tool lays down */
    bool paint_chosen;      /* the session chose its paint settings: paint_rgb is that colour and
                             * soft_paint_per_s that rate (section PNTS); false: the defaults */
    float soft_paint_per_s; /* soft paint's blend rate, 0..ARGIL_FILE_PAINT_RATE_MAX */
} argil_tool_settings_t;

typedef struct {
    vec3_t device_offset_m; /* device-to-model transform: model = scale * device + offset */
    float device_scale;
    uint32_t edits;         /* edits applied since the model was created */
} argil_state_t;

typedef struct {
    grid_t grid;            /* densities (rest = density on load), material, iso, band, and
                             * the painted material channels (section MTLS) */
    uint8_t *rgb;           /* 3 per sample, or NULL */
    argil_tool_settings_t tool;
    argil_state_t state;
    bool has_rbf;
    rbf_model_t rbf;
    bool has_octree;
    octfit_model_t octree; /* Hua & Qin §4 hierarchical fit (section OCTB) */
    uint32_t file_version; /* the format version argil_file_read found (0: not read) */
} argil_doc_t;

/* An empty document (no grid allocated), default tool and identity device transform. */
void argil_doc_init(argil_doc_t *d);

/* Frees everything the document owns and leaves it as after argil_doc_init. */
void argil_doc_free(argil_doc_t *d);

/* Writes d to path atomically (path.tmp + fsync + rename). ARGIL_ERR_ARG (no grid),
 * ARGIL_ERR_NONFINITE (NaN or Inf, a painted material value out of grid_mat_valid's range, or a
 * chosen soft-paint rate out of 0..ARGIL_FILE_PAINT_RATE_MAX),
 * IO / NOMEM with err naming the path and the failing call. Painted channels are stored as runs
 * of their painted samples only. */
argil_err_t argil_file_write(const char *path, const argil_doc_t *d, char *err, size_t err_len);

/* The number of runs channel m (n samples, unpainted value def) is stored as, and the samples
 * inside them; runs bridge up to ARGIL_FILE_RUN_GAP unpainted samples. 0 runs: nothing painted. */
uint32_t argil_file_mat_runs(const float *m, size_t n, float def, uint64_t *samples);

/* Reads path into d (initialised by the call; empty on error). ARGIL_ERR_PARSE with err naming
 * the path, the byte offset and the rule broken (magic, version, length, checksum, section,
 * value ranges); IO / NOMEM. */
argil_err_t argil_file_read(const char *path, argil_doc_t *d, char *err, size_t err_len);

#endif
