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

/* Reads a raw volume of dims samples of type t (big_endian for multi-byte types); the file size
 * must be exactly dims product × type size. ARGIL_ERR_ARG (dims < 1 or above
 * VOLUME_SAMPLES_MAX), PARSE (size mismatch, NaN/Inf), IO, NOMEM; err names the path and byte. */
argil_err_t volume_read_raw(const char *path, const int32_t dims[3], vol_type_t t, bool big_endian,
                            volume_t *out, char *err, size_t err_len);

/* Reads a 3-D NRRD (NRRD0001..5 magic; type, dimension: 3, sizes, encoding: raw, endian,
 * spacings / space directions, space origin; attached data or 'data file:' beside the header).
 * PARSE with err naming the path, the header line or the byte, and the rule. */
argil_err_t volume_read_nrrd(const char *path, volume_t *out, char *err, size_t err_len);

/* Frees the values; v becomes empty. */
void volume_free(volume_t *v);

#endif
