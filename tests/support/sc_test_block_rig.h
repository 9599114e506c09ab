/*
 * sc_test_block_rig.h: the whole-engine rig of the needle and Doppler host-simulator tests
 * (test_needle_engine, test_doppler_engine, test_needle_doppler_replay): the block case
 * (sc_test_case.h) loaded into a host-simulated engine, the tracker emulator's probe (pressing
 * over the block's middle, optionally rolled about its x axis so that the beam sees the flow)
 * and its needle, and a feeder that puts every probe and needle sample due before an engine
 * frame on the rig's bus, on the virtual clock.
 * Test code: fails through cmocka's assertions; nothing allocates.
 */
#ifndef SC_TEST_BLOCK_RIG_H
#define SC_TEST_BLOCK_RIG_H

#include <stdint.h>

#include "sc_hs_rig.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

/* The block case of these tests: 12 x 6 x 8 nodes, a vein (not thrombosed), named "block";
 * built by sc_test_block_group_setup (a cmocka group setup), freed by the teardown. */
extern sc_test_case sc_test_block;
int sc_test_block_group_setup(void **state);
int sc_test_block_group_teardown(void **state);

/* Initialise rig with sc_test_engine_def() for block (its collider, the case named "block",
 * the only catalogue entry), the rig's seed, and, with doppler_whole_image, the colour box over
 * the whole image at a PRF of 8000 Hz; then add and load the case. Asserts each step. */
void sc_test_block_rig_up(sc_hs_rig *rig, const sc_test_case *block, uint64_t seed,
                          int doppler_whole_image);

/* The probe's script: SC_EMU_PRESS over the block's middle, 2 mm hover, depth_mm deep, 10 s,
 * the default orientation (beam down) rolled roll_deg about the probe's x axis (0: none). */
sc_emu_def sc_test_block_probe_def(const sc_test_case *block, float depth_mm, float roll_deg);

/* The needle in the image plane (y of the vein's skin point), entering the skin at x = entry_x_mm
 * (tracker frame) along (dir_x_mm, 0, -10), 10 mm/s, 14 mm deep at most, held hold_s. */
sc_emu_needle_def sc_test_block_needle_def(const sc_test_case *block, float entry_x_mm,
                                           float dir_x_mm, double hold_s);

/* Puts the probe's (and the needle's, when not NULL) samples due before each engine frame on
 * the rig's peer node. Times count from t0, the rig's clock at sc_test_feed_start. */
typedef struct sc_test_feed {
    sc_emu *probe;
    sc_emu_needle *needle;
    uint64_t t0_ns, probe_next_ns, needle_next_ns;
} sc_test_feed;

void sc_test_feed_start(sc_test_feed *feed, const sc_hs_rig *rig, sc_emu *probe,
                        sc_emu_needle *needle);
/* Send every sample due at or before release_ns. Asserts the emulators' results. */
void sc_test_feed_due(sc_test_feed *feed, sc_hs_rig *rig, uint64_t release_ns);

#endif /* SC_TEST_BLOCK_RIG_H */
