/* gw_bscan.c: the console's B-scan message, see gw_bscan.h and docs/console.md. */
#include "gw_bscan.h"

#include <string.h>

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) {
        p[i] = (uint8_t)(v >> (8 * i));
    }
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof v);
    put_u32(p, v);
}

void gw_spectrum_clear(gw_spectrum_hist *h)
{
    h->n = 0u;
    h->head = 0u;
    h->bins = 0u;
}

static void spectrum_push(gw_spectrum_hist *h, uint32_t frame_no, const uint8_t *col, uint16_t bins)
{
    if (bins != h->bins) {
        gw_spectrum_clear(h);
        h->bins = bins;
    }
    h->frame_no[h->head] = frame_no;
    memcpy(h->col[h->head], col, bins);
    h->head = (h->head + 1u) % GW_BSCAN_COLUMNS;
    if (h->n < GW_BSCAN_COLUMNS) {
        h->n++;
    }
}

/* The Doppler record's box and gate agree with the frame's geometry (the display link's
 * decoder checked it against the packet's frame; checked again here because the record may be
 * a later frame's geometry's after a lost FRAME_BEGIN). */
static int doppler_ok(const sc_dlink_done *d)
{
    const sc_dlink_doppler *p = &d->doppler;
    const uint32_t lines = d->frame.line_count, samples = d->frame.samples;
    return p->box_line_lo < p->box_line_hi && p->box_line_hi <= lines &&
           p->box_sample_lo < p->box_sample_hi && p->box_sample_hi <= samples &&
           p->gate_line < lines && p->gate_sample_lo < p->gate_sample_hi &&
           p->gate_sample_hi <= samples && p->bins <= SC_DLINK_SPECTRUM_MAX;
}

size_t gw_bscan_build(uint8_t *out, size_t cap, const sc_dlink_done *d, gw_spectrum_hist *h)
{
    const uint32_t lines = d->frame.line_count, samples = d->frame.samples;
    if (d->image == NULL || lines == 0u || samples == 0u || lines > SC_MAX_SCAN_LINES ||
        samples > SC_MAX_SCAN_SAMPLES) {
        return 0u;
    }
    const int dop = d->doppler_seen && doppler_ok(d);
    if (dop && d->doppler.bins > 0u) {
        spectrum_push(h, d->frame.frame_no, d->doppler.spectrum, d->doppler.bins);
    }
    const uint32_t bl = dop ? (uint32_t)d->doppler.box_line_hi - d->doppler.box_line_lo : 0u;
    const uint32_t bs = dop ? (uint32_t)d->doppler.box_sample_hi - d->doppler.box_sample_lo : 0u;
    const int col = dop && d->colour != NULL;
    const uint32_t ncol = dop ? h->n : 0u;
    size_t need = GW_BSCAN_HDR + (size_t)lines * samples;
    if (d->params_known) {
        need += GW_BSCAN_PARAMS;
    }
    if (dop) {
        need += GW_BSCAN_DOPPLER + (size_t)ncol * (4u + h->bins);
    }
    if (col) {
        need += (size_t)bl * bs;
    }
    if (need > cap) {
        return 0u;
    }
    uint8_t *m = out;
    memset(m, 0, GW_BSCAN_HDR);
    m[0] = 'B';
    m[1] = (uint8_t)((d->params_known ? GW_BSCAN_HAS_PARAMS : 0u) |
                     (dop ? GW_BSCAN_HAS_DOPPLER : 0u) | (col ? GW_BSCAN_HAS_COLOUR : 0u));
    put_u32(m + 4, d->frame.frame_no);
    put_u16(m + 8, (uint16_t)lines);
    put_u16(m + 10, (uint16_t)samples);
    put_u16(m + 12, d->frame.geometry_id);
    put_u16(m + 14, d->frame.flags);
    put_f32(m + 16, d->begin.depth_mm);
    put_f32(m + 20, d->begin.width_mm);
    put_f32(m + 24, d->begin.radius_mm);
    put_u16(m + 28, d->end.compression_pm);
    put_u16(m + 30, d->end.artery_compression_pm);
    m += GW_BSCAN_HDR;
    for (uint32_t l = 0; l < lines; l++) { /* the assembler's rows have a fixed stride */
        memcpy(m + (size_t)l * samples, d->image + (size_t)l * SC_MAX_SCAN_SAMPLES, samples);
    }
    m += (size_t)lines * samples;
    if (d->params_known) {
        put_f32(m, d->params.gain_db);
        put_f32(m + 4, d->params.dynamic_range_db);
        put_f32(m + 8, d->params.focus_mm);
        put_f32(m + 12, d->params.frequency_mhz);
        for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC; i++) {
            put_f32(m + 16 + 4 * i, d->params.tgc_db[i]);
        }
        m += GW_BSCAN_PARAMS;
    }
    if (dop) {
        const sc_dlink_doppler *p = &d->doppler;
        put_u16(m, p->box_line_lo);
        put_u16(m + 2, p->box_line_hi);
        put_u16(m + 4, p->box_sample_lo);
        put_u16(m + 6, p->box_sample_hi);
        put_f32(m + 8, p->nyquist_mm_s);
        put_f32(m + 12, p->steer_deg);
        put_f32(m + 16, p->gate_velocity_mm_s);
        put_u16(m + 20, p->gate_line);
        put_u16(m + 22, p->gate_sample_lo);
        put_u16(m + 24, p->gate_sample_hi);
        put_u16(m + 26, (uint16_t)h->bins);
        put_u16(m + 28, (uint16_t)ncol);
        put_u16(m + 30, 0u);
        m += GW_BSCAN_DOPPLER;
        for (uint32_t i = 0; i < ncol; i++) { /* oldest first */
            const uint32_t s = (h->head + GW_BSCAN_COLUMNS - ncol + i) % GW_BSCAN_COLUMNS;
            put_u32(m, h->frame_no[s]);
            memcpy(m + 4, h->col[s], h->bins);
            m += 4u + h->bins;
        }
    }
    if (col) {
        for (uint32_t l = 0; l < bl; l++) {
            const int8_t *row = d->colour + (size_t)(d->doppler.box_line_lo + l) * SC_MAX_SCAN_SAMPLES +
                                d->doppler.box_sample_lo;
            memcpy(m, row, bs);
            m += bs;
        }
    }
    return (size_t)(m - out);
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static float get_f32(const uint8_t *p)
{
    const uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

int gw_bscan_parse(const uint8_t *m, size_t n, gw_bscan_view *v)
{
    memset(v, 0, sizeof *v);
    if (n < GW_BSCAN_HDR || m[0] != 'B' || (m[1] & ~0x07u) != 0u || m[2] != 0u || m[3] != 0u) {
        return -1;
    }
    v->flags = m[1];
    v->frame_no = get_u32(m + 4);
    v->lines = get_u16(m + 8);
    v->samples = get_u16(m + 10);
    v->geometry_id = get_u16(m + 12);
    v->link_flags = get_u16(m + 14);
    v->depth_mm = get_f32(m + 16);
    v->width_mm = get_f32(m + 20);
    v->radius_mm = get_f32(m + 24);
    v->vein_pm = get_u16(m + 28);
    v->artery_pm = get_u16(m + 30);
    if (v->lines == 0u || v->samples == 0u || v->lines > SC_MAX_SCAN_LINES ||
        v->samples > SC_MAX_SCAN_SAMPLES) {
        return -1;
    }
    size_t p = GW_BSCAN_HDR;
    const size_t img = (size_t)v->lines * v->samples;
    if (n - p < img) {
        return -1;
    }
    v->image = m + p;
    p += img;
    if (v->flags & GW_BSCAN_HAS_PARAMS) {
        if (n - p < GW_BSCAN_PARAMS) {
            return -1;
        }
        v->params = m + p;
        p += GW_BSCAN_PARAMS;
    }
    if ((v->flags & GW_BSCAN_HAS_COLOUR) && !(v->flags & GW_BSCAN_HAS_DOPPLER)) {
        return -1; /* colour needs its box */
    }
    if (v->flags & GW_BSCAN_HAS_DOPPLER) {
        if (n - p < GW_BSCAN_DOPPLER) {
            return -1;
        }
        const uint8_t *d = m + p;
        v->doppler = d;
        v->box_line_lo = get_u16(d);
        v->box_line_hi = get_u16(d + 2);
        v->box_sample_lo = get_u16(d + 4);
        v->box_sample_hi = get_u16(d + 6);
        v->bins = get_u16(d + 26);
        v->columns = get_u16(d + 28);
        if (v->box_line_lo >= v->box_line_hi || v->box_line_hi > v->lines ||
            v->box_sample_lo >= v->box_sample_hi || v->box_sample_hi > v->samples ||
            v->bins > SC_DLINK_SPECTRUM_MAX || v->columns > GW_BSCAN_COLUMNS ||
            get_u16(d + 30) != 0u) {
            return -1;
        }
        p += GW_BSCAN_DOPPLER;
        const size_t cols = (size_t)v->columns * (4u + v->bins);
        if (n - p < cols) {
            return -1;
        }
        v->spectrum = v->columns ? m + p : NULL;
        p += cols;
        if (v->flags & GW_BSCAN_HAS_COLOUR) {
            const size_t box = (size_t)(v->box_line_hi - v->box_line_lo) *
                               (size_t)(v->box_sample_hi - v->box_sample_lo);
            if (n - p < box) {
                return -1;
            }
            v->colour = (const int8_t *)(m + p);
            p += box;
        }
    }
    return p == n ? 0 : -1;
}
