/* test_doppler_engine.c: colour Doppler through the whole engine on the host simulator: the
 * block case (vein and artery along y), the probe pressing with a 20-degree roll about its
 * x axis so that the beam has a component along the flow; colour reaches the display in the
 * vessels, with the two flows in opposite colours, one Doppler record per frame, and the same
 * colour for the same input (replayed, hashes). */
#include "sc_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_hs_storage.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

static sc_test_case block;
static sc_hs_rig rig;
static sc_emu emu;

static int group_setup(void **state)
{
    (void)state;
    return sc_test_case_make(&block, 12, 6, 8, SC_LABEL_VEIN, "block") == SC_OK ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    free(block.bytes);
    return 0;
}

typedef struct run_out {
    uint32_t red, blue; /* coloured pixels of the last frame, by sign */
    uint64_t colour_hash;
    uint64_t frames, records, contact_frames;
} run_out;

static run_out run_session(uint32_t frames)
{
    sc_engine_def def = sc_test_engine_def();
    def.tissue.collider = sc_test_scene_collider(&block.scene);
    def.doppler.box_u0 = 0.0f;
    def.doppler.box_u1 = 1.0f;
    def.doppler.box_v0 = 0.0f;
    def.doppler.box_v1 = 1.0f;
    def.doppler.prf_hz = 8000.0f;
    def.case_names[0] = "block";
    def.case_count = 1;
    assert_int_equal(sc_hs_rig_init(&rig, &def, 3, 0), SC_OK);
    assert_int_equal(sc_hs_storage_add(&rig.storage, "block", block.bytes, block.size), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig.engine, "block"), SC_OK);
    sc_emu_def pd = sc_emu_default_def();
    pd.script = SC_EMU_PRESS;
    memcpy(pd.point_mm, block.centre_tracker_mm, sizeof pd.point_mm);
    pd.hover_mm = 2.0f;
    pd.depth_mm = 3.0f;
    pd.duration_s = 10.0;
    /* the default orientation (beam down) rolled 20 degrees about x */
    const float a = 10.0f * 3.14159265f / 180.0f;
    const float r[4] = {cosf(a), sinf(a), 0.0f, 0.0f};
    const float b[4] = {pd.base_q[0], pd.base_q[1], pd.base_q[2], pd.base_q[3]};
    pd.base_q[0] = r[0] * b[0] - r[1] * b[1] - r[2] * b[2] - r[3] * b[3];
    pd.base_q[1] = r[0] * b[1] + r[1] * b[0] + r[2] * b[3] - r[3] * b[2];
    pd.base_q[2] = r[0] * b[2] - r[1] * b[3] + r[2] * b[0] + r[3] * b[1];
    pd.base_q[3] = r[0] * b[3] + r[1] * b[2] - r[2] * b[1] + r[3] * b[0];
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    const uint64_t t0 = rig.clock.now_ns;
    uint64_t next = 0, contact_frames = 0;
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    for (uint32_t i = 0; i < frames; i++) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        while (t0 + next <= release) {
            uint64_t t;
            const int k = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t);
            assert_true(k >= 0);
            for (int j = 0; j < k; j++) {
                (void)sc_can_send(&rig.peer, &f[j]);
            }
            next = t + (uint64_t)(1e9 / emu.def.rate_hz);
        }
        sc_engine_step(&rig.engine, NULL);
        contact_frames += rig.engine.tissue_out.contact;
    }
    run_out o = {0};
    o.contact_frames = contact_frames;
    for (size_t i = 0; i < sizeof rig.display.colour; i++) {
        o.red += rig.display.colour[i] > 0;
        o.blue += rig.display.colour[i] < 0;
    }
    o.colour_hash = rig.display.colour_hash;
    o.frames = rig.display.frames_complete;
    o.records = rig.display.doppler_records;
    return o;
}

static void colour_reaches_the_display_in_the_vessels_and_is_replayable(void **state)
{
    (void)state;
    const run_out a = run_session(150); /* 2.5 s: in contact from about 1 s */
    const sc_doppler_status *ds = sc_engine_get_doppler_status(&rig.engine);
    print_message("colour: red %u blue %u px (engine %u coloured, %u aliased), gate %.0f mm/s\n",
                  a.red, a.blue, ds->colour_pixels, ds->aliased_pixels,
                  (double)ds->gate_velocity_mm_s);
    assert_true(rig.engine.tissue_out.contact);
    /* one Doppler record per frame in contact (a dark frame has no colour pass) */
    assert_int_equal(a.frames, 150u);
    assert_int_equal(a.records, a.contact_frames);
    assert_true(a.contact_frames > 60u);
    assert_int_equal(rig.display.protocol_errors, 0);
    /* artery (+) and vein (-) flow opposite ways: both colours */
    assert_true(a.red > 20u && a.blue > 20u);
    assert_int_equal(a.red + a.blue, ds->colour_pixels);
    const run_out b = run_session(150);
    assert_true(a.colour_hash == b.colour_hash);
    assert_int_equal(a.red, b.red);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(colour_reaches_the_display_in_the_vessels_and_is_replayable),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
