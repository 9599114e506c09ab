/*
 * vw_cine.h: the viewer's cine loop: the last frames received (a scanner's "last seconds"),
 * kept in a ring so that a frozen image can be stepped back and forward, and the calipers'
 * distance on the scan-converted image.
 * Host code: vw_cine_init allocates the ring once (capacity x the largest frame); pushing copies
 * a frame (O(lines x samples)), never allocates.
 */
#ifndef VW_CINE_H
#define VW_CINE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_dlink.h"
#include "sc_hal_display.h"

typedef struct vw_cine {
    uint32_t capacity; /* frames */
    uint32_t count;    /* frames held, <= capacity */
    uint32_t head;     /* slot of the next push */
    sc_dlink_done *meta;
    uint8_t *images; /* capacity x SC_MAX_SCAN_LINES x SC_MAX_SCAN_SAMPLES */
} vw_cine;

/* Allocate a ring of capacity frames (>= 1). 0, or -1 when out of memory. */
int vw_cine_init(vw_cine *c, uint32_t capacity);
void vw_cine_free(vw_cine *c);

/* Keep a copy of a closed frame (image rows of stride SC_MAX_SCAN_SAMPLES, as the assembler
 * gives them); the oldest is dropped when the ring is full. */
void vw_cine_push(vw_cine *c, const sc_dlink_done *d);

/* The frame `back` frames before the newest (0: the newest), its image pointing into the ring,
 * or NULL when back >= count. */
const sc_dlink_done *vw_cine_get(const vw_cine *c, uint32_t back);

/* Step a cine position (frames back from the newest) by delta (+1 one frame older), clamped
 * to the frames held. */
uint32_t vw_cine_step(const vw_cine *c, uint32_t back, int delta);

/* Calipers: the distance in mm between raster points (x0, y0) and (x1, y1) of a w x h raster
 * rendered by sc_scanconv from geometry g (its pixels are square: one scale for both axes). */
double vw_caliper_mm(const sc_display_frame_info *g, uint32_t w, uint32_t h, double x0, double y0,
                     double x1, double y1);

#endif /* VW_CINE_H */
