/* sc_can_rxmb.c: receive mailboxes, see sc_can_rxmb.h. */
#include "sc_can_rxmb.h"

#include <string.h>

#include "sc_config.h"
#include "sc_err.h"

sc_can_rxmb_def sc_can_rxmb_default_def(void)
{
    return (sc_can_rxmb_def){.stream_cap = SC_CAN_RX_BURST_MAX};
}

int sc_can_rxmb_init(sc_can_rxmb *mb, const sc_can_rxmb_def *def)
{
    if (mb == NULL || def == NULL || def->stream_cap == 0u ||
        def->stream_cap > SC_CAN_RXMB_STREAM_MAX) {
        return SC_ERR_RANGE;
    }
    memset(mb, 0, sizeof *mb);
    mb->def = *def;
    return SC_OK;
}

int sc_can_rxmb_is_priority(const sc_can_frame *f)
{
    if (f->flags & SC_CAN_FLAG_ERR) {
        return 1;
    }
    return !(f->flags & SC_CAN_FLAG_EXT) && f->id >= SC_CAN_RXMB_PRIO_ID_LO &&
           f->id <= SC_CAN_RXMB_PRIO_ID_HI;
}

int sc_can_rxmb_put(sc_can_rxmb *mb, const sc_can_frame *f)
{
    mb->c.put++;
    if (sc_can_rxmb_is_priority(f)) {
        if (mb->prio_count == SC_CAN_RXMB_PRIO_MAX) {
            mb->c.prio_dropped++;
            return SC_ERR_NO_SPACE;
        }
        mb->prio[(mb->prio_head + mb->prio_count) % SC_CAN_RXMB_PRIO_MAX] = *f;
        mb->prio_count++;
        if (mb->prio_count > mb->c.prio_depth_max) {
            mb->c.prio_depth_max = mb->prio_count;
        }
        return SC_OK;
    }
    const uint32_t cap = mb->def.stream_cap;
    if (mb->stream_count == cap) {
        /* the newest pose wins: the oldest frame gives its place */
        mb->stream_head = (mb->stream_head + 1u) % cap;
        mb->stream_count--;
        mb->c.stream_overwritten++;
    }
    mb->stream[(mb->stream_head + mb->stream_count) % cap] = *f;
    mb->stream_count++;
    if (mb->stream_count > mb->c.stream_depth_max) {
        mb->c.stream_depth_max = mb->stream_count;
    }
    return SC_OK;
}

int sc_can_rxmb_take(sc_can_rxmb *mb, sc_can_frame *out)
{
    if (mb->prio_count > 0u) {
        *out = mb->prio[mb->prio_head];
        mb->prio_head = (mb->prio_head + 1u) % SC_CAN_RXMB_PRIO_MAX;
        mb->prio_count--;
        mb->c.prio_taken++;
        return SC_OK;
    }
    if (mb->stream_count > 0u) {
        *out = mb->stream[mb->stream_head];
        mb->stream_head = (mb->stream_head + 1u) % mb->def.stream_cap;
        mb->stream_count--;
        mb->c.stream_taken++;
        return SC_OK;
    }
    return SC_ERR_WOULD_BLOCK;
}

uint32_t sc_can_rxmb_depth(const sc_can_rxmb *mb)
{
    return mb->prio_count + mb->stream_count;
}

uint32_t sc_can_rxmb_drain(sc_can_rxmb *mb, const sc_can_dev *src, uint32_t max, uint64_t ts_ns)
{
    uint32_t n = 0;
    sc_can_frame f;
    while (n < max && sc_can_recv(src, &f) == SC_OK) {
        if (ts_ns != 0u) {
            f.ts_ns = ts_ns;
        }
        (void)sc_can_rxmb_put(mb, &f); /* a refusal is counted in the mailbox */
        n++;
    }
    return n;
}

int sc_can_rxmb_port_init(sc_can_rxmb_port *p, const sc_can_rxmb_def *def, sc_can_dev src,
                          uint32_t drain_max)
{
    if (p == NULL || src.ops == NULL || src.ops->recv == NULL || drain_max == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_can_rxmb_init(&p->mb, def);
    if (rc != SC_OK) {
        return rc;
    }
    p->src = src;
    p->drain_max = drain_max;
    p->drain_limited = 0;
    return SC_OK;
}

static int port_send(void *ctx, const sc_can_frame *f)
{
    const sc_can_rxmb_port *p = ctx;
    return sc_can_send(&p->src, f);
}

static int port_recv(void *ctx, sc_can_frame *out)
{
    sc_can_rxmb_port *p = ctx;
    if (sc_can_rxmb_drain(&p->mb, &p->src, p->drain_max, 0u) == p->drain_max) {
        p->drain_limited++;
    }
    return sc_can_rxmb_take(&p->mb, out);
}

static int port_filters(void *ctx, const sc_can_filter *filters, size_t count)
{
    /* acceptance filters stay the transport's (SocketCAN: the kernel's); frames already in
     * the mailboxes were accepted under the old ones, as in a controller */
    const sc_can_rxmb_port *p = ctx;
    return sc_can_set_filters(&p->src, filters, count);
}

static int port_state(void *ctx, sc_can_state *st, sc_can_counters *c)
{
    const sc_can_rxmb_port *p = ctx;
    const int rc = sc_can_get_state(&p->src, st, c);
    if (rc == SC_OK && c != NULL) {
        /* the mailboxes' losses are the controller's: receive frames lost */
        const uint64_t lost = p->mb.c.prio_dropped + p->mb.c.stream_overwritten;
        c->rx_dropped += (uint32_t)(lost > UINT32_MAX ? UINT32_MAX : lost);
    }
    return rc;
}

sc_can_dev sc_can_rxmb_port_dev(sc_can_rxmb_port *p)
{
    static const sc_can_ops ops = {
        .send = port_send, .recv = port_recv, .set_filters = port_filters, .get_state = port_state};
    return (sc_can_dev){.ops = &ops, .ctx = p};
}
