/* fuzz_sc_dlink.c: the display-link decoder and frame assembler take any datagram sequence
 * (the input is split into datagrams by a length prefix), never crash, and keep their
 * counters consistent. */
#include <string.h>

#include "sc_dlink.h"
#include "sc_err.h"
#include "sc_fuzz.h"

static sc_dlink_asm rx;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_dlink_asm_init(&rx);
    size_t off = 0;
    uint64_t offered = 0, rejected = 0;
    while (off + 2u <= size) {
        size_t len = (size_t)data[off] | ((size_t)data[off + 1u] << 8u);
        off += 2u;
        if (len > size - off) {
            len = size - off;
        }
        int rc = sc_dlink_asm_push(&rx, data + off, len);
        offered++;
        rejected += rc < 0;
        if (rc == 1) {
            const sc_dlink_done *d = sc_dlink_asm_done(&rx);
            SC_FUZZ_CHECK(d != NULL);
            SC_FUZZ_CHECK(d->lines_received + d->lines_lost == d->frame.line_count);
            if (d->doppler_seen) { /* the decoder checked the record against its frame */
                SC_FUZZ_CHECK(d->doppler.box_line_hi <= d->frame.line_count);
                SC_FUZZ_CHECK(d->doppler.box_sample_hi <= d->frame.samples);
                SC_FUZZ_CHECK(d->doppler.bins <= SC_DLINK_SPECTRUM_MAX);
                SC_FUZZ_CHECK(d->doppler.nyquist_mm_s > 0.0f);
            }
        }
        off += len;
    }
    sc_dlink_asm_flush(&rx);
    SC_FUZZ_CHECK(rx.stats.packets == offered);
    SC_FUZZ_CHECK(rx.stats.rejected == rejected);
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

/* Seeds 3, 4: a frame with colour Doppler (display link version 3): B-mode lines, a colour
 * line per line, the doppler record with a spectrum, the end. */
static size_t colour_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    sc_dlink_frame f = {.frame_no = 40u + i, .flags = 1, .line_count = 4, .samples = 16,
                        .geometry_id = (uint16_t)(i & 1u)};
    sc_dlink_begin b = {.depth_mm = 40.0f, .width_mm = 38.0f, .radius_mm = (i & 1u) ? 40.0f : 0.0f};
    sc_dlink_end e = {.lines_sent = 4, .lines_dropped = 0, .compression_pm = 100,
                      .artery_compression_pm = 0};
    uint8_t pkt[1024], line[16];
    int8_t col[12];
    size_t n = put_pkt(buf, 0, cap, pkt, sc_dlink_encode_begin(pkt, sizeof pkt, &f, &b));
    for (uint16_t l = 0; l < 4u && n; l++) {
        memset(line, 30 * l, sizeof line);
        n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_line(pkt, sizeof pkt, &f, l, line, 16));
        for (int k = 0; k < 12; k++) {
            col[k] = (int8_t)((k - 6) * 20);
        }
        if (n) {
            n = put_pkt(buf, n, cap, pkt,
                        sc_dlink_encode_colour(pkt, sizeof pkt, &f, l, 2u, col, 12u));
        }
    }
    sc_dlink_doppler d;
    memset(&d, 0, sizeof d);
    d.box_line_lo = 0;
    d.box_line_hi = 4;
    d.box_sample_lo = 2;
    d.box_sample_hi = 14;
    d.nyquist_mm_s = 308.0f;
    d.steer_deg = 20.0f;
    d.gate_velocity_mm_s = -150.0f;
    d.gate_line = 2;
    d.gate_sample_lo = 6;
    d.gate_sample_hi = 9;
    d.bins = 32;
    for (uint32_t k = 0; k < 32u; k++) {
        d.spectrum[k] = (uint8_t)(k * 8u);
    }
    if (n) {
        n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_doppler(pkt, sizeof pkt, &f, &d));
    }
    if (n) {
        n = put_pkt(buf, n, cap, pkt, sc_dlink_encode_end(pkt, sizeof pkt, &f, &e));
    }
    return n;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i == 3u || i == 4u) {
        return colour_seed(i, buf, cap);
    }
    if (i > 2u) {
        return 0;
    }
    sc_dlink_frame f = {.frame_no = 7u + i, .flags = 0, .line_count = 4, .samples = 16,
                        .geometry_id = (uint16_t)(i & 1u)};
    sc_dlink_begin b = {.depth_mm = 60.0f, .width_mm = 38.0f};
    sc_dlink_end e = {.lines_sent = 4, .lines_dropped = 0, .compression_pm = 500,
                      .artery_compression_pm = SC_DLINK_COMPRESSION_UNKNOWN};
    uint8_t pkt[1024], line[16];
    size_t n = 0;
    for (int p = -1; p <= 4; p++) {
        int len;
        if (p < 0) {
            len = sc_dlink_encode_begin(pkt, sizeof(pkt), &f, &b);
        } else if (p < 4) {
            memset(line, p * 40 + (int)i, sizeof(line));
            len = sc_dlink_encode_line(pkt, sizeof(pkt), &f, (uint16_t)p, line, 16);
        } else {
            len = sc_dlink_encode_end(pkt, sizeof(pkt), &f, &e);
        }
        if (len <= 0 || n + 2u + (size_t)len > cap) {
            return 0;
        }
        buf[n++] = (uint8_t)(len & 0xFF);
        buf[n++] = (uint8_t)((unsigned)len >> 8u);
        memcpy(buf + n, pkt, (size_t)len);
        n += (size_t)len;
    }
    return n;
}
