/* sc_assess.c: the assessment of a compression exam; see sc_assess.h. */
#include "sc_assess.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"

sc_assess_def sc_assess_default_def(void)
{
    return (sc_assess_def){
        .coapt_ratio = 0.05f,
        .artery_min_ratio = 0.75f,
        .firm_force_n = 8.0f, /* neck-ijv: the vein coapts by 12 N (tests/hostsim/test_assess) */
        .force_max_n = 60.0f,
        .min_view_frames = 6u,
        .points = {1u, 2u, 1u, 1u, 3u, 2u},
    };
}

int sc_assess_def_validate(const sc_assess_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->coapt_ratio) || !isfinite(d->artery_min_ratio) ||
        !isfinite(d->firm_force_n) || !isfinite(d->force_max_n)) {
        return SC_ERR_NOT_FINITE;
    }
    uint32_t total = 0;
    for (uint32_t c = 0; c < SC_ASSESS_CRITERIA; c++) {
        total += d->points[c];
    }
    if (!(d->coapt_ratio > 0.0f && d->coapt_ratio <= 1.0f) ||
        !(d->artery_min_ratio > 0.0f && d->artery_min_ratio <= 1.0f) ||
        !(d->firm_force_n > 0.0f) || !(d->force_max_n >= d->firm_force_n) || total > 255u ||
        d->min_view_frames > SC_ASSESS_HOLD_MAX) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

static void clear_record(sc_assess_report *r)
{
    const uint32_t resets = r->resets;
    const uint8_t finding = r->finding;
    memset(r, 0, sizeof(*r));
    r->version = SC_ASSESS_REPORT_VERSION;
    r->revision = SC_ASSESS_REPORT_REVISION;
    r->resets = resets;
    r->finding = finding;
    r->call = SC_ASSESS_CALL_NONE;
    r->peak_force_n = -1.0f;
    r->venous_force_max_n = -1.0f;
    for (uint32_t v = 0; v < SC_ASSESS_VESSELS; v++) {
        r->vessel[v].min_ratio = -1.0f;
        r->vessel[v].force_at_min_n = -1.0f;
    }
}

/* A new exam on the same def: the record emptied (its resets and finding kept), the runs the
 * artery check and the held force count restarted, and the empty record scored. */
static void restart(sc_assess *a)
{
    clear_record(&a->r);
    a->artery_low_frames = 0u;
    a->hold_n = 0u;
    sc_assess_score(&a->def, &a->r);
}

int sc_assess_init(sc_assess *a, const sc_assess_def *def)
{
    if (a == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_assess_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    memset(a, 0, sizeof(*a));
    a->def = *def;
    a->r.finding = SC_ASSESS_CALL_NORMAL;
    restart(a);
    return SC_OK;
}

int sc_assess_begin_case(sc_assess *a, uint8_t finding)
{
    if (finding != SC_ASSESS_CALL_NORMAL && finding != SC_ASSESS_CALL_DVT) {
        return SC_ERR_RANGE;
    }
    a->r.finding = finding;
    restart(a);
    return SC_OK;
}

void sc_assess_reset(sc_assess *a)
{
    a->r.resets++;
    restart(a);
}

int sc_assess_set_call(sc_assess *a, uint8_t call)
{
    if (call != SC_ASSESS_CALL_NORMAL && call != SC_ASSESS_CALL_DVT) {
        return SC_ERR_RANGE;
    }
    a->r.call = call;
    a->r.calls++;
    sc_assess_score(&a->def, &a->r);
    return SC_OK;
}

static float avail(float v)
{
    return isfinite(v) && v >= 0.0f ? v : -1.0f;
}

/* The force held over the last min_view_frames contact frames (at least one): the least of
 * theirs, or -1 until that many in a row have had one. The peak force and the firm press are
 * the trainee's press, held 0.1 s as the artery's compression is: a frame's transient is not.
 * The implicit step's ten CG iterations leave the nodes next to the contact behind for a few
 * frames as the contact grows or shrinks, and K (x - X) over the contact overshoots there
 * (docs/assessment.md, "The held force": 64x32x32 MSDS, 16 mm, 82.9 N in a frame against
 * 33.4 N with 40 iterations, held 17.9 against 13.3 N; the default 8 mm press 8.08 N in a
 * frame, a firm press, against 3.61 N, held 4.37 against 3.46 N). */
static float hold_force(sc_assess *a, float force)
{
    const uint32_t n = a->def.min_view_frames > 1u ? a->def.min_view_frames : 1u;
    if (force < 0.0f) {
        a->hold_n = 0u;
        return -1.0f;
    }
    a->hold[a->hold_at] = force;
    a->hold_at = a->hold_at + 1u < n ? a->hold_at + 1u : 0u;
    if (a->hold_n < n) {
        a->hold_n++;
    }
    if (a->hold_n < n) {
        return -1.0f;
    }
    float m = a->hold[0];
    for (uint32_t i = 1; i < n; i++) {
        m = a->hold[i] < m ? a->hold[i] : m;
    }
    return m;
}

void sc_assess_update(sc_assess *a, const sc_assess_in *in)
{
    sc_assess_report *r = &a->r;
    const uint32_t frame = r->frames;
    r->frames++;
    if (in->puncture == (uint8_t)SC_LABEL_ARTERY && r->artery_punctures < 255u) {
        r->artery_punctures++;
    } else if (in->puncture == (uint8_t)SC_LABEL_VEIN && r->vein_punctures < 255u) {
        r->vein_punctures++;
    }
    if (in->puncture != 0u) {
        sc_assess_score(&a->def, r);
    }
    if (!in->contact) {
        a->artery_low_frames = 0u;
        a->hold_n = 0u;
        return;
    }
    r->contact_frames++;
    const float force = avail(in->force_n);
    const float held = hold_force(a, force);
    if (held > r->peak_force_n) {
        r->peak_force_n = held;
    }
    for (uint32_t v = 0; v < SC_ASSESS_VESSELS; v++) {
        const float ratio = avail(in->area_ratio[v]);
        if (ratio < 0.0f) {
            if (v == SC_ASSESS_ARTERY) {
                a->artery_low_frames = 0u;
            }
            continue;
        }
        sc_assess_vessel_rec *x = &r->vessel[v];
        x->frames_in_view++;
        if (x->min_ratio < 0.0f || ratio < x->min_ratio) {
            x->min_ratio = ratio;
            x->force_at_min_n = force;
            x->min_frame = frame;
        }
        x->coapted = (uint8_t)(x->min_ratio <= a->def.coapt_ratio);
        if (v != SC_ASSESS_ARTERY && held > r->venous_force_max_n) {
            r->venous_force_max_n = held;
        }
        /* The artery counts as compressed when it is held below the limit for
         * min_view_frames (0.1 s) in a row, the same span that makes a vessel count as imaged:
         * a single frame's dip (the pulse's diastolic trough as the press lands) is not a
         * trainee squeezing the artery. */
        if (v == SC_ASSESS_ARTERY) {
            if (ratio < a->def.artery_min_ratio) {
                if (a->artery_low_frames < UINT32_MAX) {
                    a->artery_low_frames++;
                }
                if (a->artery_low_frames >= a->def.min_view_frames) {
                    r->artery_over = 1u;
                }
            } else {
                a->artery_low_frames = 0u;
            }
        }
    }
    sc_assess_score(&a->def, r);
}

void sc_assess_score(const sc_assess_def *def, sc_assess_report *r)
{
    const sc_assess_vessel_rec *vein = &r->vessel[SC_ASSESS_VEIN];
    const sc_assess_vessel_rec *thr = &r->vessel[SC_ASSESS_THROMBUS];
    const int imaged = vein->frames_in_view >= def->min_view_frames ||
                       thr->frames_in_view >= def->min_view_frames;
    uint8_t met[SC_ASSESS_CRITERIA];
    met[SC_ASSESS_CRIT_VEIN_IMAGED] = (uint8_t)imaged;
    met[SC_ASSESS_CRIT_COMPRESSED] =
        (uint8_t)(imaged && (vein->coapted || r->venous_force_max_n >= def->firm_force_n));
    met[SC_ASSESS_CRIT_ARTERY_SPARED] = (uint8_t)(imaged && !r->artery_over);
    met[SC_ASSESS_CRIT_FORCE_SAFE] = (uint8_t)(imaged && r->peak_force_n <= def->force_max_n);
    met[SC_ASSESS_CRIT_CALL_CORRECT] =
        (uint8_t)(r->call != SC_ASSESS_CALL_NONE && r->call == r->finding);
    met[SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE] = (uint8_t)(imaged && r->artery_punctures == 0u);
    uint32_t score = 0, max = 0;
    uint8_t bits = 0;
    for (uint32_t c = 0; c < SC_ASSESS_CRITERIA; c++) {
        if (c < SC_ASSESS_CRITERIA_R0) {
            r->points[c] = def->points[c];
        } else {
            r->puncture_points = def->points[c];
        }
        max += def->points[c];
        if (met[c]) {
            bits = (uint8_t)(bits | (1u << c));
            score += def->points[c];
        }
    }
    r->criteria_met = bits;
    r->score = (uint8_t)score; /* <= 255: checked by sc_assess_def_validate */
    r->score_max = (uint8_t)max;
}

uint8_t sc_assess_report_points(const sc_assess_report *r, uint32_t c)
{
    if (c < SC_ASSESS_CRITERIA_R0) {
        return r->points[c];
    }
    return c == (uint32_t)SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE ? r->puncture_points : 0u;
}

const sc_assess_report *sc_assess_get(const sc_assess *a)
{
    return &a->r;
}

void sc_assess_to_msg(const sc_assess_report *r, sc_assess_msg *out)
{
    memset(out, 0, sizeof(*out));
    for (uint32_t v = 0; v < SC_ASSESS_VESSELS; v++) {
        out->min_ratio[v] = r->vessel[v].min_ratio;
        out->force_at_min_n[v] = r->vessel[v].force_at_min_n;
        out->coapted[v] = r->vessel[v].coapted;
    }
    out->peak_force_n = r->peak_force_n;
    out->artery_over = r->artery_over;
    out->call = r->call;
    out->finding = r->finding;
    out->criteria_met = r->criteria_met;
    out->score = r->score;
    out->score_max = r->score_max;
    out->artery_punctured = r->artery_punctures != 0u ? 1u : 0u;
    out->vein_punctured = r->vein_punctures != 0u ? 1u : 0u;
}

const char *sc_assess_criterion_name(sc_assess_criterion c)
{
    switch (c) {
    case SC_ASSESS_CRIT_VEIN_IMAGED:
        return "vein_imaged";
    case SC_ASSESS_CRIT_COMPRESSED:
        return "compressed";
    case SC_ASSESS_CRIT_ARTERY_SPARED:
        return "artery_spared";
    case SC_ASSESS_CRIT_FORCE_SAFE:
        return "force_safe";
    case SC_ASSESS_CRIT_CALL_CORRECT:
        return "call_correct";
    case SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE:
        return "no_artery_puncture";
    case SC_ASSESS_CRITERIA:
        break;
    }
    return "?";
}
