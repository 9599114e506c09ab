/*
 * sc_scan_overlay.h: what a scanner's display shows beside the B-scan, drawn into the grey raster
 * that sc_scanconv renders (same fit: the image fills the raster keeping its aspect):
 *  - depth scale in cm along the image's right edge (a major tick and its number every cm, a
 *    minor tick every 5 mm; along the fan's right edge for a curvilinear probe);
 *  - focus marker: a triangle at the transmit focus depth on the left edge;
 *  - orientation marker: a filled square at the top corner on the side of scan line 0 (the
 *    probe's notch side);
 *  - readout: probe type and frequency, depth in cm, gain, dynamic range, and the TGC bands.
 * Items whose value the frame record does not carry (0) are left out. Host code: pure drawing
 * into the caller's raster, never allocates.
 */
#ifndef SC_SCAN_OVERLAY_H
#define SC_SCAN_OVERLAY_H

#include <stdint.h>

#include "sc_hal_display.h"

#define SC_OVERLAY_FG 255u /* ticks, marks, text */
#define SC_OVERLAY_BG 0u   /* band behind text */

/* Raster position (pixel centre coordinates, x right, y down) of the point depth_mm below the
 * probe face on the image's right edge (linear: the last line's edge; curvilinear: the fan's
 * right edge ray), for a w x h raster rendered by sc_scanconv from frame geometry g.
 * edge 0: the left edge instead. Returns 0, or -1 when depth_mm is outside [0, depth]. */
int sc_overlay_edge_px(const sc_display_frame_info *g, uint32_t w, uint32_t h, double depth_mm,
                       int right, double *px, double *py);

/* Draw the overlay into raster (w x h grey bytes, row-major). O(w + h + text). */
void sc_overlay_draw(uint8_t *raster, uint32_t w, uint32_t h, const sc_display_frame_info *g);
/* The same with the orientation marker and the readout top_px lower (below a sink's own band). */
void sc_overlay_draw_below(uint8_t *raster, uint32_t w, uint32_t h, const sc_display_frame_info *g,
                           int top_px);

/* The same over an RGB raster (w x h x 3 bytes, a colour Doppler frame): drawn on plane (w x h
 * scratch bytes) prefilled with a value the overlay never writes, then copied as grey where it
 * drew, its dark band behind the text included. */
void sc_overlay_draw_rgb(uint8_t *rgb, uint8_t *plane, uint32_t w, uint32_t h,
                         const sc_display_frame_info *g);

/* Text in the overlay's 5x7 font (upper case, digits, . + - : /; others blank), cell 6x8 times
 * scale, at (x, y). Returns the x after the text. */
int sc_overlay_text(uint8_t *raster, uint32_t w, uint32_t h, int x, int y, int scale, uint8_t v,
                    const char *s);

#endif /* SC_SCAN_OVERLAY_H */
