/*
 * sc_health.h: the engine's health state machine and named fault codes.
 *
 * States: INIT (no case running yet), RUNNING, DEGRADED (working, with a degrading fault
 * active: images may be stale or the tissue was reset), FAULT (cannot image: no valid case,
 * CAN bus-off, repeated instability). The state is a pure function of the active fault bits and
 * the "ready" flag, so it can never disagree with them; every raise edge is counted per fault
 * and the last transition is kept for the status frame.
 *
 * Never allocates, never calls the OS; O(SC_FAULT_COUNT) per call at most.
 */
#ifndef SC_HEALTH_H
#define SC_HEALTH_H

#include <stdint.h>

typedef enum sc_health_state {
    SC_HEALTH_INIT = 0,
    SC_HEALTH_RUNNING = 1,
    SC_HEALTH_DEGRADED = 2,
    SC_HEALTH_FAULT = 3,
} sc_health_state;

/* X(name, bit, fatal) : fatal faults put the engine in FAULT, the others in DEGRADED. */
#define SC_FAULT_LIST(X)                                                                       \
    X(SC_FAULT_NO_CASE, 0, 1)          /* no valid case loaded */                              \
    X(SC_FAULT_DEADLINE, 1, 0)         /* deadline misses above threshold in the window */     \
    X(SC_FAULT_TRACKER_TIMEOUT, 2, 0)  /* no valid pose within the timeout: probe lifted */    \
    X(SC_FAULT_TRACKER_DATA, 3, 0)     /* E2E or plausibility rejects in the last second */    \
    X(SC_FAULT_CAN_PASSIVE, 4, 0)      /* controller error-passive or warning */               \
    X(SC_FAULT_CAN_BUS_OFF, 5, 1)      /* controller bus-off */                                \
    X(SC_FAULT_PHYS_UNSTABLE, 6, 0)    /* physics diverged and was reset to rest */            \
    X(SC_FAULT_PHYS_REPEATED, 7, 1)    /* physics diverged repeatedly: given up */             \
    X(SC_FAULT_DISPLAY_LINK, 8, 0)     /* display sink down or dropping lines */               \
    X(SC_FAULT_CONFIG, 9, 0)           /* a runtime command or setting was refused */          \
    X(SC_FAULT_WATCHDOG, 10, 0)        /* no watchdog available: running unguarded */

typedef enum sc_fault {
#define SC_FAULT_ENUM_(name, bit, fatal) name = (bit),
    SC_FAULT_LIST(SC_FAULT_ENUM_)
#undef SC_FAULT_ENUM_
        SC_FAULT_COUNT
} sc_fault;

typedef struct sc_health {
    uint32_t active;       /* bit per sc_fault */
    uint8_t ready;         /* a case is loaded and the loop started */
    sc_health_state state; /* derived, cached */
    sc_health_state prev_state;
    uint32_t transitions;
    uint32_t raised[SC_FAULT_COUNT]; /* raise edges per fault */
} sc_health;

void sc_health_init(sc_health *h);
void sc_health_set_ready(sc_health *h, int ready);
/* Set (raise) or clear a fault bit. Raising an active fault is not a new edge. */
void sc_health_raise(sc_health *h, sc_fault f);
void sc_health_clear(sc_health *h, sc_fault f);
void sc_health_set(sc_health *h, sc_fault f, int active);
int sc_health_is_active(const sc_health *h, sc_fault f);

const char *sc_health_state_name(sc_health_state s);
const char *sc_fault_name(sc_fault f);
int sc_fault_is_fatal(sc_fault f);

#endif /* SC_HEALTH_H */
