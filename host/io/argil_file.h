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

/* What argil_file_read returns: ARGIL_FILE_OK, a failure outside the file (argument, system
 * call, memory), or the rule the file broke. */
typedef enum {
    ARGIL_FILE_OK = 0,
    ARGIL_FILE_ERR_ARG = -1, /* no path or no document */
    ARGIL_FILE_ERR_IO = -2, /* the file cannot be opened or read, or is not regular */
    ARGIL_FILE_ERR_NOMEM = -3, /* an allocation failed */
    ARGIL_FILE_ERR_FILE_SIZE = -4, /* a file larger than IO_FILE_MAX_BYTES */
    ARGIL_FILE_ERR_SHORT = -5, /* shorter than the 32-byte header and 4-byte checksum */
    ARGIL_FILE_ERR_MAGIC = -6, /* the first 8 bytes are not "ARGIL\r\n\x1a" */
    ARGIL_FILE_ERR_HEADER_CRC = -7, /* the header's CRC-32C does not match */
    ARGIL_FILE_ERR_VERSION = -8, /* format version 0 or newer than ARGIL_FILE_VERSION */
    ARGIL_FILE_ERR_SECTION_COUNT = -9, /* section count not in 1..ARGIL_FILE_SECTIONS_MAX */
    ARGIL_FILE_ERR_FILE_LENGTH = -10, /* the declared file length differs from the real size */
    ARGIL_FILE_ERR_FILE_CRC = -11, /* the whole file's CRC-32C does not match */
    ARGIL_FILE_ERR_SECTION_HEAD = -12, /* a section head runs past the end of the file */
    ARGIL_FILE_ERR_SECTION_LENGTH = -13, /* a section length runs past the end of the file */
    ARGIL_FILE_ERR_SECTION_CRC = -14, /* a section's CRC-32C does not match */
    ARGIL_FILE_ERR_TRAILING = -15, /* bytes between the last section and the file checksum */
    ARGIL_FILE_ERR_GRID_MISSING = -16, /* no GRID section */
    ARGIL_FILE_ERR_GRID_REPEATED = -17, /* a second GRID section */
    ARGIL_FILE_ERR_GRID_HEAD = -18, /* GRID shorter than its 36-byte head */
    ARGIL_FILE_ERR_GRID_DIM = -19, /* a GRID dimension below 1 */
    ARGIL_FILE_ERR_GRID_SAMPLES_MAX = -20, /* GRID holds more than GRID_SAMPLES_MAX samples */
    ARGIL_FILE_ERR_GRID_LENGTH = -21, /* GRID length does not match its dimensions */
    ARGIL_FILE_ERR_GRID_GEOMETRY = -22, /* GRID spacing, origin, iso or band not finite (> 0) */
    ARGIL_FILE_ERR_GRID_DENSITY = -23, /* a GRID density not a finite number in [0, 1] */
    ARGIL_FILE_ERR_MATL_SIZE = -24, /* MATL repeated or not 20 bytes */
    ARGIL_FILE_ERR_MATL_VALUE = -25, /* MATL values out of spring_material_valid's range */
    ARGIL_FILE_ERR_TOOL_SIZE = -26, /* TOOL repeated or not 16 bytes */
    ARGIL_FILE_ERR_TOOL_VALUE = -27, /* TOOL radius or strength out of range */
    ARGIL_FILE_ERR_STAT_SIZE = -28, /* STAT repeated or not 20 bytes */
    ARGIL_FILE_ERR_STAT_VALUE = -29, /* STAT transform not finite or scale not > 0 */
    ARGIL_FILE_ERR_PNTS_SIZE = -30, /* PNTS repeated or not 4 bytes */
    ARGIL_FILE_ERR_PNTS_RATE = -31, /* PNTS rate not in 0..ARGIL_FILE_PAINT_RATE_MAX */
    ARGIL_FILE_ERR_COLR_REPEATED = -32, /* a second COLR section */
    ARGIL_FILE_ERR_COLR_LENGTH = -33, /* COLR is not 3 bytes per GRID sample */
    ARGIL_FILE_ERR_MTLS_REPEATED = -34, /* a second MTLS section */
    ARGIL_FILE_ERR_MTLS_VERSION = -35, /* MTLS in a version-1 file */
    ARGIL_FILE_ERR_MTLS_COUNT = -36, /* MTLS channel count absent or not in 1..GRID_MAT_N */
    ARGIL_FILE_ERR_MTLS_CHANNEL = -37, /* an MTLS channel head past the section, its id not
                                        * increasing in 0..3, or no runs */
    ARGIL_FILE_ERR_MTLS_RUN = -38, /* an MTLS run empty, out of order, beyond the grid or
                                    * past the section */
    ARGIL_FILE_ERR_MTLS_VALUE = -39, /* an MTLS value out of grid_mat_valid's range */
    ARGIL_FILE_ERR_MTLS_TRAILING = -40, /* bytes after the last MTLS channel */
    ARGIL_FILE_ERR_RBF3_HEAD = -41, /* RBF3 repeated or shorter than 28 bytes */
    ARGIL_FILE_ERR_RBF3_COUNT = -42, /* RBF3 centre count out of range or not its length's */
    ARGIL_FILE_ERR_RBF3_VALUE = -43, /* RBF3 holds NaN or Inf */
    ARGIL_FILE_ERR_OCTB_HEAD = -44, /* OCTB repeated or shorter than its 40-byte head */
    ARGIL_FILE_ERR_OCTB_NODES = -45, /* OCTB node count not in 1..OCTFIT_NODES_MAX or past
                                      * the section */
    ARGIL_FILE_ERR_OCTB_PER_AXIS = -46, /* OCTB coefficients per axis not OCTFIT_N */
    ARGIL_FILE_ERR_OCTB_KIND = -47, /* OCTB kind not 0 or 1 */
    ARGIL_FILE_ERR_OCTB_GEOMETRY = -48, /* OCTB origin, size, errors or overlap out of range */
    ARGIL_FILE_ERR_OCTB_LENGTH = -49, /* OCTB length does not match its nodes and leaves */
    ARGIL_FILE_ERR_OCTB_LINKS = -50, /* OCTB child links do not form an octree */
    ARGIL_FILE_ERR_OCTB_COEF = -51 /* an OCTB coefficient NaN or Inf */
} argil_file_err_t;

/* The argil_err_t a command reports for e: ARG, IO and NOMEM as themselves, every rule of the
 * file (and a file too large) ARGIL_ERR_PARSE. */
argil_err_t argil_file_err_argil(argil_file_err_t e);

/* Reads path into d (initialised by the call; empty on error). Returns the rule the file broke
 * with err naming the path, the byte offset and the rule; ARG / IO / FILE_SIZE / NOMEM. */
argil_file_err_t argil_file_read(const char *path, argil_doc_t *d, char *err, size_t err_len);

#endif
