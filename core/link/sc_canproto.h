/*
 * sc_canproto.h: the sonocomp CAN protocol codec (config/sonocomp.dbc is the source of truth;
 * the tables here mirror it and tests/unit/test_sc_canproto.c checks them against the file).
 *
 * Messages (11-bit ids, Intel byte order, E2E header in bytes 0-1, see sc_e2e.h):
 *   0x080 CmdSelectCase  0x081 CmdSetMethod  0x082 CmdSetImaging  0x083 CmdReset
 *   0x084 CmdFreshnessSync  0x085 CmdVessels  0x086 CmdDoppler  0x087 CmdAssessment
 *   0x090 CmdMaterial (the second command block 0x090..0x097, auth 0x098..0x09F; 0x091..0x097
 *         and 0x099..0x09F are unused and filtered out)                          (in, event)
 *   0x088..0x08F, 0x098 CmdAuth*: the cryptographic PDU of command id - 8 (sc_secoc.h) (in)
 *   0x100 ProbePosePos   0x101 ProbePoseQuat 0x102 ProbePoseAux                    (in, 10 ms)
 *   0x110 ProbePoseFD    (in, 10 ms, CAN FD 20 bytes: the three above in one frame)
 *   0x200 EngineStatus   0x201 EngineTiming  0x202 TrackerDiag  0x203 AuthDiag    (out, 100 ms)
 *   0x210 AssessVessels  0x211 AssessForce   0x212 AssessScore: the compression exam's
 *         assessment (core/imaging/sc_assess.h)                                    (out, 100 ms)
 * A classic pose spans the three 0x10x frames, tied by one E2E counter value shared by the
 * three frames of a sample. E2E data ID = CAN id. Every message but the CmdAuth* frames
 * carries the E2E header (their integrity is their MAC's).
 *
 * All functions are pure: no state, no allocation, no OS; deterministic. Encoding validates
 * every physical value (finite, representable) and fails with SC_ERR_NOT_FINITE or
 * SC_ERR_CAN_SIGNAL; decoding validates the frame (id, FD flag, length: SC_ERR_CAN_ID,
 * SC_ERR_CAN_DLC) and, for commands, the value ranges (SC_ERR_CAN_SIGNAL). Decoding never
 * checks the E2E header: that is sc_e2e's job, done before. Costs are O(signals of the
 * message), at most SC_CANPROTO_MAX_SIGS.
 */
#ifndef SC_CANPROTO_H
#define SC_CANPROTO_H

#include <stddef.h>
#include <stdint.h>

#include "sc_e2e.h"
#include "sc_hal_can.h"

typedef enum sc_msg {
    SC_MSG_CMD_CASE = 0,
    SC_MSG_CMD_METHOD,
    SC_MSG_CMD_IMAGING,
    SC_MSG_CMD_RESET,
    SC_MSG_CMD_SYNC,
    SC_MSG_CMD_ASSESS, /* CmdAssessment 0x087: reset the assessment, the trainee's call */
    SC_MSG_CMD_VESSELS, /* CmdVessels 0x085: heart and breathing rates, Valsalva, pulsation */
    SC_MSG_CMD_DOPPLER, /* CmdDoppler 0x086: colour on/off, scale (PRF), steering, gain */
    SC_MSG_CMD_MATERIAL, /* CmdMaterial 0x090: one label's E and nu, damping, CG iterations */
    SC_MSG_POSE_POS,
    SC_MSG_POSE_QUAT,
    SC_MSG_POSE_AUX,
    SC_MSG_POSE_FD,
    SC_MSG_STATUS,
    SC_MSG_TIMING,
    SC_MSG_DIAG,
    SC_MSG_AUTH_DIAG,
    SC_MSG_AUTH_CASE, /* the cryptographic PDUs, in command order */
    SC_MSG_AUTH_METHOD,
    SC_MSG_AUTH_IMAGING,
    SC_MSG_AUTH_RESET,
    SC_MSG_AUTH_SYNC,
    SC_MSG_AUTH_ASSESS,
    SC_MSG_AUTH_VESSELS,
    SC_MSG_AUTH_DOPPLER,
    SC_MSG_AUTH_MATERIAL,
    SC_MSG_ASSESS_VESSELS, /* the assessment's status frames (out) */
    SC_MSG_ASSESS_FORCE,
    SC_MSG_ASSESS_SCORE,
    /* the tracked needle (issue 18): a second tool, E2E protected like the probe */
    SC_MSG_NEEDLE_POS,
    SC_MSG_NEEDLE_DIR,
    SC_MSG_NEEDLE_AUX,
    SC_MSG_NEEDLE_STATUS, /* engine out */
    SC_MSG_COUNT
} sc_msg;

#define SC_CMD_MSGS 9u /* commands SC_MSG_CMD_CASE..SC_MSG_CMD_MATERIAL; SC_MSG_AUTH_* likewise */
/* 1 for the secured commands (authentic PDUs), 1 for their cryptographic PDUs. */
#define SC_MSG_IS_CMD(m)  ((unsigned)(m) <= (unsigned)SC_MSG_CMD_MATERIAL)
#define SC_MSG_IS_AUTH(m)                                                                          \
    ((unsigned)(m) >= (unsigned)SC_MSG_AUTH_CASE && (unsigned)(m) <= (unsigned)SC_MSG_AUTH_MATERIAL)
#define SC_MSG_IS_NEEDLE_IN(m)                                                                   \
    ((unsigned)(m) >= (unsigned)SC_MSG_NEEDLE_POS && (unsigned)(m) <= (unsigned)SC_MSG_NEEDLE_AUX)

#define SC_CANPROTO_MAX_SIGS 14u /* AssessScore */

enum {
    SC_CANID_CMD_CASE = 0x080,
    SC_CANID_CMD_METHOD = 0x081,
    SC_CANID_CMD_IMAGING = 0x082,
    SC_CANID_CMD_RESET = 0x083,
    SC_CANID_CMD_SYNC = 0x084,
    SC_CANID_CMD_VESSELS = 0x085,
    SC_CANID_CMD_DOPPLER = 0x086,
    SC_CANID_CMD_ASSESS = 0x087,
    SC_CANID_AUTH_OFFSET = 0x008, /* CmdAuth id = command id + 8 */
    SC_CANID_AUTH_CASE = 0x088,
    SC_CANID_AUTH_SYNC = 0x08C,
    SC_CANID_AUTH_VESSELS = 0x08D,
    SC_CANID_AUTH_DOPPLER = 0x08E,
    SC_CANID_AUTH_ASSESS = 0x08F,
    SC_CANID_CMD_MATERIAL = 0x090, /* second command block 0x090..0x097, auth 0x098..0x09F */
    SC_CANID_AUTH_MATERIAL = 0x098,
    SC_CANID_POSE_POS = 0x100,
    SC_CANID_POSE_QUAT = 0x101,
    SC_CANID_POSE_AUX = 0x102,
    SC_CANID_POSE_FD = 0x110,
    SC_CANID_STATUS = 0x200,
    SC_CANID_TIMING = 0x201,
    SC_CANID_DIAG = 0x202,
    SC_CANID_AUTH_DIAG = 0x203,
    SC_CANID_ASSESS_VESSELS = 0x210, /* the assessment block 0x210..0x212 */
    SC_CANID_ASSESS_FORCE = 0x211,
    SC_CANID_ASSESS_SCORE = 0x212,
    /* needle block: in 0x120..0x122, out 0x220 (0x120..0x12F and 0x220..0x22F reserved for the
     * needle and Doppler) */
    SC_CANID_NEEDLE_POS = 0x120,
    SC_CANID_NEEDLE_DIR = 0x121,
    SC_CANID_NEEDLE_AUX = 0x122,
    SC_CANID_NEEDLE_STATUS = 0x220,
};

/* One signal as in the DBC: raw little-endian bit field, phys = raw * factor + offset. */
typedef struct sc_can_sig {
    const char *name;
    uint16_t start_bit; /* Intel: bit index of the LSB, byte * 8 + bit */
    uint8_t bits;
    uint8_t is_signed;
    float factor;
    float offset;
    float min; /* DBC range of valid physical values */
    float max;
    const char *unit;
} sc_can_sig;

typedef struct sc_can_msg_info {
    const char *name;
    uint32_t can_id;
    uint16_t data_id;    /* E2E data ID */
    uint8_t len;         /* payload bytes */
    uint8_t fd;          /* 1: CAN FD frame */
    uint16_t cycle_ms;   /* 0: sent on event */
    uint16_t timeout_ms; /* receive timeout, 0: none */
    uint8_t e2e;         /* 1: bytes 0-1 are the E2E header (all but the CmdAuth frames) */
    uint8_t sig_count;
    const sc_can_sig *sigs;
} sc_can_msg_info;

/* Table entry of a message, NULL for an invalid index. O(1). */
const sc_can_msg_info *sc_canproto_info(sc_msg m);

/* Message of a received frame: SC_ERR_CAN_ID for an id not in the protocol (or extended, RTR,
 * error frames), SC_ERR_CAN_DLC for a length or FD flag that does not match. O(SC_MSG_COUNT). */
int sc_canproto_classify(const sc_can_frame *f, sc_msg *out);

/* Raw bit field access (Intel byte order). get sign-extends signed signals. O(bits). */
int64_t sc_canproto_get_raw(const uint8_t *data, const sc_can_sig *s);
void sc_canproto_put_raw(uint8_t *data, const sc_can_sig *s, int64_t raw);
/* Physical value to raw: round to nearest, SC_ERR_NOT_FINITE, SC_ERR_CAN_SIGNAL when the raw
 * value does not fit the field. O(1). */
int sc_canproto_phys_to_raw(const sc_can_sig *s, float phys, int64_t *raw);
float sc_canproto_raw_to_phys(const sc_can_sig *s, int64_t raw);

/* Decodes every signal of a classified frame into phys[0..sig_count-1] (table order).
 * Errors of sc_canproto_classify; SC_ERR_NO_SPACE if cap < sig_count. */
int sc_canproto_decode_phys(const sc_can_frame *f, sc_msg *msg, float *phys, size_t cap);

/* ---- probe pose (in) ------------------------------------------------------------------- */
enum { SC_TRACKING_OK = 0, SC_TRACKING_LOST = 1 };
#define SC_FORCE_NOT_AVAILABLE_RAW 0xFFFFu

typedef struct sc_pose_msg {
    float pos_mm[3];
    float q[4];    /* w, x, y, z as sent (not normalised) */
    float force_n; /* contact force, valid when force_valid */
    uint8_t force_valid;
    uint8_t tracking; /* SC_TRACKING_* */
} sc_pose_msg;

/* Encodes one pose sample with E2E counter `counter` (same for all parts): 3 classic frames
 * (0x100, 0x101, 0x102) or, with fd, 1 frame 0x110. *n gets the frame count. ts_ns of the
 * frames is 0. SC_ERR_NO_SPACE when cap is too small. */
int sc_canproto_encode_pose(const sc_pose_msg *m, uint8_t counter, int fd, sc_can_frame *out,
                            size_t cap, size_t *n);
/* Writes the fields that message `msg` carries into *m (other fields untouched); returns the
 * part bit (1 << (msg - SC_MSG_POSE_POS)) for the classic parts, 7 for the FD frame. Errors of
 * sc_canproto_classify, SC_ERR_CAN_ID for a frame that is not a pose. */
int sc_canproto_decode_pose_part(const sc_can_frame *f, sc_pose_msg *m);
#define SC_POSE_PARTS_ALL 7u

/* ---- needle pose (in) and needle status (out) ------------------------------------------
 * One needle sample = NeedlePosePos (tip position), NeedlePoseDir (unit shaft direction, hub to
 * tip, Q14), NeedleAux (insertion depth: shaft length below the skin; tracking state), back to
 * back with one E2E counter, like the probe's pose. */
typedef struct sc_needle_msg {
    float tip_mm[3];   /* tracker frame */
    float dir[3];      /* as sent (receiver checks the norm) */
    float depth_mm;    /* inserted length, [0, 3276.7] */
    uint8_t tracking;  /* SC_TRACKING_* */
} sc_needle_msg;
#define SC_NEEDLE_PARTS_ALL 7u
/* 3 classic frames (0x120..0x122), counter as given. SC_ERR_NO_SPACE (cap < 3),
 * SC_ERR_CAN_SIGNAL / SC_ERR_NOT_FINITE for a value outside its signal. O(1). */
int sc_canproto_encode_needle(const sc_needle_msg *m, uint8_t counter, sc_can_frame *out,
                              size_t cap, size_t *n);
/* Writes the fields of one needle frame into *m; returns its part bit (1, 2, 4). Errors of
 * sc_canproto_classify, SC_ERR_CAN_ID for a frame that is not a needle part. O(1). */
int sc_canproto_decode_needle_part(const sc_can_frame *f, sc_needle_msg *m);

typedef struct sc_needle_status_msg {
    uint8_t tip_vessel;         /* label the tip is in now: 0 none, SC_LABEL_VEIN, _ARTERY */
    uint8_t needle_tracked;     /* a valid needle sample within its timeout */
    uint8_t last_puncture;      /* label of the last lumen entry (0: none yet) */
    uint8_t vein_punctures;     /* entries into a vein lumen (saturating at 255) */
    uint8_t artery_punctures;   /* entries into an artery lumen: faults of the exam */
    uint16_t needle_rejected;   /* needle frames refused (E2E, plausibility, length) */
} sc_needle_status_msg;
int sc_canproto_encode_needle_status(const sc_needle_status_msg *s, uint8_t counter,
                                     sc_can_frame *out);
int sc_canproto_decode_needle_status(const sc_can_frame *f, sc_needle_status_msg *s);

/* ---- commands (in) ----------------------------------------------------------------------- */
typedef enum sc_cmd_kind {
    SC_CMD_SELECT_CASE = 1,
    SC_CMD_SET_METHOD = 2,
    SC_CMD_SET_IMAGING = 3,
    SC_CMD_RESET = 4,
    SC_CMD_SYNC_FRESHNESS = 5, /* CmdFreshnessSync: the sender's freshness bits 16..63 */
    SC_CMD_ASSESS = 6,         /* CmdAssessment: reset the assessment, or the trainee's call */
    SC_CMD_VESSELS = 7,        /* CmdVessels: the lumens' drive (heart, breathing, Valsalva) */
    SC_CMD_DOPPLER = 8,        /* CmdDoppler: colour Doppler on/off, scale, steering, gain */
    SC_CMD_MATERIAL = 9,       /* CmdMaterial: a label's material, the solver's parameters */
} sc_cmd_kind;

enum { SC_METHOD_MSDS = 0, SC_METHOD_FEM = 1 };
enum { SC_SCAN_LINEAR = 0, SC_SCAN_CURVILINEAR = 1 };
enum { SC_RESET_TISSUE = 1, SC_RESET_FAULTS = 2, SC_RESET_ALL = 3 };
/* CmdAssessment: Action 1 resets the assessment (Call 0), 2 enters the trainee's call (Call 1
 * normal, 2 DVT). Any other pair is refused (SC_ERR_CAN_SIGNAL). */
enum { SC_ASSESS_ACTION_RESET = 1, SC_ASSESS_ACTION_CALL = 2 };
enum { SC_ASSESS_CALL_NONE = 0, SC_ASSESS_CALL_NORMAL = 1, SC_ASSESS_CALL_DVT = 2 };

typedef struct sc_imaging_cmd {
    float depth_mm;      /* 10..250 */
    float gain_db;       /* -40..40, 0.5 dB steps */
    float dyn_range_db;  /* 20..100 */
    float tgc_db_per_cm; /* 0..10 */
    uint8_t geometry;    /* SC_SCAN_* */
} sc_imaging_cmd;

/* CmdVessels: heart rate 30..200 bpm, respiration 0..40 breaths/min (the lumen law also
 * refuses 1..3: sc_lumen_drive_validate, counted by the engine), Valsalva held, the arterial
 * pulse on (off: no pressure pulse, the heart's clock runs on for the Doppler flow). */
typedef struct sc_vessels_cmd {
    float heart_rate_bpm;
    float resp_rate_bpm;
    uint8_t valsalva; /* 0/1 */
    uint8_t pulse;    /* 0/1 */
} sc_vessels_cmd;

/* CmdDoppler: colour (and spectral) Doppler on/off, scale as PRF 100..20000 Hz, steering
 * -30..30 deg (1 deg steps), colour gain -30..30 dB (0.5 dB steps). The engine applies them
 * with sc_engine_set_doppler (its validation, e.g. wall filter <= PRF/4, may still refuse). */
typedef struct sc_doppler_cmd {
    uint8_t on;
    float prf_hz;
    float steer_deg;
    float gain_db;
} sc_doppler_cmd;

/* CmdMaterial: the material of one tissue label (skin..thrombus; outside and bone are refused:
 * bone's nodes are fixed) as Young's modulus 0.1..6553.4 kPa (0.1 kPa steps) and Poisson
 * ratio 0..0.49 (0.002 steps), and the simulation parameters of the paper's FEM/MSDS dialogs
 * that apply to both methods: the damping gamma/k = Rayleigh beta 0.01..0.5 s (0.002 s steps;
 * Algorithm 1's 0.1 s), the CG iterations per frame 1..63 (FEM and the implicit MSDS; default
 * SC_PHYS_CG_ITERATIONS_DEFAULT) and the corotated FEM on/off. The engine rebuilds the
 * running case's tissue with them (sc_engine.h). */
#define SC_MATERIAL_LABEL_MIN 1u /* SC_LABEL_SKIN */
#define SC_MATERIAL_LABEL_MAX 7u /* SC_LABEL_THROMBUS */
typedef struct sc_material_cmd {
    uint8_t label;          /* SC_MATERIAL_LABEL_MIN..SC_MATERIAL_LABEL_MAX */
    uint8_t cg_iterations;  /* 1..63 */
    uint8_t corotated;      /* 0/1 */
    float e_kpa;            /* 0.1..6553.4 */
    float poisson;          /* 0..0.49 */
    float damping_s;        /* gamma / k, 0.01..0.5 */
} sc_material_cmd;

typedef struct sc_cmd {
    sc_cmd_kind kind;
    uint8_t case_id;        /* SELECT_CASE: 0..254 */
    uint8_t method;         /* SET_METHOD: SC_METHOD_* */
    uint8_t reset_target;   /* RESET: SC_RESET_* */
    union {                     /* the kind's settings (one at a time: sc_cmd stays 48 B) */
        sc_imaging_cmd imaging; /* SET_IMAGING */
        sc_vessels_cmd vessels; /* VESSELS */
        sc_doppler_cmd doppler; /* DOPPLER */
        sc_material_cmd material; /* MATERIAL */
    };
    uint64_t fv_high;       /* SYNC_FRESHNESS: freshness value >> 16, 0..2^48-1 */
    uint8_t sender;         /* the authenticated sender (set by the receiver; sc_secoc.h) */
    uint8_t assess_action;  /* ASSESS: SC_ASSESS_ACTION_* */
    uint8_t assess_call;    /* ASSESS: SC_ASSESS_CALL_* (NONE with the reset) */
} sc_cmd;

/* The message of a command kind (SC_MSG_COUNT for an unknown kind). O(1). */
sc_msg sc_canproto_cmd_msg(sc_cmd_kind k);

/* One frame, E2E-protected with `counter`. SC_ERR_INVALID_ARG for an unknown kind,
 * SC_ERR_CAN_SIGNAL / SC_ERR_NOT_FINITE for values outside the DBC ranges. */
int sc_canproto_encode_cmd(const sc_cmd *c, uint8_t counter, sc_can_frame *out);
/* Decodes and range-checks a command frame (SC_ERR_CAN_SIGNAL outside the DBC ranges). */
int sc_canproto_decode_cmd(const sc_can_frame *f, sc_cmd *out);

/* ---- engine status (out) ----------------------------------------------------------------- */
#define SC_STATUS_CASE_NONE         255u
#define SC_AREA_RATIO_NOT_AVAILABLE (-1.0f)

typedef struct sc_status_msg {
    uint8_t state;            /* sc_health_state */
    uint8_t method;           /* SC_METHOD_* */
    uint8_t probe_contact;    /* collider touching the skin */
    uint8_t probe_lifted;     /* tracker silent or lost: collider removed */
    uint16_t fault_bits;      /* sc_health active bits */
    uint32_t deadline_misses; /* saturates at 65535 on the bus */
    uint8_t case_id;          /* SC_STATUS_CASE_NONE when none */
    uint32_t worst_frame_us;  /* saturates at 65535 */
    float vein_area_ratio;    /* lumen area / rest area, <0 not available */
    float artery_area_ratio;
    uint32_t poses_accepted; /* sent modulo 65536 */
    uint32_t rejected_e2e;   /* saturating on the bus */
    uint32_t rejected_plausibility;
    uint32_t lift_events;
    uint32_t cmds_authenticated; /* sent modulo 65536 */
    uint32_t auth_rejected;      /* every refused command authentication, saturating */
    uint32_t auth_bad_mac;       /* of which: MAC wrong (saturating at 255) */
    uint32_t auth_stale;         /* of which: freshness stale or replayed (saturating at 255) */
} sc_status_msg;

#define SC_STATUS_FRAMES 4u
/* Encodes EngineStatus, EngineTiming, TrackerDiag, AuthDiag (in that order) into out[0..3],
 * each protected with the counter of its sender state tx[0..3] (advanced). Counters saturate
 * to their fields. SC_ERR_CAN_SIGNAL for a state/method out of range or a non-finite ratio. */
int sc_canproto_encode_status(const sc_status_msg *s, sc_e2e_tx tx[SC_STATUS_FRAMES],
                              sc_can_frame out[SC_STATUS_FRAMES]);
/* Writes the fields one of the four status frames carries into *s (ratios that are "not
 * available" decode to SC_AREA_RATIO_NOT_AVAILABLE). Errors of sc_canproto_classify,
 * SC_ERR_CAN_ID for a frame that is not a status frame. */
int sc_canproto_decode_status_part(const sc_can_frame *f, sc_status_msg *s);

/* ---- assessment (out): AssessVessels, AssessForce, AssessScore --------------------------------
 * The compression exam's assessment (core/imaging/sc_assess.h) in three frames. Ratios and
 * forces that are "not available" (vessel never in view, no force) are negative here and
 * 0xFFFF on the bus. */
#define SC_ASSESS_FRAMES  3u
#define SC_ASSESS_VESSELS 3u /* vein, artery, thrombosed vein (sc_assess_vessel) */
#define SC_FORCE_NOT_AVAILABLE (-1.0f)

typedef struct sc_assess_msg {
    float min_ratio[SC_ASSESS_VESSELS]; /* deepest compression: smallest area ratio; < 0 n/a */
    float force_at_min_n[SC_ASSESS_VESSELS]; /* force when it was reached; < 0 n/a */
    float peak_force_n;                 /* largest force held 0.1 s in the exam; < 0 n/a */
    uint8_t coapted[SC_ASSESS_VESSELS]; /* min ratio <= the coaptation threshold */
    uint8_t artery_over;                /* artery compressed below its limit */
    uint8_t call;                       /* SC_ASSESS_CALL_* entered by the trainee */
    uint8_t finding;                    /* the case's truth: SC_ASSESS_CALL_NORMAL / _DVT */
    uint8_t criteria_met;               /* bit per criterion (sc_assess_criterion) */
    uint8_t score;                      /* points of the met criteria */
    uint8_t score_max;                  /* points of every criterion */
    uint8_t artery_punctured;           /* the needle entered the artery since the reset */
    uint8_t vein_punctured;             /* the needle entered a vein since the reset */
} sc_assess_msg;

/* Encodes AssessVessels, AssessForce, AssessScore into out[0..2], each protected with the
 * counter of its sender state tx[0..2] (advanced). Ratios clamp to the field's range (a ratio
 * above 65.534 is sent as 65.534), forces likewise to 655.34 N. O(1). Errors:
 * SC_ERR_NOT_FINITE (a NaN or infinite value), SC_ERR_CAN_SIGNAL (call or finding above 2). */
int sc_canproto_encode_assess(const sc_assess_msg *a, sc_e2e_tx tx[SC_ASSESS_FRAMES],
                              sc_can_frame out[SC_ASSESS_FRAMES]);
/* Writes the fields one of the three frames carries into *a ("not available" decodes to a
 * negative value). Errors of sc_canproto_classify, SC_ERR_CAN_ID for another message. O(1). */
int sc_canproto_decode_assess_part(const sc_can_frame *f, sc_assess_msg *a);

#endif /* SC_CANPROTO_H */
