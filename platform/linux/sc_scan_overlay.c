/* sc_scan_overlay.c: a scanner's display items over the scan-converted B-scan, see
 * sc_scan_overlay.h. The geometry is sc_scanconv's fit (build_linear, build_sector). */
#include "sc_scan_overlay.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The 5x7 font, shared with the viewer (tools/viewer/vw_overlay.c calls sc_overlay_text). */
/* Rows top to bottom, bit 4 = leftmost column. */
static const uint8_t k_digits[10][7] = {
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},
};
static const uint8_t k_upper[26][7] = {
    {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}, {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E},
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}, {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C},
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10},
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}, {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C},
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11},
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10},
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}, {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}, {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04},
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}, {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11},
    {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F},
};
static const struct {
    char c;
    uint8_t rows[7];
} k_punct[] = {
    {'.', {0, 0, 0, 0, 0, 0x0C, 0x0C}},
    {'+', {0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {':', {0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0}},
    {'/', {0, 0x01, 0x02, 0x04, 0x08, 0x10, 0}},
    {'-', {0, 0, 0, 0x1F, 0, 0, 0}},
    {'=', {0, 0, 0x1F, 0, 0x1F, 0, 0}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
};

static const uint8_t *glyph(char c)
{
    if (c >= '0' && c <= '9') {
        return k_digits[c - '0'];
    }
    if (c >= 'a' && c <= 'z') {
        c = (char)(c - 'a' + 'A');
    }
    if (c >= 'A' && c <= 'Z') {
        return k_upper[c - 'A'];
    }
    for (size_t i = 0; i < sizeof k_punct / sizeof k_punct[0]; i++) {
        if (k_punct[i].c == c) {
            return k_punct[i].rows;
        }
    }
    return NULL;
}

static void fill(uint8_t *img, uint32_t w, uint32_t h, int x, int y, int rw, int rh, uint8_t v)
{
    for (int j = y; j < y + rh; j++) {
        if (j < 0 || (uint32_t)j >= h) {
            continue;
        }
        for (int i = x; i < x + rw; i++) {
            if (i >= 0 && (uint32_t)i < w) {
                img[(size_t)j * w + (uint32_t)i] = v;
            }
        }
    }
}

int sc_overlay_text(uint8_t *raster, uint32_t w, uint32_t h, int x, int y, int scale, uint8_t v,
                    const char *s)
{
    for (; *s; s++) {
        const uint8_t *gl = glyph(*s);
        if (gl) {
            for (int r = 0; r < 7; r++) {
                for (int c = 0; c < 5; c++) {
                    if (gl[r] & (0x10u >> c)) {
                        fill(raster, w, h, x + c * scale, y + r * scale, scale, scale, v);
                    }
                }
            }
        }
        x += 6 * scale;
    }
    return x;
}

/* Text on a dark band one pixel wider all round. */
static int label(uint8_t *r, uint32_t w, uint32_t h, int x, int y, const char *s)
{
    const int n = (int)strlen(s);
    fill(r, w, h, x - 1, y - 1, 6 * n + 1, 9, SC_OVERLAY_BG);
    return sc_overlay_text(r, w, h, x, y, 1, SC_OVERLAY_FG, s);
}

int sc_overlay_edge_px(const sc_display_frame_info *g, uint32_t w, uint32_t h, double depth_mm,
                       int right, double *px, double *py)
{
    const double d_mm = g->depth_mm > 0.0f ? g->depth_mm : 1.0;
    if (!(depth_mm >= 0.0 && depth_mm <= d_mm) || w == 0u || h == 0u) {
        return -1;
    }
    if (g->geometry_id == 1u) {
        const double r0 = g->radius_mm > 0.0f ? g->radius_mm : 0.0, r1 = r0 + d_mm;
        const double half = (g->width_mm > 0.0f ? g->width_mm : 60.0) * M_PI / 360.0;
        const double w_mm = 2.0 * r1 * sin(half), z0 = r0 * cos(half), h_mm = r1 - z0;
        const double s = fmax(w_mm / w, h_mm / h);
        const double r = r0 + depth_mm, a = right ? half : -half;
        /* pixel (x, y) has its centre at x + 0.5: the point's pixel coordinates */
        *px = w / 2.0 + r * sin(a) / s - 0.5;
        *py = (r * cos(a) - z0) / s - 0.5;
        return 0;
    }
    const double w_mm = g->width_mm > 0.0f ? g->width_mm : 1.0;
    const double s = fmax(w_mm / w, d_mm / h);
    const double x0 = (w - w_mm / s) / 2.0;
    *px = (right ? x0 + w_mm / s : x0) - 0.5;
    *py = depth_mm / s - 0.5;
    return 0;
}

/* Depth scale: a tick every 5 mm (major, numbered, every 10 mm) pointing into the image from
 * its right edge. */
static void depth_scale(uint8_t *r, uint32_t w, uint32_t h, const sc_display_frame_info *g)
{
    for (int mm = 5; mm <= (int)g->depth_mm; mm += 5) {
        double x, y;
        if (sc_overlay_edge_px(g, w, h, (double)mm, 1, &x, &y) != 0) {
            continue;
        }
        const int major = mm % 10 == 0;
        const int len = major ? 10 : 5;
        const int xi = (int)lround(x), yi = (int)lround(y);
        fill(r, w, h, xi - len + 1, yi, len, 1, SC_OVERLAY_FG);
        if (major) {
            char t[16];
            snprintf(t, sizeof t, "%d", mm / 10);
            label(r, w, h, xi - len - 2 - 6 * (int)strlen(t), yi - 3, t);
        }
    }
}

/* Focus: a triangle pointing into the image from the left edge at the focus depth. */
static void focus_marker(uint8_t *r, uint32_t w, uint32_t h, const sc_display_frame_info *g)
{
    double x, y;
    if (!(g->focus_mm > 0.0f) || sc_overlay_edge_px(g, w, h, g->focus_mm, 0, &x, &y) != 0) {
        return;
    }
    const int xl = (int)lround(x), yi = (int)lround(y);
    const int xi = xl < 0 ? 0 : xl; /* the edge pixel, inside the raster */
    for (int i = 0; i < 5; i++) {
        fill(r, w, h, xi + i, yi - (4 - i), 1, 2 * (4 - i) + 1, SC_OVERLAY_FG);
    }
}

void sc_overlay_draw(uint8_t *raster, uint32_t w, uint32_t h, const sc_display_frame_info *g)
{
    sc_overlay_draw_below(raster, w, h, g, 0);
}

/* the plane's untouched value: neither SC_OVERLAY_FG nor SC_OVERLAY_BG */
#define SC_OVERLAY_NONE 128u
_Static_assert(SC_OVERLAY_NONE != SC_OVERLAY_FG && SC_OVERLAY_NONE != SC_OVERLAY_BG,
               "the untouched value differs from what the overlay writes");

void sc_overlay_draw_rgb(uint8_t *rgb, uint8_t *plane, uint32_t w, uint32_t h,
                         const sc_display_frame_info *g)
{
    if (rgb == NULL || plane == NULL) {
        return;
    }
    const size_t n = (size_t)w * h;
    memset(plane, SC_OVERLAY_NONE, n);
    sc_overlay_draw(plane, w, h, g);
    for (size_t i = 0; i < n; i++) {
        if (plane[i] != SC_OVERLAY_NONE) {
            rgb[3u * i] = rgb[3u * i + 1u] = rgb[3u * i + 2u] = plane[i];
        }
    }
}

void sc_overlay_draw_below(uint8_t *raster, uint32_t w, uint32_t h, const sc_display_frame_info *g,
                           int top_px)
{
    if (raster == NULL || g == NULL || w < 32u || h < 32u || !(g->depth_mm > 0.0f)) {
        return;
    }
    depth_scale(raster, w, h, g);
    focus_marker(raster, w, h, g);
    /* orientation: the side of scan line 0, at the top */
    double x, y;
    if (sc_overlay_edge_px(g, w, h, 0.0, 0, &x, &y) == 0) {
        fill(raster, w, h, (int)lround(x) + 2, top_px + 2, 7, 7, SC_OVERLAY_FG);
    }
    /* readout, top left below the marker: probe, depth; gain, range; TGC */
    char t[96];
    const int probe_l = g->geometry_id == 1u;
    if (g->frequency_mhz > 0.0f) {
        snprintf(t, sizeof t, "%s %.1fMHZ D%.1fCM", probe_l ? "C" : "L", (double)g->frequency_mhz,
                 (double)g->depth_mm / 10.0);
    } else {
        snprintf(t, sizeof t, "%s D%.1fCM", probe_l ? "C" : "L", (double)g->depth_mm / 10.0);
    }
    label(raster, w, h, 14, top_px + 3, t);
    if (g->dynamic_range_db > 0.0f) {
        snprintf(t, sizeof t, "G%+.0fDB DR%.0f", (double)g->gain_db, (double)g->dynamic_range_db);
        label(raster, w, h, 14, top_px + 13, t);
        int n = snprintf(t, sizeof t, "TGC");
        for (uint32_t i = 0; i < SC_DISPLAY_TGC_BANDS && n > 0 && (size_t)n < sizeof t; i++) {
            n += snprintf(t + n, sizeof t - (size_t)n, " %+.0f", (double)g->tgc_db[i]);
        }
        label(raster, w, h, 14, top_px + 23, t);
    }
}
