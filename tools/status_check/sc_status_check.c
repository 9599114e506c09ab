/*
 * sc_status_check.c: reads a candump -l log of a bus and reports what the engine said on it:
 * every status frame (EngineStatus, EngineTiming, TrackerDiag) is E2E-checked with its own
 * receiver state and decoded with the core codec. Prints key=value figures on one line:
 *   status_frames e2e_bad state case_id method contact_frames lifted_last poses_accepted
 *   rejected_e2e rejected_plausibility lift_events misses worst_frame_us min_vein_pm
 *   max_artery_pm_at_min log_rejected
 * Used by the HIL test to judge the engine from its own status frames, as a bench would.
 *   sc-status-check LOG
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_candump.h"
#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_err.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: sc-status-check CANDUMP_LOG\n");
        return 2;
    }
    FILE *fp = fopen(argv[1], "r");
    if (!fp) {
        fprintf(stderr, "sc-status-check: cannot open %s\n", argv[1]);
        return 2;
    }
    const sc_msg msgs[SC_STATUS_FRAMES] = {SC_MSG_STATUS, SC_MSG_TIMING, SC_MSG_DIAG,
                                           SC_MSG_AUTH_DIAG};
    sc_e2e_rx rx[SC_STATUS_FRAMES];
    for (unsigned i = 0; i < SC_STATUS_FRAMES; i++) {
        sc_e2e_rx_def d = sc_e2e_rx_default_def(sc_canproto_info(msgs[i])->data_id);
        d.max_delta_counter = 1; /* the engine sends every status frame: no loss on vcan */
        sc_e2e_rx_init(&rx[i], &d);
    }
    sc_candump_reader r;
    sc_candump_reader_init(&r, fp);
    sc_candump_rec rec;
    sc_status_msg s;
    memset(&s, 0, sizeof(s));
    unsigned frames = 0, bad = 0, contact = 0, status_msgs = 0;
    float min_vein = 2.0f, artery_at_min = -1.0f;
    while (sc_candump_reader_next(&r, &rec) == SC_OK) {
        sc_msg m;
        if (sc_canproto_classify(&rec.frame, &m) != SC_OK) {
            continue;
        }
        for (unsigned i = 0; i < SC_STATUS_FRAMES; i++) {
            if (m != msgs[i]) {
                continue;
            }
            frames++;
            const sc_e2e_status e = sc_e2e_check(&rx[i], rec.frame.data, rec.frame.len,
                                                 rec.ts_us * 1000u);
            if (!sc_e2e_status_usable(e)) {
                bad++;
                continue;
            }
            if (sc_canproto_decode_status_part(&rec.frame, &s) != SC_OK) {
                bad++;
                continue;
            }
            if (m == SC_MSG_STATUS) {
                status_msgs++;
                contact += s.probe_contact;
            }
            if (m == SC_MSG_TIMING && s.probe_contact && s.vein_area_ratio >= 0.0f &&
                s.vein_area_ratio < min_vein) {
                min_vein = s.vein_area_ratio;
                artery_at_min = s.artery_area_ratio;
            }
        }
    }
    fclose(fp);
    printf("status_frames=%u e2e_bad=%u state=%u case_id=%u method=%u contact_frames=%u "
           "lifted_last=%u poses_accepted=%u rejected_e2e=%u rejected_plausibility=%u "
           "lift_events=%u misses=%u worst_frame_us=%u min_vein_pm=%d artery_at_min_pm=%d "
           "log_rejected=%u cmds_authenticated=%u auth_rejected=%u auth_bad_mac=%u "
           "auth_stale=%u\n",
           frames, bad, s.state, s.case_id, s.method, contact, s.probe_lifted, s.poses_accepted,
           s.rejected_e2e, s.rejected_plausibility, s.lift_events, s.deadline_misses,
           s.worst_frame_us, min_vein > 1.5f ? -1 : (int)lroundf(1000.0f * min_vein),
           artery_at_min < 0.0f ? -1 : (int)lroundf(1000.0f * artery_at_min),
           sc_candump_reader_rejected_total(&r), s.cmds_authenticated, s.auth_rejected,
           s.auth_bad_mac, s.auth_stale);
    return frames > 0u ? 0 : 1;
}
