/*
 * sc_hs_clock.h: the host simulator's virtual clock.
 *
 * Time advances only when told: sleep_until_ns moves it forward to the target (never back),
 * sc_hs_clock_advance_ns moves it by a step (tests use it inside a stage to model work), and
 * an optional per-read cost models the time that reading the clock itself takes.
 * Deterministic; no wall time involved.
 */
#ifndef SC_HS_CLOCK_H
#define SC_HS_CLOCK_H

#include <stdint.h>

#include "sc_hal_clock.h"

typedef struct sc_hs_clock {
    uint64_t now_ns;
    uint64_t sleeps;       /* calls of sleep_until_ns */
    uint64_t slept_ns;     /* total virtual time spent sleeping */
} sc_hs_clock;

void sc_hs_clock_init(sc_hs_clock *c, uint64_t start_ns);
void sc_hs_clock_advance_ns(sc_hs_clock *c, uint64_t dt_ns);
sc_clock_dev sc_hs_clock_dev(sc_hs_clock *c);

#endif /* SC_HS_CLOCK_H */
