/*
 * test_assess.c: the compression exam's assessment (core/imaging/sc_assess.h) from the whole
 * engine on the host simulator, on the phantom cases the `cases` target builds: the tracker
 * emulator's press script over the vessels, the trainee's call and the reset as authenticated
 * CAN commands (CmdAssessment), and the assessment read both through sc_engine_assessment()
 * and from the engine's AssessVessels / AssessForce / AssessScore frames on the bus.
 *   - neck-ijv, a press that coapts the vein: the coaptation criterion is scored, the artery
 *     is spared, the force at the deepest compression is available and positive;
 *   - femoral-dvt, the same press: the thrombosed vein does not coapt, the call DVT scores the
 *     call criterion, a call "normal" then loses it, the reset clears the exam.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_assess.h"
#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_storage_linux.h"
#include "sc_test_cmd.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
static uint64_t t0_ns;         /* the rig's clock when the emulator's script starts */
static sc_assess_msg on_bus;   /* the assessment as decoded from the engine's frames */
static uint32_t bus_parts;     /* bit per assessment frame seen since the last clear */

static void rig_up(const char *case_file)
{
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    def.case_names[0] = case_file;
    def.case_count = 1u;
    assert_int_equal(sc_hs_rig_init(&rig, &def, 1u, 0), SC_OK);
    sc_storage_linux_init(&storage, SC_BINARY_DIR "/cases");
    rig.hal.storage = sc_storage_linux_dev(&storage);
    const int rc = sc_engine_load_case(&rig.engine, case_file);
    if (rc != SC_OK) {
        print_message("case %s/cases/%s: %s (build the `cases` target)\n", SC_BINARY_DIR,
                      case_file, sc_err_str(rc));
    }
    assert_int_equal(rc, SC_OK);
    /* the press script over the top centre of the mesh box (the phantoms centre their
     * vessels under it), 16 mm deep: hover 0.5 s, descend 1 s, hold 1 s, rise 1 s */
    const sc_case *cs = sc_engine_get_case(&rig.engine);
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_emu_def ed = sc_emu_default_def();
    sc_xform_apply(&v2t, p_vol, ed.point_mm);
    ed.depth_mm = 16.0f;
    ed.duration_s = 60.0;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    memset(&on_bus, 0, sizeof on_bus);
    bus_parts = 0;
    t0_ns = rig.clock.now_ns;
}

static int send_peer(void *ctx, const sc_can_frame *f)
{
    return sc_can_send((const sc_can_dev *)ctx, f);
}

/* What the peer node received from the engine: the assessment frames, CRC checked, decoded. */
static void drain_peer(void)
{
    sc_can_frame f;
    while (sc_can_recv(&rig.peer, &f) == SC_OK) {
        sc_msg m;
        if (sc_canproto_classify(&f, &m) != SC_OK || m < SC_MSG_ASSESS_VESSELS ||
            m > SC_MSG_ASSESS_SCORE) {
            continue;
        }
        assert_int_equal(sc_e2e_crc(sc_canproto_info(m)->data_id, f.data, f.len), f.data[0]);
        assert_int_equal(sc_canproto_decode_assess_part(&f, &on_bus), SC_OK);
        bus_parts |= 1u << (unsigned)(m - SC_MSG_ASSESS_VESSELS);
    }
}

static void run_s(double seconds)
{
    const uint32_t n = (uint32_t)(seconds * rig.engine.def.sched.rate_hz);
    for (uint32_t i = 0; i < n; i++) {
        (void)sc_emu_feed(&emu, sc_engine_next_release_ns(&rig.engine) - t0_ns, send_peer,
                          &rig.peer);
        sc_engine_step(&rig.engine, NULL);
        drain_peer();
    }
}

static void send_assess(uint8_t action, uint8_t call)
{
    const sc_cmd c = {.kind = SC_CMD_ASSESS, .assess_action = action, .assess_call = call};
    assert_int_equal(sc_test_send_cmd(&rig.peer, &c), SC_OK);
    run_s(0.2); /* received, authenticated, applied, and a status period on the bus */
}

static void print_report(const char *what, const sc_assess_report *r)
{
    static const char *const names[SC_ASSESS_VESSELS] = {"vein", "artery", "thrombus"};
    print_message("%s: %u frames, %u in contact, peak force %.2f N, call %u, finding %u, "
                  "score %u/%u (criteria 0x%02x)\n",
                  what, r->frames, r->contact_frames, (double)r->peak_force_n, r->call,
                  r->finding, r->score, r->score_max, r->criteria_met);
    for (uint32_t v = 0; v < SC_ASSESS_VESSELS; v++) {
        print_message("  %-8s min ratio %6.3f (force there %6.2f N) coapted %u, %u frames in view\n",
                      names[v], (double)r->vessel[v].min_ratio,
                      (double)r->vessel[v].force_at_min_n, r->vessel[v].coapted,
                      r->vessel[v].frames_in_view);
    }
}

static int met(const sc_assess_report *r, sc_assess_criterion c)
{
    return (r->criteria_met >> (unsigned)c) & 1u;
}

static void neck_ijv_press_that_coapts_the_vein_scores_coaptation(void **state)
{
    (void)state;
    rig_up("neck-ijv.scase");
    run_s(3.0); /* hover, descend, hold at 16 mm */
    const sc_assess_report *r = sc_engine_assessment(&rig.engine);
    print_report("neck-ijv, 16 mm press", r);
    assert_int_equal(r->version, SC_ASSESS_REPORT_VERSION);
    assert_int_equal(r->finding, SC_ASSESS_CALL_NORMAL);
    assert_true(r->vessel[SC_ASSESS_VEIN].min_ratio >= 0.0f);
    assert_true(r->vessel[SC_ASSESS_VEIN].min_ratio <= 0.05f);
    assert_int_equal(r->vessel[SC_ASSESS_VEIN].coapted, 1);
    assert_true(r->vessel[SC_ASSESS_VEIN].force_at_min_n > 0.0f);
    /* the peak force is the force held 0.1 s (sc_assess.h), which need not reach the frame's
     * own force at the vein's minimum: a firm press and a safe one */
    const sc_assess_def d = sc_assess_default_def();
    assert_true(r->peak_force_n >= d.firm_force_n);
    assert_true(r->peak_force_n <= d.force_max_n);
    assert_int_equal(r->vessel[SC_ASSESS_ARTERY].coapted, 0);
    assert_int_equal(r->artery_over, 0);
    assert_true(met(r, SC_ASSESS_CRIT_VEIN_IMAGED));
    assert_true(met(r, SC_ASSESS_CRIT_COMPRESSED));
    assert_true(met(r, SC_ASSESS_CRIT_ARTERY_SPARED));
    assert_false(met(r, SC_ASSESS_CRIT_CALL_CORRECT)); /* no call yet */
    /* the call "normal" is right on this case */
    send_assess(SC_ASSESS_ACTION_CALL, SC_ASSESS_CALL_NORMAL);
    r = sc_engine_assessment(&rig.engine);
    assert_int_equal(r->call, SC_ASSESS_CALL_NORMAL);
    assert_true(met(r, SC_ASSESS_CRIT_CALL_CORRECT));
    /* the engine's frames on the bus say the same */
    assert_int_equal(bus_parts, 7u);
    assert_int_equal(on_bus.coapted[SC_ASSESS_VEIN], 1);
    assert_int_equal(on_bus.call, SC_ASSESS_CALL_NORMAL);
    assert_int_equal(on_bus.finding, SC_ASSESS_CALL_NORMAL);
    assert_int_equal(on_bus.criteria_met, r->criteria_met);
    assert_int_equal(on_bus.score, r->score);
    assert_int_equal(on_bus.score_max, r->score_max);
    assert_float_equal(on_bus.min_ratio[SC_ASSESS_VEIN], r->vessel[SC_ASSESS_VEIN].min_ratio,
                       0.0006f);
    assert_true(on_bus.min_ratio[SC_ASSESS_THROMBUS] < 0.0f); /* no thrombus in this case */
}

static void femoral_dvt_press_with_the_call_dvt_scores_the_call(void **state)
{
    (void)state;
    rig_up("femoral-dvt.scase");
    run_s(3.0);
    const sc_assess_report *r = sc_engine_assessment(&rig.engine);
    print_report("femoral-dvt, 16 mm press", r);
    assert_int_equal(r->finding, SC_ASSESS_CALL_DVT);
    assert_true(r->vessel[SC_ASSESS_THROMBUS].min_ratio > 0.5f); /* the thrombus holds */
    assert_int_equal(r->vessel[SC_ASSESS_THROMBUS].coapted, 0);
    assert_true(met(r, SC_ASSESS_CRIT_VEIN_IMAGED));
    assert_true(met(r, SC_ASSESS_CRIT_COMPRESSED)); /* a firm press that did not coapt it */
    send_assess(SC_ASSESS_ACTION_CALL, SC_ASSESS_CALL_DVT);
    r = sc_engine_assessment(&rig.engine);
    assert_int_equal(r->call, SC_ASSESS_CALL_DVT);
    assert_true(met(r, SC_ASSESS_CRIT_CALL_CORRECT));
    const uint8_t score_dvt = r->score;
    assert_int_equal(on_bus.call, SC_ASSESS_CALL_DVT);
    assert_int_equal(on_bus.finding, SC_ASSESS_CALL_DVT);
    assert_int_equal(on_bus.score, score_dvt);
    /* the last call counts: "normal" is wrong here */
    send_assess(SC_ASSESS_ACTION_CALL, SC_ASSESS_CALL_NORMAL);
    r = sc_engine_assessment(&rig.engine);
    assert_false(met(r, SC_ASSESS_CRIT_CALL_CORRECT));
    assert_int_equal(r->score + r->points[SC_ASSESS_CRIT_CALL_CORRECT], score_dvt);
    /* the reset forgets the exam and the call */
    const uint32_t resets = r->resets;
    send_assess(SC_ASSESS_ACTION_RESET, SC_ASSESS_CALL_NONE);
    r = sc_engine_assessment(&rig.engine);
    assert_int_equal(r->resets, resets + 1u);
    assert_int_equal(r->call, SC_ASSESS_CALL_NONE);
    assert_true(r->frames < 20u); /* counted again from the reset */
    assert_int_equal(on_bus.call, SC_ASSESS_CALL_NONE);
    assert_int_equal(rig.engine.counters.commands_refused, 0);
}

static void a_bad_assessment_command_is_refused_and_counted(void **state)
{
    (void)state;
    rig_up("neck-ijv.scase");
    /* Action Call with no call: the codec refuses to encode it, so build the frame by hand,
     * E2E-protected; the tracker refuses it at decode (counted cmd_rejected) */
    sc_can_frame f = {.id = SC_CANID_CMD_ASSESS, .len = 8};
    f.data[2] = (uint8_t)SC_ASSESS_ACTION_CALL; /* AssessCall 0 */
    assert_int_equal(sc_e2e_protect_with(SC_CANID_CMD_ASSESS, 0u, f.data, f.len), SC_OK);
    sc_cmd c;
    assert_int_equal(sc_canproto_decode_cmd(&f, &c), SC_ERR_CAN_SIGNAL);
    const uint32_t before = sc_tracker_counters(&rig.engine.tracker)->outcome[SC_TRK_CMD_REJECTED];
    assert_int_equal(sc_can_send(&rig.peer, &f), SC_OK);
    run_s(0.1);
    assert_int_equal(sc_tracker_counters(&rig.engine.tracker)->outcome[SC_TRK_CMD_REJECTED],
                     before + 1u);
    assert_int_equal(sc_engine_assessment(&rig.engine)->call, SC_ASSESS_CALL_NONE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(neck_ijv_press_that_coapts_the_vein_scores_coaptation),
        cmocka_unit_test(femoral_dvt_press_with_the_call_dvt_scores_the_call),
        cmocka_unit_test(a_bad_assessment_command_is_refused_and_counted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
