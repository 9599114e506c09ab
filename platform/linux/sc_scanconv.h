/*
 * sc_scanconv.h: scan conversion of a B-scan (scan lines x samples, line-major) into a raster
 * a screen or a PNG shows, preserving the image's physical aspect.
 *
 * Linear geometry: lines are columns across width_mm, samples are rows down depth_mm.
 * Curvilinear: lines fan out over a sector of width_mm degrees from the apex, radius_mm behind
 * the probe face; samples run along each line from radius_mm to radius_mm + depth_mm, so the
 * probe face is the arc at the top of the raster. Pixels outside the image are 0.
 * A lookup table maps each output pixel to its source sample once per geometry, so a frame
 * costs one table walk. The table is allocated by sc_scanconv_init (host code, at start-up).
 */
#ifndef SC_SCANCONV_H
#define SC_SCANCONV_H

#include <stdint.h>

#include "sc_hal_display.h"

typedef struct sc_scanconv {
    uint32_t width, height;          /* output raster (fit mode: the image's box, see below) */
    uint32_t cap_w, cap_h;           /* the canvas sc_scanconv_init was given */
    int fit;                         /* 1: width x height shrink to the image (sc_scanconv_set_fit) */
    uint32_t *lut;                   /* width*height source indices, UINT32_MAX = outside */
    sc_display_frame_info geom;      /* geometry the table was built for */
    uint32_t stride;
    int valid;
} sc_scanconv;

/* Allocates the table for a width x height raster. 0, or -1 when out of memory. */
int sc_scanconv_init(sc_scanconv *c, uint32_t width, uint32_t height);
void sc_scanconv_free(sc_scanconv *c);

/* Fit mode, for sinks whose raster size is free (PNG files): the raster shrinks to the image's
 * bounding box at the scale it has in the cap_w x cap_h canvas (the aspect kept, one side at
 * the canvas size), so no black rows or columns surround the image; width and height change
 * with the geometry when a frame is rendered (read them after sc_scanconv_render*). Off (the
 * default): the raster is the canvas, the image centred at its top (fixed screens). */
void sc_scanconv_set_fit(sc_scanconv *c, int on);

/* The raster sc_scanconv_set_fit(c, 1) renders frame geometry info into: *w x *h, at most
 * cap_w x cap_h, at least 1 x 1. Pure. */
void sc_scanconv_fit_size(const sc_display_frame_info *info, uint32_t cap_w, uint32_t cap_h,
                          uint32_t *w, uint32_t *h);

/* Renders image (line-major, row stride `stride` samples per line) of geometry info into
 * out (width*height grey bytes, row-major). Rebuilds the table when the geometry changed. */
void sc_scanconv_render(sc_scanconv *c, const sc_display_frame_info *info, const uint8_t *image,
                        uint32_t stride, uint8_t *out);

/* As sc_scanconv_render, in RGB (3 bytes per pixel, rows of 3 * width): grey B-mode, and
 * where the colour plane (same layout as image, signed, 0 none) has a value the scanner's
 * colour map (sc_doppler_colour_rgb: red toward the probe, blue away) instead. */
void sc_scanconv_render_colour(sc_scanconv *c, const sc_display_frame_info *info,
                               const uint8_t *image, const int8_t *colour, uint32_t stride,
                               uint8_t *rgb);

#endif /* SC_SCANCONV_H */
