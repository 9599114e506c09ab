/*
 * sc_hal_display.h: the display controller contract: a B-scan leaves line by line.
 *
 * A frame is frame_begin, then `lines` calls of line (any order, each at most once), then
 * frame_end. Each call is non-blocking and bounded in time; a sink that cannot keep up drops
 * and counts, it never stalls the frame loop. Mandatory: frame_begin, line, frame_end.
 * Optional: link_state, colour_line, doppler (NULL answers SC_ERR_NOT_SUPPORTED; a sink without
 * the colour ops shows the B-mode image only).
 * Colour Doppler (core/imaging/sc_doppler.h), when on, adds to a frame between frame_begin and
 * frame_end: one colour_line per scan line of the colour box (after that line's B-mode line), then
 * one doppler record (box, scale, steering, sample gate and this frame's spectrum column).
 * The sample buffer passed to line() is owned by the caller and valid only during the call.
 *
 * What the display needs with a frame travels with that frame: the geometry in frame_begin's
 * info, and what the frame's own pass computes (the vessels' compression measure) in
 * frame_end's record. Lines leave as soon as they are computed and the measure comes from the
 * same pass, so the frame's closing record is the first place that holds it; every sink gets
 * it in the same frame, none reads it from the engine afterwards.
 *
 * Return values of every op: SC_OK; SC_ERR_STATE (call out of order: line or frame_end without
 * a frame_begin, frame numbers that do not match); SC_ERR_INVALID_ARG (NULL, line_index >=
 * lines, count != samples); SC_ERR_IO / SC_ERR_WOULD_BLOCK (the link refused data: counted as
 * dropped lines, the frame goes on); SC_ERR_NOT_SUPPORTED (optional op absent).
 */
#ifndef SC_HAL_DISPLAY_H
#define SC_HAL_DISPLAY_H

#include <stdint.h>

#include "sc_err.h"

/* TGC bands a frame's record carries (the B-scan's SC_BSCAN_TGC_BANDS). */
#define SC_DISPLAY_TGC_BANDS 8u

typedef struct sc_display_frame_info {
    uint32_t frame_no;    /* engine frame counter */
    uint16_t lines;       /* scan lines in this frame */
    uint16_t samples;     /* samples (pixels) per line */
    uint16_t geometry_id; /* 0 linear, 1 curvilinear; tells the sink how to scan-convert */
    uint16_t flags;       /* SC_DISPLAY_FLAG_* */
    float depth_mm;       /* imaging depth */
    float width_mm;       /* linear: aperture width; curvilinear: sector angle in degrees */
    float radius_mm;      /* curvilinear: probe face radius (apex radius_mm behind the face,
                           * samples from radius_mm to radius_mm + depth_mm); linear: 0 */
    /* what a scanner's display shows beside the image (overlay: depth scale from depth_mm,
     * focus marker, gain / range / TGC readout, probe type from geometry_id and frequency);
     * 0 where the sender has none (a sink then leaves that item out) */
    float gain_db;
    float dynamic_range_db;
    float focus_mm; /* transmit focus below the probe face */
    float frequency_mhz;
    float tgc_db[SC_DISPLAY_TGC_BANDS]; /* per depth band, shallow first */
} sc_display_frame_info;

enum {
    SC_DISPLAY_FLAG_CONTACT = 1u << 0, /* probe in contact with the skin */
    SC_DISPLAY_FLAG_FROZEN = 1u << 1,  /* image frozen (fault or reset) */
};

/* The closing record of a frame: what the frame's pass computed. */
typedef struct sc_display_end_info {
    uint32_t frame_no;       /* as in frame_begin */
    float vein_area_ratio;   /* image area of the vein now / at rest, this frame; < 0: none */
    float artery_area_ratio; /* the same for the artery */
} sc_display_end_info;

/* Colour Doppler of a frame: the box, the scale and this frame's pulsed-wave spectrum column.
 * Colour values (colour_line) are signed bytes: v / nyquist_mm_s * 127 of the velocity along the
 * beam, positive toward the probe (red), negative away (blue), 0 no colour (no flow, wall filter,
 * outside the lumens). Spectrum bin i covers velocities (toward the probe)
 * -nyquist + i * 2 nyquist / bins .. one bin further; 0 black .. 255 white (log-compressed). */
#define SC_DISPLAY_SPECTRUM_MAX_BINS 128u
typedef struct sc_display_doppler_info {
    uint32_t frame_no;
    uint16_t box_line_lo, box_line_hi;     /* colour box: lines [lo, hi) */
    uint16_t box_sample_lo, box_sample_hi; /* samples [lo, hi) */
    float nyquist_mm_s;                    /* scale: the velocity that aliases, > 0 */
    float steer_deg;                       /* colour beam steering, + toward increasing x */
    float gate_velocity_mm_s;              /* model velocity along the beam at the gate centre
                                              (before aliasing); 0 outside a lumen */
    uint16_t gate_line;                    /* pulsed-wave gate: line and samples [lo, hi) */
    uint16_t gate_sample_lo, gate_sample_hi;
    uint16_t spectrum_bins;                /* 0 (no spectrum) .. SC_DISPLAY_SPECTRUM_MAX_BINS */
    const uint8_t *spectrum;               /* spectrum_bins bytes, valid during the call */
} sc_display_doppler_info;

typedef struct sc_display_link_state {
    uint8_t up;            /* link usable */
    uint32_t lines_sent;   /* since start */
    uint32_t lines_dropped;
} sc_display_link_state;

typedef struct sc_display_ops {
    int (*frame_begin)(void *ctx, const sc_display_frame_info *info);
    int (*line)(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                uint16_t count);
    int (*frame_end)(void *ctx, const sc_display_end_info *end);
    int (*link_state)(void *ctx, sc_display_link_state *state);
    /* optional: colour values of samples [first, first + count) of a line (sc_display_doppler_info) */
    int (*colour_line)(void *ctx, uint32_t frame_no, uint16_t line_index, uint16_t first,
                       const int8_t *values, uint16_t count);
    /* optional: the frame's Doppler record, once per frame before frame_end */
    int (*doppler)(void *ctx, const sc_display_doppler_info *info);
} sc_display_ops;

typedef struct sc_display_dev {
    const sc_display_ops *ops;
    void *ctx;
} sc_display_dev;

static inline int sc_display_frame_begin(const sc_display_dev *dev,
                                         const sc_display_frame_info *info)
{
    return dev->ops->frame_begin(dev->ctx, info);
}

static inline int sc_display_line(const sc_display_dev *dev, uint32_t frame_no,
                                  uint16_t line_index, const uint8_t *samples, uint16_t count)
{
    return dev->ops->line(dev->ctx, frame_no, line_index, samples, count);
}

static inline int sc_display_frame_end(const sc_display_dev *dev, const sc_display_end_info *end)
{
    return dev->ops->frame_end(dev->ctx, end);
}

/* The closing record of a frame that carries no measure (test patterns, tools): a pointer to
 * a compound literal of the enclosing block. */
#define SC_DISPLAY_END_PLAIN(fno)                                                             \
    (&(const sc_display_end_info){                                                               \
        .frame_no = (fno), .vein_area_ratio = -1.0f, .artery_area_ratio = -1.0f})

static inline int sc_display_get_link_state(const sc_display_dev *dev,
                                            sc_display_link_state *st)
{
    return dev->ops->link_state ? dev->ops->link_state(dev->ctx, st) : SC_ERR_NOT_SUPPORTED;
}

static inline int sc_display_colour_line(const sc_display_dev *dev, uint32_t frame_no,
                                         uint16_t line_index, uint16_t first,
                                         const int8_t *values, uint16_t count)
{
    return dev->ops->colour_line ? dev->ops->colour_line(dev->ctx, frame_no, line_index, first,
                                                         values, count)
                                 : SC_ERR_NOT_SUPPORTED;
}

static inline int sc_display_doppler(const sc_display_dev *dev,
                                     const sc_display_doppler_info *info)
{
    return dev->ops->doppler ? dev->ops->doppler(dev->ctx, info) : SC_ERR_NOT_SUPPORTED;
}

#endif /* SC_HAL_DISPLAY_H */
