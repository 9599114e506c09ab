/* vw_overlay.c: palette, rectangles and text (see vw_overlay.h); the 5x7 font is the display
 * sinks' (platform/linux/sc_scan_overlay.h), so the viewer and the PNG/KMS overlays read alike. */
#include "vw_overlay.h"

#include <string.h>

#include "sc_scan_overlay.h"

void vw_palette(uint8_t rgb[768])
{
    memset(rgb, 0, 768);
    for (uint32_t i = 0; i < VW_GREY_LEVELS; i++) {
        const uint8_t v =
            (uint8_t)((i * 255u + (VW_GREY_LEVELS - 1u) / 2u) / (VW_GREY_LEVELS - 1u));
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = v;
    }
    const uint8_t extra[][3] = {{16, 16, 24},  {255, 255, 255}, {40, 220, 60},
                                {230, 40, 40}, {240, 210, 40},  {40, 200, 230}};
    for (uint32_t i = 0; i < sizeof extra / sizeof extra[0]; i++) {
        memcpy(rgb + 3 * (VW_COL_BAND + i), extra[i], 3);
    }
}

void vw_fill_rect(uint8_t *img, uint32_t w, uint32_t h, int x, int y, int rw, int rh, uint8_t col)
{
    for (int j = y; j < y + rh; j++) {
        if (j < 0 || (uint32_t)j >= h) {
            continue;
        }
        for (int i = x; i < x + rw; i++) {
            if (i >= 0 && (uint32_t)i < w) {
                img[(size_t)j * w + (uint32_t)i] = col;
            }
        }
    }
}

int vw_text(uint8_t *img, uint32_t w, uint32_t h, int x, int y, int scale, uint8_t col,
            const char *s)
{
    return sc_overlay_text(img, w, h, x, y, scale, col, s); /* the sinks' font (sc_scan_overlay.h) */
}
