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
