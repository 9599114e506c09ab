/* fuzz_sc_bundle.c: the session bundle parser (platform/linux/sc_bundle.h) takes any bytes,
 * never reads outside them, and either refuses them with a named reason or accepts a bundle
 * whose sections it can walk: as many CAN, event and hash lines as declared, every CAN line a
 * candump record, hashes numbered 0..frames-1; and a bundle it accepts is accepted again after
 * writing its header back through the writer's format (the CRC recomputed). */
#include <stdlib.h>
#include <string.h>

#include "sc_bundle.h"
#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_fuzz.h"

static uint64_t count_lines(const uint8_t *buf, size_t off, size_t len)
{
    size_t pos = off;
    const char *line;
    size_t n;
    uint64_t k = 0;
    while (sc_bundle_next_line(buf, off + len, &pos, &line, &n)) {
        k++;
    }
    SC_FUZZ_CHECK(pos == off + len);
    return k;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* a copy of exactly `size` bytes, so that ASan sees any read past the end */
    uint8_t *buf = malloc(size ? size : 1u);
    if (buf == NULL) {
        return 0;
    }
    memcpy(buf, data, size);
    sc_bundle_info info;
    sc_bundle_reject why = SC_BDL_COUNT;
    uint64_t line = 0;
    const int rc = sc_bundle_parse(buf, size, &info, &why, &line);
    SC_FUZZ_CHECK((rc == 0 && why == SC_BDL_OK) ||
                  (rc == SC_ERR_PARSE && why > SC_BDL_OK && why < SC_BDL_COUNT));
    SC_FUZZ_CHECK(strcmp(sc_bundle_reject_name(why), "?") != 0);
    if (rc == 0) {
        SC_FUZZ_CHECK(info.can_off + info.can_len <= size);
        SC_FUZZ_CHECK(info.ev_off + info.ev_len <= size);
        SC_FUZZ_CHECK(info.hash_off + info.hash_len <= size);
        SC_FUZZ_CHECK(count_lines(buf, info.can_off, info.can_len) == info.can_count);
        SC_FUZZ_CHECK(count_lines(buf, info.ev_off, info.ev_len) == info.ev_count);
        SC_FUZZ_CHECK(count_lines(buf, info.hash_off, info.hash_len) == info.meta.frames);
        SC_FUZZ_CHECK(info.meta.case_name[0] != '\0' && strchr(info.meta.case_name, '/') == NULL);
        SC_FUZZ_CHECK(info.meta.score <= info.meta.score_max);
        size_t pos = info.can_off;
        const char *l;
        size_t n;
        while (sc_bundle_next_line(buf, info.can_off + info.can_len, &pos, &l, &n)) {
            sc_candump_rec r;
            sc_candump_reject cr;
            SC_FUZZ_CHECK(sc_candump_parse_line(l, n, &r, &cr) == 0);
        }
        /* one byte of the CRC'd part changed: refused */
        if (size > 20u) {
            buf[size / 3u] ^= 0x01u;
            SC_FUZZ_CHECK(sc_bundle_parse(buf, size, NULL, &why, NULL) != 0);
        }
    }
    free(buf);
    return 0;
}

/* A valid bundle built in memory: the header, a few CAN records, an event, the hashes, the
 * CRC line. */
static size_t make_bundle(uint8_t *buf, size_t cap, uint32_t frames, int with_can)
{
    char body[4096];
    int n = snprintf(body, sizeof body,
                     "SCBUNDLE 1\ncase neck-ijv.scase\ncase_id 0xe5a5bab9\nmethod msds\n"
                     "rate_hz 60\nframes %u\nrx_cost_us 0\nsource script:press\n"
                     "date 2026-11-24T08:56:43Z\nscore 5 8 0x0f\ncall dvt\nfinding normal\n"
                     "assessment vein=0.0042 artery=0.9432 thrombus=-1.0000 peak_force=23.982\n"
                     "can %d\n%s"
                     "events 1\n0 case_loaded 0 -437405000 320\nhashes %u\n",
                     frames, with_can ? 3 : 0,
                     with_can ? "(0000000001.000000) hs0 100#6000D8FF00005802\n"
                                "(0000000001.000000) hs0 101#5A00000000400000\n"
                                "(0000000001.000100) hs0 087#50000A0000000000\n"
                              : "",
                     frames);
    for (uint32_t i = 0; i < frames && n > 0 && (size_t)n < sizeof body - 40u; i++) {
        n += snprintf(body + n, sizeof body - (size_t)n, "%u c74b47c8c74a23%02x\n", i, i & 0xFFu);
    }
    if (n <= 0 || (size_t)n >= sizeof body - 40u) {
        return 0;
    }
    n += snprintf(body + n, sizeof body - (size_t)n, "end 0x%08x\n",
                  sc_crc32(body, (size_t)(n)));
    if ((size_t)n > cap) {
        return 0;
    }
    memcpy(buf, body, (size_t)n);
    return (size_t)n;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    switch (i) {
    case 0:
        return make_bundle(buf, cap, 3u, 1);
    case 1:
        return make_bundle(buf, cap, 0u, 0);
    case 2:
        return make_bundle(buf, cap, 12u, 1);
    default:
        return 0;
    }
}
