/*
 * test_vessel_cmds.c: the heart, the breathing, Valsalva and the Doppler settings by CAN
 * command (CmdVessels 0x085, CmdDoppler 0x086), end to end: the commands are signed
 * (sc_cmdsign, with their MACs at 0x08D / 0x08E) and sent through the host simulator's bus
 * while the probe rests on the neck-ijv phantom (the `cases` target), MSDS. Checked:
 *   - loaded, the case's own drive (its DRIV section: neck-ijv 60 / min, 12 breaths / min)
 *     runs: the artery's image area oscillates at 1.0 Hz (issue 18 item 1, "in the case");
 *   - a CmdVessels with heart rate 108 / min (breathing off) overrides it and makes the
 *     artery's image area oscillate at 1.8 Hz (largest DFT bin of 4 s at 60 Hz), one with
 *     72 / min at 1.2 Hz;
 *   - a CmdVessels with Valsalva held distends the vein (image area up >= 5%), released it
 *     comes back within 2%;
 *   - (probe rolled 20 degrees so that the beam has a component along the flow) a CmdDoppler
 *     with colour off leaves no coloured sample; on again, with a new scale,
 *     steering and gain, colour comes back and the engine's settings are the commanded ones;
 *   - bad values reach the engine and are refused and counted (commands_refused): breathing
 *     2 / min (the lumen law takes 0 or 4..60) and a scale of 200 Hz under the 100 Hz wall
 *     filter (it must be <= PRF / 4); the previous settings stay;
 *   - a case switch applies the new case's drive (its DRIV replaces the commanded one), and
 *     CmdVessels' "pulse on" takes the running case's pulse pressure.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_canproto.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_cmd.h"
#include "sc_test_press.h"
#include "sc_test_signal.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
static sc_emu_row rows[2];
static uint64_t t0;
static int more = 1;

#define MAX_SAMPLES 512u
static float series[MAX_SAMPLES];

static float ratio(uint32_t label)
{
    const sc_bscan_status *b = sc_bscan_status_get(&rig.engine.bscan);
    return b->areas_valid ? b->area_ratio[label] : -1.0f;
}

/* the probe 1 mm into the skin over the middle of the mesh's top for the whole run, its
 * default orientation rolled roll_deg about its x axis (a beam component along the flow for
 * the Doppler) */
static void rig_up_rolled(double duration_s, float roll_deg)
{
    sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", "neck-ijv.scase",
                         SC_TISSUE_MSDS);
    const sc_case *cs = &rig.engine.slot.c;
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_emu_def ed = sc_emu_default_def();
    float top[3];
    sc_xform_apply(&v2t, p_vol, top);
    sc_emu_row r = {0.0, {top[0], top[1], top[2] - 1.0f}, {0, 0, 0, 0}, -1.0f};
    const float a = 0.5f * roll_deg * 3.14159265f / 180.0f;
    const float q[4] = {cosf(a), sinf(a), 0.0f, 0.0f};
    const float *b = ed.base_q;
    r.q[0] = q[0] * b[0] - q[1] * b[1] - q[2] * b[2] - q[3] * b[3];
    r.q[1] = q[0] * b[1] + q[1] * b[0] + q[2] * b[3] - q[3] * b[2];
    r.q[2] = q[0] * b[2] - q[1] * b[3] + q[2] * b[0] + q[3] * b[1];
    r.q[3] = q[0] * b[3] + q[1] * b[2] - q[2] * b[1] + q[3] * b[0];
    rows[0] = r;
    r.t_s = duration_s;
    rows[1] = r;
    ed.script = SC_EMU_CSV;
    ed.rows = rows;
    ed.n_rows = 2u;
    ed.duration_s = duration_s;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    t0 = rig.clock.now_ns;
    more = 1;
}

static void rig_up(double duration_s)
{
    rig_up_rolled(duration_s, 0.0f);
}

static void record(uint32_t frames, uint32_t label, float *out)
{
    for (uint32_t f = 0; f < frames; f++) {
        sc_test_press_frame(&rig, &emu, t0, &more);
        assert_true(sc_test_press_state_finite(&rig));
        if (out != NULL) {
            out[f] = ratio(label);
            assert_true(out[f] > 0.0f);
        }
    }
}

/* sends the signed command through the simulated bus and runs 6 frames (100 ms): received,
 * authenticated, applied; returns the change of commands_applied (1) or of commands_refused
 * (-1), 0 if neither moved */
static int send(const sc_cmd *c)
{
    const uint64_t applied = rig.engine.counters.commands_applied;
    const uint64_t refused = rig.engine.counters.commands_refused;
    assert_int_equal(sc_test_send_cmd(&rig.peer, c), SC_OK);
    record(6u, SC_LABEL_ARTERY, NULL);
    const int a = (int)(rig.engine.counters.commands_applied - applied);
    const int r = (int)(rig.engine.counters.commands_refused - refused);
    assert_true(a + r <= 1);
    return a == 1 ? 1 : r == 1 ? -1 : 0;
}

static int send_vessels(float hr, float rr, uint8_t valsalva, uint8_t pulse)
{
    sc_cmd c = {.kind = SC_CMD_VESSELS};
    c.vessels = (sc_vessels_cmd){hr, rr, valsalva, pulse};
    return send(&c);
}

static int send_doppler(uint8_t on, float prf, float steer, float gain)
{
    sc_cmd c = {.kind = SC_CMD_DOPPLER};
    c.doppler = (sc_doppler_cmd){on, prf, steer, gain};
    return send(&c);
}

static void heart_rate_command_sets_the_arterys_pulse(void **state)
{
    (void)state;
    rig_up(30.0);
    const uint32_t hz = rig.engine.def.sched.rate_hz;
    const uint32_t n = 4u * hz;
    assert_true(n <= MAX_SAMPLES);
    /* the case's drive first: neck-ijv's DRIV says 60 / min */
    {
        const sc_case_drive *cd = &rig.engine.slot.c.drive;
        const sc_lumen_drive *dr = &sc_test_press_tissue(&rig)->lumen.drive;
        assert_int_equal(cd->present, 1u);
        assert_float_equal(cd->d.heart_rate_bpm, 60.0f, 0.0f);
        assert_float_equal(dr->heart_rate_bpm, cd->d.heart_rate_bpm, 0.0f);
        assert_float_equal(dr->resp_rate_bpm, cd->d.resp_rate_bpm, 0.0f);
        record(hz, SC_LABEL_ARTERY, NULL); /* settle */
        record(n, SC_LABEL_ARTERY, series);
        const double f = sc_test_peak_hz(series, n, 1.0 / hz);
        print_message("case drive %.0f / min: artery image area peak at %.3f Hz (set %.3f Hz)\n",
                      (double)cd->d.heart_rate_bpm, f, (double)cd->d.heart_rate_bpm / 60.0);
        assert_true(fabs(f - (double)cd->d.heart_rate_bpm / 60.0) <= 0.125 + 1e-9);
    }
    const float bpm[2] = {108.0f, 72.0f};
    for (int i = 0; i < 2; i++) {
        assert_int_equal(send_vessels(bpm[i], 0.0f, 0u, 1u), 1);
        assert_float_equal(sc_test_press_tissue(&rig)->lumen.drive.heart_rate_bpm, bpm[i], 0.0f);
        record(hz, SC_LABEL_ARTERY, NULL); /* settle */
        record(n, SC_LABEL_ARTERY, series);
        const double f = sc_test_peak_hz(series, n, 1.0 / hz);
        print_message("CmdVessels %.0f / min: artery image area peak at %.3f Hz (set %.3f Hz)\n",
                      (double)bpm[i], f, (double)bpm[i] / 60.0);
        assert_true(fabs(f - (double)bpm[i] / 60.0) <= 0.125 + 1e-9); /* bins 0.25 Hz apart */
    }
    /* pulsation off: the artery's pressure pulse is gone, its area nearly still */
    assert_int_equal(send_vessels(72.0f, 0.0f, 0u, 0u), 1);
    record(hz, SC_LABEL_ARTERY, NULL);
    record(n, SC_LABEL_ARTERY, series);
    float lo = series[0], hi = series[0];
    for (uint32_t i = 1; i < n; i++) {
        lo = fminf(lo, series[i]);
        hi = fmaxf(hi, series[i]);
    }
    print_message("CmdVessels pulsation off: artery area %.4f..%.4f\n", (double)lo, (double)hi);
    assert_true(hi - lo <= 0.005f);
    assert_int_equal(rig.engine.counters.phys_resets, 0u);
}

static void valsalva_command_distends_the_vein(void **state)
{
    (void)state;
    rig_up(30.0);
    const uint32_t hz = rig.engine.def.sched.rate_hz;
    assert_int_equal(send_vessels(72.0f, 0.0f, 0u, 0u), 1); /* still vessels */
    record(hz, SC_LABEL_VEIN, series);
    const float before = sc_test_mean(series + hz / 2u, hz / 2u);
    assert_int_equal(send_vessels(72.0f, 0.0f, 1u, 0u), 1);
    record(2u * hz, SC_LABEL_VEIN, series);
    const float during = sc_test_mean(series + hz, hz);
    assert_int_equal(send_vessels(72.0f, 0.0f, 0u, 0u), 1);
    record(2u * hz, SC_LABEL_VEIN, series);
    const float after = sc_test_mean(series + hz, hz);
    print_message("CmdVessels Valsalva: vein image area %.3f, held %.3f (%+.1f%%), released %.3f\n",
                  (double)before, (double)during, 100.0 * (double)(during / before - 1.0f),
                  (double)after);
    assert_true(during >= 1.05f * before);
    assert_true(fabsf(after - before) <= 0.02f * before);
}

static void doppler_command_switches_colour_and_sets_the_scale(void **state)
{
    (void)state;
    rig_up_rolled(30.0, 20.0f);
    record(30u, SC_LABEL_ARTERY, NULL);
    const sc_doppler_status *st = sc_engine_get_doppler_status(&rig.engine);
    const uint32_t on_before = st->colour_pixels;
    assert_true(on_before > 0u); /* the default settings colour the lumens */
    assert_int_equal(send_doppler(0u, 4000.0f, 0.0f, 0.0f), 1);
    uint32_t coloured = 0;
    for (int f = 0; f < 30; f++) {
        record(1u, SC_LABEL_ARTERY, NULL);
        coloured += st->colour_pixels;
        assert_int_equal(rig.engine.doppler_on, 0);
    }
    assert_int_equal(coloured, 0u);
    assert_int_equal(send_doppler(1u, 2500.0f, -20.0f, 6.0f), 1);
    record(30u, SC_LABEL_ARTERY, NULL);
    const sc_doppler_def *d = sc_engine_get_doppler_def(&rig.engine);
    assert_int_equal(d->enabled, 1u);
    assert_float_equal(d->prf_hz, 2500.0f, 0.0f);
    assert_float_equal(d->steer_deg, -20.0f, 0.0f);
    assert_float_equal(d->gain_db, 6.0f, 0.0f);
    assert_int_equal(rig.engine.doppler_on, 1);
    print_message("CmdDoppler: %u coloured samples with the defaults, 0 over 30 frames off, %u "
                  "on at 2500 Hz, -20 deg, +6 dB\n",
                  on_before, st->colour_pixels);
    assert_true(st->colour_pixels > 0u);
}

static void bad_values_are_refused_and_counted(void **state)
{
    (void)state;
    rig_up(30.0);
    record(10u, SC_LABEL_ARTERY, NULL);
    assert_int_equal(send_vessels(90.0f, 12.0f, 0u, 1u), 1);
    const uint64_t refused = rig.engine.counters.commands_refused;
    /* breathing 2 / min: inside the DBC's 0..40, outside the lumen law's 0 or 4..60 */
    assert_int_equal(send_vessels(90.0f, 2.0f, 0u, 1u), -1);
    assert_float_equal(sc_test_press_tissue(&rig)->lumen.drive.resp_rate_bpm, 12.0f, 0.0f);
    /* a scale of 200 Hz under the 100 Hz wall filter (wall <= PRF / 4) */
    const sc_doppler_def before = *sc_engine_get_doppler_def(&rig.engine);
    assert_int_equal(send_doppler(1u, 200.0f, 0.0f, 0.0f), -1);
    assert_float_equal(sc_engine_get_doppler_def(&rig.engine)->prf_hz, before.prf_hz, 0.0f);
    assert_true(rig.engine.counters.commands_refused == refused + 2u);
    print_message("refused and counted: breathing 2 / min, PRF 200 Hz (commands_refused %llu)\n",
                  (unsigned long long)rig.engine.counters.commands_refused);
    /* a case switch applies the new case's drive (femoral's DRIV: 78 / min, 16 breaths, 6 kPa),
     * replacing the commanded one; a command then overrides it again */
    assert_int_equal(sc_engine_load_case(&rig.engine, "femoral.scase"), SC_OK);
    const sc_lumen_drive *dr = &sc_test_press_tissue(&rig)->lumen.drive;
    assert_float_equal(dr->heart_rate_bpm, 78.0f, 0.0f);
    assert_float_equal(dr->resp_rate_bpm, 16.0f, 0.0f);
    assert_float_equal(dr->pulse_pa, 6.0e3f, 0.0f);
    assert_int_equal(send_vessels(90.0f, 12.0f, 0u, 1u), 1);
    dr = &sc_test_press_tissue(&rig)->lumen.drive;
    assert_float_equal(dr->heart_rate_bpm, 90.0f, 0.0f);
    assert_float_equal(dr->resp_rate_bpm, 12.0f, 0.0f);
    assert_float_equal(dr->pulse_pa, 6.0e3f, 0.0f); /* "pulse on": the case's pulse pressure */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(heart_rate_command_sets_the_arterys_pulse),
        cmocka_unit_test(valsalva_command_distends_the_vein),
        cmocka_unit_test(doppler_command_switches_colour_and_sets_the_scale),
        cmocka_unit_test(bad_values_are_refused_and_counted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
