/*
 * vw_overlay.h: a 5x7 bitmap font and rectangles drawn into an 8-bit indexed raster (the
 * viewer's overlay: frame rate, probe contact, the vessels' compression measure, losses).
 * SDL2 has no text of its own and the viewer links nothing else.
 */
#ifndef VW_OVERLAY_H
#define VW_OVERLAY_H

#include <stdint.h>

/* Palette indices: 0..VW_GREY_LEVELS-1 are a grey ramp, the rest overlay colours. */
#define VW_GREY_LEVELS 248u
enum {
    VW_COL_BAND = 248,   /* dark band behind text */
    VW_COL_TEXT = 249,   /* white */
    VW_COL_OK = 250,     /* green */
    VW_COL_BAD = 251,    /* red */
    VW_COL_WARN = 252,   /* yellow */
    VW_COL_VESSEL = 253, /* cyan */
};

void vw_palette(uint8_t rgb[768]);
/* Grey byte (0..255) to palette index. */
static inline uint8_t vw_grey_index(uint8_t v)
{
    return (uint8_t)((v * (VW_GREY_LEVELS - 1u) + 127u) / 255u);
}

void vw_fill_rect(uint8_t *img, uint32_t w, uint32_t h, int x, int y, int rw, int rh, uint8_t col);
/* Text at (x, y), glyph cell 6x8 times scale. Unknown characters draw as blanks. Returns the
 * x after the text. */
int vw_text(uint8_t *img, uint32_t w, uint32_t h, int x, int y, int scale, uint8_t col,
            const char *s);

#endif /* VW_OVERLAY_H */
