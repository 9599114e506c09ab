/* test_needle_engine.c: the tracked needle through the whole engine on the host simulator: the
 * tracker emulator's needle frames on the simulated bus, the engine's receiver, the needle in
 * the image, and the puncture reports that leave on CAN (NeedleStatus, 0x220): a vein entered
 * twice is reported twice, each entry once, and no artery. The assessment (issue 18 item 3):
 * a needle into the artery is a fault of the exam, counted once, in the record and on CAN
 * (AssessScore's ArteryPunctured, criterion 5 not met); into the vein, none. Deterministic
 * (virtual clock). */
#include "sc_test.h"

#include <math.h>
#include <stdlib.h>

#include "sc_canproto.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_test_block_rig.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_emu_needle needle;

typedef struct needle_seen {
    uint32_t status_frames;
    sc_needle_status_msg last;
    uint32_t score_frames; /* AssessScore frames read back */
    sc_assess_msg assess;  /* their last content */
    uint32_t max_drawn;
    uint32_t max_tip_contacts; /* tissue nodes the tip pushed */
    float max_moved_mm;        /* largest node displacement seen (the probe only hovers) */
} needle_seen;

/* n frames; probe and needle samples due before each frame go on the bus, the engine's
 * NeedleStatus frames are read back by the peer */
static sc_test_feed feed;

static void run(uint32_t n, needle_seen *seen)
{
    for (uint32_t i = 0; i < n; i++) {
        sc_test_feed_due(&feed, &rig, sc_engine_next_release_ns(&rig.engine));
        sc_engine_step(&rig.engine, NULL);
        const sc_needle_status *ns = sc_engine_get_needle_status(&rig.engine);
        if (getenv("NEEDLE_TRACE") && i % 10u == 0u) {
            print_message("t %.2f present %u tip %u (deformed %u) depth %.1f rej %u\n",
                          (double)(rig.clock.now_ns - feed.t0_ns) * 1e-9, ns->present,
                          ns->tip_label, ns->tip_label_deformed, (double)rig.engine.needle.depth_mm,
                          rig.engine.needle_rx.rejected);
        }
        seen->max_drawn = ns->drawn_pixels > seen->max_drawn ? ns->drawn_pixels : seen->max_drawn;
        const uint32_t tc = rig.engine.tissue[rig.engine.active].tip_contacts;
        seen->max_tip_contacts = tc > seen->max_tip_contacts ? tc : seen->max_tip_contacts;
        if (tc > 0u) {
            const sc_tissue *tt = &rig.engine.tissue[rig.engine.active];
            for (uint32_t k = 0; k < tt->mesh.node_count; k++) {
                const float ux = tt->nodes.x[k] - tt->mesh.rest_x[k];
                const float uy = tt->nodes.y[k] - tt->mesh.rest_y[k];
                const float uz = tt->nodes.z[k] - tt->mesh.rest_z[k];
                seen->max_moved_mm = fmaxf(seen->max_moved_mm, sqrtf(ux * ux + uy * uy + uz * uz));
            }
        }
        sc_can_frame r;
        while (sc_can_recv(&rig.peer, &r) == SC_OK) {
            if (r.id == SC_CANID_NEEDLE_STATUS) {
                assert_int_equal(sc_canproto_decode_needle_status(&r, &seen->last), SC_OK);
                assert_int_equal(sc_e2e_crc(SC_CANID_NEEDLE_STATUS, r.data, r.len), r.data[0]);
                seen->status_frames++;
            } else if (r.id == SC_CANID_ASSESS_SCORE) {
                assert_int_equal(sc_canproto_decode_assess_part(&r, &seen->assess), SC_OK);
                seen->score_frames++;
            }
        }
    }
}

static void a_needle_into_the_vein_is_reported_once_per_entry_on_can(void **state)
{
    (void)state;
    sc_test_block_rig_up(&rig, &sc_test_block, 7, 0);
    /* the probe rests lightly over the block's middle (its plane holds both vessels) */
    const sc_emu_def pd = sc_test_block_probe_def(&sc_test_block, 1.0f, 0.0f);
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    /* the needle in the image plane, from 8 mm beside the vein toward its axis (8 mm across,
     * 10 mm down; tracker frame: (x, -y, -z) of the volume), 14 mm deep at most */
    const sc_emu_needle_def nd = sc_test_block_needle_def(
        &sc_test_block, sc_test_block.vein_tracker_mm[0] - 8.0f, 8.0f, 1.0);
    assert_int_equal(sc_emu_needle_init(&needle, &nd), SC_OK);
    sc_test_feed_start(&feed, &rig, &emu, &needle);
    needle_seen seen = {0};
    run(180, &seen); /* 3 s: in (the wall at about 1.5 s), held */
    print_message("after 3 s: %u status frames, vein %u artery %u last %u tip %u, drawn %u px\n",
                  seen.status_frames, seen.last.vein_punctures, seen.last.artery_punctures,
                  seen.last.last_puncture, seen.last.tip_vessel, seen.max_drawn);
    assert_true(seen.status_frames >= 25u);
    assert_int_equal(seen.last.vein_punctures, 1u);
    assert_int_equal(seen.last.artery_punctures, 0u);
    assert_int_equal(seen.last.last_puncture, SC_LABEL_VEIN);
    assert_int_equal(seen.last.tip_vessel, SC_LABEL_VEIN);
    assert_int_equal(seen.last.needle_tracked, 1u);
    assert_int_equal(seen.last.needle_rejected, 0u);
    assert_true(seen.max_drawn > 20u); /* the shaft is in the image */
    /* the tip pushed tissue: nodes near it held on its sphere, moved from rest */
    {
        const sc_tissue *t = &rig.engine.tissue[rig.engine.active];
        const float *tip = rig.engine.needle.tip_mm;
        float moved = 0.0f;
        for (uint32_t i = 0; i < t->mesh.node_count; i++) {
            const float dx = t->nodes.x[i] - tip[0], dy = t->nodes.y[i] - tip[1],
                        dz = t->nodes.z[i] - tip[2];
            if (dx * dx + dy * dy + dz * dz < 3.0f * 3.0f) { /* the 2.2 mm tip sphere and beyond */
                const float ux = t->nodes.x[i] - t->mesh.rest_x[i];
                const float uy = t->nodes.y[i] - t->mesh.rest_y[i];
                const float uz = t->nodes.z[i] - t->mesh.rest_z[i];
                moved = fmaxf(moved, sqrtf(ux * ux + uy * uy + uz * uz));
            }
        }
        print_message("tip contacts up to %u, nodes moved up to %.2f mm while pushed (%.2f mm "
                      "near the held tip now)\n",
                      seen.max_tip_contacts, (double)seen.max_moved_mm, (double)moved);
        assert_true(seen.max_tip_contacts > 0u);
        assert_true(seen.max_moved_mm > 0.1f); /* the probe hovers: only the tip moves them */
    }
    run(180, &seen); /* out (3.3 .. 4.7 s) and in again */
    print_message("after 6 s: vein %u artery %u\n", seen.last.vein_punctures,
                  seen.last.artery_punctures);
    assert_int_equal(seen.last.vein_punctures, 2u);
    assert_int_equal(seen.last.artery_punctures, 0u);
    assert_int_equal(sc_engine_get_needle_status(&rig.engine)->vein_punctures, 2u);
    /* the assessment: two vein entries, no fault */
    const sc_assess_report *ar = sc_engine_assessment(&rig.engine);
    print_message("assessment: vein %u artery %u punctures, criteria 0x%02x, score %u/%u\n",
                  ar->vein_punctures, ar->artery_punctures, ar->criteria_met, ar->score,
                  ar->score_max);
    assert_int_equal(ar->vein_punctures, 2u);
    assert_int_equal(ar->artery_punctures, 0u);
    assert_true(ar->criteria_met & (1u << SC_ASSESS_CRIT_VEIN_IMAGED));
    assert_true(ar->criteria_met & (1u << SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE));
    assert_true(seen.score_frames > 0u);
    assert_int_equal(seen.assess.artery_punctured, 0u);
    assert_int_equal(seen.assess.vein_punctured, 1u);
    assert_int_equal(seen.assess.criteria_met, ar->criteria_met);
}

/* The same needle path mirrored onto the artery: one arterial puncture, the exam's fault. */
static void a_needle_into_the_artery_is_a_fault_of_the_exam_once(void **state)
{
    (void)state;
    sc_test_block_rig_up(&rig, &sc_test_block, 7, 0);
    const sc_emu_def pd = sc_test_block_probe_def(&sc_test_block, 1.0f, 0.0f);
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    /* from 8 mm beyond the artery (away from the vein) toward its axis, 14 mm deep at most */
    const sc_emu_needle_def nd = sc_test_block_needle_def(
        &sc_test_block, sc_test_block.scene.p.artery_x_mm + 8.0f, -8.0f, 1.0);
    assert_int_equal(sc_emu_needle_init(&needle, &nd), SC_OK);
    sc_test_feed_start(&feed, &rig, &emu, &needle);
    needle_seen seen = {0};
    run(180, &seen); /* 3 s: in and held in the artery */
    const sc_assess_report *ar = sc_engine_assessment(&rig.engine);
    print_message("artery: needle status vein %u artery %u last %u; assessment artery %u vein %u, "
                  "criteria 0x%02x, score %u/%u\n",
                  seen.last.vein_punctures, seen.last.artery_punctures, seen.last.last_puncture,
                  ar->artery_punctures, ar->vein_punctures, ar->criteria_met, ar->score,
                  ar->score_max);
    assert_int_equal(seen.last.artery_punctures, 1u);
    assert_int_equal(seen.last.vein_punctures, 0u);
    assert_int_equal(ar->artery_punctures, 1u); /* once, although the tip stays in */
    assert_int_equal(ar->vein_punctures, 0u);
    assert_false(ar->criteria_met & (1u << SC_ASSESS_CRIT_NO_ARTERY_PUNCTURE));
    assert_true(ar->score + ar->puncture_points <= ar->score_max);
    assert_true(seen.score_frames > 0u);
    assert_int_equal(seen.assess.artery_punctured, 1u);
    assert_int_equal(seen.assess.criteria_met, ar->criteria_met);
    assert_int_equal(seen.assess.score, ar->score);
    /* the assessment's reset forgets the fault; the needle's own counters stay */
    sc_assess_reset(&rig.engine.assess);
    assert_int_equal(sc_engine_assessment(&rig.engine)->artery_punctures, 0u);
    run(30, &seen); /* held in the lumen: no new entry, no new fault */
    assert_int_equal(sc_engine_assessment(&rig.engine)->artery_punctures, 0u);
    assert_int_equal(sc_engine_get_needle_status(&rig.engine)->artery_punctures, 1u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_needle_into_the_vein_is_reported_once_per_entry_on_can),
        cmocka_unit_test(a_needle_into_the_artery_is_a_fault_of_the_exam_once),
    };
    return cmocka_run_group_tests(tests, sc_test_block_group_setup, sc_test_block_group_teardown);
}
