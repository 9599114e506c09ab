/* fuzz_sc_canproto.c: the CAN protocol's decoders (core/link/sc_canproto.c: classification,
 * every signal of a message, pose parts, status parts as sc-status-check and the bench read
 * them) take any frame, never crash, agree with each other on what a frame is, and decode
 * only finite values. Input: records of [flags, id_lo, id_hi, len, data...len]; bit 7 of the
 * flags byte steers the id to one of the protocol's ids (index id_lo). */
#include <math.h>
#include <string.h>

#include "sc_canproto.h"
#include "sc_err.h"
#include "sc_fuzz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t off = 0;
    while (off + 4u <= size) {
        sc_can_frame f;
        memset(&f, 0, sizeof f);
        f.flags = data[off] & 0x1Fu;
        f.id = (uint32_t)data[off + 1u] | ((uint32_t)data[off + 2u] << 8);
        if (f.flags & SC_CAN_FLAG_EXT) {
            f.id |= (uint32_t)data[off + 2u] << 16;
        } else {
            f.id &= 0x7FFu;
        }
        if (data[off] & 0x80u) {
            const sc_can_msg_info *mi = sc_canproto_info((sc_msg)(data[off + 1u] % SC_MSG_COUNT));
            if (mi) {
                f.id = mi->can_id;
            }
        }
        f.len = (uint8_t)(data[off + 3u] % (SC_CAN_MAX_DLEN + 1u));
        off += 4u;
        const size_t n = f.len < size - off ? f.len : size - off;
        memcpy(f.data, data + off, n);
        off += n;

        sc_msg m;
        const int rc = sc_canproto_classify(&f, &m);
        SC_FUZZ_CHECK(rc == 0 || rc == SC_ERR_CAN_ID || rc == SC_ERR_CAN_DLC);
        if (rc == 0) {
            const sc_can_msg_info *mi = sc_canproto_info(m);
            SC_FUZZ_CHECK(mi != NULL && mi->can_id == f.id && mi->len == f.len);
            SC_FUZZ_CHECK(!(f.flags & (SC_CAN_FLAG_EXT | SC_CAN_FLAG_RTR | SC_CAN_FLAG_ERR)));
        }
        float phys[64];
        sc_msg m2;
        const int rp = sc_canproto_decode_phys(&f, &m2, phys, 64u);
        SC_FUZZ_CHECK(rp == rc);
        if (rp == 0) {
            SC_FUZZ_CHECK(m2 == m);
            const sc_can_msg_info *mi = sc_canproto_info(m);
            for (unsigned s = 0; s < mi->sig_count; s++) {
                SC_FUZZ_CHECK(isfinite(phys[s]));
            }
        }
        sc_pose_msg p;
        memset(&p, 0, sizeof p);
        const int pp = sc_canproto_decode_pose_part(&f, &p);
        SC_FUZZ_CHECK(pp < 0 || rc == 0);
        if (pp > 0) {
            SC_FUZZ_CHECK(pp == 1 || pp == 2 || pp == 4 || pp == 7);
            for (int k = 0; k < 3; k++) {
                SC_FUZZ_CHECK(isfinite(p.pos_mm[k]));
            }
            for (int k = 0; k < 4; k++) {
                SC_FUZZ_CHECK(isfinite(p.q[k]));
            }
        }
        sc_status_msg st;
        memset(&st, 0, sizeof st);
        const int sp = sc_canproto_decode_status_part(&f, &st);
        SC_FUZZ_CHECK(sp < 0 || rc == 0);
        SC_FUZZ_CHECK(!(pp >= 0 && sp >= 0)); /* a frame is a pose or a status, not both */
        if (sp >= 0) {
            SC_FUZZ_CHECK(isfinite(st.vein_area_ratio) && isfinite(st.artery_area_ratio));
        }
    }
    return 0;
}

size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap)
{
    if (i > 2u || cap < 256u) {
        return 0;
    }
    sc_can_frame f[SC_STATUS_FRAMES > 3 ? SC_STATUS_FRAMES : 3];
    size_t nf = 0;
    if (i < 2u) {
        const sc_pose_msg p = {.pos_mm = {1.0f, -2.0f, 30.0f}, .q = {0.0f, 1.0f, 0.0f, 0.0f},
                               .force_n = 2.5f, .force_valid = 1};
        if (sc_canproto_encode_pose(&p, 3, (int)i, f, 3, &nf) != 0) {
            return 0;
        }
    } else {
        const sc_status_msg s = {.state = 1, .case_id = 0, .vein_area_ratio = 0.5f,
                                 .artery_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE};
        sc_e2e_tx tx[SC_STATUS_FRAMES];
        memset(tx, 0, sizeof tx);
        if (sc_canproto_encode_status(&s, tx, f) != 0) {
            return 0;
        }
        nf = SC_STATUS_FRAMES;
    }
    size_t off = 0;
    for (size_t k = 0; k < nf && off + 4u + f[k].len <= cap; k++) {
        buf[off++] = (uint8_t)(f[k].flags & 0x1Fu);
        buf[off++] = (uint8_t)(f[k].id & 0xFFu);
        buf[off++] = (uint8_t)(f[k].id >> 8);
        buf[off++] = f[k].len;
        memcpy(buf + off, f[k].data, f[k].len);
        off += f[k].len;
    }
    return off;
}
