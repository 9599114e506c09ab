/* test_sc_pool.c: the solvers on the worker pool (hal/sc_hal_pool.h) give bit-identical state
 * for every worker count. The host simulator's pool (platform/hostsim/sc_hs_pool.h) runs the
 * ranges a pool of W workers hands out, worker by worker, the last worker first: a job whose
 * result depended on which worker ran which range, or on their order, changes the hash. The
 * mesh, 40 x 16 x 16 nodes (10,240), has two of the CG's sum blocks and ten mat-vec ranges, and
 * two ranges of the cell passes (sc_grid.h: SC_GRID_ASM_SPAN); 40 x 16 x 28 (17,920 nodes) has
 * three, so a seam where the even range's sums come before the odd one's (and, above two ranges
 * of SC_GRID_ASM_SPAN, the finer per-mesh split of sc_grid.asm_span: 16 ranges, and the CG's
 * sum blocks of 1,024 nodes whose p.Ap partials come from the mat-vec's job). The springs'
 * passes run on the pool at every size; the collider's detection (a tilted probe pressed into a
 * 40 x 30 x 20 grid of jittered nodes) gives the serial contact set on every pool; the lumen
 * law's passes (40 x 16 x 28: many ranges) give the serial volumes, forces and clear. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sc_collider.h"
#include "sc_err.h"
#include "sc_hs_pool.h"
#include "sc_labels.h"
#include "sc_lumen.h"
#include "sc_material.h"
#include "sc_pool_linux.h"
#include "sc_test_tissue_scene.h"
#include "sc_simd.h"
#include "sc_tissue.h"

static sc_tissue g_t; /* large: static */
static sc_test_scene g_scene;

typedef enum run_kind { RUN_MSDS, RUN_FEM, RUN_FEM_COROTATED, RUN_KINDS } run_kind;

/* a press and a lift on the scene, `workers` 0: no pool (NULL), else the host pool of that
 * many workers; returns the state hash and the ranges the pool ran */
static uint32_t g_ny = 16u, g_nz = 16u; /* the mesh is 40 x g_ny x g_nz */
/* the linear FEM's floor (sc_grid.h, "rest K kept aside"): a floor ratio other than the
 * default's (0: the default), and the whole re-assembly forced on a mesh that keeps the copy */
static float g_floor_ratio = 0.0f;
static int g_whole_matrix = 0;
static float g_press_step_mm = 0.8f; /* the press's depth per frame (4 frames) */
static int g_full_restore = 0; /* every rest K restore copies every row (not the floor's ranges) */
static uint32_t g_floor_frames; /* frames whose step added the floor onto the kept rest K */
static float g_force[3];        /* the probe's force at the deepest frame (sc_tissue_probe_force_n) */
static uint32_t g_force_contacts; /* and the contacts it summed */

static uint64_t scripted_run_on(run_kind kind, uint32_t workers, const sc_pool_dev *thread_pool,
                                uint64_t *ranges_run)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = 40u;
    p.ny = g_ny;
    p.nz = g_nz;
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d =
        sc_test_scene_tissue_def(&g_scene, kind == RUN_MSDS ? SC_TISSUE_MSDS : SC_TISSUE_FEM);
    d.fem.corotated = kind == RUN_FEM_COROTATED ? 1u : 0u;
    if (g_floor_ratio > 0.0f) {
        d.fem.floor_volume_ratio = g_floor_ratio;
    }
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
    if (g_whole_matrix) {
        g_t.fem.grid.rest_saved = 0u;
    }
    g_floor_frames = 0u;
    for (int f = 0; f < 8; f++) {
        /* press 3.2 mm (by default), then lift */
        const float depth = f < 5 ? g_press_step_mm * (float)f : -1.0f;
        const sc_pose pose = sc_test_scene_probe(&g_scene, depth);
        if (g_full_restore) {
            g_t.fem.grid.rest_patched = 0u;
        }
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
        g_floor_frames += (g_t.fem.grid.rest_saved && !g_t.fem.rest_k) ? 1u : 0u;
        if (f == 4) {
            (void)sc_tissue_probe_force_n(&g_t, g_force);
            g_force_contacts = g_t.contacts.count;
        }
    }
    *ranges_run = (workers > 0u && thread_pool == NULL) ? pool.ranges : 0u;
    return sc_tissue_state_hash(&g_t);
}

static uint64_t scripted_run(run_kind kind, uint32_t workers, uint64_t *ranges_run)
{
    return scripted_run_on(kind, workers, NULL, ranges_run);
}

/* The mat-vec's software prefetch is a hint (sc_simd.h): forced on, forced off and by the mesh
 * (on: 40x16x16 is above SC_GRID_PREFETCH_NODES) give the same state hash, serial and on two
 * workers, for every method, so the platform's measured choice (sc_cpu.h) cannot change a
 * result. */
static void matvec_prefetch_on_and_off_give_the_same_state_hash(void **state)
{
    (void)state;
    for (int k = 0; k < (int)RUN_KINDS; k++) {
        uint64_t ranges = 0u, h[SC_SIMD_PREFETCH_COUNT][2];
        for (int p = 0; p < (int)SC_SIMD_PREFETCH_COUNT; p++) {
            assert_int_equal(sc_simd_select_prefetch((sc_simd_prefetch)p), SC_OK);
            h[p][0] = scripted_run((run_kind)k, 0u, &ranges);
            h[p][1] = scripted_run((run_kind)k, 2u, &ranges);
            print_message("kind %d, prefetch %s: %016llx / %016llx\n", k,
                          sc_simd_prefetch_name((sc_simd_prefetch)p), (unsigned long long)h[p][0],
                          (unsigned long long)h[p][1]);
        }
        assert_true(g_t.fem.grid.prefetch == 1u); /* the mesh's rule would prefetch */
        for (int p = 1; p < (int)SC_SIMD_PREFETCH_COUNT; p++) {
            assert_true(h[p][0] == h[0][0] && h[p][1] == h[0][0]);
        }
    }
    assert_int_equal(sc_simd_select_prefetch(SC_SIMD_PREFETCH_MESH), SC_OK);
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

/* The probe's force on the pool (contacts in ranges of 256, sc_tissue.c): a press with more
 * than one range of contacts gives the same bits with no pool and 1, 2 and 4 host-pool workers
 * (and the appliance's threads), and the force pushes back against the press (+z up). */
static void probe_force_is_the_same_for_every_worker_count(void **state)
{
    (void)state;
    g_press_step_mm = 1.6f; /* 6.4 mm */
    for (int k = 0; k < (int)RUN_KINDS; k += 1) {
        uint64_t ranges = 0u;
        (void)scripted_run((run_kind)k, 0u, &ranges);
        const float want[3] = {g_force[0], g_force[1], g_force[2]};
        print_message("%d: %u contacts, force %.4f %.4f %.4f N\n", k, (unsigned)g_force_contacts,
                      (double)want[0], (double)want[1], (double)want[2]);
        assert_true(g_force_contacts > 256u);
        assert_true(want[2] * want[2] > want[0] * want[0] + want[1] * want[1]);
        for (uint32_t w = 1u; w <= 4u; w *= 2u) {
            (void)scripted_run((run_kind)k, w, &ranges);
            assert_memory_equal(g_force, want, sizeof want);
        }
        static sc_pool_linux lp;
        sc_pool_dev dev;
        assert_int_equal(sc_pool_linux_start(&lp, 2u, -1, 50u, &dev), 0);
        (void)scripted_run_on((run_kind)k, 2u, &dev, &ranges);
        sc_pool_linux_stop(&lp);
        assert_memory_equal(g_force, want, sizeof want);
    }
    g_press_step_mm = 0.8f;
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

/* The linear FEM with the floor met on a mesh that keeps its rest K aside (40 x 16 x 28, three
 * cell ranges, as every mesh above SC_GRID_REST_COPY_NODES; a floor at half the rest volume, the
 * largest allowed, and a 10 mm press, so that tets go below it): the steps that add the floor
 * onto the kept copy give the same bits with no pool, 1, 2, 4 host-pool workers and every row
 * restored from the copy each step (not only the floor's ranges), and the same motion as the
 * whole re-assembly within rounding (the two sum the floor in a different order). */
static void linear_floor_on_the_kept_rest_k_matches_the_whole_reassembly(void **state)
{
    (void)state;
    g_nz = 28u;
    g_floor_ratio = 0.5f;
    g_press_step_mm = 2.5f;
    uint64_t ranges = 0u;
    const uint64_t serial = scripted_run(RUN_FEM, 0u, &ranges);
    const uint32_t floor_frames = g_floor_frames;
    static float kept[3][SC_MAX_NODES];
    const uint32_t nn = g_t.mesh.node_count;
    memcpy(kept[0], g_t.nodes.x, nn * sizeof(float));
    memcpy(kept[1], g_t.nodes.y, nn * sizeof(float));
    memcpy(kept[2], g_t.nodes.z, nn * sizeof(float));
    for (uint32_t w = 1u; w <= 4u; w *= 2u) {
        const uint64_t h = scripted_run(RUN_FEM, w, &ranges);
        assert_true(h == serial);
    }
    /* restoring the floor's ranges only is restoring the whole rest K */
    g_full_restore = 1;
    assert_true(scripted_run(RUN_FEM, 2u, &ranges) == serial);
    g_full_restore = 0;
    g_whole_matrix = 1;
    (void)scripted_run(RUN_FEM, 0u, &ranges);
    g_whole_matrix = 0;
    assert_int_equal(g_floor_frames, 0u); /* the whole path kept no copy */
    float diff = 0.0f, moved = 0.0f;
    const float *now[3] = {g_t.nodes.x, g_t.nodes.y, g_t.nodes.z};
    const float *rest[3] = {g_t.mesh.rest_x, g_t.mesh.rest_y, g_t.mesh.rest_z};
    for (uint32_t c = 0; c < 3u; c++) {
        for (uint32_t i = 0; i < nn; i++) {
            diff = fmaxf(diff, fabsf(now[c][i] - kept[c][i]));
            moved = fmaxf(moved, fabsf(kept[c][i] - rest[c][i]));
        }
    }
    print_message("floor on the kept rest K: %u of 8 frames; the whole re-assembly's positions "
                  "within %.3g mm (largest displacement %.3f mm)\n",
                  (unsigned)floor_frames, (double)diff, (double)moved);
    assert_true(floor_frames >= 3u);
    assert_true(moved > 0.5f);
    assert_true(diff < 1e-3f * moved);
    g_floor_ratio = 0.0f;
    g_press_step_mm = 0.8f;
    g_nz = 16u;
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

/* The collider on the pool: the contacts (nodes, planes, order) and the counters of a
 * detection are those of the serial detection, for 1..4 host-pool workers and 2 threads. */
static float g_cx[24000], g_cy[24000], g_cz[24000];
static sc_contact_set g_serial, g_pooled;

static void collider_on_the_pool_gives_the_serial_contacts(void **state)
{
    (void)state;
    const sc_collider_grid g = {40u, 30u, 20u, {0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}};
    uint32_t rng = 777u;
    for (uint32_t k = 0; k < g.nz; k++) {
        for (uint32_t j = 0; j < g.ny; j++) {
            for (uint32_t i = 0; i < g.nx; i++) {
                const uint32_t n = i + g.nx * (j + g.ny * k);
                float jit[3];
                for (uint32_t a = 0; a < 3u; a++) {
                    rng = rng * 1664525u + 1013904223u;
                    jit[a] = 0.3f * ((float)(rng >> 8) / 16777216.0f - 0.5f);
                }
                g_cx[n] = (float)i + jit[0];
                g_cy[n] = (float)j + jit[1];
                g_cz[n] = (float)k + jit[2];
            }
        }
    }
    sc_collider c;
    assert_int_equal(sc_collider_init(&c, &(sc_collider_def){.shape = SC_COLLIDER_ROUNDED_BOX,
                                                              .sphere_radius_mm = 10.0f,
                                                              .half_mm = {20.0f, 5.0f, 10.0f},
                                                              .round_radius_mm = 2.0f,
                                                              .margin_mm = 0.5f}),
                     SC_OK);
    assert_null(c.pool);
    sc_pose pose = sc_pose_identity();
    const float ang = 0.3f; /* tilted about y, face 4 mm into the grid's top */
    pose.q[0] = cosf(ang / 2.0f);
    pose.q[2] = sinf(ang / 2.0f);
    pose.pos_mm[0] = 19.5f;
    pose.pos_mm[1] = 14.5f;
    pose.pos_mm[2] = 4.0f;
    assert_int_equal(sc_collider_set_pose(&c, &pose), SC_OK);
    sc_collider_detect(&c, &g, g_cx, g_cy, g_cz, NULL, 1.0f, &g_serial);
    print_message("serial: %u contacts, %u candidates, %u MPR calls\n", g_serial.count,
                  g_serial.candidates, g_serial.mpr_calls);
    assert_true(g_serial.count > 100u && g_serial.candidates >= SC_COLLIDER_POOL_MIN);
    for (uint32_t w = 1u; w <= 5u; w++) {
        sc_hs_pool hp;
        static sc_pool_linux lp;
        sc_pool_dev dev;
        if (w <= 4u) {
            sc_hs_pool_init(&hp, w, &dev);
        } else {
            assert_int_equal(sc_pool_linux_start(&lp, 2u, -1, 50u, &dev), 0);
        }
        c.pool = &dev;
        memset(&g_pooled, 0xA5, sizeof g_pooled);
        sc_collider_detect(&c, &g, g_cx, g_cy, g_cz, NULL, 1.0f, &g_pooled);
        if (w <= 4u) {
            assert_true(hp.ranges > 1u); /* it did go through the pool, in chunks */
        } else {
            sc_pool_linux_stop(&lp);
        }
        assert_int_equal(g_pooled.count, g_serial.count);
        assert_int_equal(g_pooled.candidates, g_serial.candidates);
        assert_int_equal(g_pooled.mpr_calls, g_serial.mpr_calls);
        assert_memory_equal(g_pooled.c, g_serial.c, (size_t)g_serial.count * sizeof g_serial.c[0]);
    }
}

/* The lumen law's passes on the pool (sc_lumen.h "Workers"): on 40 x 16 x 28 (17,920 nodes,
 * above SC_LUMEN_SERIAL_NODES) the passes run in many ranges; after a press, one frame's volumes,
 * pressures, boundary forces and face count, and the clear after it, are bit for bit those of
 * the same split run without a pool, for 1, 2, 4 host-pool workers and 2 real threads. */
static sc_lumen g_lum0;
static sc_nodes g_nodes0, g_ref;

static void lumen_apply_and_clear(const sc_pool_dev *pool, sc_nodes *after_apply)
{
    g_t.lumen = g_lum0;
    g_t.nodes = g_nodes0;
    g_t.lumen.pool = pool;
    sc_lumen_apply(&g_t.lumen, &g_t.mesh, &g_t.nodes);
    *after_apply = g_t.nodes;
    sc_lumen_clear(&g_t.lumen, &g_t.mesh, &g_t.nodes);
}

static void lumen_check(uint32_t ny, uint32_t nz)
{
    uint64_t ranges = 0u;
    g_ny = ny;
    g_nz = nz;
    (void)scripted_run(RUN_MSDS, 0u, &ranges);
    g_ny = 16u;
    g_nz = 16u;
    assert_true(g_t.lumen.count >= 2u);   /* the scene's vein and artery */
    assert_true(g_t.lumen.ranges >= 8u);  /* split: the mesh is above SC_LUMEN_SERIAL_NODES */
    assert_true(g_t.lumen.ranges <= SC_LUMEN_RANGES);
    assert_true((uint64_t)g_t.lumen.ranges * g_t.lumen.span_tets >= g_t.mesh.tet_count);
    /* a frame's external forces start at zero (the last frame's clear) */
    g_lum0 = g_t.lumen;
    g_nodes0 = g_t.nodes;
    static sc_nodes serial_applied;
    lumen_apply_and_clear(NULL, &serial_applied);
    g_ref = g_t.nodes;
    const sc_lumen serial = g_t.lumen;
    const size_t nn = (size_t)g_t.mesh.node_count * sizeof(float);
    print_message("lumen: %u vessels, %u ranges of %u tets, %u faces loaded\n", serial.count,
                  serial.ranges, serial.span_tets, serial.faces);
    assert_true(serial.faces > 100u);
    uint32_t loaded = 0;
    for (uint32_t i = 0; i < g_t.mesh.node_count; i++) {
        loaded += fabsf(serial_applied.fx[i]) + fabsf(serial_applied.fy[i]) +
                      fabsf(serial_applied.fz[i]) > 0.0f;
        assert_false(fabsf(g_ref.fx[i]) + fabsf(g_ref.fy[i]) + fabsf(g_ref.fz[i]) > 0.0f);
    }
    assert_true(loaded > 100u);
    static sc_nodes pooled_applied;
    for (uint32_t w = 1u; w <= 5u; w++) {
        sc_hs_pool hp;
        static sc_pool_linux lp;
        sc_pool_dev dev;
        if (w == 3u) {
            continue;
        }
        if (w <= 4u) {
            sc_hs_pool_init(&hp, w, &dev);
        } else {
            assert_int_equal(sc_pool_linux_start(&lp, 2u, -1, 50u, &dev), 0);
        }
        lumen_apply_and_clear(&dev, &pooled_applied);
        if (w <= 4u) {
            assert_true(hp.ranges >= g_t.lumen.ranges); /* it did go through the pool */
        } else {
            sc_pool_linux_stop(&lp);
        }
        assert_int_equal(g_t.lumen.faces, serial.faces);
        assert_memory_equal(g_t.lumen.v, serial.v, sizeof serial.v);
        assert_memory_equal(pooled_applied.fx, serial_applied.fx, nn);
        assert_memory_equal(pooled_applied.fy, serial_applied.fy, nn);
        assert_memory_equal(pooled_applied.fz, serial_applied.fz, nn);
        assert_memory_equal(g_t.nodes.fx, g_ref.fx, nn);
        assert_memory_equal(g_t.nodes.fy, g_ref.fy, nn);
        assert_memory_equal(g_t.nodes.fz, g_ref.fz, nn);
    }
}

static void lumen_passes_give_the_serial_bits_for_1_2_and_4_workers(void **state)
{
    (void)state;
    lumen_check(16u, 28u);
    lumen_check(26u, 17u); /* ranges of exactly a multiple of four (test_sc_grid_split) */
}

/* 40 x 26 x 17 (17,680 nodes) cuts into a multiple of four cell ranges and lumen ranges as it
 * is. Re-cutting them gave spans narrower than the two-apart minimum: sc_grid_init's assert
 * stopped the case load, and the lumen's ranges two apart shared nodes (test_sc_grid_split: every
 * mesh). It builds, and 1, 2 and 4 host-pool workers and two real threads give the serial state
 * hash, MSDS and linear FEM. */
static void a_mesh_of_four_ranges_exactly_builds_and_gives_the_serial_hash(void **state)
{
    (void)state;
    g_ny = 26u;
    g_nz = 17u;
    for (int k = 0; k < (int)RUN_FEM_COROTATED; k++) {
        uint64_t ranges = 0u;
        const uint64_t serial = scripted_run((run_kind)k, 0u, &ranges);
        assert_int_equal(g_t.fem.grid.asm_span, sc_grid_asm_span(40u, 26u, 17u));
        assert_true(g_t.fem.grid.asm_span > 40u * 26u + 40u + SC_GRID_CELL_BLOCK);
        for (uint32_t w = 1u; w <= 4u; w *= 2u) {
            const uint64_t h = scripted_run((run_kind)k, w, &ranges);
            print_message("%d, %u worker(s): state hash %016llx\n", k, (unsigned)w,
                          (unsigned long long)h);
            assert_true(h == serial);
        }
        static sc_pool_linux lp;
        sc_pool_dev dev;
        assert_int_equal(sc_pool_linux_start(&lp, 2u, -1, 50u, &dev), 0);
        const uint64_t h = scripted_run_on((run_kind)k, 2u, &dev, &ranges);
        sc_pool_linux_stop(&lp);
        assert_true(h == serial);
    }
    g_ny = 16u;
    g_nz = 16u;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(host_pool_runs_every_range_once),
        cmocka_unit_test(collider_on_the_pool_gives_the_serial_contacts),
        cmocka_unit_test(state_hash_is_the_same_for_1_2_3_and_4_workers),
        cmocka_unit_test(matvec_prefetch_on_and_off_give_the_same_state_hash),
        cmocka_unit_test(probe_force_is_the_same_for_every_worker_count),
        cmocka_unit_test(three_cell_ranges_give_the_same_hash_for_1_2_and_4_workers),
        cmocka_unit_test(linux_pool_threads_give_the_serial_state_hash),
        cmocka_unit_test(lumen_passes_give_the_serial_bits_for_1_2_and_4_workers),
        cmocka_unit_test(linear_floor_on_the_kept_rest_k_matches_the_whole_reassembly),
        cmocka_unit_test(a_mesh_of_four_ranges_exactly_builds_and_gives_the_serial_hash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
