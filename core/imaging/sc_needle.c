/* sc_needle.c: the tracked needle in the B-scan and its punctures (see sc_needle.h). */
#include "sc_needle.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"

sc_needle_def sc_needle_default_def(void)
{
    return (sc_needle_def){
        .radius_mm = 0.6f, .elev_half_mm = 1.0f, .reverb_spacing_mm = 1.0f, .reverb_count = 4u};
}

int sc_needle_init(sc_needle *n, const sc_needle_def *def)
{
    if (n == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(def->radius_mm) || !isfinite(def->elev_half_mm) ||
        !isfinite(def->reverb_spacing_mm)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(def->radius_mm > 0.0f && def->radius_mm <= 2.0f) ||
        !(def->elev_half_mm > 0.0f && def->elev_half_mm <= 5.0f) ||
        !(def->reverb_spacing_mm > 0.0f && def->reverb_spacing_mm <= 5.0f) ||
        def->reverb_count > 8u) {
        return SC_ERR_RANGE;
    }
    memset(n, 0, sizeof *n);
    n->def = *def;
    return SC_OK;
}

void sc_needle_set(sc_needle *n, int present, const float tip_mm[3], const float dir[3],
                   float depth_mm)
{
    n->present = 0u;
    if (!present || tip_mm == NULL || dir == NULL || !isfinite(depth_mm) || depth_mm < 0.0f) {
        return;
    }
    for (unsigned i = 0; i < 3u; i++) {
        if (!isfinite(tip_mm[i]) || !isfinite(dir[i])) {
            return;
        }
        n->tip_mm[i] = tip_mm[i];
        n->dir[i] = dir[i];
    }
    n->depth_mm = depth_mm;
    n->present = 1u;
}

void sc_needle_frame_begin(sc_needle *n, const sc_xform *img2vol)
{
    sc_needle_status *st = &n->status;
    st->present = n->present;
    st->drawn_pixels = 0u;
    st->in_plane = 0u;
    n->visible = 0u;
    n->tip_best_d2 = INFINITY;
    n->tip_line_label = SC_LABEL_OUTSIDE;
    if (!n->present) {
        return;
    }
    const sc_xform v2i = sc_xform_inverse(img2vol);
    float hub[3], a[3], b[3];
    for (unsigned i = 0; i < 3u; i++) {
        hub[i] = n->tip_mm[i] - n->depth_mm * n->dir[i];
    }
    sc_xform_apply(&v2i, hub, a);
    sc_xform_apply(&v2i, n->tip_mm, b);
    memcpy(n->tip_img, b, sizeof b);
    /* clip the shaft to the elevational slab |y| <= h */
    const float h = n->def.elev_half_mm;
    float t0 = 0.0f, t1 = 1.0f;
    const float dy = b[1] - a[1];
    if (fabsf(dy) < 1e-6f) {
        if (fabsf(a[1]) > h) {
            return;
        }
    } else {
        float ta = (-h - a[1]) / dy, tb = (h - a[1]) / dy;
        if (ta > tb) {
            const float t = ta;
            ta = tb;
            tb = t;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
        if (t0 > t1) {
            return;
        }
    }
    st->in_plane = (uint8_t)(t0 <= 0.0f && t1 >= 1.0f);
    n->e0x = a[0] + t0 * (b[0] - a[0]);
    n->e0z = a[2] + t0 * (b[2] - a[2]);
    n->e1x = a[0] + t1 * (b[0] - a[0]);
    n->e1z = a[2] + t1 * (b[2] - a[2]);
    /* specular: the shaft's in-plane direction across the (vertical) beam */
    const float lx = b[0] - a[0], lz = b[2] - a[2];
    const float ll = sqrtf(lx * lx + lz * lz);
    n->spec = ll > 1e-6f ? fabsf(lx) / ll : 0.0f;
    n->visible = 1u;
}

/* Squared distance of (px, pz) to the segment (ax, az)-(bx, bz). */
static float seg_d2(float px, float pz, float ax, float az, float bx, float bz)
{
    const float vx = bx - ax, vz = bz - az;
    const float l2 = vx * vx + vz * vz;
    float t = l2 > 0.0f ? ((px - ax) * vx + (pz - az) * vz) / l2 : 0.0f;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    const float dx = px - (ax + t * vx), dz = pz - (az + t * vz);
    return dx * dx + dz * dz;
}

void sc_needle_line(sc_needle *n, const sc_bscan_line_view *v)
{
    if (!n->present) {
        return;
    }
    /* the tip's label in the deformed configuration: from the sample nearest the tip, when the
     * tip is in the slab */
    if (fabsf(n->tip_img[1]) <= n->def.elev_half_mm) {
        const float l2 = v->dir_x * v->dir_x + v->dir_z * v->dir_z;
        if (l2 > 0.0f) {
            float s = ((n->tip_img[0] - v->org_x) * v->dir_x + (n->tip_img[2] - v->org_z) * v->dir_z) /
                      l2;
            if (s >= 0.0f && s <= (float)(v->samples_n - 1u)) {
                const uint32_t k = (uint32_t)(s + 0.5f);
                const float dx = v->org_x + (float)k * v->dir_x - n->tip_img[0];
                const float dz = v->org_z + (float)k * v->dir_z - n->tip_img[2];
                const float d2 = dx * dx + dz * dz;
                if (d2 < n->tip_best_d2) {
                    n->tip_best_d2 = d2;
                    n->tip_line_label = v->labels[k];
                }
            }
        }
    }
    if (!n->visible) {
        return;
    }
    const float r = n->def.radius_mm, r2 = r * r;
    const uint32_t echoes = n->def.reverb_count;
    const float reach = r + (float)echoes * n->def.reverb_spacing_mm;
    /* the samples of this line within the shaft's box (grown by its echoes below it) */
    const float xmin = fminf(n->e0x, n->e1x) - r, xmax = fmaxf(n->e0x, n->e1x) + r;
    const float zmin = fminf(n->e0z, n->e1z) - r, zmax = fmaxf(n->e0z, n->e1z) + reach;
    float s0 = 0.0f, s1 = (float)(v->samples_n - 1u);
    const float o[2] = {v->org_x, v->org_z}, d[2] = {v->dir_x, v->dir_z};
    const float lo[2] = {xmin, zmin}, hi[2] = {xmax, zmax};
    for (unsigned a = 0; a < 2u; a++) {
        if (fabsf(d[a]) < 1e-9f) {
            if (o[a] < lo[a] || o[a] > hi[a]) {
                return;
            }
            continue;
        }
        float ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        if (ta > tb) {
            const float t = ta;
            ta = tb;
            tb = t;
        }
        s0 = ta > s0 ? ta : s0;
        s1 = tb < s1 ? tb : s1;
    }
    if (s0 > s1) {
        return;
    }
    const uint32_t k0 = (uint32_t)ceilf(s0), k1 = (uint32_t)floorf(s1);
    for (uint32_t k = k0; k <= k1 && k < v->samples_n; k++) {
        const float px = v->org_x + (float)k * v->dir_x, pz = v->org_z + (float)k * v->dir_z;
        float val = 0.0f;
        if (seg_d2(px, pz, n->e0x, n->e0z, n->e1x, n->e1z) <= r2) {
            val = 255.0f;
        } else {
            float amp = 0.55f * n->spec;
            for (uint32_t e = 1; e <= echoes && amp * 255.0f >= 8.0f; e++) {
                const float sh = (float)e * n->def.reverb_spacing_mm;
                if (seg_d2(px, pz, n->e0x, n->e0z + sh, n->e1x, n->e1z + sh) <= 0.5f * r2) {
                    val = 255.0f * amp;
                    break;
                }
                amp *= 0.6f;
            }
        }
        if (val > (float)v->out[k]) {
            v->out[k] = (uint8_t)(val + 0.5f);
            n->status.drawn_pixels++;
        }
    }
}

static uint8_t rigid_label(const sc_volume *v, const float p[3])
{
    if (v == NULL || v->labels == NULL) {
        return SC_LABEL_OUTSIDE;
    }
    int32_t idx[3];
    for (unsigned a = 0; a < 3u; a++) {
        const float f = (p[a] - v->origin_mm[a]) / v->spacing_mm[a];
        if (!(f >= -0.5f && f < (float)v->dim[a] - 0.5f)) {
            return SC_LABEL_OUTSIDE;
        }
        idx[a] = (int32_t)(f + 0.5f);
    }
    return v->labels[(size_t)idx[0] +
                     (size_t)v->dim[0] * ((size_t)idx[1] + (size_t)v->dim[1] * (size_t)idx[2])];
}

int sc_needle_frame_end(sc_needle *n, const sc_volume *v)
{
    sc_needle_status *st = &n->status;
    if (!n->present) {
        st->tip_label = SC_LABEL_OUTSIDE;
        n->prev_label = SC_LABEL_OUTSIDE;
        return 0;
    }
    /* the nearest sample must be within a sample pitch or so of the tip */
    const int from_line = n->tip_best_d2 <= 0.25f;
    const uint8_t lab = from_line ? n->tip_line_label : rigid_label(v, n->tip_mm);
    st->tip_label = lab;
    st->tip_label_deformed = (uint8_t)from_line;
    const int lumen = lab == SC_LABEL_VEIN || lab == SC_LABEL_ARTERY;
    const int entered = lumen && lab != n->prev_label;
    n->prev_label = lab;
    if (!entered) {
        return 0;
    }
    st->last_puncture = lab;
    if (lab == SC_LABEL_VEIN) {
        st->vein_punctures++;
    } else {
        st->artery_punctures++;
    }
    return 1;
}

const sc_needle_status *sc_needle_status_get(const sc_needle *n)
{
    return &n->status;
}
