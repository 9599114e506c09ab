/*
 * sc_hal_display.h: the display controller contract: a B-scan leaves line by line.
 *
 * A frame is frame_begin, then `lines` calls of line (any order, each at most once), then
 * frame_end. Each call is non-blocking and bounded in time; a sink that cannot keep up drops
 * and counts, it never stalls the frame loop. Mandatory: frame_begin, line, frame_end.
 * Optional: link_state (NULL answers SC_ERR_NOT_SUPPORTED).
 * The sample buffer passed to line() is owned by the caller and valid only during the call.
 */
#ifndef SC_HAL_DISPLAY_H
#define SC_HAL_DISPLAY_H

#include <stdint.h>

#include "sc_err.h"

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
} sc_display_frame_info;

enum {
    SC_DISPLAY_FLAG_CONTACT = 1u << 0, /* probe in contact with the skin */
    SC_DISPLAY_FLAG_FROZEN = 1u << 1,  /* image frozen (fault or reset) */
};

typedef struct sc_display_link_state {
    uint8_t up;            /* link usable */
    uint32_t lines_sent;   /* since start */
    uint32_t lines_dropped;
} sc_display_link_state;

typedef struct sc_display_ops {
    int (*frame_begin)(void *ctx, const sc_display_frame_info *info);
    int (*line)(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                uint16_t count);
    int (*frame_end)(void *ctx, uint32_t frame_no);
    int (*link_state)(void *ctx, sc_display_link_state *state);
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

static inline int sc_display_frame_end(const sc_display_dev *dev, uint32_t frame_no)
{
    return dev->ops->frame_end(dev->ctx, frame_no);
}

static inline int sc_display_get_link_state(const sc_display_dev *dev,
                                            sc_display_link_state *st)
{
    return dev->ops->link_state ? dev->ops->link_state(dev->ctx, st) : SC_ERR_NOT_SUPPORTED;
}

#endif /* SC_HAL_DISPLAY_H */
