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

#define ARGIL_FILE_VERSION 1u
#define ARGIL_FILE_HEADER_BYTES 32u
#define ARGIL_FILE_SECTIONS_MAX 64u

typedef struct {
    uint32_t tool_kind;     /* the active tool (an app-level enum; 0 = none) */
    float radius_m;         /* tool radius */
    float strength;         /* 0..1 */
    uint8_t paint_rgb[3];   /* colour the paint tool lays down */
} argil_tool_settings_t;

typedef struct {
    vec3_t device_offset_m; /* device-to-model transform: model = scale * device + offset */
    float device_scale;
    uint32_t edits;         /* edits applied since the model was created */
} argil_state_t;

typedef struct {
    grid_t grid;            /* densities (rest = density on load), material, iso, band */
    uint8_t *rgb;           /* 3 per sample, or NULL */
    argil_tool_settings_t tool;
    argil_state_t state;
    bool has_rbf;
    rbf_model_t rbf;
    bool has_octree;
    octfit_model_t octree; /* Hua & Qin §4 hierarchical fit (section OCTB) */
} argil_doc_t;

/* An empty document (no grid allocated), default tool and identity device transform. */
void argil_doc_init(argil_doc_t *d);

/* Frees everything the document owns and leaves it as after argil_doc_init. */
void argil_doc_free(argil_doc_t *d);

/* Writes d to path atomically (path.tmp + fsync + rename). ARGIL_ERR_ARG (no grid, non-finite
 * values), IO / NOMEM with err naming the path and the failing call. */
argil_err_t argil_file_write(const char *path, const argil_doc_t *d, char *err, size_t err_len);

/* Reads path into d (initialised by the call; empty on error). ARGIL_ERR_PARSE with err naming
 * the path, the byte offset and the rule broken (magic, version, length, checksum, section,
 * value ranges); IO / NOMEM. */
argil_err_t argil_file_read(const char *path, argil_doc_t *d, char *err, size_t err_len);

#endif
