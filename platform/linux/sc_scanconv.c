/* sc_scanconv.c: B-scan scan conversion, see sc_scanconv.h. */
#include "sc_scanconv.h"

#include "sc_doppler.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int sc_scanconv_init(sc_scanconv *c, uint32_t width, uint32_t height)
{
    memset(c, 0, sizeof(*c));
    c->lut = malloc((size_t)width * height * sizeof(uint32_t));
    if (!c->lut) {
        return -1;
    }
    c->width = c->cap_w = width;
    c->height = c->cap_h = height;
    return 0;
}

void sc_scanconv_set_fit(sc_scanconv *c, int on)
{
    c->fit = on != 0;
    c->valid = 0;
    if (!c->fit) {
        c->width = c->cap_w;
        c->height = c->cap_h;
    }
}

/* The image's physical box (mm): linear width x depth; curvilinear the fan's bounding box. */
static void image_box_mm(const sc_display_frame_info *g, double *w_mm, double *h_mm)
{
    const double d_mm = g->depth_mm > 0.0f ? g->depth_mm : 1.0;
    if (g->geometry_id == 1u) {
        const double r0 = g->radius_mm > 0.0f ? g->radius_mm : 0.0;
        const double r1 = r0 + d_mm;
        const double half = (g->width_mm > 0.0f ? g->width_mm : 60.0) * M_PI / 360.0;
        *w_mm = 2.0 * r1 * sin(half);
        *h_mm = r1 - r0 * cos(half);
    } else {
        *w_mm = g->width_mm > 0.0f ? g->width_mm : 1.0;
        *h_mm = d_mm;
    }
}

static uint32_t fit_side(double mm, double s, uint32_t cap)
{
    const double px = floor(mm / s + 1e-6);
    return px < 1.0 ? 1u : (px > (double)cap ? cap : (uint32_t)px);
}

void sc_scanconv_fit_size(const sc_display_frame_info *info, uint32_t cap_w, uint32_t cap_h,
                          uint32_t *w, uint32_t *h)
{
    double w_mm, h_mm;
    image_box_mm(info, &w_mm, &h_mm);
    const double s = fmax(w_mm / cap_w, h_mm / cap_h); /* mm per pixel in the canvas */
    *w = fit_side(w_mm, s, cap_w);
    *h = fit_side(h_mm, s, cap_h);
}

void sc_scanconv_free(sc_scanconv *c)
{
    free(c->lut);
    memset(c, 0, sizeof(*c));
}

static int same_geom(const sc_display_frame_info *a, const sc_display_frame_info *b)
{
    return a->lines == b->lines && a->samples == b->samples && a->geometry_id == b->geometry_id &&
           memcmp(&a->depth_mm, &b->depth_mm, sizeof(float)) == 0 &&
           memcmp(&a->radius_mm, &b->radius_mm, sizeof(float)) == 0 &&
           memcmp(&a->width_mm, &b->width_mm, sizeof(float)) == 0;
}

static void build_linear(sc_scanconv *c, const sc_display_frame_info *g, uint32_t stride)
{
    const double w_mm = g->width_mm > 0.0f ? g->width_mm : 1.0;
    const double d_mm = g->depth_mm > 0.0f ? g->depth_mm : 1.0;
    /* mm per pixel: fit the whole image, keep the aspect */
    const double s = fmax(w_mm / c->width, d_mm / c->height);
    const double x0 = (c->width - w_mm / s) / 2.0;
    for (uint32_t y = 0; y < c->height; y++) {
        for (uint32_t x = 0; x < c->width; x++) {
            const double xm = (x + 0.5 - x0) * s;
            const double zm = (y + 0.5) * s;
            uint32_t v = UINT32_MAX;
            if (xm >= 0.0 && xm < w_mm && zm < d_mm) {
                uint32_t l = (uint32_t)(xm / w_mm * g->lines);
                uint32_t k = (uint32_t)(zm / d_mm * g->samples);
                if (l < g->lines && k < g->samples) {
                    v = l * stride + k;
                }
            }
            c->lut[(size_t)y * c->width + x] = v;
        }
    }
}

static void build_sector(sc_scanconv *c, const sc_display_frame_info *g, uint32_t stride)
{
    const double d_mm = g->depth_mm > 0.0f ? g->depth_mm : 1.0;
    const double r0 = g->radius_mm > 0.0f ? g->radius_mm : 0.0;
    const double r1 = r0 + d_mm;
    const double half = (g->width_mm > 0.0f ? g->width_mm : 60.0) * M_PI / 360.0;
    /* bounding box of the fan (apex at the origin, beam along +z) */
    const double w_mm = 2.0 * r1 * sin(half);
    const double z0 = r0 * cos(half);
    const double h_mm = r1 - z0;
    const double s = fmax(w_mm / c->width, h_mm / c->height);
    const double cx = c->width / 2.0;
    for (uint32_t y = 0; y < c->height; y++) {
        for (uint32_t x = 0; x < c->width; x++) {
            const double xm = (x + 0.5 - cx) * s;
            const double zm = z0 + (y + 0.5) * s;
            const double r = sqrt(xm * xm + zm * zm);
            const double a = atan2(xm, zm);
            uint32_t v = UINT32_MAX;
            if (r >= r0 && r < r1 && a >= -half && a < half) {
                uint32_t l = (uint32_t)((a + half) / (2.0 * half) * g->lines);
                uint32_t k = (uint32_t)((r - r0) / d_mm * g->samples);
                if (l < g->lines && k < g->samples) {
                    v = l * stride + k;
                }
            }
            c->lut[(size_t)y * c->width + x] = v;
        }
    }
}

static void ensure_lut(sc_scanconv *c, const sc_display_frame_info *info, uint32_t stride);

void sc_scanconv_render_colour(sc_scanconv *c, const sc_display_frame_info *info,
                               const uint8_t *image, const int8_t *colour, uint32_t stride,
                               uint8_t *rgb)
{
    ensure_lut(c, info, stride);
    const size_t n = (size_t)c->width * c->height;
    for (size_t i = 0; i < n; i++) {
        const uint32_t v = c->lut[i];
        uint8_t *px = rgb + 3u * i;
        if (v == UINT32_MAX) {
            px[0] = px[1] = px[2] = 0u;
        } else if (colour[v] != 0) {
            sc_doppler_colour_rgb(colour[v], px);
        } else {
            px[0] = px[1] = px[2] = image[v];
        }
    }
}

static void ensure_lut(sc_scanconv *c, const sc_display_frame_info *info, uint32_t stride)
{
    if (!c->valid || c->stride != stride || !same_geom(&c->geom, info)) {
        if (c->fit) {
            sc_scanconv_fit_size(info, c->cap_w, c->cap_h, &c->width, &c->height);
        }
        if (info->geometry_id == 1u) {
            build_sector(c, info, stride);
        } else {
            build_linear(c, info, stride);
        }
        c->geom = *info;
        c->stride = stride;
        c->valid = 1;
    }
}

void sc_scanconv_render(sc_scanconv *c, const sc_display_frame_info *info, const uint8_t *image,
                        uint32_t stride, uint8_t *out)
{
    ensure_lut(c, info, stride);
    const size_t n = (size_t)c->width * c->height;
    for (size_t i = 0; i < n; i++) {
        const uint32_t v = c->lut[i];
        out[i] = v == UINT32_MAX ? 0u : image[v];
    }
}
