/*
 * sc_assess.h: the assessment of a compression exam (the DVT compression test, the vein check
 * before a central line), computed by the engine from what it simulates, frame by frame.
 *
 * What it measures, per vessel of the case in view (vein, artery, thrombosed vein; a vessel is
 * "in view" in a frame with probe contact where the B-scan's compression measure has its area
 * ratio, sc_bscan.h): the deepest compression reached (smallest image-area ratio now / rest),
 * the force on the probe at that frame (sc_tissue_probe_force_n), whether it coapted (ratio <=
 * coapt_ratio); over the exam the peak force held for min_view_frames (0.1 s: a press, not a
 * frame's transient of the solve, docs/assessment.md) and whether the artery was compressed below
 * artery_min_ratio; the trainee's call (normal / DVT, a CAN command) against the case's finding
 * (DVT when the case's mesh holds thrombus); the tracked needle's lumen entries (an arterial
 * puncture is a fault). A score sums the points of the criteria met
 * (sc_assess_criterion, each met or not, with its points in the report).
 *
 * The record (sc_assess_report, version SC_ASSESS_REPORT_VERSION) is plain data: the engine's
 * accessor sc_engine_assessment() returns it, the status stage sends it on CAN (AssessVessels,
 * AssessForce, AssessScore of config/sonocomp.dbc), the console shows it.
 *
 * Rules: fixed memory (one sc_assess inside the engine, sizeof asserted), no allocation, no OS,
 * deterministic (a pure function of the inputs in order). One writer. Costs: every function is
 * O(1) (sc_assess_score O(SC_ASSESS_CRITERIA)) but sc_assess_update, O(min_view_frames) (the
 * held force's minimum: 6 by default, at most SC_ASSESS_HOLD_MAX). Bad input (a non-finite
 * ratio or force) is treated as "not available", never asserted; a bad call value is refused
 * (SC_ERR_RANGE).
 */
#ifndef SC_ASSESS_H
#define SC_ASSESS_H

#include <stdint.h>

#include "sc_canproto.h"

#define SC_ASSESS_REPORT_VERSION 1u
/* Compatible revision of the version-1 layout: 0 the first (five criteria), 1 adds the needle's
 * punctures and criterion 5 in bytes formerly reserved (docs/assessment.md). */
#define SC_ASSESS_REPORT_REVISION 1u
#define SC_ASSESS_CRITERIA_R0     5u /* criteria whose points sit in points[] */

/* The vessels assessed (index of the report's vessel[] and of the CAN signals). */
typedef enum sc_assess_vessel {
    SC_ASSESS_VEIN = 0,     /* label vein */
    SC_ASSESS_ARTERY = 1,   /* label artery */
    SC_ASSESS_THROMBUS = 2, /* label thrombus: the thrombosed vein's lumen */
} sc_assess_vessel;
_Static_assert(SC_ASSESS_VESSELS == 3u, "three vessels");

/* The criteria of the score, bit n of criteria_met = criterion n. */
typedef enum sc_assess_criterion {
    SC_ASSESS_CRIT_VEIN_IMAGED = 0, /* the vein (or the thrombosed vein) was in view under the
                                     * probe for at least min_view_frames frames */
    SC_ASSESS_CRIT_COMPRESSED,      /* the compression was decisive: the vein coapted, or a
                                     * press of at least firm_force_n with the vein (or the
                                     * thrombosed vein) in view did not make it coapt */
    SC_ASSESS_CRIT_ARTERY_SPARED,   /* a vein was imaged and the artery was never held below
                                     * artery_min_ratio for min_view_frames frames in a row */
    SC_ASSESS_CRIT_FORCE_SAFE,      /* a vein was imaged and the peak force stayed <=
                                     * force_max_n (met when the force is not available) */
    SC_ASSESS_CRIT_CALL_CORRECT,    /* the trainee's call equals the case's finding */
    SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE, /* a vein was imaged and the needle's tip never entered
                                        * the artery's lumen (an arterial puncture is a fault
                                        * of the exam, issue 18) */
    SC_ASSESS_CRITERIA
} sc_assess_criterion;

typedef struct sc_assess_def {
    float coapt_ratio;      /* coapted: area ratio <= this (0.05) */
    float artery_min_ratio; /* artery compressed too much: ratio below this (0.75) */
    float firm_force_n;     /* a press this firm makes a normal vein coapt (N) */
    float force_max_n;      /* more than this is an unsafe press (N) */
    uint32_t min_view_frames; /* frames in view before a vessel counts as imaged */
    uint8_t points[SC_ASSESS_CRITERIA]; /* points of each criterion */
} sc_assess_def;

/* One frame's input. */
typedef struct sc_assess_in {
    uint8_t contact;                   /* the probe touches the tissue */
    float area_ratio[SC_ASSESS_VESSELS]; /* < 0 (or non-finite): not in view */
    float force_n;                     /* < 0 (or non-finite): not available */
    uint8_t puncture;                  /* the needle's tip entered a lumen this frame: its label
                                        * (SC_LABEL_VEIN, SC_LABEL_ARTERY); 0 none. The needle
                                        * reports each entry once (sc_needle.h); counted with
                                        * or without probe contact */
} sc_assess_in;

typedef struct sc_assess_vessel_rec {
    float min_ratio;         /* smallest area ratio while in view; -1: never in view */
    float force_at_min_n;    /* force in that frame; -1: not available */
    uint32_t frames_in_view; /* frames with contact and the vessel in the image */
    uint32_t min_frame;      /* index (report.frames) of the frame of min_ratio */
    uint8_t coapted;         /* min_ratio <= coapt_ratio */
    uint8_t reserved[3];
} sc_assess_vessel_rec;
_Static_assert(sizeof(sc_assess_vessel_rec) == 20u, "vessel record layout");

/* The assessment record (layout version SC_ASSESS_REPORT_VERSION; docs/assessment.md). */
typedef struct sc_assess_report {
    uint32_t version;        /* SC_ASSESS_REPORT_VERSION */
    uint32_t frames;         /* frames assessed since the last reset (or case) */
    uint32_t contact_frames; /* of which with probe contact */
    uint32_t resets;         /* assessment resets (command) since the engine started */
    uint32_t calls;          /* calls entered since the last reset (the last one counts) */
    sc_assess_vessel_rec vessel[SC_ASSESS_VESSELS];
    float peak_force_n;        /* largest force held in contact (the least of min_view_frames
                                * contact frames in a row); -1: never held */
    float venous_force_max_n;  /* largest force held with the vein or thrombosed vein in view */
    uint8_t artery_over;       /* the artery's ratio fell below artery_min_ratio */
    uint8_t call;              /* SC_ASSESS_CALL_*: the trainee's call (NONE: not yet) */
    uint8_t finding;           /* SC_ASSESS_CALL_NORMAL or _DVT: the case's truth */
    uint8_t criteria_met;      /* bit per sc_assess_criterion */
    uint8_t points[SC_ASSESS_CRITERIA_R0]; /* points of criteria 0..4 (from the def) */
    uint8_t score;             /* sum of the points of the met criteria */
    uint8_t score_max;         /* sum of all points */
    /* revision 1 of the layout (bytes 99..102 were reserved zero in revision 0: a reader of
     * revision 0 ignores them and still reads a consistent score / score_max) */
    uint8_t artery_punctures;  /* needle entries into the artery's lumen, saturating at 255 */
    uint8_t vein_punctures;    /* needle entries into a vein's lumen, saturating at 255 */
    uint8_t puncture_points;   /* points of criterion 5 (no_artery_puncture) */
    uint8_t revision;          /* SC_ASSESS_REPORT_REVISION */
    uint8_t reserved;          /* 0 */
} sc_assess_report;
_Static_assert(SC_ASSESS_CRITERIA == 6u, "six criteria: the record's layout");
_Static_assert(sizeof(sc_assess_report) == 104u, "assessment record layout (docs/assessment.md)");

/* the largest min_view_frames (4.25 s at 60 Hz): the held force's window (sc_assess.hold) */
#define SC_ASSESS_HOLD_MAX 255u

typedef struct sc_assess {
    sc_assess_def def;
    sc_assess_report r;
    uint32_t artery_low_frames; /* consecutive contact frames with the artery in view below
                                 * artery_min_ratio; artery_over at min_view_frames of them */
    uint32_t hold_n;            /* consecutive contact frames with a force, up to
                                 * min_view_frames (contact lost, or no force: 0) */
    uint32_t hold_at;           /* hold's next slot */
    float hold[SC_ASSESS_HOLD_MAX]; /* the forces of the last hold_n of those frames (a ring of
                                     * min_view_frames): their minimum is the force held */
} sc_assess;

/* coapt 0.05, artery 0.75, firm press 8 N, unsafe above 60 N, 6 frames (0.1 s) in view;
 * points: imaged 1, compressed 2, artery spared 1, force safe 1, call correct 3, no arterial
 * puncture 2 (10 in all). */
sc_assess_def sc_assess_default_def(void);
/* SC_ERR_INVALID_ARG (NULL), SC_ERR_NOT_FINITE, SC_ERR_RANGE (ratios outside (0, 1], forces
 * <= 0 or firm above max, more than 255 points in all, min_view_frames above
 * SC_ASSESS_HOLD_MAX). O(1). */
int sc_assess_def_validate(const sc_assess_def *def);

/* Validate def and start empty with finding NORMAL. Errors of sc_assess_def_validate. */
int sc_assess_init(sc_assess *a, const sc_assess_def *def);
/* A new case: its finding (SC_ASSESS_CALL_NORMAL or _DVT, else SC_ERR_RANGE) and a reset. */
int sc_assess_begin_case(sc_assess *a, uint8_t finding);
/* Forget the exam (the command's reset): every measure and the call; the finding and the
 * reset count stay. O(1), cannot fail. */
void sc_assess_reset(sc_assess *a);
/* The trainee's call (SC_ASSESS_CALL_NORMAL or _DVT; SC_ERR_RANGE otherwise, nothing
 * changed). The last call counts. O(1). */
int sc_assess_set_call(sc_assess *a, uint8_t call);
/* One frame. O(min_view_frames). */
void sc_assess_update(sc_assess *a, const sc_assess_in *in);
/* The criteria and score of a record under def (pure: writes criteria_met, points, score,
 * score_max of *r). O(SC_ASSESS_CRITERIA). */
void sc_assess_score(const sc_assess_def *def, sc_assess_report *r);
/* Points of criterion c in a scored record (points[] or puncture_points); 0 for an unknown c.
 * O(1). */
uint8_t sc_assess_report_points(const sc_assess_report *r, uint32_t c);
/* The record (scored). O(1). */
const sc_assess_report *sc_assess_get(const sc_assess *a);
/* The CAN status message of a record. O(1). */
void sc_assess_to_msg(const sc_assess_report *r, sc_assess_msg *out);
/* Name of a criterion ("vein_imaged", ...), "?" for an unknown one. */
const char *sc_assess_criterion_name(sc_assess_criterion c);

#endif /* SC_ASSESS_H */
