/* Writes 8-bit RGB images as PNG (stb_image_write from Debian's libstb-dev), whole or not at
 * all: the file appears by rename once complete. */
#ifndef ARGIL_PNG_WRITE_H
#define ARGIL_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

#include "shared/argil_err.h"

/* Writes width × height RGB pixels (top row first) to path. ARGIL_ERR_ARG for a bad size,
 * ARGIL_ERR_IO / NOMEM with "<path>: why" in err. */
argil_err_t png_write_rgb(const char *path, int width, int height, const uint8_t *rgb, char *err,
                          size_t err_len);

#endif
