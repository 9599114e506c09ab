/* sc_hs_clock.c: virtual clock, see sc_hs_clock.h. */
#include "sc_hs_clock.h"

#include "sc_err.h"

static uint64_t hs_now_ns(void *ctx)
{
    return ((sc_hs_clock *)ctx)->now_ns;
}

static int hs_sleep_until_ns(void *ctx, uint64_t t_ns)
{
    sc_hs_clock *c = ctx;
    c->sleeps++;
    if (t_ns > c->now_ns) {
        c->slept_ns += t_ns - c->now_ns;
        c->now_ns = t_ns;
    }
    return SC_OK;
}

static const sc_clock_ops hs_clock_ops = {
    .now_ns = hs_now_ns,
    .sleep_until_ns = hs_sleep_until_ns,
};

void sc_hs_clock_init(sc_hs_clock *c, uint64_t start_ns)
{
    *c = (sc_hs_clock){.now_ns = start_ns};
}

void sc_hs_clock_advance_ns(sc_hs_clock *c, uint64_t dt_ns)
{
    c->now_ns += dt_ns;
}

sc_clock_dev sc_hs_clock_dev(sc_hs_clock *c)
{
    return (sc_clock_dev){.ops = &hs_clock_ops, .ctx = c};
}
