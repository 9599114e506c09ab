/* sc_hs_can.c: in-process CAN bus with fault injection, see sc_hs_can.h. */
#include "sc_hs_can.h"

#include <string.h>

#include "sc_err.h"

static uint32_t rng_next(sc_hs_can_bus *bus)
{
    /* xorshift64*: deterministic, good enough for fault draws */
    uint64_t x = bus->rng;
    x ^= x >> 12u;
    x ^= x << 25u;
    x ^= x >> 27u;
    bus->rng = x;
    return (uint32_t)((x * 2685821657736338717ull) >> 32u);
}

static int draw(sc_hs_can_bus *bus, uint32_t ppm)
{
    return ppm != 0u && (rng_next(bus) % 1000000u) < ppm;
}

void sc_hs_can_bus_init(sc_hs_can_bus *bus, const sc_clock_dev *clock, uint64_t seed)
{
    memset(bus, 0, sizeof(*bus));
    bus->clock = clock;
    bus->rng = seed ? seed : 0x9E3779B97F4A7C15ull;
}

int sc_hs_can_add_node(sc_hs_can_bus *bus)
{
    if (bus->node_count >= SC_HS_CAN_MAX_NODES) {
        return SC_ERR_NO_SPACE;
    }
    uint32_t i = bus->node_count++;
    memset(&bus->nodes[i], 0, sizeof(bus->nodes[i]));
    bus->nodes[i].bus = bus;
    bus->nodes[i].index = i;
    return (int)i;
}

void sc_hs_can_set_faults(sc_hs_can_bus *bus, const sc_hs_can_faults *faults)
{
    bus->faults = *faults;
}

static int accepts(const sc_hs_can_node *n, const sc_can_frame *f)
{
    if (f->flags & SC_CAN_FLAG_ERR) {
        return 1; /* error frames always reach the controller's owner */
    }
    if (n->filter_count == 0u) {
        return 1;
    }
    for (uint32_t i = 0; i < n->filter_count; i++) {
        const sc_can_filter *flt = &n->filters[i];
        if (((flt->flags ^ f->flags) & SC_CAN_FLAG_EXT) == 0u &&
            (f->id & flt->mask) == (flt->id & flt->mask)) {
            return 1;
        }
    }
    return 0;
}

static void enqueue(sc_hs_can_node *n, const sc_can_frame *f, uint64_t at_ns)
{
    if (!accepts(n, f)) {
        n->rx_filtered++; /* the controller's acceptance filter: the owner never sees it */
        return;
    }
    if (n->count >= SC_HS_CAN_QUEUE) {
        n->rx_overruns++;
        return;
    }
    sc_hs_can_slot *s = &n->queue[(n->head + n->count) % SC_HS_CAN_QUEUE];
    s->frame = *f;
    s->frame.ts_ns = at_ns;
    s->deliver_at_ns = at_ns;
    n->count++;
}

static void broadcast(sc_hs_can_bus *bus, uint32_t from, const sc_can_frame *f)
{
    const uint64_t at = sc_clock_now_ns(bus->clock) + bus->faults.delay_ns;
    for (uint32_t i = 0; i < bus->node_count; i++) {
        if (i != from) {
            enqueue(&bus->nodes[i], f, at);
        }
    }
}

int sc_hs_can_inject(sc_hs_can_bus *bus, uint32_t node, const sc_can_frame *frame)
{
    if (node >= bus->node_count) {
        return SC_ERR_INVALID_ARG;
    }
    sc_hs_can_node *n = &bus->nodes[node];
    if (n->count >= SC_HS_CAN_QUEUE) {
        n->rx_overruns++;
        return SC_ERR_NO_SPACE;
    }
    sc_hs_can_slot *s = &n->queue[(n->head + n->count) % SC_HS_CAN_QUEUE];
    s->frame = *frame;
    s->deliver_at_ns = 0;
    n->count++;
    return SC_OK;
}

void sc_hs_can_flush(sc_hs_can_bus *bus)
{
    if (bus->held_valid) {
        bus->held_valid = 0;
        broadcast(bus, bus->held_from, &bus->held);
    }
}

static int hs_send(void *ctx, const sc_can_frame *frame)
{
    sc_hs_can_node *n = ctx;
    sc_hs_can_bus *bus = n->bus;
    sc_hs_can_injected *mine = &bus->by_sender[n->index];
    if (!sc_can_len_valid(frame->len, frame->flags) || (frame->flags & SC_CAN_FLAG_ERR)) {
        return SC_ERR_INVALID_ARG;
    }
    if (bus->bus_off) {
        n->tx_refused++;
        return SC_ERR_CAN_BUS_OFF;
    }
    n->tx_frames++;
    bus->injected.sent++;
    mine->sent++;
    if (draw(bus, bus->faults.drop_ppm)) {
        bus->injected.dropped++;
        mine->dropped++;
        return SC_OK; /* lost on the wire: the sender cannot tell */
    }
    sc_can_frame f = *frame;
    if (f.len > 0u && draw(bus, bus->faults.corrupt_ppm)) {
        uint32_t bit = rng_next(bus) % (8u * f.len);
        f.data[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        bus->injected.corrupted++;
        mine->corrupted++;
    }
    const int dup = draw(bus, bus->faults.duplicate_ppm);
    if (dup) {
        bus->injected.duplicated++;
        mine->duplicated++;
    }
    if (!bus->held_valid && draw(bus, bus->faults.reorder_ppm)) {
        bus->held = f;
        bus->held_from = n->index;
        bus->held_valid = 1;
        bus->injected.reordered++;
        mine->reordered++;
        if (dup) {
            broadcast(bus, n->index, &f);
        }
        return SC_OK;
    }
    broadcast(bus, n->index, &f);
    if (dup) {
        broadcast(bus, n->index, &f);
    }
    sc_hs_can_flush(bus); /* a held frame goes out after this one: order swapped */
    return SC_OK;
}

static int hs_recv(void *ctx, sc_can_frame *out)
{
    sc_hs_can_node *n = ctx;
    if (n->count == 0u) {
        return SC_ERR_WOULD_BLOCK;
    }
    const sc_hs_can_slot *s = &n->queue[n->head];
    if (s->deliver_at_ns > sc_clock_now_ns(n->bus->clock)) {
        return SC_ERR_WOULD_BLOCK; /* still in flight (injected delay) */
    }
    *out = s->frame;
    n->head = (n->head + 1u) % SC_HS_CAN_QUEUE;
    n->count--;
    n->rx_frames++;
    return SC_OK;
}

static int hs_set_filters(void *ctx, const sc_can_filter *filters, size_t count)
{
    sc_hs_can_node *n = ctx;
    if (count > SC_HS_CAN_MAX_FILTERS) {
        return SC_ERR_NO_SPACE;
    }
    if (count && !filters) {
        return SC_ERR_INVALID_ARG;
    }
    for (size_t i = 0; i < count; i++) {
        n->filters[i] = filters[i];
    }
    n->filter_count = (uint32_t)count;
    return SC_OK;
}

static int hs_get_state(void *ctx, sc_can_state *state, sc_can_counters *counters)
{
    sc_hs_can_node *n = ctx;
    if (state) {
        *state = n->bus->bus_off ? SC_CAN_STATE_BUS_OFF : SC_CAN_STATE_ERROR_ACTIVE;
    }
    if (counters) {
        *counters = (sc_can_counters){
            .tx_err = n->bus->bus_off ? 256u : 0u,
            .rx_err = 0u,
            .rx_dropped = n->rx_overruns,
            .tx_dropped = n->tx_refused,
        };
    }
    return SC_OK;
}

static const sc_can_ops hs_can_ops = {
    .send = hs_send,
    .recv = hs_recv,
    .set_filters = hs_set_filters,
    .get_state = hs_get_state,
};

sc_can_dev sc_hs_can_dev(sc_hs_can_bus *bus, uint32_t node)
{
    return (sc_can_dev){.ops = &hs_can_ops, .ctx = &bus->nodes[node]};
}

void sc_hs_can_set_bus_off(sc_hs_can_bus *bus, int bus_off)
{
    const uint8_t was = bus->bus_off;
    bus->bus_off = bus_off ? 1u : 0u;
    if (bus->bus_off != was) {
        sc_can_frame ef = {0};
        ef.flags = SC_CAN_FLAG_ERR;
        ef.id = bus->bus_off ? SC_CAN_ERRF_BUS_OFF : SC_CAN_ERRF_RESTARTED;
        const uint64_t now = sc_clock_now_ns(bus->clock);
        for (uint32_t i = 0; i < bus->node_count; i++) {
            enqueue(&bus->nodes[i], &ef, now);
        }
        bus->injected.error_frames++;
    }
}
