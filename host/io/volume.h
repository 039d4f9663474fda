/* Scalar volumes for import and fitting: raw files (dimensions and sample type given by the
 * caller) and NRRD (attached or detached raw data). Values become floats, x fastest. */
#ifndef ARGIL_VOLUME_H
#define ARGIL_VOLUME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"
#include "shared/vec3.h"

#define VOLUME_SAMPLES_MAX ((uint64_t)1 << 30)

typedef enum { VOL_U8, VOL_I8, VOL_U16, VOL_I16, VOL_U32, VOL_I32, VOL_F32, VOL_F64 } vol_type_t;

typedef struct {
    int32_t dims[3];
    float spacing_m[3]; /* per axis; 1 when the file gives none */
    vec3_t origin_m;
    float *value;       /* dims[0]*dims[1]*dims[2], x fastest */
} volume_t;

/* Parses a type name: u8 i8 u16 i16 u32 i32 f32 f64 (and NRRD's spellings: uchar, unsigned
 * char, uint8, short, int16, ushort, float, double ...); false for anything else. */
bool vol_type_parse(const char *name, vol_type_t *out);

/* What a volume reader returns: VOLUME_OK, a failure outside the file (argument, system call,
 * memory), or the rule the file broke. */
typedef enum {
    VOLUME_OK = 0,
    VOLUME_ERR_ARG = -1,         /* an argument out of range: raw dims < 1 or above 2^30 samples */
    VOLUME_ERR_IO = -2,          /* a file cannot be opened or read, or is not a regular file */
    VOLUME_ERR_NOMEM = -3,       /* an allocation failed */
    VOLUME_ERR_FILE_SIZE = -4,   /* a file larger than IO_FILE_MAX_BYTES */
    VOLUME_ERR_DATA_LENGTH = -5, /* data bytes differ from sizes × the type's size */
    VOLUME_ERR_SAMPLE = -6,      /* a sample is NaN, Inf or beyond float range */
    VOLUME_ERR_MAGIC = -7,       /* line 1 is not NRRD0001..NRRD0005 */
    VOLUME_ERR_HEADER_END = -8,  /* the header does not end with a blank line */
    VOLUME_ERR_LINE_LONG = -9,   /* a header line longer than 255 bytes */
    VOLUME_ERR_LINE_NUL = -10,   /* a header line holds a NUL byte */
    VOLUME_ERR_FIELD = -11,      /* a header line is neither '<field>: <value>' nor 'key:=value' */
    VOLUME_ERR_TYPE = -12,       /* type names no sample type vol_type_parse knows */
    VOLUME_ERR_DIMENSION = -13,  /* dimension is not 3 */
    VOLUME_ERR_SIZES = -14,      /* sizes is not three whole numbers 1..2^30 */
    VOLUME_ERR_SAMPLES_MAX = -15, /* sizes give more than VOLUME_SAMPLES_MAX samples */
    VOLUME_ERR_ENCODING = -16,   /* encoding is not raw */
    VOLUME_ERR_ENDIAN = -17,     /* endian is neither little nor big */
    VOLUME_ERR_SPACINGS = -18,   /* spacings is not three positive numbers */
    VOLUME_ERR_DIRECTIONS = -19, /* space directions is not three vectors of non-zero length */
    VOLUME_ERR_ORIGIN = -20,     /* space origin is not one finite vector */
    VOLUME_ERR_DATA_FILE = -21,  /* data file is not one plain file name beside the header */
    VOLUME_ERR_MISSING = -22     /* type, dimension, sizes, encoding (or endian for a multi-byte
                                  * type) is absent */
} volume_err_t;

/* The argil_err_t a command reports for e: ARG, IO and NOMEM as themselves, every rule of the
 * file (and a file too large) ARGIL_ERR_PARSE. */
argil_err_t volume_err_argil(volume_err_t e);

/* Reads a raw volume of dims samples of type t (big_endian for multi-byte types); the file size
 * must be exactly dims product × type size. VOLUME_ERR_ARG (dims < 1 or above
 * VOLUME_SAMPLES_MAX), DATA_LENGTH, SAMPLE, IO, FILE_SIZE, NOMEM; err names the path and byte. */
volume_err_t volume_read_raw(const char *path, const int32_t dims[3], vol_type_t t, bool big_endian,
                             volume_t *out, char *err, size_t err_len);

/* Reads a 3-D NRRD (NRRD0001..5 magic; type, dimension: 3, sizes, encoding: raw, endian,
 * spacings / space directions, space origin; attached data or 'data file:' beside the header).
 * Returns the rule the file broke, with err naming the path, the header line or the byte. */
volume_err_t volume_read_nrrd(const char *path, volume_t *out, char *err, size_t err_len);

/* Frees the values; v becomes empty. */
void volume_free(volume_t *v);

#endif
