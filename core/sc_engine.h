/*
 * sc_engine.h: the engine object: every piece of engine state in one caller-placed struct.
 *
 * The platform places one sc_engine where it wants (static storage on an MCU, locked memory on
 * Linux), fills an sc_hal with its devices, and calls:
 *   sc_engine_init()       once: validates the definition, sets up the scheduler stages;
 *   sc_engine_load_case()  at start-up and on a "select case" command: validates the case
 *                          completely before switching; a bad case is refused and the running
 *                          case stays;
 *   sc_engine_step()       once per frame: sleeps until the frame's release time through the
 *                          HAL clock, then runs the fixed stage list (CAN rx, physics, imaging
 *                          and line streaming, status), detects deadline misses, feeds the
 *                          watchdog.
 * Thread rules: one thread drives an engine. Memory: never allocates; no OS calls; all I/O goes
 * through the HAL. Deterministic: the same case and input sequence give bit-identical output.
 */
#ifndef SC_ENGINE_H
#define SC_ENGINE_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_hal.h"
#include "sc_health.h"
#include "sc_sched.h"

typedef struct sc_engine_def {
    sc_sched_def sched;
    uint32_t watchdog_timeout_ms; /* 0: do not arm the watchdog */
} sc_engine_def;

typedef struct sc_engine_counters {
    uint64_t can_rx_frames;       /* data frames taken from the controller */
    uint64_t can_rx_error_frames; /* error frames (bus-off, passive, controller problems) */
    uint64_t can_rx_burst_limited; /* frames in which the rx drain stopped at its bound */
    uint64_t can_tx_failed;       /* status frames the controller refused */
    uint64_t display_errors;      /* display calls that returned an error */
    uint64_t watchdog_kicks;
} sc_engine_counters;

typedef struct sc_engine_status {
    sc_health_state state;
    uint32_t faults;       /* active sc_fault bits */
    uint64_t frames;
    uint64_t misses;
    uint64_t worst_frame_ns;
    uint64_t p99_frame_ns;
} sc_engine_status;

typedef struct sc_engine {
    const sc_hal *hal;
    sc_engine_def def;
    sc_sched sched;
    sc_health health;
    sc_engine_counters counters;
    sc_can_state can_state;
} sc_engine;

sc_engine_def sc_engine_default_def(void);

/* Validate def, reset all state, register the stages. O(stages). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL or a mandatory HAL op missing), SC_ERR_RANGE (rate). */
int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal);

/* Register an extra stage after the built-in ones (platform work, tests). SC_ERR_NO_SPACE. */
int sc_engine_add_stage(sc_engine *e, const char *name, sc_stage_fn fn);

/* Run one frame through the scheduler. Bounded by the stages' fixed worst cases. */
void sc_engine_step(sc_engine *e, sc_frame_result *out);

void sc_engine_get_status(const sc_engine *e, sc_engine_status *out);

#endif /* SC_ENGINE_H */
