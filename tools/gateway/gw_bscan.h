/*
 * gw_bscan.h: the console's B-scan message ('B', docs/console.md): one assembled display-link
 * frame (platform/dlink) with what the page's scanner display needs: the grey image, the imaging
 * parameters of FRAME_PARAMS (gain, dynamic range, focus, frequency, TGC), and with colour
 * Doppler the colour box, scale and gate, the colour values inside the box and the last
 * pulsed-wave spectrum columns (so a page that receives 20 frames a second still scrolls every
 * column of a 60 Hz engine).
 *
 * Memory: the caller's buffers; never allocates. Threads: one writer per gw_spectrum_hist.
 */
#ifndef GW_BSCAN_H
#define GW_BSCAN_H

#include <stddef.h>
#include <stdint.h>

#include "sc_dlink.h"

#define GW_BSCAN_HDR 32u
#define GW_BSCAN_PARAMS 48u     /* gain, range, focus, frequency, tgc[8]: f32 */
#define GW_BSCAN_DOPPLER 32u    /* box, scale, steering, gate velocity, gate, bins, columns */
#define GW_BSCAN_COLUMNS 16u    /* spectrum columns kept and sent (newest last) */
/* extension flags (byte 1 of the header) */
#define GW_BSCAN_HAS_PARAMS  0x01u
#define GW_BSCAN_HAS_DOPPLER 0x02u
#define GW_BSCAN_HAS_COLOUR  0x04u
/* Largest message: header, image, parameters, Doppler record with every column, a colour box
 * as large as the image. */
#define GW_BSCAN_MAX                                                                        \
    (GW_BSCAN_HDR + 2u * SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES + GW_BSCAN_PARAMS +        \
     GW_BSCAN_DOPPLER + GW_BSCAN_COLUMNS * (4u + SC_DLINK_SPECTRUM_MAX))

/* The spectrum columns of the last frames that carried a DOPPLER record, oldest first. */
typedef struct gw_spectrum_hist {
    uint32_t n;                                       /* columns held, 0..GW_BSCAN_COLUMNS */
    uint32_t head;                                    /* next slot */
    uint16_t bins;                                    /* of every column held */
    uint32_t frame_no[GW_BSCAN_COLUMNS];
    uint8_t col[GW_BSCAN_COLUMNS][SC_DLINK_SPECTRUM_MAX];
} gw_spectrum_hist;

/* Forget every column (a new engine is shown: its frame numbers restart). */
void gw_spectrum_clear(gw_spectrum_hist *h);

/* Build the message of frame d into out (cap bytes); first adds d's spectrum column (if any)
 * to h (a change of the bin count clears h first). Returns the message length, or 0 when the
 * frame is not shown (inconsistent with its own geometry, or cap too small). */
size_t gw_bscan_build(uint8_t *out, size_t cap, const sc_dlink_done *d, gw_spectrum_hist *h);

/* A 'B' message read back (the page's decoder, tools/console/www/scanner.js decodeBscan, in C:
 * the tests' reference). Pointers into the message. */
typedef struct gw_bscan_view {
    uint8_t flags;
    uint32_t frame_no;
    uint16_t lines, samples, geometry_id, link_flags;
    float depth_mm, width_mm, radius_mm;
    uint16_t vein_pm, artery_pm;
    const uint8_t *image;   /* lines x samples, line after line */
    const uint8_t *params;  /* GW_BSCAN_PARAMS bytes, or NULL */
    const uint8_t *doppler; /* GW_BSCAN_DOPPLER bytes, or NULL */
    uint16_t box_line_lo, box_line_hi, box_sample_lo, box_sample_hi, bins, columns;
    const uint8_t *spectrum; /* columns x (u32 frame, bins bytes), or NULL */
    const int8_t *colour;    /* box lines x box samples, or NULL */
} gw_bscan_view;

/* Read message m (n bytes). Returns 0, or -1 when it is not a 'B' message, is shorter or longer
 * than its header and sections say, or its box or columns disagree with its geometry. */
int gw_bscan_parse(const uint8_t *m, size_t n, gw_bscan_view *v);

#endif /* GW_BSCAN_H */
