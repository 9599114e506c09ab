/* sc_hs_can_tap.c: stamping, reporting CAN pass-through, see sc_hs_can_tap.h. */
#include "sc_hs_can_tap.h"

#include "sc_err.h"

static int tap_send(void *ctx, const sc_can_frame *f)
{
    sc_hs_can_tap *t = ctx;
    return sc_can_send(&t->inner, f);
}

static int tap_recv(void *ctx, sc_can_frame *out)
{
    sc_hs_can_tap *t = ctx;
    const int rc = sc_can_recv(&t->inner, out);
    if (rc == SC_OK) {
        out->ts_ns = sc_clock_now_ns(t->clock);
        t->frames++;
        if (t->cost_clock != NULL && t->cost_ns != 0u) {
            sc_hs_clock_advance_ns(t->cost_clock, t->cost_ns);
        }
        if (t->fn) {
            t->fn(t->user, out);
        }
    }
    return rc;
}

static int tap_set_filters(void *ctx, const sc_can_filter *f, size_t n)
{
    sc_hs_can_tap *t = ctx;
    return sc_can_set_filters(&t->inner, f, n);
}

static int tap_get_state(void *ctx, sc_can_state *st, sc_can_counters *c)
{
    sc_hs_can_tap *t = ctx;
    return sc_can_get_state(&t->inner, st, c);
}

static const sc_can_ops tap_ops = {
    .send = tap_send,
    .recv = tap_recv,
    .set_filters = tap_set_filters,
    .get_state = tap_get_state,
};

void sc_hs_can_tap_init(sc_hs_can_tap *t, sc_can_dev inner, const sc_clock_dev *clock,
                        sc_hs_can_tap_fn fn, void *user)
{
    *t = (sc_hs_can_tap){.inner = inner, .clock = clock, .fn = fn, .user = user, .frames = 0};
}

sc_can_dev sc_hs_can_tap_dev(sc_hs_can_tap *t)
{
    return (sc_can_dev){.ops = &tap_ops, .ctx = t};
}
