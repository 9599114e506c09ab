/* sc_health.c: health state machine, see sc_health.h. */
#include "sc_health.h"

#include "sc_assert.h"

SC_STATIC_ASSERT(SC_FAULT_COUNT <= 32, "fault bits must fit a uint32_t");

static const uint32_t fatal_mask = 0u
#define SC_FAULT_FATAL_(name, bit, fatal) | ((fatal) ? (1u << (bit)) : 0u)
    SC_FAULT_LIST(SC_FAULT_FATAL_)
#undef SC_FAULT_FATAL_
    ;

static sc_health_state derive(const sc_health *h)
{
    if (h->active & fatal_mask) {
        return SC_HEALTH_FAULT;
    }
    if (!h->ready) {
        return SC_HEALTH_INIT;
    }
    return h->active ? SC_HEALTH_DEGRADED : SC_HEALTH_RUNNING;
}

static void update(sc_health *h)
{
    sc_health_state s = derive(h);
    if (s != h->state) {
        h->prev_state = h->state;
        h->state = s;
        h->transitions++;
    }
}

void sc_health_init(sc_health *h)
{
    SC_ASSERT(h);
    *h = (sc_health){0};
    h->state = SC_HEALTH_INIT;
    h->prev_state = SC_HEALTH_INIT;
}

void sc_health_set_ready(sc_health *h, int ready)
{
    h->ready = ready ? 1u : 0u;
    update(h);
}

void sc_health_raise(sc_health *h, sc_fault f)
{
    SC_ASSERT((unsigned)f < SC_FAULT_COUNT);
    uint32_t bit = 1u << (unsigned)f;
    if (!(h->active & bit)) {
        h->active |= bit;
        h->raised[f]++;
        update(h);
    }
}

void sc_health_clear(sc_health *h, sc_fault f)
{
    SC_ASSERT((unsigned)f < SC_FAULT_COUNT);
    h->active &= ~(1u << (unsigned)f);
    update(h);
}

void sc_health_set(sc_health *h, sc_fault f, int active)
{
    if (active) {
        sc_health_raise(h, f);
    } else {
        sc_health_clear(h, f);
    }
}

int sc_health_is_active(const sc_health *h, sc_fault f)
{
    return (h->active >> (unsigned)f) & 1u;
}

const char *sc_health_state_name(sc_health_state s)
{
    switch (s) {
    case SC_HEALTH_INIT:
        return "init";
    case SC_HEALTH_RUNNING:
        return "running";
    case SC_HEALTH_DEGRADED:
        return "degraded";
    case SC_HEALTH_FAULT:
        return "fault";
    }
    return "unknown";
}

const char *sc_fault_name(sc_fault f)
{
    switch (f) {
#define SC_FAULT_NAME_(name, bit, fatal)                                                       \
    case name:                                                                                 \
        return #name;
        SC_FAULT_LIST(SC_FAULT_NAME_)
#undef SC_FAULT_NAME_
    case SC_FAULT_COUNT:
        break;
    }
    return "SC_FAULT_UNKNOWN";
}

int sc_fault_is_fatal(sc_fault f)
{
    return (unsigned)f < SC_FAULT_COUNT && ((fatal_mask >> (unsigned)f) & 1u);
}
