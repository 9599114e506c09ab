/* fuzz_sc_tracker.c: the tracker takes any sequence of CAN frames (outside input off the bus)
 * and poll times, never crashes, counts every frame under exactly one outcome, and only ever
 * holds a pose that passes its plausibility checks (unit quaternion, inside the workspace).
 * Input: records of [ctl, id_lo, id_hi, len, dt_ms, data...len]; ctl bits 0-4 are the frame
 * flags, bit 6 asks for a valid E2E header (so decoding gets exercised), bit 7 with bits 5-6
 * steers the id towards the protocol's. */
#include <math.h>
#include <string.h>

#include "sc_e2e.h"
#include "sc_err.h"
#include "sc_fuzz.h"
#include "sc_tracker.h"

static sc_tracker trk;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sc_tracker_def def = sc_tracker_default_def();
    SC_FUZZ_CHECK(sc_tracker_init(&trk, &def) == 0);
    uint64_t now = 1000000000u, fed = 0;
    size_t off = 0;
    while (off + 5u <= size) {
        const uint8_t ctl = data[off];
        sc_can_frame f;
        memset(&f, 0, sizeof f);
        f.flags = data[off] & 0x1Fu;
        f.id = (uint32_t)data[off + 1u] | ((uint32_t)(data[off + 2u] & 0x07u) << 8);
        if (data[off] & 0x80u) {
            f.id += 0x100u * (uint32_t)(data[off] >> 5 & 3u); /* steer towards protocol ids */
        }
        f.len = data[off + 3u] % (SC_CAN_MAX_DLEN + 1u);
        now += data[off + 4u] * 1000000u;
        off += 5u;
        const size_t n = f.len < size - off ? f.len : size - off;
        memcpy(f.data, data + off, n);
        off += n;
        if (ctl & 0x40u) {
            (void)sc_e2e_protect_with((uint16_t)f.id, f.data[1], f.data, f.len);
        }
        const sc_trk_outcome o = sc_tracker_on_frame(&trk, &f, now);
        SC_FUZZ_CHECK((unsigned)o < (unsigned)SC_TRK_OUTCOME_COUNT);
        fed++;
        sc_pose p;
        int contact = -1;
        const int rc = sc_tracker_poll(&trk, now, &p, &contact);
        SC_FUZZ_CHECK((rc == 0 && contact == 1) || (rc == SC_ERR_TIMEOUT && contact == 0));
        if (rc == 0) {
            SC_FUZZ_CHECK(fabsf(sc_quat_norm2(p.q) - 1.0f) < 1e-4f);
            for (int k = 0; k < 3; k++) {
                SC_FUZZ_CHECK(p.pos_mm[k] >= def.ws_min_mm[k] && p.pos_mm[k] <= def.ws_max_mm[k]);
            }
        }
        sc_cmd c;
        while (sc_tracker_take_command(&trk, &c) == 0) {
            SC_FUZZ_CHECK(c.kind >= SC_CMD_SELECT_CASE && c.kind <= SC_CMD_RESET);
        }
    }
    const sc_trk_counters *k = sc_tracker_counters(&trk);
    uint64_t sum = 0;
    for (int o = 0; o < (int)SC_TRK_OUTCOME_COUNT; o++) {
        sum += k->outcome[o];
    }
    SC_FUZZ_CHECK(k->frames == fed && sum == fed);
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 1u || cap < 64u) {
        return 0;
    }
    /* one classic pose sample (i = 0) or one FD pose (i = 1), properly protected */
    sc_pose_msg p = {.pos_mm = {1.0f, 2.0f, 3.0f}, .q = {1.0f, 0.0f, 0.0f, 0.0f}};
    sc_can_frame f[3];
    size_t n = 0;
    if (sc_canproto_encode_pose(&p, 0, (int)i, f, 3, &n) != 0) {
        return 0;
    }
    size_t off = 0;
    for (size_t k = 0; k < n && off + 5u + f[k].len <= cap; k++) {
        buf[off++] = (uint8_t)((f[k].flags & 0x1Fu) | 0x40u);
        buf[off++] = (uint8_t)(f[k].id & 0xFFu);
        buf[off++] = (uint8_t)(f[k].id >> 8);
        buf[off++] = f[k].len;
        buf[off++] = 10u;
        memcpy(buf + off, f[k].data, f[k].len);
        off += f[k].len;
    }
    return off;
}
