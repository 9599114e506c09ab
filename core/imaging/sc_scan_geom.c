/* sc_scan_geom.c: scan geometry of linear and curvilinear probes, see sc_scan_geom.h. */
#include "sc_scan_geom.h"

#include <math.h>
#include <stddef.h>

#include "sc_err.h"

#define SC_SCAN_PI_F 3.14159265358979323846f

sc_scan_def sc_scan_default_def(void)
{
    sc_scan_def d;
    d.kind = SC_SCAN_GEOM_LINEAR;
    d.lines_n = 256u;
    d.samples_n = 512u;
    d.depth_mm = 60.0f;
    d.width_mm = 38.0f;
    d.radius_mm = 40.0f;
    d.sector_deg = 60.0f;
    d.image_to_probe = sc_xform_identity();
    return d;
}

sc_scan_def sc_scan_curvilinear_default_def(void)
{
    sc_scan_def d = sc_scan_default_def();
    d.kind = SC_SCAN_GEOM_CURVILINEAR;
    d.lines_n = 128u;
    d.depth_mm = 80.0f;
    return d;
}

static int def_valid(const sc_scan_def *d)
{
    if (d->kind != SC_SCAN_GEOM_LINEAR && d->kind != SC_SCAN_GEOM_CURVILINEAR) {
        return 0;
    }
    if (d->lines_n < 2u || d->lines_n > SC_MAX_SCAN_LINES || d->samples_n < 2u ||
        d->samples_n > SC_MAX_SCAN_SAMPLES) {
        return 0;
    }
    if (!isfinite(d->depth_mm) || !(d->depth_mm > 0.0f) || d->depth_mm > 300.0f) {
        return 0;
    }
    if (d->kind == SC_SCAN_GEOM_LINEAR) {
        if (!isfinite(d->width_mm) || !(d->width_mm > 0.0f) || d->width_mm > 200.0f) {
            return 0;
        }
    } else {
        if (!isfinite(d->radius_mm) || !(d->radius_mm > 0.0f) || d->radius_mm > 200.0f) {
            return 0;
        }
        if (!isfinite(d->sector_deg) || !(d->sector_deg > 0.0f) || d->sector_deg > 170.0f) {
            return 0;
        }
    }
    return sc_xform_is_rigid(&d->image_to_probe, 1e-4f);
}

int sc_scan_geom_init(sc_scan_geom *g, const sc_scan_def *def)
{
    if (g == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!def_valid(def)) {
        return SC_ERR_IMG_GEOMETRY;
    }
    g->def = *def;
    const float dr = def->depth_mm / (float)def->samples_n;
    g->sample_mm = dr;
    if (def->kind == SC_SCAN_GEOM_LINEAR) {
        const float pitch = def->width_mm / (float)def->lines_n;
        g->line_first = -0.5f * def->width_mm + 0.5f * pitch;
        g->line_pitch = pitch;
        for (uint32_t l = 0; l < def->lines_n; l++) {
            g->start_x_mm[l] = g->line_first + (float)l * pitch;
            g->start_z_mm[l] = 0.5f * dr;
            g->step_x_mm[l] = 0.0f;
            g->step_z_mm[l] = dr;
        }
        for (uint32_t k = 0; k < def->samples_n; k++) {
            g->sample_area_mm2[k] = pitch * dr;
        }
        g->s_min = -(float)def->samples_n;
    } else {
        const float sector = def->sector_deg * (SC_SCAN_PI_F / 180.0f);
        const float dth = sector / (float)def->lines_n;
        const float r0 = def->radius_mm + 0.5f * dr;
        g->line_first = -0.5f * sector + 0.5f * dth;
        g->line_pitch = dth;
        for (uint32_t l = 0; l < def->lines_n; l++) {
            const float th = g->line_first + (float)l * dth;
            const float s = sinf(th), c = cosf(th);
            g->start_x_mm[l] = r0 * s;
            g->start_z_mm[l] = r0 * c - def->radius_mm;
            g->step_x_mm[l] = dr * s;
            g->step_z_mm[l] = dr * c;
        }
        for (uint32_t k = 0; k < def->samples_n; k++) {
            g->sample_area_mm2[k] = (r0 + (float)k * dr) * dth * dr;
        }
        g->s_min = -r0 / dr;
    }
    return SC_OK;
}

void sc_scan_geom_pixel(const sc_scan_geom *g, uint32_t l, uint32_t k, float out_mm[3])
{
    out_mm[0] = g->start_x_mm[l] + (float)k * g->step_x_mm[l];
    out_mm[1] = 0.0f;
    out_mm[2] = g->start_z_mm[l] + (float)k * g->step_z_mm[l];
}

/* floorf and ceilf without the libm call (the portable x86-64 build has no rounding
 * instruction; this runs for every boundary face and plane tet of a frame): the same value for
 * every finite x in int32's range but the sign of a zero result, which the +-1 below removes;
 * libm's beyond. */
static inline float floor_nolibm(float x)
{
    if (!(x > -2147483520.0f && x < 2147483520.0f)) {
        return floorf(x);
    }
    const float t = (float)(int32_t)x; /* toward zero, exact below 2^24; above, x is whole */
    return t > x ? t - 1.0f : t;
}

static inline float ceil_nolibm(float x)
{
    if (!(x > -2147483520.0f && x < 2147483520.0f)) {
        return ceilf(x);
    }
    const float t = (float)(int32_t)x;
    return t < x ? t + 1.0f : t;
}

int sc_scan_geom_line_range(const sc_scan_geom *g, float xmin, float xmax, float zmin, float zmax,
                            int32_t *lo, int32_t *hi)
{
    const int32_t last = (int32_t)g->def.lines_n - 1;
    float a, b;
    if (g->def.kind == SC_SCAN_GEOM_LINEAR) {
        a = (xmin - g->line_first) / g->line_pitch;
        b = (xmax - g->line_first) / g->line_pitch;
    } else {
        const float za = g->def.radius_mm; /* z + R: distance in front of the apex */
        if (!(zmax + za > 0.0f)) {
            return 0;
        }
        const float z0 = (zmin + za > 1e-3f) ? zmin + za : 1e-3f;
        const float z1 = zmax + za;
        const float c0 = atan2f(xmin, z0), c1 = atan2f(xmax, z0);
        const float c2 = atan2f(xmin, z1), c3 = atan2f(xmax, z1);
        float amin = fminf(fminf(c0, c1), fminf(c2, c3));
        float amax = fmaxf(fmaxf(c0, c1), fmaxf(c2, c3));
        a = (amin - g->line_first) / g->line_pitch;
        b = (amax - g->line_first) / g->line_pitch;
    }
    if (!(b >= -1.0f) || !(a <= (float)last + 1.0f)) {
        return 0;
    }
    float fa = floor_nolibm(a) - 1.0f, fb = ceil_nolibm(b) + 1.0f;
    *lo = fa < 0.0f ? 0 : (int32_t)fa;
    *hi = fb > (float)last ? last : (int32_t)fb;
    return *lo <= *hi;
}
