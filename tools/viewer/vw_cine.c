/* vw_cine.c: cine ring and calipers (see vw_cine.h). */
#include "vw_cine.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_scan_overlay.h"

#define VW_FRAME_BYTES ((size_t)SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES)

int vw_cine_init(vw_cine *c, uint32_t capacity)
{
    memset(c, 0, sizeof *c);
    if (capacity == 0u) {
        return -1;
    }
    c->meta = calloc(capacity, sizeof *c->meta);
    c->images = malloc(VW_FRAME_BYTES * capacity);
    if (c->meta == NULL || c->images == NULL) {
        vw_cine_free(c);
        return -1;
    }
    c->capacity = capacity;
    return 0;
}

void vw_cine_free(vw_cine *c)
{
    free(c->meta);
    free(c->images);
    memset(c, 0, sizeof *c);
}

void vw_cine_push(vw_cine *c, const sc_dlink_done *d)
{
    if (c->capacity == 0u || d == NULL || d->image == NULL) {
        return;
    }
    uint8_t *img = c->images + VW_FRAME_BYTES * c->head;
    memcpy(img, d->image, (size_t)d->frame.line_count * SC_MAX_SCAN_SAMPLES);
    c->meta[c->head] = *d;
    c->meta[c->head].image = img;
    c->head = (c->head + 1u) % c->capacity;
    if (c->count < c->capacity) {
        c->count++;
    }
}

const sc_dlink_done *vw_cine_get(const vw_cine *c, uint32_t back)
{
    if (back >= c->count) {
        return NULL;
    }
    const uint32_t slot = (c->head + c->capacity - 1u - back) % c->capacity;
    return &c->meta[slot];
}

uint32_t vw_cine_step(const vw_cine *c, uint32_t back, int delta)
{
    if (c->count == 0u) {
        return 0u;
    }
    const int64_t b = (int64_t)back + delta;
    return b < 0 ? 0u : (b >= (int64_t)c->count ? c->count - 1u : (uint32_t)b);
}

double vw_caliper_mm(const sc_display_frame_info *g, uint32_t w, uint32_t h, double x0, double y0,
                     double x1, double y1)
{
    /* the raster's scale from two points of known depth on the same edge */
    double ax, ay, bx, by;
    if (sc_overlay_edge_px(g, w, h, 0.0, 0, &ax, &ay) != 0 ||
        sc_overlay_edge_px(g, w, h, (double)g->depth_mm, 0, &bx, &by) != 0) {
        return -1.0;
    }
    const double px = hypot(bx - ax, by - ay);
    if (!(px > 0.0)) {
        return -1.0;
    }
    return hypot(x1 - x0, y1 - y0) * (double)g->depth_mm / px;
}
