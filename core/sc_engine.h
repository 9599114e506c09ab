/*
 * sc_engine.h: the engine object: every piece of engine state in one caller-placed struct.
 *
 * The platform places one sc_engine where it wants (static storage on an MCU, locked memory on
 * Linux), fills an sc_hal with its devices, and calls:
 *   sc_engine_init()       once: validates the definition, sets up the scheduler stages;
 *   sc_engine_load_case()  at start-up and on a "select case" command: the case is validated
 *                          completely (sc_case_load) before anything of the running case is
 *                          touched; a bad case is refused, counted, and the running case stays;
 *   sc_engine_step()       once per frame: sleeps until the frame's release time through the
 *                          HAL clock, then runs the fixed stage list, detects deadline misses,
 *                          feeds the watchdog.
 *
 * The frame (paper Fig. 1 recast as firmware stages, each timed by the scheduler):
 *   rx       drain at most SC_CAN_RX_BURST_MAX CAN frames into the tracker (E2E, pose
 *            assembly, plausibility, commands), apply queued commands, take the newest valid
 *            pose and carry it tracker -> volume frame with the case's registration;
 *   physics  one tissue step (MSDS or FEM, collider, skin, stability guard);
 *   imaging  B-scan synthesis through the deformed mesh, each line streamed to the display
 *            as soon as it is computed; the vessels' compression measure;
 *   status   every status_period_ms: the status frames (state, faults, misses, worst frame
 *            time, compression measure, tracker counters) on CAN.
 *
 * Thread rules: one thread drives an engine. Memory: never allocates; no OS calls; all I/O goes
 * through the HAL. Deterministic: the same case and input sequence (frames and their time
 * stamps on the HAL clock) give bit-identical output.
 */
#ifndef SC_ENGINE_H
#define SC_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_bscan.h"
#include "sc_case.h"
#include "sc_config.h"
#include "sc_hal.h"
#include "sc_health.h"
#include "sc_sched.h"
#include "sc_tissue.h"
#include "sc_tracker.h"

#ifndef SC_ENGINE_MAX_CASES
#define SC_ENGINE_MAX_CASES 16u
#endif

typedef struct sc_engine_def {
    sc_sched_def sched;
    uint32_t watchdog_timeout_ms;  /* 0: do not arm the watchdog */
    uint32_t status_period_ms;     /* status frames on CAN; DBC cycle time 100 ms */
    uint32_t tracker_fault_hold_ms; /* TRACKER_DATA stays active this long after a reject */
    uint32_t phys_fault_hold_ms;   /* PHYS_UNSTABLE stays active this long after a reset */
    uint32_t phys_resets_fatal;    /* this many guard resets within phys_fault_hold_ms * 10:
                                    * PHYS_REPEATED (fatal) until a reset command */
    sc_tracker_def tracker;
    sc_tissue_def tissue;          /* mesh region and materials come from the case */
    sc_bscan_def bscan;            /* calibration comes from the case */
    /* Case catalogue for the select-case command: case id i names case_names[i] in storage. */
    const char *case_names[SC_ENGINE_MAX_CASES];
    uint32_t case_count;
} sc_engine_def;

typedef struct sc_engine_counters {
    uint64_t can_rx_frames;         /* frames taken from the controller (data and error) */
    uint64_t can_rx_burst_limited;  /* frames in which the rx drain stopped at its bound */
    uint64_t can_tx_failed;         /* status frames the controller refused */
    uint64_t commands_applied;
    uint64_t commands_refused;      /* unknown case id, load failure, bad settings */
    uint64_t case_loads;
    uint64_t case_load_failures;
    int last_case_error;            /* sc_err of the last refused case */
    uint64_t phys_resets;           /* stability guard resets */
    uint64_t imaging_errors;        /* frames whose synthesis or display returned an error */
    uint64_t watchdog_kicks;
} sc_engine_counters;

typedef struct sc_engine_status {
    sc_health_state state;
    uint32_t faults;        /* active sc_fault bits */
    uint64_t frames;
    uint64_t misses;
    uint64_t worst_frame_ns;
    uint64_t p99_frame_ns;
    uint8_t case_loaded;
    uint8_t case_id;
    sc_tissue_method method;
    uint8_t probe_tracked;  /* a valid pose this frame */
    uint8_t probe_contact;  /* the collider touches the tissue */
    float vein_area_ratio;  /* image area of the vein now / at rest; < 0: not available */
    float artery_area_ratio;
} sc_engine_status;

typedef struct sc_engine {
    const sc_hal *hal;
    sc_engine_def def;
    sc_sched sched;
    sc_health health;
    sc_engine_counters counters;
    sc_tracker tracker;
    /* the running case: a validated view into storage bytes kept open while it runs
     * (slot.c); case_loaded once the tissue and imaging are built for it */
    sc_case_slot slot;
    uint8_t case_loaded;
    uint8_t case_id;
    /* this frame's probe */
    uint8_t probe_tracked;
    uint8_t probe_contact;
    sc_pose probe_tracker;   /* tracker frame */
    sc_xform probe_to_volume;
    sc_pose probe_volume;
    /* bookkeeping of time-held faults */
    uint64_t last_tracker_reject_ns;
    uint32_t tracker_rejects_seen;
    uint64_t last_phys_reset_ns;
    uint32_t phys_resets_window;
    uint64_t phys_window_start_ns;
    uint64_t next_status_ns;
    uint32_t frame_no;
    uint64_t miss_logged_ns;  /* end of the frame of the last miss line; 0: none yet */
    uint32_t misses_unlogged; /* misses since then that got no line of their own */
    sc_bscan bscan;
    sc_tissue tissue; /* the large one last */
} sc_engine;

sc_engine_def sc_engine_default_def(void);

/* Validate def, reset all state, register the stages. The engine starts without a case (fault
 * SC_FAULT_NO_CASE) until sc_engine_load_case succeeds. O(stages). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL, a mandatory HAL op missing, case catalogue too long),
 * SC_ERR_RANGE (rate, periods), errors of sc_tracker_def_validate and sc_bscan_init. */
int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal);

/* Open `name` in case storage, validate it, and only then replace the running case: tissue
 * (mesh, materials, solvers) rebuilt at rest, imaging attached to the new mesh, calibration
 * taken. O(case bytes) for the validation plus O(tets) for the rebuild: a load-time
 * operation (a frame that loads a case misses its deadline, which is counted). Never
 * allocates. Errors: SC_ERR_NOT_FOUND and storage errors, every sc_case_load error (the
 * running case stays), and errors of the rebuild (then no case runs: SC_FAULT_NO_CASE). */
int sc_engine_load_case(sc_engine *e, const char *name);

/* Register an extra stage after the built-in ones (platform work, tests). SC_ERR_NO_SPACE. */
int sc_engine_add_stage(sc_engine *e, const char *name, sc_stage_fn fn);

/* Run one frame through the scheduler. Bounded by the stages' fixed worst cases. */
void sc_engine_step(sc_engine *e, sc_frame_result *out);

void sc_engine_get_status(const sc_engine *e, sc_engine_status *out);

/* Hash of the engine's physical state (tissue nodes and skin): the determinism check. */
uint64_t sc_engine_state_hash(const sc_engine *e);

#endif /* SC_ENGINE_H */
