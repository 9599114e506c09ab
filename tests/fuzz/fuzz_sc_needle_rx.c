/* fuzz_sc_needle_rx.c: the tracked needle's receiver takes any sequence of CAN frames and poll
 * times, never crashes, counts every frame under exactly one outcome, and only ever holds a
 * needle that passes its plausibility checks (unit direction, tip in the workspace, depth in
 * range). Input: records of [ctl, id_lo, len, dt_ms, data...len]; the id is 0x120 + id_lo % 4
 * when ctl bit 7 is set (the needle's ids and one past them), else any 11-bit id from id_lo and
 * ctl bits 0-2; ctl bit 6 asks for a valid E2E header. */
#include <math.h>
#include <string.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_fuzz.h"
#include "sc_needle_rx.h"

static sc_needle_rx rx;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const sc_needle_rx_def def = sc_needle_rx_default_def();
    SC_FUZZ_CHECK(sc_needle_rx_init(&rx, &def) == 0);
    uint64_t now = 1000000000u, fed = 0;
    size_t off = 0;
    while (off + 4u <= size) {
        const uint8_t ctl = data[off];
        sc_can_frame f;
        memset(&f, 0, sizeof f);
        f.id = (ctl & 0x80u) ? SC_CANID_NEEDLE_POS + (data[off + 1u] & 3u)
                             : (uint32_t)data[off + 1u] | ((uint32_t)(ctl & 7u) << 8);
        f.flags = (uint8_t)((ctl >> 3) & 0x03u); /* EXT, RTR sometimes */
        f.len = data[off + 2u] % (SC_CAN_MAX_DLEN + 1u);
        now += data[off + 3u] * 1000000u;
        off += 4u;
        const size_t n = f.len < size - off ? f.len : size - off;
        memcpy(f.data, data + off, n);
        off += n;
        if (ctl & 0x40u) {
            (void)sc_e2e_protect_with((uint16_t)f.id, f.data[1], f.data, f.len);
        }
        const sc_needle_outcome o = sc_needle_rx_on_frame(&rx, &f, now);
        SC_FUZZ_CHECK((unsigned)o < (unsigned)SC_NEEDLE_OUTCOME_COUNT);
        fed++;
        sc_needle_sample s;
        if (sc_needle_rx_poll(&rx, now, &s)) {
            const float nn = s.dir[0] * s.dir[0] + s.dir[1] * s.dir[1] + s.dir[2] * s.dir[2];
            SC_FUZZ_CHECK(fabsf(nn - 1.0f) < 1e-3f);
            for (int k = 0; k < 3; k++) {
                SC_FUZZ_CHECK(fabsf(s.tip_mm[k]) <= def.workspace_mm);
            }
            SC_FUZZ_CHECK(s.depth_mm >= 0.0f && s.depth_mm <= def.max_depth_mm);
        }
    }
    uint64_t sum = 0;
    for (int o = 0; o < (int)SC_NEEDLE_OUTCOME_COUNT; o++) {
        sum += rx.outcome[o];
    }
    SC_FUZZ_CHECK(sum == fed);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 1u || cap < 64u) {
        return 0;
    }
    /* one needle sample (i = 0) or one with a bent direction (implausible, i = 1) */
    sc_needle_msg m = {.tip_mm = {10.0f, 0.0f, 20.0f}, .dir = {0.0f, 0.6f, 0.8f},
                       .depth_mm = 22.0f, .tracking = SC_TRACKING_OK};
    if (i == 1u) {
        m.dir[2] = 0.2f;
    }
    sc_can_frame f[3];
    size_t n = 0;
    if (sc_canproto_encode_needle(&m, 0, f, 3, &n) != 0) {
        return 0;
    }
    size_t off = 0;
    for (size_t k = 0; k < n && off + 4u + f[k].len <= cap; k++) {
        buf[off++] = (uint8_t)(0x80u | 0x40u);
        buf[off++] = (uint8_t)(f[k].id - SC_CANID_NEEDLE_POS);
        buf[off++] = f[k].len;
        buf[off++] = 10u;
        memcpy(buf + off, f[k].data, f[k].len);
        off += f[k].len;
    }
    return off;
}
