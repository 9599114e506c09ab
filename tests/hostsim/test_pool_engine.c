/* test_pool_engine.c: the whole engine on the host simulator with its HAL pool at 1, 2 and 4
 * workers (platform/hostsim/sc_hs_pool.h: the ranges W workers would take, run worker by
 * worker, the last first) gives the same image of every frame and the same final state: the
 * FEM and the stable MSDS on a 40 x 16 x 16 case (two of the CG's sum blocks), the probe
 * pressing and sweeping. */
#include "sc_test.h"

#include <stdlib.h>
#include <string.h>

#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

#define FRAMES 40u

static sc_hs_rig rig;
static sc_emu emu;
static sc_test_case wide;

static int group_setup(void **state)
{
    (void)state;
    return sc_test_case_make(&wide, 40, 16, 16, SC_LABEL_VEIN, "wide") == SC_OK ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    free(wide.bytes);
    return 0;
}

/* FRAMES frames of a press on the case with `workers` host-pool workers: the image hash of
 * every frame into img, the final state hash returned */
static uint64_t pressed_run(sc_tissue_method method, uint32_t workers, uint64_t img[FRAMES])
{
    sc_engine_def def = sc_test_engine_def();
    def.tissue.method = method;
    def.tissue.collider = sc_test_scene_collider(&wide.scene);
    def.case_names[0] = "wide";
    def.case_count = 1;
    assert_int_equal(sc_hs_rig_init(&rig, &def, 3, 0), SC_OK);
    sc_hs_pool_init(&rig.pool, workers, &rig.hal.pool);
    assert_int_equal(sc_hs_storage_add(&rig.storage, "wide", wide.bytes, wide.size), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig.engine, "wide"), SC_OK);
    sc_emu_def d = sc_emu_default_def();
    d.script = SC_EMU_SWEEP; /* held 4 mm in from the first sample, swept 10 mm */
    memcpy(d.point_mm, wide.centre_tracker_mm, sizeof d.point_mm);
    d.depth_mm = 4.0f;
    d.length_mm = 10.0f;
    d.period_s = 2.0;
    d.duration_s = 1.0;
    assert_int_equal(sc_emu_init(&emu, &d), SC_OK);
    const uint64_t t0 = rig.clock.now_ns;
    uint64_t next_ns = 0;
    int more = 1;
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    uint32_t contact = 0;
    for (uint32_t i = 0; i < FRAMES; i++) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        while (more && t0 + next_ns <= release) {
            uint64_t t_ns;
            const int k = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t_ns);
            if (k < 0) {
                more = 0;
                break;
            }
            for (int j = 0; j < k; j++) {
                (void)sc_can_send(&rig.peer, &f[j]);
            }
            next_ns = t_ns + (uint64_t)(1e9 / emu.def.rate_hz);
        }
        sc_engine_step(&rig.engine, NULL);
        sc_engine_status st;
        sc_engine_get_status(&rig.engine, &st);
        contact += st.probe_contact ? 1u : 0u;
        img[i] = rig.display.hash_count ? rig.display.hashes[rig.display.hash_count - 1u] : 0u;
    }
    assert_true(contact > 5u); /* the probe did press */
    if (workers > 1u) {
        assert_true(rig.pool.ranges > 0u); /* the solver went through the pool */
    }
    return sc_engine_state_hash(&rig.engine);
}

static void check_method(sc_tissue_method method)
{
    static uint64_t img1[FRAMES], img[FRAMES];
    const uint64_t state1 = pressed_run(method, 1u, img1);
    assert_true(img1[FRAMES - 1u] != 0u); /* frames were displayed and hashed */
    for (uint32_t w = 2u; w <= 4u; w += 2u) {
        const uint64_t state = pressed_run(method, w, img);
        print_message("%s, %u workers: state %016llx (1 worker %016llx)\n",
                      method == SC_TISSUE_FEM ? "FEM" : "MSDS", (unsigned)w,
                      (unsigned long long)state, (unsigned long long)state1);
        assert_true(state == state1);
        assert_memory_equal(img, img1, sizeof img);
    }
}

static void fem_frames_and_state_are_the_same_for_1_2_and_4_workers(void **state)
{
    (void)state;
    check_method(SC_TISSUE_FEM);
}

static void msds_frames_and_state_are_the_same_for_1_2_and_4_workers(void **state)
{
    (void)state;
    check_method(SC_TISSUE_MSDS);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fem_frames_and_state_are_the_same_for_1_2_and_4_workers),
        cmocka_unit_test(msds_frames_and_state_are_the_same_for_1_2_and_4_workers),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
