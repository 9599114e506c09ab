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
        }
        off += len;
    }
    sc_dlink_asm_flush(&rx);
    SC_FUZZ_CHECK(rx.stats.packets == offered);
    SC_FUZZ_CHECK(rx.stats.rejected == rejected);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
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
