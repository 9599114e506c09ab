/*
 * sc_engine.h: the engine: every piece of engine state in one caller-placed object, and the
 * frame that runs it. The platform's whole view of the core.
 *
 * ---- Integration ------------------------------------------------------------------------
 * The platform places one sc_engine where it wants (static storage on an MCU, locked memory on
 * Linux; sizeof(sc_engine) is fixed by config/sc_config.h), fills an sc_hal with its devices
 * (hal/sc_hal.h: CAN, display, clock, storage, log, watchdog), and calls:
 *   sc_engine_init()         once: validates the definition, resets every subsystem;
 *   sc_engine_load_case()    at start-up: the whole case switch below in one call;
 *   sc_engine_step()         once per frame, forever;
 *   sc_engine_select_case()  any time: asks for a case switch by name (the CAN command
 *                            CmdSelectCase asks by catalogue index); it runs between frames;
 * and reads the engine through the const getters at the end of this file (status, counters,
 * timing, the running case, the tissue, the tracker). A platform never writes engine fields.
 *
 * ---- The frame (sc_engine_step) ------------------------------------------------------------
 * One call per stage, in this order, each a function with a small typed input and output; the
 * scheduler (sc_sched.h) times each and counts a frame that ends after its deadline as a miss
 * (counted and reported, never queued). Worst-case work per stage, bounded by config/ limits:
 *   rx       CAN -> sc_probe_in (the probe's pose in the volume frame, or lifted).
 *            At most SC_CAN_RX_BURST_MAX frames drained into the tracker (E2E, 3-frame pose
 *            assembly, plausibility; commands authenticated (AES-CMAC and freshness, at most
 *            one 2-block CMAC per frame drained) and queued, not applied), the newest valid
 *            pose carried tracker -> volume frame with the case's registration. O(burst).
 *   physics  sc_probe_in -> sc_tissue_out (contact, node state of the tet mesh, the probe's
 *            force). One tissue step (sc_tissue.h): MSDS O(iterations x nodes) or FEM
 *            O(iterations x nonzeros), collider O(contact candidates), skin, stability guard
 *            O(nodes); in contact the probe's force, O(contacts) (sc_tissue_probe_force_n:
 *            the step's matrix is still in the caches).
 *   imaging  sc_tissue_out -> sc_image_out (scan lines to the display, the compression
 *            measure). O(lines x samples) plus the tets each line crosses (sc_bscan.h); every
 *            line leaves through the display HAL as soon as it is computed, the frame's
 *            compression measure closes the display frame (hal/sc_hal_display.h). Then the
 *            exam's assessment takes the frame and the physics stage's force (sc_assess.h:
 *            O(1)).
 *   status   sc_image_out -> CAN status frames every status_period_ms: the four status
 *            frames and the three assessment frames (0x210..0x212). O(1).
 *            Then, when hal->state is present, the console state stream (sc_state.h): at most
 *            every state_period_ms a few fixed records handed to the state device, never
 *            waiting (O(state_vert_records x 112) vertex interpolations).
 *   control  between this frame and the next, in the frame's slack: the queued commands
 *            (O(SC_CAN_CMD_QUEUE_MAX); a CmdMaterial starts a switch to the running case with
 *            its overrides, sc_engine_set_material), then at most one slice of a pending case
 *            switch:
 *              open      the storage mapping, the file's framing (O(sections));
 *              validate  at most case_check_slice_bytes of CRC / label pass (sc_case.h);
 *              build     the next case's tissue in the standby slot, one build phase per
 *                        slice (sc_tissue_build_step: mesh, labels, springs, MSDS, 10 of the
 *                        MSDS mass scaling's 100 power iterations, FEM, contact; each O(tets)
 *                        or O(nodes)) while the running case runs;
 *              swap      imaging attached to the new mesh (O(tets)), calibration taken, the
 *                        slots exchanged: the next frame runs the new case.
 *            A slice runs only when the slack left is at least the longest that kind of slice
 *            has taken so far (measured on the HAL clock; def.control_slice_estimate_ns until
 *            then), so a switch never makes a frame miss; a slice that has waited
 *            control_wait_frames frames runs anyway (counted in control_forced). With one
 *            tissue slot (SC_ENGINE_TISSUE_SLOTS 1, the MCU) the build replaces the running
 *            tissue: from its first phase to the swap no case runs (dark frames).
 *
 * Measured (release build, x86-64 host, the 11.8 MB phantoms, tests/hostsim/test_case_switch):
 * a switch takes 35 frames; a frame without a switch at most 4.0 ms of host CPU, a frame with a
 * slice at most 9.3 ms (the label pass; the mass-scaling slices 8.6 ms), inside the 16.7 ms
 * period.
 *
 * ---- Rules ----------------------------------------------------------------------------------
 * Threads: one thread drives an engine; the getters may be called between steps.
 * Memory: never allocates; everything lives in the sc_engine (the case voxels stay in storage
 * and are read through the HAL's mapping). No OS calls; all I/O goes through the HAL.
 * Deterministic: the same case and input sequence (frames and their time stamps on the HAL
 * clock) give bit-identical output (sc_engine_state_hash, tests/hostsim/test_engine.c).
 * Errors: functions that can fail return 0 or a negative sc_err (sc_err.h); bad input from the
 * outside (CAN, case files, commands) is refused, counted and logged, never asserted.
 */
#ifndef SC_ENGINE_H
#define SC_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_assess.h"
#include "sc_bscan.h"
#include "sc_doppler.h"
#include "sc_needle.h"
#include "sc_needle_rx.h"
#include "sc_case.h"
#include "sc_config.h"
#include "sc_hal.h"
#include "sc_health.h"
#include "sc_sched.h"
#include "sc_state.h"
#include "sc_status_tx.h"
#include "sc_tissue.h"
#include "sc_tracker.h"

#ifndef SC_ENGINE_MAX_CASES
#define SC_ENGINE_MAX_CASES 16u
#endif
#ifndef SC_ENGINE_CASE_NAME_MAX
#define SC_ENGINE_CASE_NAME_MAX 256u /* bytes of a requested case name, with the NUL */
#endif
/* Tissue slots: 2 lets the next case be built while the running one runs (double the tissue
 * memory); 1 (the MCU) builds in place, in one slice, replacing the running case. */
#ifndef SC_ENGINE_TISSUE_SLOTS
#define SC_ENGINE_TISSUE_SLOTS 2u
#endif
_Static_assert(SC_ENGINE_TISSUE_SLOTS == 1u || SC_ENGINE_TISSUE_SLOTS == 2u,
               "one or two tissue slots");
_Static_assert(SC_ENGINE_MAX_CASES <= 254u, "case ids are 8-bit; 254 and 255 are reserved");

/* The frame's stages, in order (timing slots of the scheduler). */
typedef enum sc_engine_stage {
    SC_ENGINE_STAGE_RX = 0,
    SC_ENGINE_STAGE_PHYSICS,
    SC_ENGINE_STAGE_IMAGING,
    SC_ENGINE_STAGE_STATUS,
    SC_ENGINE_STAGE_CONTROL,
    SC_ENGINE_STAGE_PLATFORM, /* the optional platform hook */
    SC_ENGINE_STAGE_COUNT
} sc_engine_stage;
_Static_assert(SC_ENGINE_STAGE_COUNT <= SC_SCHED_MAX_STAGES, "scheduler timing slots");

/* Kinds of control slices (their worst times are tracked separately); the build slices are
 * the tissue's build phases (sc_tissue_build_phase), one per slice. */
typedef enum sc_engine_slice {
    SC_ENGINE_SLICE_OPEN = 0,
    SC_ENGINE_SLICE_VALIDATE,
    SC_ENGINE_SLICE_BUILD, /* + sc_tissue_build_phase */
    SC_ENGINE_SLICE_SWAP = SC_ENGINE_SLICE_BUILD + SC_TISSUE_BUILD_DONE,
    SC_ENGINE_SLICE_COUNT
} sc_engine_slice;

/* A platform's own work at the end of every frame (tests model load with it), timed as the
 * stage "platform". Optional. */
typedef void (*sc_engine_hook_fn)(void *user);

typedef struct sc_engine_def {
    sc_sched_def sched;
    uint32_t watchdog_timeout_ms;  /* 0: do not arm the watchdog */
    uint32_t status_period_ms;     /* status frames on CAN; DBC cycle time 100 ms */
    uint32_t tracker_fault_hold_ms; /* TRACKER_DATA stays active this long after a reject */
    uint32_t phys_fault_hold_ms;   /* PHYS_UNSTABLE stays active this long after a reset */
    uint32_t phys_resets_fatal;    /* this many guard resets within phys_fault_hold_ms * 10:
                                    * PHYS_REPEATED (fatal) until a reset command */
    uint32_t case_check_slice_bytes; /* case bytes validated per control slice (>= 4096) */
    uint32_t control_slice_estimate_ns; /* assumed cost of a slice not measured yet */
    uint32_t control_wait_frames;  /* a slice waits at most this many frames for slack */
    sc_tracker_def tracker;
    sc_tissue_def tissue;          /* mesh region and materials come from the case */
    sc_bscan_def bscan;            /* calibration comes from the case */
    sc_assess_def assess;          /* the compression exam's assessment (sc_assess.h) */
#if SC_ENABLE_DOPPLER
    sc_doppler_def doppler;        /* colour and pulsed-wave Doppler (sc_doppler.h) */
#endif
    /* Case catalogue: catalogue index i (CmdSelectCase) names case_names[i] in storage. */
    const char *case_names[SC_ENGINE_MAX_CASES];
    uint32_t case_count;
    /* Console state stream (sc_state.h, through hal->state when present): records at most
     * every state_period_ms (0: off), state_vert_records surface-vertex records per period. */
    uint32_t state_period_ms;
    uint32_t state_vert_records;
} sc_engine_def;

typedef struct sc_engine_counters {
    uint64_t can_rx_frames;         /* frames taken from the controller (data and error) */
    uint64_t can_rx_burst_limited;  /* frames in which the rx drain stopped at its bound */
    uint64_t can_tx_failed;         /* status frames the controller refused */
    uint64_t commands_applied;
    uint64_t commands_refused;      /* unknown case id, switch busy, bad settings */
    uint64_t commands_auth_refused; /* commands refused by authentication (sc_secoc.h): no
                                     * MAC, bad MAC, stale/replayed, unknown or unsynced
                                     * sender (by reason: the tracker's counters) */
    uint64_t case_loads;            /* switches completed */
    uint64_t case_load_failures;    /* switches refused (storage, validation, rebuild) */
    int last_case_error;            /* sc_err of the last refused case */
    uint64_t phys_resets;           /* stability guard resets */
    uint64_t imaging_errors;        /* frames whose synthesis or display returned an error */
    uint64_t watchdog_kicks;
    uint64_t control_slices[SC_ENGINE_SLICE_COUNT]; /* slices run, by kind */
    uint64_t control_deferred;      /* frames in which a slice waited for slack */
    uint64_t control_forced;        /* slices run after control_wait_frames without slack */
    uint64_t control_worst_ns[SC_ENGINE_SLICE_COUNT]; /* longest slice of each kind (HAL clock) */
    uint64_t case_check_bytes_worst; /* most case bytes validated in one frame */
    uint64_t material_rebuilds;     /* CmdMaterial rebuilds swapped in (and their restores) */
    uint64_t material_refused;      /* CmdMaterial refused: no case, busy, out of range (also
                                     * in commands_refused) or its rebuild failed */
} sc_engine_counters;

typedef struct sc_engine_status {
    sc_health_state state;
    uint32_t faults;        /* active sc_fault bits */
    uint64_t frames;
    uint64_t misses;
    uint64_t worst_frame_ns;
    uint64_t p99_frame_ns;
    uint8_t case_loaded;
    uint8_t case_id;        /* catalogue index; SC_ENGINE_CASE_UNLISTED; SC_STATUS_CASE_NONE */
    uint8_t switching;      /* a case switch is being prepared */
    sc_tissue_method method;
    uint8_t probe_tracked;  /* a valid pose this frame */
    uint8_t probe_contact;  /* the collider touches the tissue */
    float vein_area_ratio;  /* image area of the vein now / at rest; < 0: not available */
    float artery_area_ratio;
} sc_engine_status;

/* Case id reported for a case loaded by a name that is not in the catalogue. */
#define SC_ENGINE_CASE_UNLISTED 254u

/* ---- the stages' typed inputs and outputs ------------------------------------------------ */

/* rx -> physics, imaging: this frame's probe. */
typedef struct sc_probe_in {
    uint8_t tracked;         /* a valid pose this frame (else: lifted) */
    sc_pose pose_tracker;    /* tracker frame, as received */
    sc_xform to_volume;      /* probe frame -> volume frame (identity without a case) */
    sc_pose pose_volume;
} sc_probe_in;

/* physics -> imaging: the deformed mesh. */
typedef struct sc_tissue_out {
    uint8_t contact;         /* the collider touches the tissue */
    uint8_t reset;           /* the stability guard reset the tissue this frame */
    float force_n;           /* the probe's force on the tissue (sc_tissue_probe_force_n), N;
                                SC_FORCE_NOT_AVAILABLE without a case or contact */
    const sc_mesh *mesh;     /* NULL without a case */
    const sc_nodes *nodes;
} sc_tissue_out;

/* imaging -> status: what the image showed. */
typedef struct sc_image_out {
    int rc;                  /* sc_bscan_frame's result */
    float vein_area_ratio;   /* the compression measure; < 0: not available */
    float artery_area_ratio;
} sc_image_out;

_Static_assert(sizeof(sc_probe_in) == 1u * 4u + 28u + 48u + 28u, "sc_probe_in: flag, 3 poses");
_Static_assert(sizeof(sc_image_out) == 12u, "sc_image_out: rc and two ratios");

/* A case switch in progress (control step). */
typedef enum sc_switch_phase {
    SC_SWITCH_IDLE = 0,
    SC_SWITCH_OPEN,
    SC_SWITCH_VALIDATE,
    SC_SWITCH_BUILD,
    SC_SWITCH_SWAP,
} sc_switch_phase;

typedef struct sc_case_switch {
    sc_switch_phase phase;
    char name[SC_ENGINE_CASE_NAME_MAX];
    uint8_t case_id;          /* catalogue index or SC_ENGINE_CASE_UNLISTED */
    uint32_t waited;          /* frames the next slice has waited for slack */
    const uint8_t *data;      /* the new case's mapping (open from OPEN until the swap) */
    size_t size;
    sc_case_check check;
    sc_case c;
} sc_case_switch;

/* CmdMaterial (sc_canproto.h): the overrides of the case's own materials and of the solver's
 * parameters that a tissue was built with; all zero: the case's own (148 B). */
typedef struct sc_engine_material {
    uint16_t label_mask;         /* bit l: row l overridden */
    uint8_t sim_set;             /* the solver parameters below are overridden */
    uint8_t cg_iterations;       /* CG iterations per frame, 1..63 */
    uint8_t corotated;           /* 0/1 */
    float damping_s;             /* gamma / k = Rayleigh beta, s */
    float e_pa[SC_MAX_LABELS];   /* Young's modulus of overridden rows, Pa */
    float poisson[SC_MAX_LABELS];
} sc_engine_material;

typedef struct sc_engine {
    const sc_hal *hal;
    sc_engine_def def;
    sc_sched sched;
    sc_health health;
    sc_engine_counters counters;
    sc_tracker tracker;
    sc_status_tx status_tx;
    /* the running case: a validated view into storage bytes kept open while it runs */
    sc_case_slot slot;
    uint8_t case_loaded;
    uint8_t case_id;
    uint8_t active;          /* tissue slot of the running case */
    sc_case_switch sw;
    /* the last frame's stage outputs (status, getters) */
    sc_probe_in probe;
    sc_tissue_out tissue_out;
    sc_image_out image;
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
    sc_engine_hook_fn hook;
    void *hook_user;
    sc_assess assess;         /* the compression exam's assessment, updated every frame */
#if SC_PHYS_LUMEN
    sc_lumen_drive vessel_drive; /* the drive CmdVessels set (kept for the next case) */
    uint8_t vessel_drive_set;    /* 1: a CmdVessels was applied; every new tissue gets it */
#endif
#if SC_STATE_STREAM
    sc_state_tx state_tx; /* console state stream (sc_state.h) */
#endif
#if SC_ENABLE_DOPPLER
    sc_doppler doppler; /* flow model of the running case, colour and spectrum per frame */
    uint8_t doppler_on; /* this frame */
#endif
#if SC_ENABLE_NEEDLE
    sc_needle_rx needle_rx; /* the tracked needle's CAN receiver */
    sc_needle needle;       /* drawn in the B-scan, punctures */
    uint8_t needle_status_counter;
    uint8_t needle_entry; /* label of the lumen the tip entered this frame (0 none): the
                           * assessment's puncture input */
#endif
    /* CmdMaterial: a rebuild of the running case through the switch (the same slot) */
    sc_engine_material mat_run;  /* of the running tissue */
    sc_engine_material mat_next; /* of the rebuild being prepared */
    uint8_t mat_rebuild;         /* 1: the switch in progress is a material rebuild/restore */
    char case_name[SC_ENGINE_CASE_NAME_MAX]; /* the running case's storage name */
    sc_bscan bscan;
    sc_tissue tissue[SC_ENGINE_TISSUE_SLOTS]; /* the large ones last */
} sc_engine;

/* Defaults: 60 Hz, watchdog 500 ms, status every 100 ms, 1 MiB of case check per slice,
 * slices assumed to cost 2 ms until measured, at most 30 frames of waiting. O(1). */
sc_engine_def sc_engine_default_def(void);

/* Validate def, reset all state, name the stages. The engine starts without a case (fault
 * SC_FAULT_NO_CASE) until a switch completes. O(1) plus the subsystems' inits (no tissue
 * build). Never allocates. Errors: SC_ERR_INVALID_ARG (NULL, a mandatory HAL op missing, case
 * catalogue too long or with a NULL or too long name), SC_ERR_RANGE (rate, periods, slice
 * budget), errors of sc_tracker_def_validate, sc_bscan_init and sc_assess_def_validate. */
int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal);

/* Switch to case `name` now, outside the frame loop (start-up): every slice of the control
 * step's switch in one call. O(case bytes + tets). Errors: SC_ERR_INVALID_ARG, SC_ERR_RANGE
 * (name longer than SC_ENGINE_CASE_NAME_MAX - 1), SC_ERR_STATE (a switch is running), the
 * storage's open errors, every sc_case_load error (the running case stays), and errors of the
 * rebuild (then no case runs: SC_FAULT_NO_CASE). */
int sc_engine_load_case(sc_engine *e, const char *name);

/* Ask for a switch to case `name` (a name in case storage; catalogue or not); it is prepared
 * in slices between frames while the running case runs, and swapped in between two frames.
 * Its outcome is counted (case_loads / case_load_failures, last_case_error) and logged
 * (case_loaded / case_refused). O(name). Errors (refused at once, counted in
 * commands_refused, SC_FAULT_CONFIG raised): SC_ERR_INVALID_ARG, SC_ERR_RANGE (name too long),
 * SC_ERR_STATE (a switch is already running). */
int sc_engine_select_case(sc_engine *e, const char *name);

/* CmdMaterial: rebuild the running case's tissue with label m->label's Young's modulus and
 * Poisson ratio and the solver's damping (gamma/k = Rayleigh beta), CG iterations and
 * corotation (sc_material_cmd), on top of the overrides already in force. The rebuild is a
 * switch to the running case (reopened, validated, built in the standby slot in slices
 * between frames, swapped between two frames: off the frame path, no heap), its swap counted
 * in material_rebuilds. A case switch, or CmdReset with SC_RESET_TISSUE while overrides are
 * in force, restores the case's own materials (the latter by the same rebuild). Without a
 * material command nothing changes. O(labels). Errors (refused, counted in commands_refused
 * and material_refused): SC_ERR_INVALID_ARG (NULL), SC_ERR_STATE (no case runs, or a switch
 * or rebuild is in progress), SC_ERR_NOT_FINITE, SC_ERR_RANGE (a label outside skin..thrombus
 * or without a row in the case, E outside 0.1 kPa..6553.4 kPa, nu outside 0..0.49, damping
 * outside 0.01..0.5 s, CG iterations outside 1..min(63, SC_PHYS_ITERATIONS_MAX), corotated
 * above 1). */
int sc_engine_set_material(sc_engine *e, const sc_material_cmd *m);

/* The overrides the running tissue was built with (all zero: the case's own). O(1). */
const sc_engine_material *sc_engine_get_material(const sc_engine *e);

/* Set the platform hook (NULL: none). O(1). SC_ERR_INVALID_ARG for a NULL engine. */
int sc_engine_set_hook(sc_engine *e, sc_engine_hook_fn fn, void *user);

/* Run one frame: sleep until its release, then rx, physics, imaging, status, control (and the
 * hook), miss detection, watchdog. Bounded by the stages' worst cases above. */
void sc_engine_step(sc_engine *e, sc_frame_result *out);

/* ---- read-only views (between steps) -------------------------------------------------- */

void sc_engine_get_status(const sc_engine *e, sc_engine_status *out);
/* Hash of the engine's physical state (tissue nodes and skin): the determinism check. */
uint64_t sc_engine_state_hash(const sc_engine *e);
const sc_engine_counters *sc_engine_get_counters(const sc_engine *e);
/* The scheduler: frames, misses, per-stage and frame statistics, the next release. */
const sc_sched *sc_engine_get_sched(const sc_engine *e);
/* The running case, or NULL. */
const sc_case *sc_engine_get_case(const sc_engine *e);
/* The running case's tissue (mesh, nodes, solvers), or NULL. */
const sc_tissue *sc_engine_get_tissue(const sc_engine *e);
const sc_tracker *sc_engine_get_tracker(const sc_engine *e);
const sc_bscan_status *sc_engine_get_bscan_status(const sc_engine *e);
/* The release time of the next frame on the HAL clock (now, before the first frame). */
uint64_t sc_engine_next_release_ns(const sc_engine *e);
/* This frame's probe as the rx stage produced it. */
const sc_probe_in *sc_engine_get_probe(const sc_engine *e);
/* The compression exam's assessment (sc_assess.h; layout in docs/assessment.md): per vessel
 * the deepest compression, coaptation and force there, the peak force, the artery check, the
 * trainee's call (CAN CmdAssessment) and the scored criteria. Updated every frame after the
 * imaging stage (O(1) plus sc_tissue_probe_force_n, O(contacts)); reset by CmdAssessment's
 * reset and at every case swap (with the new case's finding). Never NULL. O(1). */
const sc_assess_report *sc_engine_assessment(const sc_engine *e);
#if SC_STATE_STREAM
/* The state stream's counters (records sent, dropped). O(1). */
const sc_state_tx *sc_engine_get_state_tx(const sc_engine *e);
#endif

#if SC_ENABLE_DOPPLER
/* Colour/spectral Doppler settings (box, steering, scale, gain, gate, flow), applied from the
 * next frame. O(1). Errors: SC_ERR_INVALID_ARG, those of sc_doppler_def_validate (the previous
 * settings stay). */
int sc_engine_set_doppler(sc_engine *e, const sc_doppler_def *def);

/* The cardiac and respiratory phases ([0, 1)) of the next frame's flow, e.g. from the pulsation
 * model; without a call the Doppler's own clocks run (def.doppler heart and breathing rates).
 * O(1). Errors: SC_ERR_INVALID_ARG, SC_ERR_NOT_FINITE. */
int sc_engine_set_flow_phase(sc_engine *e, float cardiac_phase, float resp_phase);

/* The last frame's Doppler status (colour pixels, aliasing, gate velocity). O(1). */
const sc_doppler_status *sc_engine_get_doppler_status(const sc_engine *e);
/* The Doppler settings in force (CmdDoppler changes enabled, prf_hz, steer_deg, gain_db). */
const sc_doppler_def *sc_engine_get_doppler_def(const sc_engine *e);
#endif

#if SC_ENABLE_NEEDLE
/* The tracked needle's last frame: presence, tip label, punctures (each lumen entry once; an
 * artery entry is a fault of the exam), pixels drawn; and its receiver's counters. O(1). */
const sc_needle_status *sc_engine_get_needle_status(const sc_engine *e);
const sc_needle_rx *sc_engine_get_needle_rx(const sc_engine *e);
#endif

#endif /* SC_ENGINE_H */
