/* Canvas drawing, and text in the 5×7 font of hud_font.c (see raster.h). */
#include "host/render/raster.h"

#include "host/render/hud_font.h"

#include <stdlib.h>
#include <string.h>

_Static_assert(FONT_W == HUD_GLYPH_W && FONT_H == HUD_GLYPH_H, "one 5x7 font for plots and the HUD");

argil_err_t canvas_init(canvas_t *c, int width, int height, rgb8_t bg)
{
    memset(c, 0, sizeof(*c));
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return ARGIL_ERR_ARG;
    c->rgb = malloc((size_t)width * (size_t)height * 3);
    if (c->rgb == NULL)
        return ARGIL_ERR_NOMEM;
    c->width = width;
    c->height = height;
    canvas_fill_rect(c, 0, 0, width - 1, height - 1, bg);
    return ARGIL_OK;
}

void canvas_free(canvas_t *c)
{
    free(c->rgb);
    memset(c, 0, sizeof(*c));
}

void canvas_pixel(canvas_t *c, int x, int y, rgb8_t col)
{
    if (x < 0 || y < 0 || x >= c->width || y >= c->height)
        return;
    uint8_t *p = c->rgb + ((size_t)y * (size_t)c->width + (size_t)x) * 3;
    p[0] = col.r;
    p[1] = col.g;
    p[2] = col.b;
}

void canvas_fill_rect(canvas_t *c, int x0, int y0, int x1, int y1, rgb8_t col)
{
    if (x0 > x1) { const int t = x0; x0 = x1; x1 = t; }
    if (y0 > y1) { const int t = y0; y0 = y1; y1 = t; }
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    x1 = x1 >= c->width ? c->width - 1 : x1;
    y1 = y1 >= c->height ? c->height - 1 : y1;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++)
            canvas_pixel(c, x, y, col);
}

void canvas_line(canvas_t *c, int x0, int y0, int x1, int y1, int thick, rgb8_t col)
{
    thick = thick < 1 ? 1 : (thick > 5 ? 5 : thick);
    const int lo = -(thick - 1) / 2, hi = thick / 2;
    /* Bresenham; each step stamps a thick × thick square. */
    const int dx = abs(x1 - x0), dy = -abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int e = dx + dy;
    for (;;) {
        for (int oy = lo; oy <= hi; oy++)
            for (int ox = lo; ox <= hi; ox++)
                canvas_pixel(c, x0 + ox, y0 + oy, col);
        if (x0 == x1 && y0 == y1)
            break;
        const int e2 = 2 * e;
        if (e2 >= dy) {
            e += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            e += dx;
            y0 += sy;
        }
    }
}

int canvas_text_width(const char *text, int scale)
{
    const int n = (int)strlen(text);
    return n > 0 ? (n * FONT_ADVANCE - 1) * scale : 0;
}

/* Draws character ch at scale device pixels per font pixel: its top-left font pixel at (x, y),
 * or, when up, turned a quarter left (font pixel (column b, row r) lands at (x + r, y − b)). */
static void canvas_glyph(canvas_t *c, int x, int y, char ch, int scale, bool up, rgb8_t col)
{
    uint8_t rows[FONT_H];
    (void)hud_font_glyph(ch, rows); /* a box for a character the font lacks */
    for (int r = 0; r < FONT_H; r++)
        for (int b = 0; b < FONT_W; b++) {
            if (!(rows[r] & (0x10 >> b)))
                continue;
            if (up)
                canvas_fill_rect(c, x + r * scale, y - (b + 1) * scale + 1, x + (r + 1) * scale - 1,
                                 y - b * scale, col);
            else
                canvas_fill_rect(c, x + b * scale, y + r * scale, x + (b + 1) * scale - 1,
                                 y + (r + 1) * scale - 1, col);
        }
}

/* The text scale clamped to 1..8 device pixels per font pixel. */
static int text_scale(int scale)
{
    return scale < 1 ? 1 : (scale > 8 ? 8 : scale);
}

int canvas_text(canvas_t *c, int x, int y, const char *text, int scale, rgb8_t col)
{
    scale = text_scale(scale);
    int pen = x;
    for (const char *p = text; *p; p++) {
        canvas_glyph(c, pen, y, *p, scale, false, col);
        pen += FONT_ADVANCE * scale;
    }
    return pen - x;
}

void canvas_text_up(canvas_t *c, int x, int y, const char *text, int scale, rgb8_t col)
{
    scale = text_scale(scale);
    int pen = y;
    for (const char *p = text; *p; p++) {
        canvas_glyph(c, x, pen, *p, scale, true, col);
        pen -= FONT_ADVANCE * scale;
    }
}
