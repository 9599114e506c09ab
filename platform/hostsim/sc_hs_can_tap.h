/*
 * sc_hs_can_tap.h: a pass-through sc_can_dev that stamps and reports every received frame.
 *
 * Wraps another CAN device. On each successful receive it sets the frame's time stamp to the
 * clock's time of reception (the release time of the engine frame that drained it, on the host
 * simulator) and calls the callback (e.g. to write a candump -l log). A recording stamped this
 * way and injected again before the same engine frames reproduces the engine's input exactly:
 * same frames, same order, same time stamps (the replay of tools and tests relies on it).
 * Sends, filters and state go straight to the wrapped device. Optionally each received frame
 * costs virtual time (cost_ns). Never allocates.
 */
#ifndef SC_HS_CAN_TAP_H
#define SC_HS_CAN_TAP_H

#include "sc_hal_can.h"
#include "sc_hal_clock.h"
#include "sc_hs_clock.h"

typedef void (*sc_hs_can_tap_fn)(void *user, const sc_can_frame *frame);

typedef struct sc_hs_can_tap {
    sc_can_dev inner;
    const sc_clock_dev *clock;
    sc_hs_can_tap_fn fn; /* may be NULL */
    void *user;
    uint64_t frames;
    /* optional cost model: each received frame advances cost_clock by cost_ns (the engine's
     * receive work on a slow controller; fault-injection tests use it so that input volume
     * shows on the virtual clock). NULL / 0: free. */
    sc_hs_clock *cost_clock;
    uint64_t cost_ns;
} sc_hs_can_tap;

void sc_hs_can_tap_init(sc_hs_can_tap *t, sc_can_dev inner, const sc_clock_dev *clock,
                        sc_hs_can_tap_fn fn, void *user);
sc_can_dev sc_hs_can_tap_dev(sc_hs_can_tap *t);

#endif /* SC_HS_CAN_TAP_H */
