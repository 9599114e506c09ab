/* test_doppler_engine.c: colour Doppler through the whole engine on the host simulator: the
 * block case (vein and artery along y), the probe pressing with a 20-degree roll about its
 * x axis so that the beam has a component along the flow; colour reaches the display in the
 * vessels, with the two flows in opposite colours, one Doppler record per frame, and the same
 * colour for the same input (replayed, hashes). */
#include "sc_test.h"

#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_test_block_rig.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

static sc_hs_rig rig;
static sc_emu emu;

typedef struct run_out {
    uint32_t red, blue; /* coloured pixels of the last frame, by sign */
    uint64_t colour_hash;
    uint64_t frames, records, contact_frames;
} run_out;

static run_out run_session(uint32_t frames)
{
    sc_test_block_rig_up(&rig, &sc_test_block, 3, 1);
    /* the default orientation (beam down) rolled 20 degrees about x */
    const sc_emu_def pd = sc_test_block_probe_def(&sc_test_block, 3.0f, 20.0f);
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    sc_test_feed feed;
    sc_test_feed_start(&feed, &rig, &emu, NULL);
    uint64_t contact_frames = 0;
    for (uint32_t i = 0; i < frames; i++) {
        sc_test_feed_due(&feed, &rig, sc_engine_next_release_ns(&rig.engine));
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
    return cmocka_run_group_tests(tests, sc_test_block_group_setup, sc_test_block_group_teardown);
}
