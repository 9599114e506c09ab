/* sc_canproto_dump: prints frames encoded by the core codec, one per line, for the independent
 * DBC reader (tests/can/canmatrix_check.py):
 *   <message name> <can id hex> <fd 0|1> <payload hex> <phys of each signal as the core decodes>
 * Frames: typed encodes of every message (poses classic and FD, every command, status) and,
 * per message, frames whose every signal holds a pseudo-random raw value. */
#include <stdio.h>
#include <string.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_secoc.h"

static int print_frame(const sc_can_frame *f)
{
    sc_msg m;
    float phys[SC_CANPROTO_MAX_SIGS];
    if (sc_canproto_decode_phys(f, &m, phys, SC_CANPROTO_MAX_SIGS) != 0) {
        fprintf(stderr, "core cannot decode its own frame id 0x%X\n", (unsigned)f->id);
        return 1;
    }
    const sc_can_msg_info *info = sc_canproto_info(m);
    printf("%s %X %d ", info->name, (unsigned)f->id, (f->flags & SC_CAN_FLAG_FD) ? 1 : 0);
    for (unsigned i = 0; i < f->len; i++) {
        printf("%02X", f->data[i]);
    }
    for (unsigned i = 0; i < info->sig_count; i++) {
        printf(" %.9g", (double)phys[i]);
    }
    printf("\n");
    return 0;
}

int main(void)
{
    int bad = 0;
    sc_can_frame f[SC_STATUS_FRAMES > 3u ? SC_STATUS_FRAMES : 3u];
    size_t n;
    const sc_pose_msg poses[] = {
        {.pos_mm = {12.3f, -45.6f, 78.9f},
         .q = {0.9238795f, 0.0f, 0.3826834f, 0.0f},
         .force_n = 3.21f,
         .force_valid = 1},
        {.pos_mm = {-1638.4f, 1638.35f, 0.0f},
         .q = {-2.0f, 1.9999f, -0.5f, 0.25f},
         .force_valid = 0,
         .tracking = SC_TRACKING_LOST},
    };
    for (size_t p = 0; p < sizeof poses / sizeof poses[0]; p++) {
        for (int fd = 0; fd <= 1; fd++) {
            if (sc_canproto_encode_pose(&poses[p], (uint8_t)(p + 3u), fd, f, 3, &n) != 0) {
                return 1;
            }
            for (size_t k = 0; k < n; k++) {
                bad |= print_frame(&f[k]);
            }
        }
    }
    const sc_cmd cmds[] = {
        {.kind = SC_CMD_SELECT_CASE, .case_id = 42},
        {.kind = SC_CMD_SET_METHOD, .method = SC_METHOD_FEM},
        {.kind = SC_CMD_SET_IMAGING,
         .imaging = {.depth_mm = 45.5f,
                     .gain_db = -7.5f,
                     .dyn_range_db = 65.0f,
                     .tgc_db_per_cm = 0.8f,
                     .geometry = SC_SCAN_CURVILINEAR}},
        {.kind = SC_CMD_RESET, .reset_target = SC_RESET_FAULTS},
        {.kind = SC_CMD_SYNC_FRESHNESS, .fv_high = 0x123456789ABCull},
    };
    for (size_t c = 0; c < sizeof cmds / sizeof cmds[0]; c++) {
        if (sc_canproto_encode_cmd(&cmds[c], (uint8_t)c, &f[0]) != 0) {
            return 1;
        }
        bad |= print_frame(&f[0]);
        /* its cryptographic PDU, signed with the core's CMAC and the bench key */
        sc_cmac_key k;
        sc_cmac_key_init(&k, sc_secoc_bench_key);
        f[1] = (sc_can_frame){.id = f[0].id + SC_CANID_AUTH_OFFSET, .len = 8};
        sc_secoc_sign(&k, (uint16_t)f[0].id, f[0].data, (uint8_t)c, 0x0123456789ull + c, f[1].data);
        bad |= print_frame(&f[1]);
    }
    sc_e2e_tx tx[SC_STATUS_FRAMES];
    sc_e2e_tx_init(&tx[0], SC_CANID_STATUS);
    sc_e2e_tx_init(&tx[1], SC_CANID_TIMING);
    sc_e2e_tx_init(&tx[2], SC_CANID_DIAG);
    sc_e2e_tx_init(&tx[3], SC_CANID_AUTH_DIAG);
    const sc_status_msg st = {.state = 2,
                              .method = 1,
                              .probe_contact = 1,
                              .fault_bits = 0x0204,
                              .deadline_misses = 17,
                              .case_id = 5,
                              .worst_frame_us = 9876,
                              .vein_area_ratio = 0.42f,
                              .artery_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE,
                              .poses_accepted = 1234,
                              .rejected_e2e = 5,
                              .rejected_plausibility = 6,
                              .lift_events = 2,
                              .cmds_authenticated = 70000,
                              .auth_rejected = 300,
                              .auth_bad_mac = 7,
                              .auth_stale = 400};
    if (sc_canproto_encode_status(&st, tx, f) != 0) {
        return 1;
    }
    for (int k = 0; k < (int)SC_STATUS_FRAMES; k++) {
        bad |= print_frame(&f[k]);
    }
    /* random raw values in every field of every message */
    uint32_t rng = 99u;
    for (int m = 0; m < (int)SC_MSG_COUNT; m++) {
        const sc_can_msg_info *info = sc_canproto_info((sc_msg)m);
        for (int rep = 0; rep < 20; rep++) {
            sc_can_frame g = {.id = info->can_id,
                              .len = info->len,
                              .flags = info->fd ? (uint8_t)SC_CAN_FLAG_FD : 0u};
            for (unsigned s = 2; s < info->sig_count; s++) {
                rng = rng * 1664525u + 1013904223u;
                const sc_can_sig *sig = &info->sigs[s];
                int64_t raw = (int64_t)(rng >> 8) & ((INT64_C(1) << sig->bits) - 1);
                if (sig->is_signed && (raw >> (sig->bits - 1u))) {
                    raw -= INT64_C(1) << sig->bits;
                }
                sc_canproto_put_raw(g.data, sig, raw);
            }
            if (info->e2e) {
                sc_e2e_protect_with(info->data_id, (uint8_t)rep, g.data, g.len);
            } else {
                sc_canproto_put_raw(g.data, &info->sigs[0], rep % 16); /* SenderId */
                sc_canproto_put_raw(g.data, &info->sigs[1], (rep * 7) % 16);
            }
            bad |= print_frame(&g);
        }
    }
    return bad;
}
