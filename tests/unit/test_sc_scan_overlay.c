/* test_sc_scan_overlay.c: the scanner display items drawn over the scan-converted B-scan
 * (platform/linux/sc_scan_overlay.h) sit where the geometry puts them: each depth tick on the
 * row where sc_scanconv draws that depth, for a linear and a curvilinear probe; the focus marker
 * at the focus depth; the readout only with the values the frame record carries; over a colour
 * Doppler frame (RGB) the same items, grey, and the colour kept everywhere else. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_scan_overlay.h"
#include "sc_scanconv.h"

#define W       400u
#define H       500u
#define LINES   128u
#define SAMPLES 512u

static uint8_t g_img[LINES * SAMPLES];
static uint8_t g_ras[W * H];
static uint8_t g_ovl[W * H];
static uint8_t g_rgb[3u * W * H];

static sc_display_frame_info geom(uint16_t kind)
{
    sc_display_frame_info g;
    memset(&g, 0, sizeof g);
    g.lines = LINES;
    g.samples = SAMPLES;
    g.geometry_id = kind;
    g.depth_mm = 40.0f;
    g.width_mm = kind == 1u ? 60.0f : 38.0f;
    g.radius_mm = kind == 1u ? 40.0f : 0.0f;
    return g;
}

/* Row of the raster, on the image's right edge, where sc_scanconv draws depth d: the image is
 * dark but for the samples of depth d on the last line. */
static int scanconv_row_of_depth(const sc_display_frame_info *g, float d_mm, int *col)
{
    memset(g_img, 0, sizeof g_img);
    const uint32_t k = (uint32_t)(d_mm / g->depth_mm * (float)SAMPLES);
    g_img[(size_t)(LINES - 1u) * SAMPLES + k] = 255u;
    sc_scanconv c;
    assert_int_equal(sc_scanconv_init(&c, W, H), 0);
    sc_scanconv_render(&c, g, g_img, SAMPLES, g_ras);
    sc_scanconv_free(&c);
    int best = -1;
    for (uint32_t y = 0; y < H && best < 0; y++) {
        for (uint32_t x = W; x-- > 0u;) {
            if (g_ras[(size_t)y * W + x] == 255u) {
                best = (int)y;
                *col = (int)x;
                break;
            }
        }
    }
    return best;
}

static void check_ticks(uint16_t kind)
{
    const sc_display_frame_info g = geom(kind);
    memset(g_ovl, 7, sizeof g_ovl);
    sc_overlay_draw(g_ovl, W, H, &g);
    for (int mm = 10; mm <= 40; mm += 10) {
        double x, y;
        assert_int_equal(sc_overlay_edge_px(&g, W, H, (double)mm - 0.04, 1, &x, &y), 0);
        int col = -1;
        const int row = scanconv_row_of_depth(&g, (float)mm - 0.04f, &col);
        print_message("%s %d mm: tick at (%.1f, %.1f), scan conversion row %d col %d\n",
                      kind ? "curvilinear" : "linear", mm, x, y, row, col);
        assert_true(row >= 0);
        assert_true(fabs(y - row) <= 1.5);
        assert_true(fabs(x - col) <= 2.5);
        /* the major tick is drawn there */
        double tx, ty;
        assert_int_equal(sc_overlay_edge_px(&g, W, H, (double)mm, 1, &tx, &ty), 0);
        const long xi = lround(tx), yi = lround(ty);
        if (yi >= 0 && yi < (long)H && xi >= 0 && xi < (long)W) {
            assert_int_equal(g_ovl[(size_t)yi * W + (size_t)xi], SC_OVERLAY_FG);
            assert_int_equal(g_ovl[(size_t)yi * W + (size_t)(xi - 9)], SC_OVERLAY_FG);
            /* one pixel thick */
            assert_int_not_equal(g_ovl[(size_t)(yi + 2) * W + (size_t)xi], SC_OVERLAY_FG);
        }
    }
}

static void linear_depth_ticks_sit_on_the_scan_converted_depth_rows(void **state)
{
    (void)state;
    check_ticks(0u);
}

static void curvilinear_depth_ticks_sit_on_the_fan_edge_at_their_depth(void **state)
{
    (void)state;
    check_ticks(1u);
}

static void focus_marker_is_at_the_focus_depth_and_readout_only_with_values(void **state)
{
    (void)state;
    sc_display_frame_info g = geom(0u);
    g.focus_mm = 25.0f;
    memset(g_ovl, 7, sizeof g_ovl);
    sc_overlay_draw(g_ovl, W, H, &g);
    double x, y;
    assert_int_equal(sc_overlay_edge_px(&g, W, H, 25.0, 0, &x, &y), 0);
    const long xi = lround(x) < 0 ? 0 : lround(x), yi = lround(y);
    assert_int_equal(g_ovl[(size_t)yi * W + (size_t)xi], SC_OVERLAY_FG);
    assert_int_equal(g_ovl[(size_t)yi * W + (size_t)(xi + 3)], SC_OVERLAY_FG);
    assert_int_not_equal(g_ovl[(size_t)(yi + 8) * W + (size_t)xi], SC_OVERLAY_FG);
    /* no range in the record: no gain/range/TGC lines (row 16 is the second line's middle) */
    uint32_t lit2 = 0;
    for (uint32_t xx = 14; xx < 200u; xx++) {
        lit2 += g_ovl[16u * W + xx] == SC_OVERLAY_FG;
    }
    assert_int_equal(lit2, 0);
    g.dynamic_range_db = 60.0f;
    g.gain_db = 6.0f;
    memset(g_ovl, 7, sizeof g_ovl);
    sc_overlay_draw(g_ovl, W, H, &g);
    for (uint32_t xx = 14; xx < 200u; xx++) {
        lit2 += g_ovl[16u * W + xx] == SC_OVERLAY_FG;
    }
    assert_true(lit2 > 10u);
    /* outside the depth range: no position */
    assert_int_equal(sc_overlay_edge_px(&g, W, H, 41.0, 1, &x, &y), -1);
}

/* The overlay over an RGB frame: every pixel the grey overlay writes (ticks, marks, text and
 * its dark band) is that grey in all three channels; every other pixel keeps its colour. */
static void rgb_overlay_draws_the_same_items_and_keeps_the_colour_elsewhere(void **state)
{
    (void)state;
    sc_display_frame_info g = geom(0u);
    g.focus_mm = 25.0f;
    g.dynamic_range_db = 60.0f;
    g.frequency_mhz = 7.5f;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        g_rgb[3u * i] = 200u; /* a red-orange colour flow everywhere */
        g_rgb[3u * i + 1u] = 60u;
        g_rgb[3u * i + 2u] = 10u;
    }
    static uint8_t plane[W * H];
    sc_overlay_draw_rgb(g_rgb, plane, W, H, &g);
    /* the grey overlay on two differently filled planes: a pixel it writes is the same in both */
    memset(g_ovl, 7, sizeof g_ovl);
    sc_overlay_draw(g_ovl, W, H, &g);
    memset(g_ras, 201, sizeof g_ras);
    sc_overlay_draw(g_ras, W, H, &g);
    uint32_t drawn = 0, fg = 0, bg = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const int written = g_ovl[i] != 7u || g_ras[i] != 201u;
        if (written) {
            drawn++;
            fg += g_ovl[i] == SC_OVERLAY_FG;
            bg += g_ovl[i] == SC_OVERLAY_BG;
            assert_int_equal(g_rgb[3u * i], g_ovl[i]);
            assert_int_equal(g_rgb[3u * i + 1u], g_ovl[i]);
            assert_int_equal(g_rgb[3u * i + 2u], g_ovl[i]);
        } else {
            assert_int_equal(g_rgb[3u * i], 200u);
            assert_int_equal(g_rgb[3u * i + 1u], 60u);
            assert_int_equal(g_rgb[3u * i + 2u], 10u);
        }
    }
    assert_true(fg > 100u); /* ticks, marker, text */
    assert_true(bg > 100u); /* the band behind the text */
    assert_int_equal(fg + bg, drawn);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_depth_ticks_sit_on_the_scan_converted_depth_rows),
        cmocka_unit_test(curvilinear_depth_ticks_sit_on_the_fan_edge_at_their_depth),
        cmocka_unit_test(focus_marker_is_at_the_focus_depth_and_readout_only_with_values),
        cmocka_unit_test(rgb_overlay_draws_the_same_items_and_keeps_the_colour_elsewhere),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
