/* test_sc_pool.c: the solvers on the worker pool (hal/sc_hal_pool.h) give bit-identical state
 * for every worker count. The host simulator's pool (platform/hostsim/sc_hs_pool.h) runs the
 * ranges a pool of W workers hands out, worker by worker, the last worker first: a job whose
 * result depended on which worker ran which range, or on their order, changes the hash. The
 * mesh, 40 x 16 x 16 nodes (10,240), has two of the CG's sum blocks and ten mat-vec ranges, and
 * two ranges of the cell passes (sc_grid.h: SC_GRID_ASM_SPAN); 40 x 16 x 28 (17,920 nodes) has
 * three, so a seam where the even range's sums come before the odd one's. The springs' passes
 * run on the pool at every size. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sc_err.h"
#include "sc_hs_pool.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_pool_linux.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

static sc_tissue g_t; /* large: static */
static sc_test_scene g_scene;

typedef enum run_kind { RUN_MSDS, RUN_FEM, RUN_FEM_COROTATED, RUN_KINDS } run_kind;

/* a press and a lift on the scene, `workers` 0: no pool (NULL), else the host pool of that
 * many workers; returns the state hash and the ranges the pool ran */
static uint32_t g_nz = 16u; /* the mesh is 40 x 16 x g_nz */

static uint64_t scripted_run_on(run_kind kind, uint32_t workers, const sc_pool_dev *thread_pool,
                                uint64_t *ranges_run)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = 40u;
    p.ny = 16u;
    p.nz = g_nz;
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d =
        sc_test_scene_tissue_def(&g_scene, kind == RUN_MSDS ? SC_TISSUE_MSDS : SC_TISSUE_FEM);
    d.fem.corotated = kind == RUN_FEM_COROTATED ? 1u : 0u;
    sc_material_table mat;
    sc_material_table_default(&mat);
    static sc_hs_pool pool;
    static sc_pool_dev dev;
    assert_int_equal(sc_tissue_build_begin(&g_t, &d, &g_scene.vol, &mat, SC_LABEL_FAT), SC_OK);
    if (thread_pool != NULL) {
        sc_tissue_set_pool(&g_t, thread_pool);
    } else if (workers > 0u) {
        sc_hs_pool_init(&pool, workers, &dev);
        sc_tissue_set_pool(&g_t, &dev);
    }
    int rc;
    while ((rc = sc_tissue_build_step(&g_t)) == SC_OK) {
    }
    assert_int_equal(rc, 1);
    for (int f = 0; f < 8; f++) {
        const float depth = f < 5 ? 0.8f * (float)f : -1.0f; /* press 3.2 mm, then lift */
        const sc_pose pose = sc_test_scene_probe(&g_scene, depth);
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
    }
    *ranges_run = (workers > 0u && thread_pool == NULL) ? pool.ranges : 0u;
    return sc_tissue_state_hash(&g_t);
}

static uint64_t scripted_run(run_kind kind, uint32_t workers, uint64_t *ranges_run)
{
    return scripted_run_on(kind, workers, NULL, ranges_run);
}

static void state_hash_is_the_same_for_1_2_3_and_4_workers(void **state)
{
    (void)state;
    static const char *const names[RUN_KINDS] = {"MSDS", "FEM linear", "FEM corotated"};
    for (int k = 0; k < (int)RUN_KINDS; k++) {
        uint64_t ranges = 0u;
        const uint64_t serial = scripted_run((run_kind)k, 0u, &ranges);
        for (uint32_t w = 1u; w <= 4u; w++) {
            const uint64_t h = scripted_run((run_kind)k, w, &ranges);
            print_message("%s, %u worker(s): state hash %016llx (%llu ranges)\n", names[k],
                          (unsigned)w, (unsigned long long)h, (unsigned long long)ranges);
            assert_true(ranges > 0u); /* the solver did go through the pool */
            assert_true(h == serial);
        }
    }
}

/* Three ranges of the cell passes (40 x 16 x 28): 1, 2 and 4 host-pool workers give the serial
 * hash; the pool runs more ranges than on the smaller mesh (the cell passes' and the springs'
 * jobs scale with the mesh). */
static void three_cell_ranges_give_the_same_hash_for_1_2_and_4_workers(void **state)
{
    (void)state;
    static const char *const names[RUN_KINDS] = {"MSDS", "FEM linear", "FEM corotated"};
    for (int k = 0; k < (int)RUN_KINDS; k++) {
        uint64_t ranges = 0u, small_ranges = 0u;
        g_nz = 16u;
        (void)scripted_run((run_kind)k, 1u, &small_ranges);
        g_nz = 28u;
        const uint64_t serial = scripted_run((run_kind)k, 0u, &ranges);
        for (uint32_t w = 1u; w <= 4u; w *= 2u) {
            const uint64_t h = scripted_run((run_kind)k, w, &ranges);
            print_message("%s 40x16x28, %u worker(s): state hash %016llx (%llu ranges; 40x16x16: "
                          "%llu)\n",
                          names[k], (unsigned)w, (unsigned long long)h, (unsigned long long)ranges,
                          (unsigned long long)small_ranges);
            assert_true(ranges > small_ranges);
            assert_true(h == serial);
        }
        g_nz = 16u;
    }
}

/* The same with the appliance's pool: real threads (2 and 4, not pinned) */
static void linux_pool_threads_give_the_serial_state_hash(void **state)
{
    (void)state;
    for (int k = 0; k < (int)RUN_KINDS; k++) {
        uint64_t ranges = 0u;
        const uint64_t serial = scripted_run((run_kind)k, 0u, &ranges);
        for (uint32_t w = 2u; w <= 4u; w += 2u) {
            static sc_pool_linux lp;
            sc_pool_dev dev;
            assert_int_equal(sc_pool_linux_start(&lp, w, -1, 50u, &dev), 0);
            assert_int_equal(sc_pool_workers(&dev), w);
            const uint64_t h = scripted_run_on((run_kind)k, w, &dev, &ranges);
            sc_pool_linux_stop(&lp);
            assert_true(h == serial);
        }
    }
}

/* The pool's split is the mesh's, not the workers': the host pool hands worker w the ranges
 * w, w + W, ... and every range exactly once. */
static int g_seen[64];
static void mark(void *arg, uint32_t r)
{
    (void)arg;
    g_seen[r]++;
}

static void host_pool_runs_every_range_once(void **state)
{
    (void)state;
    for (uint32_t w = 1u; w <= 5u; w++) {
        sc_hs_pool pool;
        sc_pool_dev dev;
        sc_hs_pool_init(&pool, w, &dev);
        for (uint32_t n = 0u; n <= 64u; n++) {
            memset(g_seen, 0, sizeof g_seen);
            sc_pool_run(&dev, mark, NULL, n);
            for (uint32_t r = 0; r < 64u; r++) {
                assert_int_equal(g_seen[r], r < n ? 1 : 0);
            }
        }
        assert_int_equal(sc_pool_workers(&dev), w);
    }
    assert_int_equal(sc_pool_workers(NULL), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(host_pool_runs_every_range_once),
        cmocka_unit_test(state_hash_is_the_same_for_1_2_3_and_4_workers),
        cmocka_unit_test(three_cell_ranges_give_the_same_hash_for_1_2_and_4_workers),
        cmocka_unit_test(linux_pool_threads_give_the_serial_state_hash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
