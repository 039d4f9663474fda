/* The autosave journal of a sculpting session: every applied edit step is appended as the
 * density samples it changed (sparse runs of new values, CRC-32C per record), and the painted
 * material samples it changed (grid_t.mat, record type 2) and the painted colour samples it
 * changed (grid_t.rgb, record type 3), on top of a base
 * .argil snapshot; records are written and fdatasync'ed at a bounded interval, and the journal
 * is rotated onto a new snapshot at checkpoints. After a crash the model is rebuilt bit for bit
 * as of the last whole record. Layout byte by byte: docs/files.md. */
#ifndef ARGIL_JOURNAL_H
#define ARGIL_JOURNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "host/io/argil_file.h"
#include "host/model/block_table.h"
#include "host/model/grid.h"
#include "shared/argil_err.h"

#define JOURNAL_VERSION 2u                 /* 2: record type 2 carries painted material; the
                                            * base CRC covers the painted channels */
#define JOURNAL_HEADER_BYTES 160u
#define JOURNAL_RECORD_HEAD_BYTES 52u      /* payload bytes before the runs */
#define JOURNAL_BASE_NAME_MAX 60u          /* bytes for the base file's name in the header */
#define JOURNAL_FILE "journal.log"         /* inside the session's output directory */
#define JOURNAL_BASE_PREFIX "journal-base-" /* + checkpoint number + ".argil" */
#define JOURNAL_GROW_SAMPLES 16   /* room added on a side the clay grew past (journal_rebase) */
#define JOURNAL_RUN_GAP 2u                 /* unchanged samples bridged inside one run */
#define JOURNAL_RGB_CRC_ID 4u              /* the colour's id in the base identity CRC */

typedef struct {
    float autosave_s;        /* write + fdatasync once records are this old (sim or real s) */
    float checkpoint_s;      /* new base snapshot + new journal every this many sim seconds */
    uint64_t checkpoint_bytes; /* ... or once the journal holds this many bytes */
} journal_cfg_t;

typedef struct {
    uint32_t records;         /* records appended */
    uint64_t bytes;           /* record bytes appended */
    uint32_t syncs;           /* write + fdatasync rounds */
    uint32_t checkpoints;     /* rotations onto a new base */
    uint32_t rebases;         /* of them, because the clay grew past the journal's box */
    uint64_t samples;         /* sample values journaled */
    uint64_t mat_samples;     /* painted material values journaled */
    uint64_t rgb_samples;     /* painted colour samples (3 bytes each) journaled */
} journal_stats_t;

/* One grid block of the writer's copy of the model as of the last record
 * (host/io/journal_shadow.c): only blocks the grid holds cost memory, and a block at one density
 * holds no array. */
typedef struct {
    int32_t key[3];           /* block index, as the grid's; first: the table's key */
    float uniform;            /* the density of every sample when dens is NULL */
    float *dens;              /* GRID_BN densities (x fastest), or NULL */
    float *mat[GRID_MAT_N];   /* GRID_BN values of a painted channel; NULL: its default */
    uint8_t *rgb;             /* 3 GRID_BN bytes; NULL: GRID_RGB_DEFAULT */
} journal_block_t;

/* The writer's copy of the model: an open-addressing hash of blocks by block index; a block
 * not in it reads density 0, the painted defaults and GRID_RGB_DEFAULT. */
typedef struct {
    block_table_t blocks;     /* journal_block_t by key; entries NULL: none */
    size_t arrays_bytes;      /* bytes of the blocks' arrays */
} journal_shadow_t;

/* The open journal of a running session (writer side). */
typedef struct {
    journal_cfg_t cfg;
    char *dir;
    int fd;
    int32_t dims[3];
    int32_t lo[3];            /* grid sample index of the journal's sample 0 (its box's corner) */
    float spacing_m, iso, band_m;
    vec3_t origin_m;          /* model-space position of sample lo */
    size_t n;                 /* samples */
    bool ready;               /* open, and the shadow whole (false after a failed record) */
    journal_shadow_t shadow;  /* densities, painted channels and colour as of the last record */
    bool mat_seen[GRID_MAT_N]; /* channel painted in the grid when last compared (the base
                               * snapshot then carries it) */
    bool rgb_seen;            /* likewise the colour */
    grid_block_view_t *views; /* scratch: the blocks a record compares sample by sample */
    size_t views_cap;
    uint32_t mat_writes;      /* the grid's mat_writes when its channels were last compared */
    uint32_t rgb_writes;      /* the grid's rgb_writes when its colour was last compared */
    spring_material_t material; /* as of the last record */
    uint8_t *buf;             /* records not yet written to the file */
    size_t buf_len, buf_cap;
    uint32_t seq;             /* of the last record appended (0: none yet) */
    uint32_t edits;           /* the session's edit steps as of the last record */
    uint32_t checkpoint;      /* number of the current base snapshot */
    uint64_t file_bytes;      /* in the current journal file, written or buffered */
    double oldest_pending_sim_s, oldest_pending_real_s; /* of the oldest unwritten record */
    double checkpoint_sim_s;  /* when the current base was taken */
    journal_stats_t stats;
} journal_t;

/* What a journal holds, as far as its records are whole and valid. */
typedef struct {
    uint32_t version;         /* of the journal file */
    uint32_t checkpoint;
    uint32_t first_seq;       /* seq the first record must carry */
    uint32_t records;         /* good records */
    uint32_t last_seq;        /* of the last good record (first_seq - 1 when none) */
    double last_sim_s;        /* session time of the last good record */
    uint64_t last_wall_ms;    /* wall-clock time (ms since 1970) it was made */
    uint32_t edits;           /* edit steps since the session began, as of the last record */
    spring_material_t material; /* as of the last record (the base's when there is none) */
    uint64_t samples;         /* sample values replayed */
    uint64_t mat_samples;     /* painted material values replayed */
    uint64_t rgb_samples;     /* painted colour samples replayed */
    size_t good_bytes;        /* header + good records */
    size_t torn_bytes;        /* an incomplete last record, ignored */
    char base_name[JOURNAL_BASE_NAME_MAX + 1];
    uint64_t base_len;
    uint32_t base_crc;
    int32_t dims[3];
    float spacing_m, iso, band_m;
    vec3_t origin_m;
} journal_info_t;

void journal_cfg_default(journal_cfg_t *cfg);

/* Starts a journal in dir for the grid as it is now: writes the base snapshot
 * journal-base-0.argil, then journal.log (both fsync'ed). ARGIL_ERR_STATE when dir already
 * holds a journal (never overwrites work that could be recovered: see journal_discard). */
argil_err_t journal_open(journal_t *j, const char *dir, const grid_t *g, const journal_cfg_t *cfg,
                         double sim_s, double real_s, char *err, size_t err_len);

/* A sample index box [lo, hi) (empty when lo >= hi on any axis). */
typedef struct {
    int32_t lo[3], hi[3];
} journal_box_t;

/* Appends one record when the grid's densities, material, painted channels or painted colour
 * differ from the last record (buffered; *appended says whether one was made). Only densities
 * inside box are compared when box is not NULL: the caller promises nothing changed outside it;
 * the painted channels are compared whole when box is NULL or the grid's mat_writes moved, the
 * colour when box is NULL or rgb_writes moved. edits counts the session's edit steps. When the
 * grid's bounds have grown past the journal's box (the clay grew) the journal rotates onto a new
 * base snapshot of the whole grid over its new bounds (a checkpoint) instead, and *appended is
 * true. */
argil_err_t journal_record(journal_t *j, const grid_t *g, const journal_box_t *box,
                           uint32_t edits, double sim_s, double real_s, uint64_t wall_ms,
                           bool *appended, char *err, size_t err_len);

/* True when journal_tick would write the buffered records now. */
bool journal_sync_due(const journal_t *j, double sim_s, double real_s);

/* Writes and fdatasyncs the buffered records once the oldest is autosave_s old (simulated or
 * real time), and rotates onto a new base snapshot when a checkpoint is due. */
argil_err_t journal_tick(journal_t *j, double sim_s, double real_s, char *err, size_t err_len);

/* Writes and fdatasyncs every buffered record now. */
argil_err_t journal_sync(journal_t *j, char *err, size_t err_len);

/* Writes a new base snapshot (the model as of the last record) and starts a new journal on it;
 * the old journal stays valid until the new one has replaced it by rename. */
argil_err_t journal_checkpoint(journal_t *j, double sim_s, char *err, size_t err_len);

/* Writes g's densities, painted channels and colour (g: the journal's grid; NULL: the journal's copy as
 * of the last record) with the material of the last record and edits to path as .argil, in
 * exactly the form argil recover writes, so a model and its recovery compare byte for byte. */
argil_err_t journal_write_model(const journal_t *j, const grid_t *g, uint32_t edits,
                                const char *path, char *err, size_t err_len);

/* Bytes of memory the journal holds: its copy of the model (block arrays and hash), record
 * buffer and scratch. Grows with the clay's surface, not with the journal's box. */
size_t journal_bytes(const journal_t *j);

/* Releases the journal and keeps its files (the session did not end cleanly). */
void journal_close(journal_t *j);

/* Clean end: releases the journal and removes its files. */
argil_err_t journal_finish(journal_t *j, char *err, size_t err_len);

/* True when dir holds a journal file (an unfinished session). */
bool journal_exists(const char *dir);

/* Removes a journal and every base snapshot in dir. */
argil_err_t journal_discard(const char *dir, char *err, size_t err_len);

/* What the journal readers return: JOURNAL_OK, a failure outside the file (argument, system call,
 * memory), or the rule the journal (or its base snapshot) broke. */
typedef enum {
    JOURNAL_OK = 0,
    JOURNAL_ERR_ARG = -1,             /* the caller's grid differs from the journal's */
    JOURNAL_ERR_IO = -2,              /* a file cannot be opened or read, or is not regular */
    JOURNAL_ERR_NOMEM = -3,           /* an allocation failed */
    JOURNAL_ERR_FILE_SIZE = -4,       /* a file larger than IO_FILE_MAX_BYTES */
    JOURNAL_ERR_SHORT = -5,           /* shorter than the JOURNAL_HEADER_BYTES header */
    JOURNAL_ERR_MAGIC = -6,           /* the first 8 bytes are not JOURNAL_MAGIC */
    JOURNAL_ERR_HEADER_CRC = -7,      /* the header's CRC-32C does not match */
    JOURNAL_ERR_VERSION = -8,         /* version 0 or newer than JOURNAL_VERSION */
    JOURNAL_ERR_HEADER_SIZE = -9,     /* the header size field is not JOURNAL_HEADER_BYTES */
    JOURNAL_ERR_DIMS = -10,           /* a grid dimension < 1, or over GRID_SAMPLES_MAX samples */
    JOURNAL_ERR_GEOMETRY = -11,       /* grid spacing (> 0), origin, iso or band not finite */
    JOURNAL_ERR_MATERIAL = -12,       /* the header's material out of range */
    JOURNAL_ERR_FIRST_SEQ = -13,      /* first record number 0 */
    JOURNAL_ERR_BASE_PADDING = -14,   /* the base name is not NUL-padded */
    JOURNAL_ERR_BASE_NAME = -15,      /* the base name is empty or not a plain file name */
    JOURNAL_ERR_BASE_ASCII = -16,     /* the base name is not printable ASCII */
    JOURNAL_ERR_RECORD_CRC = -17,     /* a record's CRC-32C does not match (not the last) */
    JOURNAL_ERR_RECORD_HEAD = -18,    /* a record shorter than JOURNAL_RECORD_HEAD_BYTES */
    JOURNAL_ERR_RECORD_TYPE = -19,    /* a record type not 1, or 2 or 3 in a version-2 journal */
    JOURNAL_ERR_RECORD_SEQ = -20,     /* a record number not one past the last */
    JOURNAL_ERR_RECORD_MATERIAL = -21, /* a record's material out of range */
    JOURNAL_ERR_RUN_HEAD = -22,       /* a density run head runs past the record */
    JOURNAL_ERR_RUN_RANGE = -23,      /* a density run empty, beyond the grid or past the record */
    JOURNAL_ERR_DENSITY = -24,        /* a density not a finite number in [0, 1] */
    JOURNAL_ERR_MAT_COUNT_HEAD = -25, /* the material block count runs past the record */
    JOURNAL_ERR_MAT_COUNT = -26,      /* the material block count out of range for the type */
    JOURNAL_ERR_MAT_BLOCK_HEAD = -27, /* a material block head runs past the record */
    JOURNAL_ERR_MAT_CHANNEL = -28,    /* a material channel not 0..3 increasing, or with no runs */
    JOURNAL_ERR_MAT_RUN_HEAD = -29,   /* a material run head runs past the record */
    JOURNAL_ERR_MAT_RUN_RANGE = -30,  /* a material run empty, beyond the grid or past the record */
    JOURNAL_ERR_MAT_VALUE = -31,      /* a painted material value out of grid_mat_valid's range */
    JOURNAL_ERR_RGB_COUNT_HEAD = -32, /* the colour run count runs past the record */
    JOURNAL_ERR_RGB_COUNT = -33,      /* the colour run count 0 */
    JOURNAL_ERR_RGB_RUN_HEAD = -34,   /* a colour run head runs past the record */
    JOURNAL_ERR_RGB_RUN_RANGE = -35,  /* a colour run empty, out of order, beyond the grid or past
                                       * the record */
    JOURNAL_ERR_TRAILING = -36,       /* bytes after a record's last run */
    JOURNAL_ERR_BASE_FILE = -37,      /* the base snapshot breaks a rule of .argil files */
    JOURNAL_ERR_BASE_MISMATCH = -38,  /* the base's length, CRC, material or edits differ from
                                       * the header's */
    JOURNAL_ERR_BASE_GRID = -39       /* the base's grid differs from the header's */
} journal_err_t;

/* The argil_err_t a command reports for e: ARG, IO and NOMEM as themselves, every rule of the
 * journal or its base (and a file too large) ARGIL_ERR_PARSE. */
argil_err_t journal_err_argil(journal_err_t e);

/* Decodes and checks a journal's header: the rule it broke, with err naming name and the byte. */
journal_err_t journal_header_decode(const uint8_t *data, size_t len, const char *name,
                                  journal_info_t *info, char *err, size_t err_len);

/* Walks the records after the header; with density (n samples, matching the header's dims:
 * JOURNAL_ERR_ARG otherwise) applies each good record's densities to it (painted material is
 * checked, not applied). An incomplete last record (a write cut short by a crash) is ignored and
 * counted in torn_bytes. A bad record before the end stops the walk: density holds the model as
 * of the record before it, info describes the good part, and the result is the rule the record
 * broke with err naming the byte, the record and the rule. */
journal_err_t journal_replay(const uint8_t *data, size_t len, const char *name, float *density,
                           size_t n, journal_info_t *info, char *err, size_t err_len);

/* journal_replay onto a whole grid (dims matching the header's): densities, painted channels and
 * colour (allocated as records need them); JOURNAL_ERR_NOMEM when a channel cannot be. */
journal_err_t journal_replay_grid(const uint8_t *data, size_t len, const char *name, grid_t *g,
                                journal_info_t *info, char *err, size_t err_len);

/* Reads dir's journal without its base: counts the good records (for the offer to recover). */
journal_err_t journal_probe(const char *dir, journal_info_t *info, char *err, size_t err_len);

/* Rebuilds the model in doc (initialised here) from dir's base snapshot and journal: refuses a
 * base that is not a valid .argil file (BASE_FILE), whose length or CRC differ from the header's
 * (BASE_MISMATCH), or whose grid differs (BASE_GRID). Same results as journal_replay (after a bad
 * record, its rule with doc as of the record before it). */
journal_err_t journal_recover(const char *dir, argil_doc_t *doc, journal_info_t *info, char *err,
                            size_t err_len);

/* Fills doc (initialised here, owning copies of density and of the painted channels in mat,
 * which may be NULL or hold NULLs) with the model as a journal holds it: the grid geometry,
 * material and edits from info. ARGIL_ERR_NOMEM / ARG. */
argil_err_t journal_model_doc(const journal_info_t *info, const float *density,
                              float *const mat[GRID_MAT_N], argil_doc_t *doc);

#endif
