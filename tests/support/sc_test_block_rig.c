/* sc_test_block_rig.c: see sc_test_block_rig.h. */
#include "sc_test_block_rig.h"

#include "sc_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_hs_storage.h"

sc_test_case sc_test_block;

int sc_test_block_group_setup(void **state)
{
    (void)state;
    return sc_test_case_make(&sc_test_block, 12, 6, 8, SC_LABEL_VEIN, "block") == SC_OK ? 0 : -1;
}

int sc_test_block_group_teardown(void **state)
{
    (void)state;
    free(sc_test_block.bytes);
    sc_test_block.bytes = NULL;
    return 0;
}

void sc_test_block_rig_up(sc_hs_rig *rig, const sc_test_case *block, uint64_t seed,
                          int doppler_whole_image)
{
    sc_engine_def def = sc_test_engine_def();
    def.tissue.collider = sc_test_scene_collider(&block->scene);
    if (doppler_whole_image) {
        def.doppler.box_u0 = 0.0f;
        def.doppler.box_u1 = 1.0f;
        def.doppler.box_v0 = 0.0f;
        def.doppler.box_v1 = 1.0f;
        def.doppler.prf_hz = 8000.0f;
    }
    def.case_names[0] = "block";
    def.case_count = 1;
    assert_int_equal(sc_hs_rig_init(rig, &def, seed, 0), SC_OK);
    assert_int_equal(sc_hs_storage_add(&rig->storage, "block", block->bytes, block->size), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig->engine, "block"), SC_OK);
}

sc_emu_def sc_test_block_probe_def(const sc_test_case *block, float depth_mm, float roll_deg)
{
    sc_emu_def pd = sc_emu_default_def();
    pd.script = SC_EMU_PRESS;
    memcpy(pd.point_mm, block->centre_tracker_mm, sizeof pd.point_mm);
    pd.hover_mm = 2.0f;
    pd.depth_mm = depth_mm;
    pd.duration_s = 10.0;
    /* r (half the roll about x) times the base orientation; a roll of 0 leaves it exact */
    const float a = 0.5f * roll_deg * 3.14159265f / 180.0f;
    const float r[4] = {cosf(a), sinf(a), 0.0f, 0.0f};
    const float b[4] = {pd.base_q[0], pd.base_q[1], pd.base_q[2], pd.base_q[3]};
    pd.base_q[0] = r[0] * b[0] - r[1] * b[1] - r[2] * b[2] - r[3] * b[3];
    pd.base_q[1] = r[0] * b[1] + r[1] * b[0] + r[2] * b[3] - r[3] * b[2];
    pd.base_q[2] = r[0] * b[2] - r[1] * b[3] + r[2] * b[0] + r[3] * b[1];
    pd.base_q[3] = r[0] * b[3] + r[1] * b[2] - r[2] * b[1] + r[3] * b[0];
    return pd;
}

sc_emu_needle_def sc_test_block_needle_def(const sc_test_case *block, float entry_x_mm,
                                           float dir_x_mm, double hold_s)
{
    sc_emu_needle_def nd = sc_emu_needle_default_def();
    nd.entry_mm[0] = entry_x_mm;
    nd.entry_mm[1] = block->vein_tracker_mm[1];
    nd.entry_mm[2] = 0.0f;
    nd.dir[0] = dir_x_mm;
    nd.dir[1] = 0.0f;
    nd.dir[2] = -10.0f;
    nd.speed_mm_s = 10.0f;
    nd.max_depth_mm = 14.0f;
    nd.hold_s = hold_s;
    return nd;
}

void sc_test_feed_start(sc_test_feed *feed, const sc_hs_rig *rig, sc_emu *probe,
                        sc_emu_needle *needle)
{
    *feed = (sc_test_feed){.probe = probe, .needle = needle, .t0_ns = rig->clock.now_ns};
}

void sc_test_feed_due(sc_test_feed *feed, sc_hs_rig *rig, uint64_t release_ns)
{
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    while (feed->t0_ns + feed->probe_next_ns <= release_ns) {
        uint64_t t;
        const int k = sc_emu_next(feed->probe, f, SC_EMU_MAX_FRAMES, &t);
        assert_true(k >= 0);
        for (int j = 0; j < k; j++) {
            (void)sc_can_send(&rig->peer, &f[j]);
        }
        feed->probe_next_ns = t + (uint64_t)(1e9 / feed->probe->def.rate_hz);
    }
    while (feed->needle != NULL && feed->t0_ns + feed->needle_next_ns <= release_ns) {
        uint64_t t;
        assert_int_equal(sc_emu_needle_next(feed->needle, f, 3u, &t), 3);
        for (int j = 0; j < 3; j++) {
            (void)sc_can_send(&rig->peer, &f[j]);
        }
        feed->needle_next_ns = t + (uint64_t)(1e9 / feed->needle->def.rate_hz);
    }
}
