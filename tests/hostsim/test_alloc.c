/*
 * test_alloc.c: the engine allocates nothing once initialised.
 *
 * Linked with -Wl,--wrap=malloc,calloc,realloc,free (tests/alloc.cmake): every call to the
 * heap from the core, the host simulator and this test goes through the counters below. The
 * whole engine (a case loaded: tracker, tissue with collider and skin, B-scan, status frames)
 * runs 10,000 frames on the host simulator while the tracker emulator presses, sweeps and
 * lifts the probe over the bus, once with MSDS and once with FEM; the count must stay zero.
 * The last test proves the counter sees an allocation made inside a frame, so the others can
 * fail. A small mesh and image keep the sanitizer build quick; the property does not depend
 * on the sizes.
 */
#include "sc_test.h"

#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_test_case.h"
#include "sc_trkemu.h"

static unsigned long allocs;
static int counting;

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t m);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t m);
void *__wrap_realloc(void *p, size_t n);
void __wrap_free(void *p);

void *__wrap_malloc(size_t n)
{
    allocs += (unsigned long)counting;
    return __real_malloc(n);
}

void *__wrap_calloc(size_t n, size_t m)
{
    allocs += (unsigned long)counting;
    return __real_calloc(n, m);
}

void *__wrap_realloc(void *p, size_t n)
{
    allocs += (unsigned long)counting;
    return __real_realloc(p, n);
}

void __wrap_free(void *p)
{
    allocs += (unsigned long)(counting && p);
    __real_free(p);
}

static sc_hs_rig rig;
static sc_test_case tc;
static sc_emu emu;
static uint64_t t0;

static void rig_up(sc_tissue_method m)
{
    sc_engine_def def = sc_test_engine_def();
    def.tissue.method = m;
    def.bscan.scan.lines_n = 32u;
    def.bscan.scan.samples_n = 64u;
    assert_int_equal(sc_hs_rig_init(&rig, &def, 1u, 0), SC_OK);
    assert_int_equal(sc_hs_storage_add(&rig.storage, "block", tc.bytes, tc.size), SC_OK);
    assert_int_equal(sc_engine_load_case(&rig.engine, "block"), SC_OK);
    sc_emu_def ed = sc_emu_default_def();
    ed.script = SC_EMU_PRESS; /* hover, press, hold, rise, hover: repeated */
    memcpy(ed.point_mm, tc.centre_tracker_mm, sizeof(ed.point_mm));
    ed.hover_mm = 3.0f;
    ed.depth_mm = 4.0f;
    ed.duration_s = 1000.0;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);
    t0 = rig.clock.now_ns;
}

static int send_peer(void *ctx, const sc_can_frame *f)
{
    return sc_can_send((const sc_can_dev *)ctx, f);
}

static void run_frames(uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        const uint64_t release =
            sc_engine_next_release_ns(&rig.engine);
        (void)sc_emu_feed(&emu, release - t0, send_peer, &rig.peer);
        sc_engine_step(&rig.engine, NULL);
    }
}

static void engine_allocates_nothing(sc_tissue_method m)
{
    rig_up(m);
    run_frames(10); /* warm-up: first-use paths */
    allocs = 0;
    counting = 1;
    run_frames(10000);
    counting = 0;
    assert_int_equal(rig.engine.sched.frames, 10010);
    assert_int_equal(rig.display.frames_complete, 10010);
    assert_true(rig.engine.counters.can_rx_frames >= 10000u);
    assert_true(sc_tracker_counters(&rig.engine.tracker)->outcome[SC_TRK_POSE_ACCEPTED] > 5000u);
    assert_int_equal(allocs, 0);
}

static void engine_allocates_nothing_over_10000_frames_msds(void **state)
{
    (void)state;
    engine_allocates_nothing(SC_TISSUE_MSDS);
}

static void engine_allocates_nothing_over_10000_frames_fem(void **state)
{
    (void)state;
    engine_allocates_nothing(SC_TISSUE_FEM);
}

/* volatile: an optimiser may drop a malloc/free pair whose result is never used */
static void *volatile leak_sink;

static void leaky_stage(void *user)
{
    (void)user;
    leak_sink = malloc(16);
    free(leak_sink);
}

static void counter_sees_an_allocation_inside_a_frame(void **state)
{
    (void)state;
    rig_up(SC_TISSUE_MSDS);
    assert_int_equal(sc_engine_set_hook(&rig.engine, leaky_stage, NULL), SC_OK);
    allocs = 0;
    counting = 1;
    run_frames(100);
    counting = 0;
    assert_int_equal(allocs, 200); /* one malloc and one free per frame */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(engine_allocates_nothing_over_10000_frames_msds),
        cmocka_unit_test(engine_allocates_nothing_over_10000_frames_fem),
        cmocka_unit_test(counter_sees_an_allocation_inside_a_frame),
    };
    if (sc_test_case_make(&tc, 6, 4, 5, SC_LABEL_VEIN, "block") != SC_OK) {
        return 1;
    }
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    counting = 0;
    free(tc.bytes);
    return rc;
}
