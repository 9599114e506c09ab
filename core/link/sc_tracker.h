/*
 * sc_tracker.h: the engine's receive side of the CAN protocol (sc_canproto.h).
 *
 * Feed every received frame to sc_tracker_on_frame() (at most SC_CAN_RX_BURST_MAX per engine
 * frame), then call sc_tracker_poll() once per engine frame. The tracker
 *  - checks every protocol frame with its own E2E receiver state (sc_e2e.h);
 *  - assembles a classic pose from its three frames tied by their shared E2E counter (two
 *    assembly slots, so parts of consecutive samples may interleave), or takes the CAN FD pose;
 *  - checks plausibility on top of integrity: tracking state, quaternion norm, workspace box,
 *    contact force, linear and angular speed against the last accepted pose; an implausible
 *    pose is rejected and counted by reason and never becomes the current pose;
 *  - keeps the newest valid pose: poll never waits, so a tracker slower than the frame rate
 *    never stalls a frame;
 *  - declares the probe lifted when no valid pose came for pose_timeout_ms (the engine then
 *    removes the collider and lets the tissue relax); the next valid pose ends the lift
 *    without a speed check (the probe may come back anywhere);
 *  - decodes and range-checks commands, holds each until its cryptographic PDU arrives
 *    (sc_secoc.h: the command's MAC and freshness; at most SC_TRK_AUTH_PAIR_MS later), and
 *    queues only authenticated ones into a small FIFO (SC_CAN_CMD_QUEUE_MAX) the engine takes
 *    from; a command without its MAC, with a wrong MAC, a stale or replayed freshness value, an
 *    unknown or unsynchronised sender is refused and counted by reason;
 *  - counts an exact duplicate of the last accepted frame of a message (same counter, same
 *    bytes: a bus or gateway artefact, nothing lost) as a duplicate, not as a reject;
 *  - records controller error frames (SC_CAN_ERRF_* classes) for the health state.
 * The send side (status frames) is sc_status_tx.h.
 * Every outcome is counted (saturating uint32). Receive times (frame time stamp, else now_ns)
 * are used rounded down to whole microseconds, the resolution of a candump -l log, so that
 * replaying a recorded log reproduces every time-dependent decision bit for bit.
 *
 * Thread and memory rules: one sc_tracker object, caller-owned (inside the engine object),
 * used from one thread. Never allocates, never calls the OS; deterministic for a given frame
 * sequence and time stamps. sizeof(sc_tracker) = 2,304 bytes (x86_64, default limits).
 */
#ifndef SC_TRACKER_H
#define SC_TRACKER_H

#include <stdint.h>

#include "sc_canproto.h"
#include "sc_config.h"
#include "sc_e2e.h"
#include "sc_hal_can.h"
#include "sc_pose.h"
#include "sc_secoc.h"

typedef struct sc_tracker_def {
    float ws_min_mm[3]; /* workspace box, tracker frame: a pose outside is implausible */
    float ws_max_mm[3];
    float quat_norm_tol;       /* | |q| - 1 | above this is implausible (0 < tol < 0.5) */
    float max_speed_mm_s;      /* linear speed limit between accepted poses */
    float max_ang_speed_rad_s; /* angular speed limit between accepted poses */
    float max_force_n;         /* contact force above this is implausible */
    uint32_t pose_timeout_ms;  /* no valid pose for this long: probe lifted */
    uint32_t pose_cycle_ms;    /* nominal pose period: floor of the speed check's dt */
    uint8_t max_delta_counter; /* E2E: counter steps accepted (1 = no loss tolerated) */
    uint8_t accept_fd;         /* accept the CAN FD pose 0x110 */
    sc_secoc_def secoc;        /* command authentication: key, freshness window, floor */
} sc_tracker_def;

/* Defaults: workspace x,y in [-400, 400] mm, z in [-100, 500] mm; norm tolerance 0.02;
 * 3000 mm/s (a fast hand stays below 1.5 m/s); 4 pi rad/s; 200 N; timeout 100 ms (10 pose
 * periods, as the DBC); cycle 10 ms; max delta counter 3; FD accepted; sc_secoc_default_def()
 * (the bench key). */
sc_tracker_def sc_tracker_default_def(void);
/* 0, SC_ERR_NOT_FINITE or SC_ERR_RANGE (an empty box, tolerances or limits <= 0, timeout
 * shorter than the cycle, max_delta_counter outside 1..14, a freshness window outside
 * 1..SC_SECOC_MAX_WINDOW). O(1). */
int sc_tracker_def_validate(const sc_tracker_def *def);

/* Result of one frame. */
typedef enum sc_trk_outcome {
    SC_TRK_POSE_ACCEPTED = 0, /* a complete pose passed every check: newest pose now */
    SC_TRK_POSE_PART,         /* a pose part accepted, waiting for the rest of its sample */
    SC_TRK_COMMAND,           /* a command was authenticated and queued */
    SC_TRK_NOT_OURS,          /* id not in the protocol, or one of our own outgoing ids */
    SC_TRK_BAD_LENGTH,        /* protocol id with a wrong length or FD flag */
    SC_TRK_FD_DISABLED,       /* FD pose while accept_fd is 0 */
    SC_TRK_E2E_WRONG_CRC,
    SC_TRK_E2E_WRONG_SEQUENCE,
    SC_TRK_E2E_REPEATED,
    SC_TRK_POSE_STALE,   /* a sample older than the last assembled one completed late */
    SC_TRK_NOT_TRACKING, /* the tracker itself reports it lost the probe */
    SC_TRK_REJ_QUAT_NORM,
    SC_TRK_REJ_WORKSPACE,
    SC_TRK_REJ_FORCE,
    SC_TRK_REJ_SPEED,
    SC_TRK_REJ_ANG_SPEED,
    SC_TRK_CMD_REJECTED,   /* a command signal outside its DBC range */
    SC_TRK_CMD_QUEUE_FULL, /* the engine did not take commands fast enough: dropped */
    SC_TRK_BUS_ERROR,      /* an error frame from the controller */
    SC_TRK_DUPLICATE,      /* the last accepted frame of its message again, byte for byte */
    SC_TRK_CMD_PENDING,    /* a command held until its cryptographic PDU comes */
    SC_TRK_AUTH_SYNCED,    /* a CmdFreshnessSync authenticated: the sender is synchronised */
    SC_TRK_AUTH_ORPHAN,    /* a cryptographic PDU without its command (or another's link) */
    SC_TRK_AUTH_UNKNOWN_SENDER,
    SC_TRK_AUTH_NOT_SYNCED, /* the sender has not synchronised its freshness yet */
    SC_TRK_AUTH_STALE,     /* freshness replayed, older, or past the acceptance window */
    SC_TRK_AUTH_BAD_MAC,   /* wrong key, altered command, forged */
    SC_TRK_OUTCOME_COUNT
} sc_trk_outcome;

const char *sc_trk_outcome_name(sc_trk_outcome o);
/* 1 for the E2E rejects (CRC, sequence, repeated). */
int sc_trk_outcome_is_e2e_reject(sc_trk_outcome o);
/* 1 for the plausibility rejects (norm, workspace, force, speed, angular speed). */
int sc_trk_outcome_is_implausible(sc_trk_outcome o);
/* 1 for the refused command authentications of a frame (orphan, unknown sender, not synced,
 * stale, bad MAC); commands whose MAC never came are sc_trk_counters.auth_missing. */
int sc_trk_outcome_is_auth_reject(sc_trk_outcome o);

/* The newest valid sample. */
typedef struct sc_trk_sample {
    sc_pose pose; /* quaternion normalised */
    float force_n;
    uint8_t force_valid;
    uint8_t counter; /* E2E counter of the sample */
    uint64_t rx_ns;  /* receive time (frame time stamp, else now_ns), whole microseconds */
} sc_trk_sample;

typedef struct sc_trk_counters {
    uint32_t outcome[SC_TRK_OUTCOME_COUNT];
    uint32_t frames;           /* every frame given to on_frame */
    uint32_t incomplete;       /* partial samples dropped (a part lost or rejected) */
    uint32_t lift_events;      /* valid -> lifted transitions */
    uint32_t e2e_lost;         /* messages lost as seen by counter gaps (OK_SOME_LOST) */
    uint32_t auth_missing;     /* commands whose cryptographic PDU never came (counted when
                                * SC_TRK_AUTH_PAIR_MS passed or the next command of its id
                                * came): refused */
    uint32_t bus_err_class[6]; /* error frames per SC_CAN_ERRF_* bit */
} sc_trk_counters;

#define SC_TRK_ASM_SLOTS 2u
#define SC_TRK_RX_MSGS   13u /* the E2E-protected messages received: 9 commands, 4 pose */
#define SC_TRK_FRAME_MAX 20u /* longest received payload (the FD pose) */
/* SC_TRK_AUTH_PAIR_MS (config/sc_config.h): a command waits this long for its MAC */

/* A command waiting for its cryptographic PDU. */
typedef struct sc_trk_pending {
    uint8_t used;
    uint8_t pdu[8];  /* the authentic PDU as received */
    uint64_t ts_ns;
    sc_cmd cmd;
} sc_trk_pending;

typedef struct sc_trk_asm {
    uint8_t used;
    uint8_t counter;
    uint8_t mask;   /* parts received, bit per classic pose message */
    uint32_t seq;   /* slot age: lower is older */
    uint64_t ts_ns; /* newest part's receive time */
    sc_pose_msg msg;
} sc_trk_asm;

typedef struct sc_tracker {
    sc_tracker_def def;
    sc_e2e_rx rx[SC_TRK_RX_MSGS]; /* indexed by sc_msg (commands, then pose messages) */
    uint8_t last_ok[SC_TRK_RX_MSGS][SC_TRK_FRAME_MAX]; /* last usable payload (duplicates) */
    uint8_t last_auth[SC_CMD_MSGS][SC_SECOC_AUTH_PDU_BYTES]; /* last accepted crypto PDU */
    uint8_t last_auth_pdu[SC_CMD_MSGS][8];                    /* and its command */
    uint64_t last_auth_ns[SC_CMD_MSGS];                       /* and when it came */
    uint8_t have_last_auth[SC_CMD_MSGS];
    sc_trk_pending pending[SC_CMD_MSGS];
    sc_secoc_rx secoc;
    sc_trk_asm slot[SC_TRK_ASM_SLOTS];
    uint32_t slot_seq;
    uint8_t have_pose; /* a fresh valid pose exists (not lifted) */
    uint8_t have_last_counter;
    uint8_t last_counter; /* counter of the last assembled sample */
    sc_trk_sample cur;
    sc_cmd cmd[SC_CAN_CMD_QUEUE_MAX];
    uint8_t cmd_head;
    uint8_t cmd_count;
    uint32_t bus_errors; /* SC_CAN_ERRF_* seen since the last take */
    sc_trk_counters n;
} sc_tracker;

/* Validates def and resets everything: no pose (lifted), empty queues, zero counters.
 * Errors of sc_tracker_def_validate. O(SC_TRK_RX_MSGS). */
int sc_tracker_init(sc_tracker *t, const sc_tracker_def *def);

/* Processes one received frame at now_ns (used when f->ts_ns is 0). O(signals of the
 * message), never allocates, never fails: the outcome names what happened and is counted. */
sc_trk_outcome sc_tracker_on_frame(sc_tracker *t, const sc_can_frame *f, uint64_t now_ns);

/* Once per engine frame. When a valid pose newer than pose_timeout_ms exists: *out = newest
 * pose, *contact = 1, returns 0. Otherwise (never had one, or silent past the timeout: probe
 * lifted, counted once per lift) *contact = 0, *out untouched, returns SC_ERR_TIMEOUT.
 * Also runs the E2E receivers' no-new-data/timeout bookkeeping. O(SC_TRK_RX_MSGS). */
int sc_tracker_poll(sc_tracker *t, uint64_t now_ns, sc_pose *out, int *contact);

/* The newest valid sample (force, counter, time); NULL while lifted. O(1). */
const sc_trk_sample *sc_tracker_sample(const sc_tracker *t);

/* Takes the oldest queued command: 0, or SC_ERR_WOULD_BLOCK when none. O(1). */
int sc_tracker_take_command(sc_tracker *t, sc_cmd *out);

/* Returns and clears the SC_CAN_ERRF_* classes seen in error frames since the last call. */
uint32_t sc_tracker_take_bus_errors(sc_tracker *t);

/* Counters (read-only view). O(1). */
const sc_trk_counters *sc_tracker_counters(const sc_tracker *t);
/* Sums of the E2E rejects, the plausibility rejects and the refused authentications (with
 * auth_missing). O(SC_TRK_OUTCOME_COUNT). */
uint32_t sc_tracker_rejected_e2e(const sc_tracker *t);
uint32_t sc_tracker_rejected_implausible(const sc_tracker *t);
uint32_t sc_tracker_rejected_auth(const sc_tracker *t);
/* Commands and syncs authenticated. O(1). */
uint32_t sc_tracker_authenticated(const sc_tracker *t);
/* E2E receiver state of a received message (commands and pose); NULL for others. */
const sc_e2e_rx *sc_tracker_e2e(const sc_tracker *t, sc_msg m);

#endif /* SC_TRACKER_H */
