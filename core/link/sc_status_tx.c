/* sc_status_tx.c: the status frames on CAN; see sc_status_tx.h. */
#include "sc_status_tx.h"

void sc_status_tx_init(sc_status_tx *s)
{
    sc_e2e_tx_init(&s->tx[0], sc_canproto_info(SC_MSG_STATUS)->data_id);
    sc_e2e_tx_init(&s->tx[1], sc_canproto_info(SC_MSG_TIMING)->data_id);
    sc_e2e_tx_init(&s->tx[2], sc_canproto_info(SC_MSG_DIAG)->data_id);
    sc_e2e_tx_init(&s->tx[3], sc_canproto_info(SC_MSG_AUTH_DIAG)->data_id);
    for (unsigned i = 0; i < SC_ASSESS_FRAMES; i++) {
        sc_e2e_tx_init(&s->assess_tx[i],
                       sc_canproto_info((sc_msg)((unsigned)SC_MSG_ASSESS_VESSELS + i))->data_id);
    }
}

int sc_status_tx_encode_assess(sc_status_tx *s, const sc_assess_msg *msg,
                               sc_can_frame out[SC_ASSESS_FRAMES])
{
    return sc_canproto_encode_assess(msg, s->assess_tx, out);
}

int sc_status_tx_encode(sc_status_tx *s, const sc_tracker *t, sc_status_msg *msg,
                        sc_can_frame out[SC_STATUS_FRAMES])
{
    msg->probe_lifted = (uint8_t)(t->have_pose ? 0u : 1u);
    msg->poses_accepted = sc_tracker_counters(t)->outcome[SC_TRK_POSE_ACCEPTED];
    msg->rejected_e2e = sc_tracker_rejected_e2e(t);
    msg->rejected_plausibility = sc_tracker_rejected_implausible(t);
    msg->lift_events = sc_tracker_counters(t)->lift_events;
    msg->cmds_authenticated = sc_tracker_authenticated(t);
    msg->auth_rejected = sc_tracker_rejected_auth(t);
    msg->auth_bad_mac = sc_tracker_counters(t)->outcome[SC_TRK_AUTH_BAD_MAC];
    msg->auth_stale = sc_tracker_counters(t)->outcome[SC_TRK_AUTH_STALE];
    return sc_canproto_encode_status(msg, s->tx, out);
}
