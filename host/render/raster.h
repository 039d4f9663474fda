/* A small software rasteriser for charts: an RGB canvas, lines, rectangles and text in a
 * built-in 5×7 bitmap font (digits, A–Z with lower case drawn as capitals, common signs). */
#ifndef ARGIL_RASTER_H
#define ARGIL_RASTER_H

#include <stdint.h>

#include "shared/argil_err.h"

typedef struct {
    int width, height;
    uint8_t *rgb;   /* width × height × 3, top row first */
} canvas_t;

typedef struct {
    uint8_t r, g, b;
} rgb8_t;

/* Allocates a width × height canvas (1..16384 each) filled with bg; ARGIL_ERR_ARG / NOMEM. */
argil_err_t canvas_init(canvas_t *c, int width, int height, rgb8_t bg);

void canvas_free(canvas_t *c);

/* Sets one pixel; outside the canvas nothing happens. */
void canvas_pixel(canvas_t *c, int x, int y, rgb8_t col);

/* Fills the rectangle [x0, x1] × [y0, y1] (corners in any order), clipped. */
void canvas_fill_rect(canvas_t *c, int x0, int y0, int x1, int y1, rgb8_t col);

/* A line from (x0, y0) to (x1, y1), both ends included, `thick` pixels wide (1..5), clipped. */
void canvas_line(canvas_t *c, int x0, int y0, int x1, int y1, int thick, rgb8_t col);

/* Draws text with its top-left at (x, y), each font pixel scale × scale (1..8); returns the
 * width drawn. Characters the font lacks are drawn as a box. */
int canvas_text(canvas_t *c, int x, int y, const char *text, int scale, rgb8_t col);

/* The width text would take at scale. */
int canvas_text_width(const char *text, int scale);

/* Draws text rotated 90° counter-clockwise (reading bottom to top) with the bottom-left of
 * its first character at (x, y). */
void canvas_text_up(canvas_t *c, int x, int y, const char *text, int scale, rgb8_t col);

enum { FONT_W = 5, FONT_H = 7, FONT_ADVANCE = 6 };

#endif
