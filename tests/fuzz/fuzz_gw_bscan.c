/* fuzz_gw_bscan.c: the console's B-scan message (tools/gateway/gw_bscan.c) from any display-link
 * datagram sequence (split by a length prefix, as fuzz_sc_dlink): every frame the assembler
 * closes becomes a message that reads back (gw_bscan_parse, the page's decoder in C) with the
 * frame's geometry, image rows and colour box; and the reader takes the raw input as a message
 * without crashing. */
#include <string.h>

#include "gw_bscan.h"
#include "sc_fuzz.h"

static sc_dlink_asm rx;
static gw_spectrum_hist hist;
static uint8_t msg[GW_BSCAN_MAX];

static void check_frame(const sc_dlink_done *d)
{
    const size_t n = gw_bscan_build(msg, sizeof msg, d, &hist);
    SC_FUZZ_CHECK(n > 0u); /* the buffer holds the largest frame */
    gw_bscan_view v;
    SC_FUZZ_CHECK(gw_bscan_parse(msg, n, &v) == 0);
    SC_FUZZ_CHECK(v.lines == d->frame.line_count && v.samples == d->frame.samples);
    SC_FUZZ_CHECK(v.frame_no == d->frame.frame_no && v.geometry_id == d->frame.geometry_id);
    for (uint32_t l = 0; l < v.lines; l++) {
        SC_FUZZ_CHECK(memcmp(v.image + (size_t)l * v.samples,
                             d->image + (size_t)l * SC_MAX_SCAN_SAMPLES, v.samples) == 0);
    }
    SC_FUZZ_CHECK(((v.params != NULL) == (d->params_known != 0)));
    if (v.colour != NULL) {
        SC_FUZZ_CHECK(d->colour != NULL && d->doppler_seen);
        const uint32_t bs = (uint32_t)v.box_sample_hi - v.box_sample_lo;
        for (uint32_t l = v.box_line_lo; l < v.box_line_hi; l++) {
            SC_FUZZ_CHECK(memcmp(v.colour + (size_t)(l - v.box_line_lo) * bs,
                                 d->colour + (size_t)l * SC_MAX_SCAN_SAMPLES + v.box_sample_lo,
                                 bs) == 0);
        }
    }
    SC_FUZZ_CHECK(v.columns <= GW_BSCAN_COLUMNS && v.bins <= SC_DLINK_SPECTRUM_MAX);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_dlink_asm_init(&rx);
    gw_spectrum_clear(&hist);
    gw_bscan_view v;
    (void)gw_bscan_parse(data, size, &v);
    size_t off = 0;
    while (off + 2u <= size) {
        size_t len = (size_t)data[off] | ((size_t)data[off + 1u] << 8u);
        off += 2u;
        if (len > size - off) {
            len = size - off;
        }
        if (sc_dlink_asm_push(&rx, data + off, len) == 1) {
            check_frame(sc_dlink_asm_done(&rx));
        }
        off += len;
    }
    if (sc_dlink_asm_flush(&rx) == 1) {
        check_frame(sc_dlink_asm_done(&rx));
    }
    return 0;
}

static size_t put_pkt(uint8_t *buf, size_t n, size_t cap, const uint8_t *pkt, int len)
{
    if (len <= 0 || n + 2u + (size_t)len > cap) {
        return 0;
    }
    buf[n++] = (uint8_t)(len & 0xFF);
    buf[n++] = (uint8_t)((unsigned)len >> 8u);
    memcpy(buf + n, pkt, (size_t)len);
    return n + (size_t)len;
}

/* Seeds: two frames with colour Doppler and parameters (linear, curvilinear), one without. */
size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 2u) {
        return 0;
    }
    uint8_t pkt[1024], line[16];
    int8_t col[12];
    size_t n = 0;
    int ok = 1;
    for (uint32_t fr = 0; fr < 2u && ok; fr++) {
        sc_dlink_frame f = {.frame_no = 40u + fr, .flags = 1, .line_count = 4, .samples = 16,
                            .geometry_id = (uint16_t)(i & 1u)};
        sc_dlink_begin b = {.depth_mm = 40.0f, .width_mm = 38.0f, .radius_mm = (i & 1u) ? 40.0f : 0.0f};
        sc_dlink_end e = {.lines_sent = 4, .compression_pm = 100, .artery_compression_pm = 0};
        sc_dlink_params p = {.gain_db = 3.0f, .dynamic_range_db = 60.0f, .focus_mm = 20.0f,
                             .frequency_mhz = 7.5f};
        n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_begin(pkt, sizeof pkt, &f, &b));
        if (n) {
            n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_params(pkt, sizeof pkt, &f, &p));
        }
        ok = n > 0u;
        for (uint16_t l = 0; l < 4u && ok; l++) {
            memset(line, 30 * l, sizeof line);
            n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_line(pkt, sizeof pkt, &f, l, line, 16));
            for (int k = 0; k < 12; k++) {
                col[k] = (int8_t)((k - 6) * 20);
            }
            if (n && i < 2u) {
                n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_colour(pkt, sizeof pkt, &f, l, 2u, col, 12u));
            }
            ok = n > 0u;
        }
        if (ok && i < 2u) {
            sc_dlink_doppler d;
            memset(&d, 0, sizeof d);
            d.box_line_hi = 4;
            d.box_sample_lo = 2;
            d.box_sample_hi = 14;
            d.nyquist_mm_s = 308.0f;
            d.gate_line = 2;
            d.gate_sample_lo = 6;
            d.gate_sample_hi = 9;
            d.bins = 32;
            for (uint32_t k = 0; k < 32u; k++) {
                d.spectrum[k] = (uint8_t)(k * 8u + fr);
            }
            n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_doppler(pkt, sizeof pkt, &f, &d));
            ok = n > 0u;
        }
        if (ok) {
            n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_end(pkt, sizeof pkt, &f, &e));
            ok = n > 0u;
        }
    }
    return ok ? n : 0u;
}
