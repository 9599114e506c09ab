/*
 * test_vessel_drive.c: the lumens' drive (core/physics/sc_lumen.h) in the image, whole engine
 * on the host simulator with the phantom cases (the `cases` target), both methods: the probe
 * rests on the skin over the vessels (1 mm press) and the artery's image area is sampled every
 * frame for 4 s. Checked: the area oscillates at the set heart rate (the largest DFT bin of the
 * series is the rate's, at 72 and at 108 / min), by a few percent (peak to peak 1-20%); a
 * Valsalva manoeuvre distends the vein (image area up >= 5%); in the thrombosed vein's case the
 * clot's area neither follows the pulse and the breath nor the Valsalva (within 1%); two runs
 * give the same state hash. Printed: the area's peak-to-peak change and the equivalent
 * diameter change (sqrt of the area ratio).
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_press.h"
#include "sc_test_signal.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
static sc_emu_row rows[4];

#define SETTLE_S 1.0
#define SAMPLE_S 4.0
#define PRESS_MM 1.0f
#define MAX_SAMPLES 512u

static float series[MAX_SAMPLES];

static float ratio(uint32_t label)
{
    const sc_bscan_status *b = sc_bscan_status_get(&rig.engine.bscan);
    return b->areas_valid ? b->area_ratio[label] : -1.0f;
}

/* the probe 1 mm into the skin over the middle of the mesh's top for the whole run */
static void rest_probe(double duration_s, uint64_t *t0)
{
    const sc_case *cs = &rig.engine.slot.c;
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_emu_def ed = sc_emu_default_def();
    float top[3];
    sc_xform_apply(&v2t, p_vol, top);
    sc_emu_row r = {0.0, {top[0], top[1], top[2] - PRESS_MM}, {0, 0, 0, 0}, -1.0f};
    memcpy(r.q, ed.base_q, sizeof r.q);
    rows[0] = r;
    r.t_s = duration_s;
    rows[1] = r;
    ed.script = SC_EMU_CSV;
    ed.rows = rows;
    ed.n_rows = 2u;
    ed.duration_s = duration_s;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    *t0 = rig.clock.now_ns;
}

static void set_drive(float heart_bpm, float resp_bpm)
{
    sc_lumen_drive d = sc_lumen_drive_default();
    d.heart_rate_bpm = heart_bpm;
    d.resp_rate_bpm = resp_bpm;
    assert_int_equal(sc_tissue_set_drive(sc_test_press_tissue(&rig), &d), SC_OK);
}

/* run `frames` frames, recording the label's image-area ratio of each */
static void record(uint64_t t0, int *more, uint32_t frames, uint32_t label, float *out)
{
    for (uint32_t f = 0; f < frames; f++) {
        sc_test_press_frame(&rig, &emu, t0, more);
        assert_true(sc_test_press_state_finite(&rig));
        if (out != NULL) {
            out[f] = ratio(label);
            assert_true(out[f] > 0.0f);
        }
    }
}

static void min_max(const float *x, uint32_t n, float *lo, float *hi)
{
    *lo = x[0];
    *hi = x[0];
    for (uint32_t i = 1; i < n; i++) {
        *lo = fminf(*lo, x[i]);
        *hi = fmaxf(*hi, x[i]);
    }
}

static uint64_t pulse_run(sc_tissue_method m, float bpm)
{
    sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", "neck-ijv.scase", m);
    set_drive(bpm, 0.0f);
    uint64_t t0;
    rest_probe(SETTLE_S + SAMPLE_S + 1.0, &t0);
    const uint32_t hz = rig.engine.def.sched.rate_hz;
    const uint32_t n = (uint32_t)(SAMPLE_S * hz);
    assert_true(n <= MAX_SAMPLES);
    int more = 1;
    record(t0, &more, (uint32_t)(SETTLE_S * hz), SC_LABEL_ARTERY, NULL);
    record(t0, &more, n, SC_LABEL_ARTERY, series);
    const double f = sc_test_peak_hz(series, n, 1.0 / hz);
    float lo, hi;
    min_max(series, n, &lo, &hi);
    const float pp = (hi - lo) / (0.5f * (hi + lo));
    print_message("neck-ijv %s, %.0f / min: artery image area peak %.3f Hz (set %.3f Hz), "
                  "area %.3f..%.3f of rest, peak to peak %.1f%%, diameter %.1f%%\n",
                  m == SC_TISSUE_MSDS ? "msds" : "fem", (double)bpm, f, (double)bpm / 60.0,
                  (double)lo, (double)hi, 100.0 * (double)pp,
                  100.0 * (sqrt((double)hi / (double)lo) - 1.0));
    /* the DFT's bins are 1 / SAMPLE_S = 0.25 Hz apart */
    assert_true(fabs(f - (double)bpm / 60.0) <= 0.5 / SAMPLE_S + 1e-9);
    assert_true(pp >= 0.01f && pp <= 0.20f);
    assert_int_equal(rig.engine.counters.phys_resets, 0u);
    return sc_tissue_state_hash(sc_test_press_tissue(&rig));
}

static void artery_pulsates_at_the_set_heart_rate(void **state)
{
    (void)state;
    for (int m = 0; m < 2; m++) {
        const sc_tissue_method meth = m == 0 ? SC_TISSUE_MSDS : SC_TISSUE_FEM;
        const uint64_t h1 = pulse_run(meth, 72.0f);
        const uint64_t h2 = pulse_run(meth, 72.0f);
        assert_true(h1 == h2); /* deterministic */
        (void)pulse_run(meth, 108.0f);
    }
}

static void valsalva_distends_the_vein(void **state)
{
    (void)state;
    for (int m = 0; m < 2; m++) {
        const sc_tissue_method meth = m == 0 ? SC_TISSUE_MSDS : SC_TISSUE_FEM;
        sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", "neck-ijv.scase", meth);
        set_drive(0.0f, 0.0f);
        uint64_t t0;
        rest_probe(5.0, &t0);
        const uint32_t hz = rig.engine.def.sched.rate_hz;
        int more = 1;
        record(t0, &more, hz, SC_LABEL_VEIN, series);
        const float before = sc_test_mean(series + hz / 2u, hz / 2u);
        sc_tissue_set_valsalva(sc_test_press_tissue(&rig), 1);
        record(t0, &more, 2u * hz, SC_LABEL_VEIN, series);
        const float during = sc_test_mean(series + hz, hz);
        sc_tissue_set_valsalva(sc_test_press_tissue(&rig), 0);
        record(t0, &more, 2u * hz, SC_LABEL_VEIN, series);
        const float after = sc_test_mean(series + hz, hz);
        print_message("neck-ijv %s: vein image area %.3f, Valsalva %.3f (%+.1f%%), after %.3f\n",
                      meth == SC_TISSUE_MSDS ? "msds" : "fem", (double)before, (double)during,
                      100.0 * (double)(during / before - 1.0f), (double)after);
        assert_true(during >= 1.05f * before);
        assert_true(fabsf(after - before) <= 0.02f * before);
    }
}

static void thrombosed_vein_does_not_follow_the_drive(void **state)
{
    (void)state;
    for (int m = 0; m < 2; m++) {
        const sc_tissue_method meth = m == 0 ? SC_TISSUE_MSDS : SC_TISSUE_FEM;
        sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", "femoral-dvt.scase", meth);
        set_drive(72.0f, 15.0f);
        uint64_t t0;
        rest_probe(6.0, &t0);
        const uint32_t hz = rig.engine.def.sched.rate_hz;
        int more = 1;
        record(t0, &more, hz, SC_LABEL_THROMBUS, NULL);
        sc_tissue_set_valsalva(sc_test_press_tissue(&rig), 1);
        record(t0, &more, 4u * hz, SC_LABEL_THROMBUS, series);
        float lo, hi;
        min_max(series, 4u * hz, &lo, &hi);
        print_message("femoral-dvt %s: clot image area %.4f..%.4f under pulse, breath and "
                      "Valsalva\n",
                      meth == SC_TISSUE_MSDS ? "msds" : "fem", (double)lo, (double)hi);
        assert_true(hi - lo <= 0.01f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(artery_pulsates_at_the_set_heart_rate),
        cmocka_unit_test(valsalva_distends_the_vein),
        cmocka_unit_test(thrombosed_vein_does_not_follow_the_drive),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
