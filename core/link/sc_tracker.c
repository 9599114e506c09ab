/* sc_tracker.c: CAN receive side (E2E, pose assembly, plausibility, timeout), see sc_tracker.h. */
#include "sc_tracker.h"

#include <math.h>

#include "sc_err.h"

#include <string.h>

_Static_assert(SC_MSG_CMD_CASE == 0 && SC_MSG_POSE_FD == 12, "rx message indices 0..12");
_Static_assert(SC_TRK_RX_MSGS == (unsigned)SC_MSG_POSE_FD + 1u, "rx state per message");
_Static_assert(SC_CMD_MSGS == (unsigned)SC_MSG_CMD_MATERIAL + 1u, "commands first");
/* 2,304 bytes on x86_64 with the default SC_CAN_CMD_QUEUE_MAX of 8 and five commands: 9 E2E
 * receivers of 64 B and their last payloads (180 B), 2 assembly slots of 56 B, the command
 * FIFO (48 B each), 5 pending commands (72 B each), the last accepted pairs and their times
 * (120 B), the SecOC receiver (256 B), counters (152 B). The sixth command (CmdAssessment)
 * adds a receiver, a payload, a pending command and a pair: 2,480 B in all; CmdVessels and
 * CmdDoppler 180 B each: 2,840 B (sc_cmd stays 48 B: the kinds' settings share a union);
 * CmdMaterial (0x090) another 192 B: 3,032 B. */
_Static_assert(sizeof(sc_tracker) <= 2648u + 48u * SC_CAN_CMD_QUEUE_MAX, "tracker state grew");

sc_tracker_def sc_tracker_default_def(void)
{
    return (sc_tracker_def){
        .ws_min_mm = {-400.0f, -400.0f, -100.0f},
        .ws_max_mm = {400.0f, 400.0f, 500.0f},
        .quat_norm_tol = 0.02f,
        .max_speed_mm_s = 3000.0f,
        .max_ang_speed_rad_s = 4.0f * 3.14159265f,
        .max_force_n = 200.0f,
        .pose_timeout_ms = 100u,
        .pose_cycle_ms = 10u,
        .max_delta_counter = 3u,
        .accept_fd = 1u,
        .secoc = sc_secoc_default_def(),
    };
}

int sc_tracker_def_validate(const sc_tracker_def *d)
{
    for (unsigned i = 0; i < 3u; i++) {
        if (!isfinite(d->ws_min_mm[i]) || !isfinite(d->ws_max_mm[i])) {
            return SC_ERR_NOT_FINITE;
        }
        if (!(d->ws_min_mm[i] < d->ws_max_mm[i])) {
            return SC_ERR_RANGE;
        }
    }
    if (!isfinite(d->quat_norm_tol) || !isfinite(d->max_speed_mm_s) ||
        !isfinite(d->max_ang_speed_rad_s) || !isfinite(d->max_force_n)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(d->quat_norm_tol > 0.0f && d->quat_norm_tol < 0.5f) || !(d->max_speed_mm_s > 0.0f) ||
        !(d->max_ang_speed_rad_s > 0.0f) || !(d->max_force_n > 0.0f)) {
        return SC_ERR_RANGE;
    }
    if (d->pose_cycle_ms == 0u || d->pose_timeout_ms < d->pose_cycle_ms ||
        d->max_delta_counter < 1u || d->max_delta_counter > SC_E2E_COUNTER_MOD - 2u ||
        d->secoc.window < 1u || d->secoc.window > SC_SECOC_MAX_WINDOW) {
        return SC_ERR_RANGE;
    }
    return 0;
}

const char *sc_trk_outcome_name(sc_trk_outcome o)
{
    switch (o) {
    case SC_TRK_POSE_ACCEPTED:
        return "pose_accepted";
    case SC_TRK_POSE_PART:
        return "pose_part";
    case SC_TRK_COMMAND:
        return "command";
    case SC_TRK_NOT_OURS:
        return "not_ours";
    case SC_TRK_BAD_LENGTH:
        return "bad_length";
    case SC_TRK_FD_DISABLED:
        return "fd_disabled";
    case SC_TRK_E2E_WRONG_CRC:
        return "e2e_wrong_crc";
    case SC_TRK_E2E_WRONG_SEQUENCE:
        return "e2e_wrong_sequence";
    case SC_TRK_E2E_REPEATED:
        return "e2e_repeated";
    case SC_TRK_POSE_STALE:
        return "pose_stale";
    case SC_TRK_NOT_TRACKING:
        return "not_tracking";
    case SC_TRK_REJ_QUAT_NORM:
        return "rej_quat_norm";
    case SC_TRK_REJ_WORKSPACE:
        return "rej_workspace";
    case SC_TRK_REJ_FORCE:
        return "rej_force";
    case SC_TRK_REJ_SPEED:
        return "rej_speed";
    case SC_TRK_REJ_ANG_SPEED:
        return "rej_ang_speed";
    case SC_TRK_CMD_REJECTED:
        return "cmd_rejected";
    case SC_TRK_CMD_QUEUE_FULL:
        return "cmd_queue_full";
    case SC_TRK_BUS_ERROR:
        return "bus_error";
    case SC_TRK_DUPLICATE:
        return "duplicate";
    case SC_TRK_CMD_PENDING:
        return "cmd_pending";
    case SC_TRK_AUTH_SYNCED:
        return "auth_synced";
    case SC_TRK_AUTH_ORPHAN:
        return "auth_orphan";
    case SC_TRK_AUTH_UNKNOWN_SENDER:
        return "auth_unknown_sender";
    case SC_TRK_AUTH_NOT_SYNCED:
        return "auth_not_synced";
    case SC_TRK_AUTH_STALE:
        return "auth_stale";
    case SC_TRK_AUTH_BAD_MAC:
        return "auth_bad_mac";
    case SC_TRK_OUTCOME_COUNT:
        break;
    }
    return "?";
}

int sc_trk_outcome_is_e2e_reject(sc_trk_outcome o)
{
    return o == SC_TRK_E2E_WRONG_CRC || o == SC_TRK_E2E_WRONG_SEQUENCE || o == SC_TRK_E2E_REPEATED;
}

int sc_trk_outcome_is_implausible(sc_trk_outcome o)
{
    return o == SC_TRK_REJ_QUAT_NORM || o == SC_TRK_REJ_WORKSPACE || o == SC_TRK_REJ_FORCE ||
           o == SC_TRK_REJ_SPEED || o == SC_TRK_REJ_ANG_SPEED;
}

int sc_trk_outcome_is_auth_reject(sc_trk_outcome o)
{
    return o == SC_TRK_AUTH_ORPHAN || o == SC_TRK_AUTH_UNKNOWN_SENDER ||
           o == SC_TRK_AUTH_NOT_SYNCED || o == SC_TRK_AUTH_STALE || o == SC_TRK_AUTH_BAD_MAC;
}

static void inc(uint32_t *c)
{
    if (*c != UINT32_MAX) {
        (*c)++;
    }
}

int sc_tracker_init(sc_tracker *t, const sc_tracker_def *def)
{
    int rc = sc_tracker_def_validate(def);
    if (rc != 0) {
        return rc;
    }
    *t = (sc_tracker){.def = *def};
    for (unsigned i = 0; i < SC_TRK_RX_MSGS; i++) {
        const sc_can_msg_info *info = sc_canproto_info((sc_msg)i);
        sc_e2e_rx_def rd = sc_e2e_rx_default_def(info->data_id);
        rd.max_delta_counter = def->max_delta_counter;
        rd.timeout_ms = info->cycle_ms != 0u ? def->pose_timeout_ms : 0u;
        rc = sc_e2e_rx_init(&t->rx[i], &rd);
        if (rc != 0) {
            return rc;
        }
    }
    return sc_secoc_rx_init(&t->secoc, &def->secoc);
}

static sc_trk_outcome e2e_outcome(sc_e2e_status s)
{
    switch (s) {
    case SC_E2E_WRONG_SEQUENCE:
        return SC_TRK_E2E_WRONG_SEQUENCE;
    case SC_E2E_REPEATED:
        return SC_TRK_E2E_REPEATED;
    case SC_E2E_WRONG_CRC:
    case SC_E2E_OK:
    case SC_E2E_INITIAL:
    case SC_E2E_OK_SOME_LOST:
    case SC_E2E_NO_NEW_DATA:
    case SC_E2E_TIMEOUT:
    case SC_E2E_STATUS_COUNT:
        break;
    }
    return SC_TRK_E2E_WRONG_CRC;
}

static void lift(sc_tracker *t)
{
    if (t->have_pose) {
        t->have_pose = 0u;
        inc(&t->n.lift_events);
    }
}

/* Plausibility of an assembled sample against def and the last accepted pose. */
static sc_trk_outcome judge(sc_tracker *t, const sc_pose_msg *m, uint64_t ts_ns)
{
    const sc_tracker_def *d = &t->def;
    if (m->tracking != SC_TRACKING_OK) {
        return SC_TRK_NOT_TRACKING;
    }
    const float n2 = sc_quat_norm2(m->q);
    const float norm = sqrtf(n2);
    if (!(fabsf(norm - 1.0f) <= d->quat_norm_tol)) {
        return SC_TRK_REJ_QUAT_NORM;
    }
    for (unsigned i = 0; i < 3u; i++) {
        if (!(m->pos_mm[i] >= d->ws_min_mm[i] && m->pos_mm[i] <= d->ws_max_mm[i])) {
            return SC_TRK_REJ_WORKSPACE;
        }
    }
    if (m->force_valid && !(m->force_n <= d->max_force_n)) {
        return SC_TRK_REJ_FORCE;
    }
    if (t->have_pose) {
        /* dt from receive times, floored at one pose period: frames queued behind each other
         * arrive together but were sampled a period apart. */
        const uint64_t cyc_ns = (uint64_t)d->pose_cycle_ms * 1000000u;
        const uint64_t dt_ns =
            ts_ns > t->cur.rx_ns && ts_ns - t->cur.rx_ns > cyc_ns ? ts_ns - t->cur.rx_ns : cyc_ns;
        const float dt_s = (float)dt_ns * 1e-9f;
        float d2 = 0.0f;
        for (unsigned i = 0; i < 3u; i++) {
            const float dx = m->pos_mm[i] - t->cur.pose.pos_mm[i];
            d2 += dx * dx;
        }
        if (sqrtf(d2) > d->max_speed_mm_s * dt_s) {
            return SC_TRK_REJ_SPEED;
        }
        float dot = 0.0f;
        for (unsigned i = 0; i < 4u; i++) {
            dot += m->q[i] * t->cur.pose.q[i];
        }
        dot = fabsf(dot) / norm; /* cur.pose.q is unit already */
        if (dot > 1.0f) {
            dot = 1.0f;
        }
        const float angle_rad = 2.0f * acosf(dot);
        if (angle_rad > d->max_ang_speed_rad_s * dt_s) {
            return SC_TRK_REJ_ANG_SPEED;
        }
    }
    return SC_TRK_POSE_ACCEPTED;
}

static sc_trk_outcome take_sample(sc_tracker *t, const sc_pose_msg *m, uint8_t counter,
                                  uint64_t ts_ns)
{
    if (t->have_last_counter && t->have_pose) {
        /* A sample at most max_delta_counter behind the last assembled one completed late
         * (parts reordered across ids): older than the current pose, never used. A larger
         * distance is a jump forward after losses. */
        const unsigned delta =
            (counter + SC_E2E_COUNTER_MOD - t->last_counter) % SC_E2E_COUNTER_MOD;
        if (delta == 0u || delta >= SC_E2E_COUNTER_MOD - t->def.max_delta_counter) {
            return SC_TRK_POSE_STALE;
        }
    }
    t->have_last_counter = 1u;
    t->last_counter = counter;
    const sc_trk_outcome o = judge(t, m, ts_ns);
    if (o != SC_TRK_POSE_ACCEPTED) {
        return o;
    }
    const float inv = 1.0f / sqrtf(sc_quat_norm2(m->q));
    sc_trk_sample s = {
        .force_n = m->force_n, .force_valid = m->force_valid, .counter = counter, .rx_ns = ts_ns};
    for (unsigned i = 0; i < 3u; i++) {
        s.pose.pos_mm[i] = m->pos_mm[i];
    }
    for (unsigned i = 0; i < 4u; i++) {
        s.pose.q[i] = m->q[i] * inv;
    }
    t->cur = s;
    t->have_pose = 1u;
    return SC_TRK_POSE_ACCEPTED;
}

static sc_trk_outcome on_pose_part(sc_tracker *t, const sc_can_frame *f, uint8_t counter,
                                   uint64_t ts_ns)
{
    /* find the slot of this sample, else a free one, else evict the oldest */
    sc_trk_asm *a = NULL;
    for (unsigned i = 0; i < SC_TRK_ASM_SLOTS; i++) {
        if (t->slot[i].used && t->slot[i].counter == counter) {
            a = &t->slot[i];
        }
    }
    if (a == NULL) {
        for (unsigned i = 0; i < SC_TRK_ASM_SLOTS && a == NULL; i++) {
            if (!t->slot[i].used) {
                a = &t->slot[i];
            }
        }
    }
    if (a == NULL) {
        a = &t->slot[0];
        for (unsigned i = 1; i < SC_TRK_ASM_SLOTS; i++) {
            if (t->slot[i].seq < a->seq) {
                a = &t->slot[i];
            }
        }
        inc(&t->n.incomplete);
        a->used = 0u;
    }
    if (!a->used) {
        *a = (sc_trk_asm){.used = 1u, .counter = counter, .seq = t->slot_seq++};
    }
    const int part = sc_canproto_decode_pose_part(f, &a->msg);
    if (part < 0) {
        return SC_TRK_BAD_LENGTH; /* unreachable: classified before */
    }
    a->mask = (uint8_t)(a->mask | (uint8_t)part);
    if (ts_ns > a->ts_ns) {
        a->ts_ns = ts_ns;
    }
    if (a->mask != SC_POSE_PARTS_ALL) {
        return SC_TRK_POSE_PART;
    }
    const sc_pose_msg m = a->msg;
    const uint64_t ts = a->ts_ns;
    a->used = 0u;
    /* partial samples older than this one can never complete usefully: drop them */
    for (unsigned i = 0; i < SC_TRK_ASM_SLOTS; i++) {
        sc_trk_asm *o = &t->slot[i];
        const unsigned behind = (counter + SC_E2E_COUNTER_MOD - o->counter) % SC_E2E_COUNTER_MOD;
        if (o->used && behind >= 1u && behind <= SC_E2E_COUNTER_MOD / 2u) {
            o->used = 0u;
            inc(&t->n.incomplete);
        }
    }
    return take_sample(t, &m, counter, ts);
}

static sc_trk_outcome queue_command(sc_tracker *t, const sc_cmd *c)
{
    if (t->cmd_count >= SC_CAN_CMD_QUEUE_MAX) {
        return SC_TRK_CMD_QUEUE_FULL;
    }
    t->cmd[(t->cmd_head + t->cmd_count) % SC_CAN_CMD_QUEUE_MAX] = *c;
    t->cmd_count++;
    return SC_TRK_COMMAND;
}

/* A command (authentic PDU) passed E2E: decode and hold it for its cryptographic PDU. A
 * command still waiting under the same id never got its MAC: counted missing. */
static sc_trk_outcome on_command(sc_tracker *t, const sc_can_frame *f, sc_msg m, uint64_t ts_ns)
{
    sc_cmd c;
    if (sc_canproto_decode_cmd(f, &c) != 0) {
        return SC_TRK_CMD_REJECTED;
    }
    sc_trk_pending *p = &t->pending[m];
    if (p->used && memcmp(p->pdu, f->data, sizeof(p->pdu)) == 0) {
        return SC_TRK_DUPLICATE; /* the waiting command again */
    }
    if (p->used) {
        inc(&t->n.auth_missing);
    }
    p->used = 1u;
    memcpy(p->pdu, f->data, sizeof(p->pdu));
    p->ts_ns = ts_ns;
    p->cmd = c;
    return SC_TRK_CMD_PENDING;
}

static sc_trk_outcome auth_outcome(sc_secoc_result r)
{
    switch (r) {
    case SC_SECOC_UNKNOWN_SENDER:
        return SC_TRK_AUTH_UNKNOWN_SENDER;
    case SC_SECOC_NOT_SYNCED:
        return SC_TRK_AUTH_NOT_SYNCED;
    case SC_SECOC_STALE:
        return SC_TRK_AUTH_STALE;
    case SC_SECOC_OK:
    case SC_SECOC_BAD_MAC:
    case SC_SECOC_RESULT_COUNT:
        break;
    }
    return SC_TRK_AUTH_BAD_MAC;
}

/* A cryptographic PDU: pair it with its held command, verify, and queue the command. */
static sc_trk_outcome on_auth(sc_tracker *t, const sc_can_frame *f, sc_msg m, uint64_t ts_ns)
{
    const unsigned k = (unsigned)m - (unsigned)SC_MSG_AUTH_CASE;
    sc_trk_pending *p = &t->pending[k];
    sc_secoc_auth a;
    sc_secoc_auth_decode(f->data, &a);
    /* the last accepted cryptographic PDU again: within SC_TRK_AUTH_PAIR_MS a bus duplicate,
     * later a replay (its freshness is stale); either way never applied twice */
    const int same_auth = t->have_last_auth[k] && memcmp(t->last_auth[k], f->data, 8u) == 0;
    const int soon = ts_ns >= t->last_auth_ns[k] &&
                     ts_ns - t->last_auth_ns[k] <= (uint64_t)SC_TRK_AUTH_PAIR_MS * 1000000u;
    if (!p->used || a.link != (p->pdu[1] & 0x0Fu)) {
        return same_auth ? (soon ? SC_TRK_DUPLICATE : SC_TRK_AUTH_STALE) : SC_TRK_AUTH_ORPHAN;
    }
    p->used = 0u;
    if (same_auth && memcmp(t->last_auth_pdu[k], p->pdu, 8u) == 0) {
        return soon ? SC_TRK_DUPLICATE : SC_TRK_AUTH_STALE;
    }
    const sc_msg cm = (sc_msg)k;
    const uint64_t *sync = p->cmd.kind == SC_CMD_SYNC_FRESHNESS ? &p->cmd.fv_high : NULL;
    const sc_secoc_result r =
        sc_secoc_verify(&t->secoc, sc_canproto_info(cm)->data_id, p->pdu, &a, sync, NULL);
    if (r != SC_SECOC_OK) {
        return auth_outcome(r);
    }
    memcpy(t->last_auth[k], f->data, 8u);
    memcpy(t->last_auth_pdu[k], p->pdu, 8u);
    t->last_auth_ns[k] = ts_ns;
    t->have_last_auth[k] = 1u;
    if (sync != NULL) {
        return SC_TRK_AUTH_SYNCED;
    }
    sc_cmd c = p->cmd;
    c.sender = a.sender;
    return queue_command(t, &c);
}

static sc_trk_outcome classify_and_handle(sc_tracker *t, const sc_can_frame *f, uint64_t now_ns)
{
    if (f->flags & SC_CAN_FLAG_ERR) {
        t->bus_errors |= f->id;
        for (unsigned b = 0; b < 6u; b++) {
            if (f->id & (1u << b)) {
                inc(&t->n.bus_err_class[b]);
            }
        }
        return SC_TRK_BUS_ERROR;
    }
    sc_msg m;
    const int rc = sc_canproto_classify(f, &m);
    if (rc == SC_ERR_CAN_ID ||
        (rc == 0 && (unsigned)m >= SC_TRK_RX_MSGS && !SC_MSG_IS_AUTH(m))) {
        return SC_TRK_NOT_OURS;
    }
    if (rc != 0) {
        return SC_TRK_BAD_LENGTH;
    }
    /* receive times at microsecond resolution, the candump log's: a replayed log then gives
     * every time-dependent decision (speed, timeout) exactly as the live run did */
    const uint64_t ts_ns = (f->ts_ns != 0u ? f->ts_ns : now_ns) / 1000u * 1000u;
    if (SC_MSG_IS_AUTH(m)) {
        return on_auth(t, f, m, ts_ns);
    }
    if (m == SC_MSG_POSE_FD && !t->def.accept_fd) {
        return SC_TRK_FD_DISABLED;
    }
    sc_e2e_rx *rx = &t->rx[m];
    const uint32_t lost_before = rx->lost;
    const sc_e2e_status s = sc_e2e_check(rx, f->data, f->len, ts_ns);
    t->n.e2e_lost += rx->lost - lost_before;
    if (s == SC_E2E_REPEATED && !SC_MSG_IS_CMD(m) &&
        memcmp(t->last_ok[m], f->data, f->len) == 0) {
        return SC_TRK_DUPLICATE; /* the same frame twice: nothing lost, nothing wrong */
    }
    /* Commands come from several senders, each with its own E2E counter: their order and
     * replay are the freshness value's job (per sender, authenticated), the E2E layer checks
     * only their CRC. */
    const int seq_only = SC_MSG_IS_CMD(m) && (s == SC_E2E_REPEATED || s == SC_E2E_WRONG_SEQUENCE);
    if (!sc_e2e_status_usable(s) && !seq_only) {
        return e2e_outcome(s);
    }
    memcpy(t->last_ok[m], f->data, f->len);
    const uint8_t counter = (uint8_t)(f->data[1] & 0x0Fu);
    switch (m) {
    case SC_MSG_CMD_CASE:
    case SC_MSG_CMD_METHOD:
    case SC_MSG_CMD_IMAGING:
    case SC_MSG_CMD_RESET:
    case SC_MSG_CMD_SYNC:
    case SC_MSG_CMD_ASSESS:
    case SC_MSG_CMD_VESSELS:
    case SC_MSG_CMD_DOPPLER:
    case SC_MSG_CMD_MATERIAL:
        return on_command(t, f, m, ts_ns);
    case SC_MSG_POSE_POS:
    case SC_MSG_POSE_QUAT:
    case SC_MSG_POSE_AUX:
        return on_pose_part(t, f, counter, ts_ns);
    case SC_MSG_POSE_FD: {
        sc_pose_msg pm = {0};
        (void)sc_canproto_decode_pose_part(f, &pm);
        return take_sample(t, &pm, counter, ts_ns);
    }
    case SC_MSG_STATUS:
    case SC_MSG_TIMING:
    case SC_MSG_DIAG:
    case SC_MSG_AUTH_DIAG:
    case SC_MSG_AUTH_CASE:
    case SC_MSG_AUTH_METHOD:
    case SC_MSG_AUTH_IMAGING:
    case SC_MSG_AUTH_RESET:
    case SC_MSG_AUTH_SYNC:
    case SC_MSG_AUTH_ASSESS:
    case SC_MSG_AUTH_VESSELS:
    case SC_MSG_AUTH_DOPPLER:
    case SC_MSG_AUTH_MATERIAL:
    case SC_MSG_ASSESS_VESSELS:
    case SC_MSG_ASSESS_FORCE:
    case SC_MSG_ASSESS_SCORE:
    case SC_MSG_NEEDLE_POS: /* the needle has its own receiver (sc_needle_rx.h) */
    case SC_MSG_NEEDLE_DIR:
    case SC_MSG_NEEDLE_AUX:
    case SC_MSG_NEEDLE_STATUS:
    case SC_MSG_COUNT:
        break;
    }
    return SC_TRK_NOT_OURS;
}

sc_trk_outcome sc_tracker_on_frame(sc_tracker *t, const sc_can_frame *f, uint64_t now_ns)
{
    inc(&t->n.frames);
    const sc_trk_outcome o = classify_and_handle(t, f, now_ns);
    inc(&t->n.outcome[o]);
    return o;
}

int sc_tracker_poll(sc_tracker *t, uint64_t now_ns, sc_pose *out, int *contact)
{
    for (unsigned i = 0; i < SC_TRK_RX_MSGS; i++) {
        (void)sc_e2e_poll(&t->rx[i], now_ns);
    }
    /* commands whose cryptographic PDU did not follow in time are refused */
    const uint64_t pair_ns = (uint64_t)SC_TRK_AUTH_PAIR_MS * 1000000u;
    for (unsigned i = 0; i < SC_CMD_MSGS; i++) {
        sc_trk_pending *p = &t->pending[i];
        if (p->used && now_ns > p->ts_ns && now_ns - p->ts_ns > pair_ns) {
            p->used = 0u;
            inc(&t->n.auth_missing);
        }
    }
    if (t->have_pose) {
        const uint64_t timeout_ns = (uint64_t)t->def.pose_timeout_ms * 1000000u;
        if (now_ns > t->cur.rx_ns && now_ns - t->cur.rx_ns > timeout_ns) {
            lift(t);
        }
    }
    if (!t->have_pose) {
        *contact = 0;
        return SC_ERR_TIMEOUT;
    }
    *out = t->cur.pose;
    *contact = 1;
    return 0;
}

const sc_trk_sample *sc_tracker_sample(const sc_tracker *t)
{
    return t->have_pose ? &t->cur : NULL;
}

int sc_tracker_take_command(sc_tracker *t, sc_cmd *out)
{
    if (t->cmd_count == 0u) {
        return SC_ERR_WOULD_BLOCK;
    }
    *out = t->cmd[t->cmd_head];
    t->cmd_head = (uint8_t)((t->cmd_head + 1u) % SC_CAN_CMD_QUEUE_MAX);
    t->cmd_count--;
    return 0;
}

uint32_t sc_tracker_take_bus_errors(sc_tracker *t)
{
    const uint32_t e = t->bus_errors;
    t->bus_errors = 0u;
    return e;
}

const sc_trk_counters *sc_tracker_counters(const sc_tracker *t)
{
    return &t->n;
}

uint32_t sc_tracker_rejected_e2e(const sc_tracker *t)
{
    uint64_t s = 0;
    for (unsigned i = 0; i < (unsigned)SC_TRK_OUTCOME_COUNT; i++) {
        if (sc_trk_outcome_is_e2e_reject((sc_trk_outcome)i)) {
            s += t->n.outcome[i];
        }
    }
    return s > UINT32_MAX ? UINT32_MAX : (uint32_t)s;
}

uint32_t sc_tracker_rejected_implausible(const sc_tracker *t)
{
    uint64_t s = 0;
    for (unsigned i = 0; i < (unsigned)SC_TRK_OUTCOME_COUNT; i++) {
        if (sc_trk_outcome_is_implausible((sc_trk_outcome)i)) {
            s += t->n.outcome[i];
        }
    }
    return s > UINT32_MAX ? UINT32_MAX : (uint32_t)s;
}

uint32_t sc_tracker_rejected_auth(const sc_tracker *t)
{
    uint64_t s = t->n.auth_missing;
    for (unsigned i = 0; i < (unsigned)SC_TRK_OUTCOME_COUNT; i++) {
        if (sc_trk_outcome_is_auth_reject((sc_trk_outcome)i)) {
            s += t->n.outcome[i];
        }
    }
    return s > UINT32_MAX ? UINT32_MAX : (uint32_t)s;
}

uint32_t sc_tracker_authenticated(const sc_tracker *t)
{
    const uint64_t s =
        (uint64_t)t->n.outcome[SC_TRK_COMMAND] + t->n.outcome[SC_TRK_AUTH_SYNCED];
    return s > UINT32_MAX ? UINT32_MAX : (uint32_t)s;
}

const sc_e2e_rx *sc_tracker_e2e(const sc_tracker *t, sc_msg m)
{
    return (unsigned)m < SC_TRK_RX_MSGS ? &t->rx[m] : NULL;
}
