/* The HUD's bitmap font: every character the HUD prints has a glyph, glyphs are distinct, lower
 * case draws as upper case, and the layout puts lit pixels where the glyph says, advancing one
 * cell per character and one line per '\n'. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "host/render/hud_font.h"

static int popcount_rows(const uint8_t rows[HUD_GLYPH_H])
{
    int n = 0;
    for (int r = 0; r < HUD_GLYPH_H; r++)
        for (int c = 0; c < HUD_GLYPH_W; c++)
            n += (rows[r] >> c) & 1;
    return n;
}

static void test_glyphs_cover_the_hud(void **state)
{
    (void)state;
    const char *need = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 .,:;-+=/%()[]<>_'\"!?*#|";
    uint8_t seen[64][HUD_GLYPH_H];
    size_t n = 0;
    for (const char *p = need; *p; p++) {
        uint8_t rows[HUD_GLYPH_H];
        assert_true(hud_font_glyph(*p, rows));
        if (*p != ' ')
            assert_true(popcount_rows(rows) >= 2);
        for (size_t k = 0; k < n; k++)
            assert_memory_not_equal(seen[k], rows, HUD_GLYPH_H); /* no two alike */
        memcpy(seen[n++], rows, HUD_GLYPH_H);
    }
    uint8_t lo[HUD_GLYPH_H], up[HUD_GLYPH_H];
    assert_true(hud_font_glyph('q', lo));
    assert_true(hud_font_glyph('Q', up));
    assert_memory_equal(lo, up, HUD_GLYPH_H);
    /* A character the font lacks draws as a full box, so it is seen, not lost. */
    assert_false(hud_font_glyph('\x01', lo));
    assert_int_equal(popcount_rows(lo), HUD_GLYPH_W * HUD_GLYPH_H);
}

static void test_layout_places_pixels(void **state)
{
    (void)state;
    float q[4 * 200];
    /* 'I' is 0E 04 04 04 04 04 0E: a 3-pixel run, five single pixels, a 3-pixel run = 7 quads
     * covering 11 pixels; scale 2 from (10, 20). */
    const size_t n = hud_font_layout("I", 10.0f, 20.0f, 2.0f, q, 200);
    assert_int_equal(n, 7);
    assert_float_equal(q[0], 10.0f + 1 * 2.0f, 1e-6); /* top row, columns 1..3 */
    assert_float_equal(q[1], 20.0f, 1e-6);
    assert_float_equal(q[2] - q[0], 3 * 2.0f, 1e-6);
    assert_float_equal(q[3] - q[1], 2.0f, 1e-6);
    assert_float_equal(q[4 + 0], 10.0f + 2 * 2.0f, 1e-6); /* second row: column 2 alone */
    assert_float_equal(q[4 + 2] - q[4 + 0], 2.0f, 1e-6);
    float lit = 0.0f;
    for (size_t i = 0; i < n; i++)
        lit += (q[4 * i + 2] - q[4 * i]) * (q[4 * i + 3] - q[4 * i + 1]);
    assert_float_equal(lit, 11 * 2.0f * 2.0f, 1e-4); /* the same pixels as one quad each */
    /* '#' has rows with two runs (0A = 01010: two quads) and full rows (1F: one). */
    const size_t nz = hud_font_layout("#", 0.0f, 0.0f, 1.0f, q, 200);
    lit = 0.0f;
    for (size_t i = 0; i < nz; i++)
        lit += (q[4 * i + 2] - q[4 * i]) * (q[4 * i + 3] - q[4 * i + 1]);
    assert_float_equal(lit, 2 + 2 + 5 + 2 + 5 + 2 + 2, 1e-4); /* '#': 0A 0A 1F 0A 1F 0A 0A */
    assert_int_equal(nz, 2 + 2 + 1 + 2 + 1 + 2 + 2);
    /* The second character starts one advance to the right; a newline goes down a line. */
    const size_t n2 = hud_font_layout("II", 0.0f, 0.0f, 1.0f, q, 200);
    assert_int_equal(n2, 14);
    assert_float_equal(q[4 * 7], (float)HUD_ADVANCE + 1.0f, 1e-6);
    const size_t n3 = hud_font_layout("I\nI", 0.0f, 0.0f, 1.0f, q, 200);
    assert_int_equal(n3, 14);
    assert_float_equal(q[4 * 7], 1.0f, 1e-6);
    assert_float_equal(q[4 * 7 + 1], (float)(HUD_GLYPH_H + 3), 1e-6);
    /* A short buffer is never overrun, and the count says how much was needed. */
    float small[4 * 3];
    memset(small, 0, sizeof(small));
    assert_int_equal(hud_font_layout("II", 0.0f, 0.0f, 1.0f, small, 3), 14);
    assert_int_equal(hud_font_layout("", 0.0f, 0.0f, 1.0f, NULL, 0), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glyphs_cover_the_hud),
        cmocka_unit_test(test_layout_places_pixels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
