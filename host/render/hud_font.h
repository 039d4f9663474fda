/* A 5 × 7 bitmap font (ASCII letters, digits and common punctuation; lower case is drawn as
 * upper case) for the window's heads-up line, and its layout into pixel quads. */
#ifndef ARGIL_HUD_FONT_H
#define ARGIL_HUD_FONT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define HUD_GLYPH_W 5
#define HUD_GLYPH_H 7
#define HUD_ADVANCE 6             /* glyph cells per character, one blank column between */

/* The 7 rows of c, top first, bit 4 the leftmost column; false (a filled box is drawn) for a
 * character the font lacks. */
bool hud_font_glyph(char c, uint8_t rows[HUD_GLYPH_H]);

/* Lays text out from (x, y), the top-left corner in pixels, scale pixels per font pixel;
 * writes each horizontal run of lit pixels in a glyph row as one quad (x0, y0, x1, y1) into
 * quads, at most cap of them, and returns how many the whole text needs ('\n' starts a new
 * line). One quad per run, not per pixel: llvmpipe's cost is per triangle, and a HUD of four
 * lines drawn pixel by pixel took 5.3 of a frame's 14.5 ms. */
size_t hud_font_layout(const char *text, float x, float y, float scale, float *quads,
                       size_t cap);

#endif
