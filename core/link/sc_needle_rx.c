/* sc_needle_rx.c: the tracked needle's receiver (see sc_needle_rx.h). */
#include "sc_needle_rx.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"

sc_needle_rx_def sc_needle_rx_default_def(void)
{
    return (sc_needle_rx_def){
        .workspace_mm = 1000.0f, .max_depth_mm = 200.0f, .max_speed_mm_s = 2000.0f,
        .timeout_ms = 100u};
}

int sc_needle_rx_init(sc_needle_rx *n, const sc_needle_rx_def *def)
{
    if (n == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(def->workspace_mm) || !isfinite(def->max_depth_mm) ||
        !isfinite(def->max_speed_mm_s)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(def->workspace_mm > 0.0f && def->workspace_mm <= 1638.0f) ||
        !(def->max_depth_mm > 0.0f && def->max_depth_mm <= 3276.0f) ||
        !(def->max_speed_mm_s > 0.0f) || def->timeout_ms < 10u || def->timeout_ms > 10000u) {
        return SC_ERR_RANGE;
    }
    memset(n, 0, sizeof *n);
    n->def = *def;
    for (unsigned i = 0; i < 3u; i++) {
        sc_e2e_rx_def rd =
            sc_e2e_rx_default_def((uint16_t)(SC_CANID_NEEDLE_POS + (uint16_t)i));
        rd.timeout_ms = def->timeout_ms;
        const int rc = sc_e2e_rx_init(&n->rx[i], &rd);
        if (rc != SC_OK) {
            return rc;
        }
    }
    return SC_OK;
}

int sc_needle_rx_is_needle(const sc_can_frame *f)
{
    return f != NULL && (f->flags & (SC_CAN_FLAG_EXT | SC_CAN_FLAG_RTR)) == 0u &&
           f->id >= SC_CANID_NEEDLE_POS && f->id <= SC_CANID_NEEDLE_AUX;
}

static sc_needle_outcome check_sample(sc_needle_rx *n, uint64_t now_ns)
{
    const sc_needle_msg *m = &n->msg;
    if (m->tracking != SC_TRACKING_OK) {
        return SC_NEEDLE_NOT_TRACKING;
    }
    const float nn = sqrtf(m->dir[0] * m->dir[0] + m->dir[1] * m->dir[1] + m->dir[2] * m->dir[2]);
    if (!(nn >= 0.9f && nn <= 1.1f)) {
        return SC_NEEDLE_REJ_DIR_NORM;
    }
    for (unsigned i = 0; i < 3u; i++) {
        if (!(fabsf(m->tip_mm[i]) <= n->def.workspace_mm)) {
            return SC_NEEDLE_REJ_WORKSPACE;
        }
    }
    if (!(m->depth_mm >= 0.0f && m->depth_mm <= n->def.max_depth_mm)) {
        return SC_NEEDLE_REJ_DEPTH;
    }
    if (n->have && now_ns > n->cur.rx_ns) {
        const float dt_s = (float)(now_ns - n->cur.rx_ns) * 1e-9f;
        float d2 = 0.0f;
        for (unsigned i = 0; i < 3u; i++) {
            const float d = m->tip_mm[i] - n->cur.tip_mm[i];
            d2 += d * d;
        }
        /* a jump after a pause is a new placement, not a speed: only within the timeout */
        if (dt_s * 1000.0f < (float)n->def.timeout_ms &&
            sqrtf(d2) > n->def.max_speed_mm_s * dt_s + 1.0f) {
            return SC_NEEDLE_REJ_SPEED;
        }
    }
    for (unsigned i = 0; i < 3u; i++) {
        n->cur.tip_mm[i] = m->tip_mm[i];
        n->cur.dir[i] = m->dir[i] / nn;
    }
    n->cur.depth_mm = m->depth_mm;
    n->cur.rx_ns = now_ns;
    n->have = 1u;
    return SC_NEEDLE_ACCEPTED;
}

static sc_needle_outcome handle(sc_needle_rx *n, const sc_can_frame *f, uint64_t now_ns)
{
    if (!sc_needle_rx_is_needle(f)) {
        return SC_NEEDLE_NOT_OURS;
    }
    sc_msg m;
    if (sc_canproto_classify(f, &m) != SC_OK || !SC_MSG_IS_NEEDLE_IN(m)) {
        return SC_NEEDLE_BAD_LENGTH;
    }
    const unsigned part = (unsigned)m - (unsigned)SC_MSG_NEEDLE_POS;
    const uint64_t ts = f->ts_ns != 0u ? f->ts_ns : now_ns;
    switch (sc_e2e_check(&n->rx[part], f->data, f->len, ts)) {
    case SC_E2E_OK:
    case SC_E2E_INITIAL:
    case SC_E2E_OK_SOME_LOST:
        break;
    case SC_E2E_WRONG_SEQUENCE:
        return SC_NEEDLE_E2E_SEQUENCE;
    case SC_E2E_REPEATED:
        return SC_NEEDLE_E2E_REPEATED;
    case SC_E2E_WRONG_CRC:
    case SC_E2E_NO_NEW_DATA:
    case SC_E2E_TIMEOUT:
    case SC_E2E_STATUS_COUNT:
    default:
        return SC_NEEDLE_E2E_CRC;
    }
    const uint8_t counter = (uint8_t)(f->data[1] & 0x0Fu);
    if (n->mask != 0u && counter != n->counter) {
        n->mask = 0u; /* a part of an older sample was lost: start over with this one */
    }
    n->counter = counter;
    const int bit = sc_canproto_decode_needle_part(f, &n->msg);
    if (bit < 0) {
        return SC_NEEDLE_BAD_LENGTH;
    }
    n->mask = (uint8_t)(n->mask | (uint8_t)bit);
    if (n->mask != SC_NEEDLE_PARTS_ALL) {
        return SC_NEEDLE_PART;
    }
    n->mask = 0u;
    return check_sample(n, ts);
}

sc_needle_outcome sc_needle_rx_on_frame(sc_needle_rx *n, const sc_can_frame *f, uint64_t now_ns)
{
    const sc_needle_outcome o = handle(n, f, now_ns);
    if (n->outcome[o] != UINT32_MAX) {
        n->outcome[o]++;
    }
    if (o != SC_NEEDLE_ACCEPTED && o != SC_NEEDLE_PART && o != SC_NEEDLE_NOT_OURS &&
        o != SC_NEEDLE_NOT_TRACKING && n->rejected != UINT32_MAX) {
        n->rejected++;
    }
    return o;
}

int sc_needle_rx_poll(const sc_needle_rx *n, uint64_t now_ns, sc_needle_sample *out)
{
    if (!n->have || now_ns < n->cur.rx_ns ||
        now_ns - n->cur.rx_ns > (uint64_t)n->def.timeout_ms * 1000000u) {
        return 0;
    }
    *out = n->cur;
    return 1;
}
