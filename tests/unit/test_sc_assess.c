/* test_sc_assess.c: the compression exam's assessment (core/imaging/sc_assess.h): the record
 * it keeps frame by frame and the scoring, one criterion per test where it can be. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_assess.h"
#include "sc_err.h"
#include "sc_labels.h"

static sc_assess a;

static int setup(void **state)
{
    (void)state;
    const sc_assess_def d = sc_assess_default_def();
    return sc_assess_init(&a, &d);
}

static void frame(uint8_t contact, float vein, float artery, float thrombus, float force)
{
    const sc_assess_in in = {.contact = contact, .area_ratio = {vein, artery, thrombus},
                             .force_n = force};
    sc_assess_update(&a, &in);
}

static int met(sc_assess_criterion c)
{
    return (sc_assess_get(&a)->criteria_met >> (unsigned)c) & 1u;
}

static void defaults_are_valid_and_bad_definitions_are_refused(void **state)
{
    (void)state;
    sc_assess_def d = sc_assess_default_def();
    assert_int_equal(sc_assess_def_validate(&d), SC_OK);
    assert_int_equal(sc_assess_def_validate(NULL), SC_ERR_INVALID_ARG);
    d.coapt_ratio = NAN;
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_NOT_FINITE);
    d = sc_assess_default_def();
    d.coapt_ratio = 0.0f;
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_RANGE);
    d = sc_assess_default_def();
    d.artery_min_ratio = 1.5f;
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_RANGE);
    d = sc_assess_default_def();
    d.force_max_n = d.firm_force_n * 0.5f;
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_RANGE);
    d = sc_assess_default_def();
    memset(d.points, 200, sizeof d.points); /* 1200 points do not fit the score */
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_RANGE);
    sc_assess x;
    assert_int_equal(sc_assess_init(&x, &d), SC_ERR_RANGE);
}

static void an_empty_exam_scores_nothing_and_says_not_available(void **state)
{
    (void)state;
    const sc_assess_report *r = sc_assess_get(&a);
    assert_int_equal(r->version, SC_ASSESS_REPORT_VERSION);
    assert_int_equal(r->score, 0);
    assert_int_equal(r->score_max, 10);
    assert_int_equal(r->revision, SC_ASSESS_REPORT_REVISION);
    assert_int_equal(r->criteria_met, 0);
    for (int v = 0; v < (int)SC_ASSESS_VESSELS; v++) {
        assert_true(r->vessel[v].min_ratio < 0.0f);
        assert_true(r->vessel[v].force_at_min_n < 0.0f);
    }
    assert_true(r->peak_force_n < 0.0f);
    /* frames without contact count as frames, nothing else */
    for (int i = 0; i < 10; i++) {
        frame(0u, 0.01f, 0.2f, -1.0f, 30.0f);
    }
    assert_int_equal(r->frames, 10);
    assert_int_equal(r->contact_frames, 0);
    assert_true(r->vessel[SC_ASSESS_VEIN].min_ratio < 0.0f);
    assert_int_equal(r->score, 0);
}

static void the_deepest_compression_and_its_force_are_kept(void **state)
{
    (void)state;
    const float veins[6] = {0.9f, 0.6f, 0.3f, 0.12f, 0.2f, 0.5f};
    const float forces[6] = {1.0f, 3.0f, 6.0f, 9.0f, 7.0f, 2.0f};
    for (int i = 0; i < 6; i++) {
        frame(1u, veins[i], 0.95f, -1.0f, forces[i]);
    }
    const sc_assess_report *r = sc_assess_get(&a);
    assert_float_equal(r->vessel[SC_ASSESS_VEIN].min_ratio, 0.12f, 0.0f);
    assert_float_equal(r->vessel[SC_ASSESS_VEIN].force_at_min_n, 9.0f, 0.0f);
    assert_int_equal(r->vessel[SC_ASSESS_VEIN].min_frame, 3);
    assert_int_equal(r->vessel[SC_ASSESS_VEIN].frames_in_view, 6);
    assert_int_equal(r->vessel[SC_ASSESS_VEIN].coapted, 0);
    /* the peak is the force held for min_view_frames (6) frames: their least, 1 N here */
    assert_float_equal(r->peak_force_n, 1.0f, 0.0f);
    assert_float_equal(r->venous_force_max_n, 1.0f, 0.0f);
    assert_true(r->vessel[SC_ASSESS_THROMBUS].min_ratio < 0.0f);
    /* non-finite inputs are "not available", never a minimum, and break the hold */
    frame(1u, NAN, INFINITY, NAN, NAN);
    assert_float_equal(r->vessel[SC_ASSESS_VEIN].min_ratio, 0.12f, 0.0f);
    assert_float_equal(r->peak_force_n, 1.0f, 0.0f);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.5f, 0.95f, -1.0f, 20.0f);
    }
    assert_float_equal(r->peak_force_n, 1.0f, 0.0f); /* five frames since the gap */
    frame(1u, 0.5f, 0.95f, -1.0f, 20.0f);
    assert_float_equal(r->peak_force_n, 20.0f, 0.0f);
}

static void the_peak_force_is_held_and_a_transient_is_not(void **state)
{
    (void)state;
    const sc_assess_report *r = sc_assess_get(&a);
    /* a press ramping to 12 N and held, with a two-frame transient of 80 N on the way (what
     * the implicit step's truncated solve gives as a large mesh's contact grows) */
    const float forces[12] = {2.0f, 4.0f, 6.0f, 80.0f, 80.0f, 8.0f,
                              10.0f, 12.0f, 12.0f, 12.0f, 12.0f, 12.0f};
    for (int i = 0; i < 12; i++) {
        frame(1u, 0.4f, 0.95f, -1.0f, forces[i]);
    }
    assert_float_equal(r->peak_force_n, 10.0f, 0.0f); /* the last six: 10 to 12 N */
    assert_true(met(SC_ASSESS_CRIT_FORCE_SAFE));
    frame(1u, 0.4f, 0.95f, -1.0f, 12.0f);
    assert_float_equal(r->peak_force_n, 12.0f, 0.0f);
    /* a lift ends the hold: five frames at 50 N before it and five after hold nothing (the
     * window's last six before the lift still had a 12 N frame) */
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.4f, 0.95f, -1.0f, 50.0f);
    }
    assert_float_equal(r->peak_force_n, 12.0f, 0.0f);
    frame(0u, -1.0f, -1.0f, -1.0f, 0.0f);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.4f, 0.95f, -1.0f, 50.0f);
        assert_float_equal(r->peak_force_n, 12.0f, 0.0f);
    }
    frame(1u, 0.4f, 0.95f, -1.0f, 50.0f);
    assert_float_equal(r->peak_force_n, 50.0f, 0.0f);
    /* so do a reset and a case swap */
    sc_assess_reset(&a);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.4f, 0.95f, -1.0f, 30.0f);
    }
    assert_true(r->peak_force_n < 0.0f);
    assert_int_equal(sc_assess_begin_case(&a, SC_ASSESS_CALL_NORMAL), SC_OK);
    frame(1u, 0.4f, 0.95f, -1.0f, 30.0f);
    assert_true(r->peak_force_n < 0.0f);
    /* min_view_frames 1 (or 0): every frame's force is held */
    sc_assess_def d = sc_assess_default_def();
    d.min_view_frames = 0u;
    sc_assess x;
    assert_int_equal(sc_assess_init(&x, &d), SC_OK);
    const sc_assess_in in = {.contact = 1u, .area_ratio = {0.5f, 0.95f, -1.0f}, .force_n = 7.0f};
    sc_assess_update(&x, &in);
    assert_float_equal(sc_assess_get(&x)->peak_force_n, 7.0f, 0.0f);
    /* the window's limit, run: held after its 255th frame, the least of them */
    d.min_view_frames = SC_ASSESS_HOLD_MAX;
    assert_int_equal(sc_assess_def_validate(&d), SC_OK);
    assert_int_equal(sc_assess_init(&x, &d), SC_OK);
    for (uint32_t i = 0; i < SC_ASSESS_HOLD_MAX; i++) {
        assert_true(sc_assess_get(&x)->peak_force_n < 0.0f);
        const sc_assess_in w = {.contact = 1u, .area_ratio = {0.5f, 0.95f, -1.0f},
                                .force_n = 20.0f + (float)(i % 7u)};
        sc_assess_update(&x, &w);
    }
    assert_float_equal(sc_assess_get(&x)->peak_force_n, 20.0f, 0.0f);
    d.min_view_frames = SC_ASSESS_HOLD_MAX + 1u;
    assert_int_equal(sc_assess_def_validate(&d), SC_ERR_RANGE);
}

static void the_vein_imaged_criterion_needs_min_view_frames(void **state)
{
    (void)state;
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.9f, 1.0f, -1.0f, 1.0f);
    }
    assert_false(met(SC_ASSESS_CRIT_VEIN_IMAGED));
    frame(1u, 0.9f, 1.0f, -1.0f, 1.0f);
    assert_true(met(SC_ASSESS_CRIT_VEIN_IMAGED));
    /* imaged, artery spared, force safe, no arterial puncture */
    assert_int_equal(sc_assess_get(&a)->score, 1 + 1 + 1 + 2);
}

static void coaptation_meets_the_compression_criterion(void **state)
{
    (void)state;
    for (int i = 0; i < 6; i++) {
        frame(1u, 0.5f, 1.0f, -1.0f, 2.0f);
    }
    assert_false(met(SC_ASSESS_CRIT_COMPRESSED));
    frame(1u, 0.05f, 0.98f, -1.0f, 5.0f); /* at the threshold: coapted */
    assert_int_equal(sc_assess_get(&a)->vessel[SC_ASSESS_VEIN].coapted, 1);
    assert_true(met(SC_ASSESS_CRIT_COMPRESSED));
}

static void a_firm_press_that_does_not_coapt_meets_the_compression_criterion(void **state)
{
    (void)state;
    const sc_assess_def d = sc_assess_default_def();
    for (int i = 0; i < 6; i++) {
        frame(1u, 0.6f, 0.95f, 0.9f, d.firm_force_n * 0.9f);
    }
    assert_false(met(SC_ASSESS_CRIT_COMPRESSED));
    /* held for min_view_frames (6): five frames at the firm force are not a firm press */
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.6f, 0.95f, 0.85f, d.firm_force_n);
    }
    assert_false(met(SC_ASSESS_CRIT_COMPRESSED));
    frame(1u, 0.6f, 0.95f, 0.85f, d.firm_force_n);
    assert_true(met(SC_ASSESS_CRIT_COMPRESSED));
    assert_int_equal(sc_assess_get(&a)->vessel[SC_ASSESS_THROMBUS].coapted, 0);
    /* a firm press with only the artery in view does not count */
    sc_assess_reset(&a);
    for (int i = 0; i < 10; i++) {
        frame(1u, -1.0f, 0.95f, -1.0f, d.firm_force_n * 3.0f);
    }
    assert_false(met(SC_ASSESS_CRIT_COMPRESSED));
    assert_false(met(SC_ASSESS_CRIT_VEIN_IMAGED));
}

static void compressing_the_artery_below_its_limit_loses_the_artery_criterion(void **state)
{
    (void)state;
    for (int i = 0; i < 6; i++) {
        frame(1u, 0.3f, 0.76f, -1.0f, 5.0f);
    }
    assert_true(met(SC_ASSESS_CRIT_ARTERY_SPARED));
    /* held below the limit for min_view_frames (6) frames in a row: one short of it, with the
     * run broken by a frame above, a lift or the artery out of view, is not a compression */
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.2f, 0.74f, -1.0f, 6.0f);
    }
    frame(1u, 0.2f, 0.76f, -1.0f, 6.0f);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.2f, 0.74f, -1.0f, 6.0f);
    }
    frame(0u, -1.0f, -1.0f, -1.0f, 0.0f);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.2f, 0.74f, -1.0f, 6.0f);
    }
    frame(1u, 0.2f, -1.0f, -1.0f, 6.0f);
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.2f, 0.74f, -1.0f, 6.0f);
    }
    assert_int_equal(sc_assess_get(&a)->artery_over, 0);
    assert_true(met(SC_ASSESS_CRIT_ARTERY_SPARED));
    frame(1u, 0.2f, 0.74f, -1.0f, 6.0f);
    assert_int_equal(sc_assess_get(&a)->artery_over, 1);
    assert_false(met(SC_ASSESS_CRIT_ARTERY_SPARED));
    /* and it stays lost when the artery recovers */
    frame(1u, 0.2f, 1.0f, -1.0f, 1.0f);
    assert_false(met(SC_ASSESS_CRIT_ARTERY_SPARED));
}

static void an_unsafe_force_loses_the_force_criterion(void **state)
{
    (void)state;
    const sc_assess_def d = sc_assess_default_def();
    for (int i = 0; i < 6; i++) {
        frame(1u, 0.3f, 0.9f, -1.0f, d.force_max_n);
    }
    assert_true(met(SC_ASSESS_CRIT_FORCE_SAFE));
    /* over it for five frames (one short of min_view_frames): a transient, still safe */
    for (int i = 0; i < 5; i++) {
        frame(1u, 0.3f, 0.9f, -1.0f, d.force_max_n + 0.5f);
    }
    assert_true(met(SC_ASSESS_CRIT_FORCE_SAFE));
    frame(1u, 0.3f, 0.9f, -1.0f, d.force_max_n + 0.5f);
    assert_false(met(SC_ASSESS_CRIT_FORCE_SAFE));
}

static void the_call_scores_when_it_matches_the_finding_and_the_last_call_counts(void **state)
{
    (void)state;
    assert_int_equal(sc_assess_begin_case(&a, SC_ASSESS_CALL_DVT), SC_OK);
    assert_false(met(SC_ASSESS_CRIT_CALL_CORRECT));
    assert_int_equal(sc_assess_set_call(&a, SC_ASSESS_CALL_DVT), SC_OK);
    assert_true(met(SC_ASSESS_CRIT_CALL_CORRECT));
    assert_int_equal(sc_assess_get(&a)->score, 3);
    assert_int_equal(sc_assess_set_call(&a, SC_ASSESS_CALL_NORMAL), SC_OK);
    assert_false(met(SC_ASSESS_CRIT_CALL_CORRECT));
    assert_int_equal(sc_assess_get(&a)->calls, 2);
    /* bad values: refused, nothing changed */
    assert_int_equal(sc_assess_set_call(&a, SC_ASSESS_CALL_NONE), SC_ERR_RANGE);
    assert_int_equal(sc_assess_set_call(&a, 7u), SC_ERR_RANGE);
    assert_int_equal(sc_assess_get(&a)->call, SC_ASSESS_CALL_NORMAL);
    assert_int_equal(sc_assess_begin_case(&a, 0u), SC_ERR_RANGE);
    assert_int_equal(sc_assess_get(&a)->finding, SC_ASSESS_CALL_DVT);
}

static void a_full_normal_exam_scores_every_point_and_reset_clears_it(void **state)
{
    (void)state;
    assert_int_equal(sc_assess_begin_case(&a, SC_ASSESS_CALL_NORMAL), SC_OK);
    for (int i = 0; i < 30; i++) {
        const float vein = 1.0f - 0.04f * (float)i;
        frame(1u, vein > 0.0f ? vein : 0.0f, 0.9f, -1.0f, 0.5f * (float)i);
    }
    assert_int_equal(sc_assess_set_call(&a, SC_ASSESS_CALL_NORMAL), SC_OK);
    const sc_assess_report *r = sc_assess_get(&a);
    assert_int_equal(r->criteria_met, 0x3F);
    assert_int_equal(r->score, r->score_max);
    uint32_t sum = 0;
    for (int c = 0; c < (int)SC_ASSESS_CRITERIA; c++) {
        sum += sc_assess_report_points(r, (uint32_t)c);
    }
    assert_int_equal(sc_assess_report_points(r, SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE), 2);
    assert_int_equal(sc_assess_report_points(r, 99u), 0);
    assert_int_equal(sum, r->score_max);
    /* the CAN message carries the same */
    sc_assess_msg m;
    sc_assess_to_msg(r, &m);
    assert_int_equal(m.score, r->score);
    assert_int_equal(m.criteria_met, r->criteria_met);
    assert_int_equal(m.coapted[SC_ASSESS_VEIN], 1);
    assert_float_equal(m.peak_force_n, r->peak_force_n, 0.0f);
    /* reset: the exam and the call go, the finding stays, resets counted */
    sc_assess_reset(&a);
    assert_int_equal(r->score, 0);
    assert_int_equal(r->frames, 0);
    assert_int_equal(r->call, SC_ASSESS_CALL_NONE);
    assert_int_equal(r->finding, SC_ASSESS_CALL_NORMAL);
    assert_int_equal(r->resets, 1);
    assert_string_equal(sc_assess_criterion_name(SC_ASSESS_CRIT_CALL_CORRECT), "call_correct");
    assert_string_equal(sc_assess_criterion_name(SC_ASSESS_CRITERIA), "?");
}

static void puncture(uint8_t label)
{
    const sc_assess_in in = {.contact = 0u, .area_ratio = {-1.0f, -1.0f, -1.0f},
                             .force_n = -1.0f, .puncture = label};
    sc_assess_update(&a, &in);
}

/* issue 18 item 3: an arterial puncture is a fault of the exam; a vein puncture is not */
static void arterial_puncture_fails_its_criterion_vein_puncture_does_not(void **state)
{
    (void)state;
    assert_int_equal(sc_assess_begin_case(&a, SC_ASSESS_CALL_NORMAL), SC_OK);
    for (int i = 0; i < 10; i++) {
        frame(1u, 0.9f, 0.95f, -1.0f, 2.0f);
    }
    const sc_assess_report *r = sc_assess_get(&a);
    assert_true(met(SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE)); /* imaged, no puncture */
    const uint8_t before = r->score;
    puncture((uint8_t)SC_LABEL_VEIN);
    assert_int_equal(r->vein_punctures, 1);
    assert_int_equal(r->artery_punctures, 0);
    assert_true(met(SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE));
    assert_int_equal(r->score, before);
    puncture((uint8_t)SC_LABEL_ARTERY);
    assert_int_equal(r->artery_punctures, 1);
    assert_false(met(SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE));
    assert_int_equal(r->score, before - 2);
    /* another label or none is not a puncture; the count saturates */
    puncture((uint8_t)SC_LABEL_MUSCLE);
    puncture(0u);
    assert_int_equal(r->artery_punctures, 1);
    assert_int_equal(r->vein_punctures, 1);
    for (int i = 0; i < 300; i++) {
        puncture((uint8_t)SC_LABEL_ARTERY);
    }
    assert_int_equal(r->artery_punctures, 255);
    sc_assess_msg m;
    sc_assess_to_msg(r, &m);
    assert_int_equal(m.artery_punctured, 1);
    assert_int_equal(m.vein_punctured, 1);
    assert_int_equal(m.criteria_met & (1u << SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE), 0);
    /* the reset forgets the punctures */
    sc_assess_reset(&a);
    assert_int_equal(r->artery_punctures, 0);
    assert_int_equal(r->vein_punctures, 0);
    assert_string_equal(sc_assess_criterion_name(SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE),
                        "no_artery_puncture");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(defaults_are_valid_and_bad_definitions_are_refused, setup),
        cmocka_unit_test_setup(arterial_puncture_fails_its_criterion_vein_puncture_does_not,
                               setup),
        cmocka_unit_test_setup(an_empty_exam_scores_nothing_and_says_not_available, setup),
        cmocka_unit_test_setup(the_deepest_compression_and_its_force_are_kept, setup),
        cmocka_unit_test_setup(the_peak_force_is_held_and_a_transient_is_not, setup),
        cmocka_unit_test_setup(the_vein_imaged_criterion_needs_min_view_frames, setup),
        cmocka_unit_test_setup(coaptation_meets_the_compression_criterion, setup),
        cmocka_unit_test_setup(a_firm_press_that_does_not_coapt_meets_the_compression_criterion,
                               setup),
        cmocka_unit_test_setup(compressing_the_artery_below_its_limit_loses_the_artery_criterion,
                               setup),
        cmocka_unit_test_setup(an_unsafe_force_loses_the_force_criterion, setup),
        cmocka_unit_test_setup(the_call_scores_when_it_matches_the_finding_and_the_last_call_counts,
                               setup),
        cmocka_unit_test_setup(a_full_normal_exam_scores_every_point_and_reset_clears_it, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
