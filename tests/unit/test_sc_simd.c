/* test_sc_simd.c: the instruction-set variants of the hot kernels (sc_simd.h) give the same
 * bits, and the selection refuses what the build or the CPU does not have. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_cpu.h"
#include "sc_fem.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_msds.h"
#include "sc_msds_implicit.h"
#include "sc_collider.h"
#include "sc_simd.h"
#include "sc_skin.h"
#include "sc_springs.h"

static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_springs g_sp;
static sc_msds g_msds;
static sc_material_table g_mat;
static sc_fem g_fem;
static uint8_t g_kin[SC_MAX_NODES];
static sc_skin g_skin;

static uint64_t fnv_floats(uint64_t h, const float *p, uint32_t n)
{
    const unsigned char *b = (const unsigned char *)p;
    for (size_t i = 0; i < (size_t)n * sizeof(float); i++) {
        h = (h ^ b[i]) * 1099511628211ull;
    }
    return h;
}

/* A layered block pressed from above by a force that grows over the run, so that springs
 * stretch and compress, tets change volume, and a few nodes move fast; then the state hash
 * (positions and velocities, bit for bit). nx odd gives every loop a remainder. */
static uint64_t run_scene(uint32_t nx, uint32_t ny, uint32_t nz, float volume_ratio)
{
    sc_mesh_def d = sc_mesh_default_def();
    d.nx = nx;
    d.ny = ny;
    d.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    sc_material_table_default(&g_mat);
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &g_mat, SC_LABEL_FAT), SC_OK);
    static const uint8_t mix[] = {SC_LABEL_FAT, SC_LABEL_VEIN, SC_LABEL_MUSCLE, SC_LABEL_ARTERY,
                                  SC_LABEL_THROMBUS};
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        g_mesh.tet_label[t] = mix[(t * 7u + t / 13u) % 5u];
    }
    assert_int_equal(sc_springs_from_tets(&g_sp, (const uint32_t(*)[4])g_mesh.tet, g_mesh.tet_label,
                                          g_mesh.tet_count, &g_mat),
                     SC_OK);
    sc_msds_def def = sc_msds_default_def();
    def.volume_stiffness_ratio = volume_ratio;
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &def), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    /* k = 0 is the skin side (the bottom and the sides are fixed) */
    for (uint32_t step = 0; step < 120u; step++) {
        for (uint32_t i = 0; i < nx * ny; i++) {
            const uint32_t ix = i % nx;
            /* a press on the middle third of the top, sideways on one edge */
            g_nodes.fz[i] = (ix > nx / 3u && ix < 2u * nx / 3u) ? 1e-3f * (float)step : 0.0f;
            g_nodes.fx[i] = ix == 0u ? 2e-4f * (float)step : 0.0f;
        }
        sc_msds_substep(&g_msds, &g_nodes);
    }
    uint64_t h = 1469598103934665603ull;
    h = fnv_floats(h, g_nodes.x, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.y, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.z, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vx, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vy, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vz, g_mesh.node_count);
    /* the scene must have moved, or equal hashes would prove nothing */
    float dmax = 0.0f;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float dz = fabsf(g_mesh.rest_z[i] - g_nodes.z[i]);
        dmax = dz > dmax ? dz : dmax;
    }
    printf("# %ux%ux%u ratio %.0f: largest vertical displacement %.3f mm\n", nx, ny, nz,
           (double)volume_ratio, (double)dmax);
    assert_true(dmax > 0.2f);
    return h;
}

/* Every variant this build has and this CPU runs gives the generic variant's bits, with and
 * without the volume term, on an even and an odd grid. */
static void variants_give_identical_bits(void **state)
{
    (void)state;
    const sc_simd best = sc_cpu_best_simd();
    static const uint32_t shapes[2][3] = {{12u, 8u, 8u}, {11u, 7u, 6u}};
    const float ratios[2] = {0.0f, sc_msds_default_def().volume_stiffness_ratio};
    int compared = 0;
    for (uint32_t sh = 0; sh < 2u; sh++) {
        for (uint32_t r = 0; r < 2u; r++) {
            assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
            const uint64_t ref = run_scene(shapes[sh][0], shapes[sh][1], shapes[sh][2], ratios[r]);
            for (int v = 1; v < (int)SC_SIMD_COUNT; v++) {
                if (!sc_simd_built((sc_simd)v) || v > (int)best) {
                    printf("# %s: not built or not on this CPU, skipped\n",
                           sc_simd_name((sc_simd)v));
                    continue;
                }
                assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
                const uint64_t h =
                    run_scene(shapes[sh][0], shapes[sh][1], shapes[sh][2], ratios[r]);
                printf("# %ux%ux%u ratio %.0f: generic %016llx, %s %016llx\n", shapes[sh][0],
                       shapes[sh][1], shapes[sh][2], (double)ratios[r], (unsigned long long)ref,
                       sc_simd_name((sc_simd)v), (unsigned long long)h);
                assert_true(h == ref);
                compared++;
            }
        }
    }
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    printf("# %d comparisons (best variant here: %s)\n", compared, sc_simd_name(best));
}

/* The implicit solvers (sc_grid_kern.inc: FEM linear and corotated, the stable MSDS) on the
 * mixed block: a press by kinematic nodes deep enough that tets meet the volume floor, with a
 * sideways force, then the release (the unloaded warm start). Returns the state hash. */
static int g_no_face_pairs; /* 1: run_implicit_cfg's MSDS without springs_pair */

static uint64_t run_implicit_cfg(uint32_t nx, uint32_t ny, uint32_t nz, int method,
                                 int springs_fused, int face_pairs)
{
    sc_mesh_def d = sc_mesh_default_def();
    d.nx = nx;
    d.ny = ny;
    d.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    sc_material_table_default(&g_mat);
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &g_mat, SC_LABEL_FAT), SC_OK);
    static const uint8_t mix[] = {SC_LABEL_FAT, SC_LABEL_VEIN, SC_LABEL_MUSCLE, SC_LABEL_ARTERY,
                                  SC_LABEL_THROMBUS};
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        g_mesh.tet_label[t] = mix[(t * 7u + t / 13u) % 5u];
    }
    assert_int_equal(sc_springs_from_tets(&g_sp, (const uint32_t(*)[4])g_mesh.tet, g_mesh.tet_label,
                                          g_mesh.tet_count, &g_mat),
                     SC_OK);
    sc_msds_def md = sc_msds_default_def();
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &md), SC_OK);
    /* the grid's face diagonals join odd nodes only (springs_pair's premise, sc_msds.faces_odd) */
    assert_int_equal(g_msds.faces_odd, 1);
    if (g_no_face_pairs) {
        g_msds.faces_odd = 0u; /* the whole-vector face springs (springs_pair refused) */
    }
    sc_fem_def fd = sc_fem_default_def();
    fd.corotated = method == 1 ? 1u : 0u;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &fd), SC_OK);
    if (springs_fused >= 0) {
        g_fem.grid.springs_fused = (uint8_t)springs_fused; /* the other way, same bits */
    }
    if (face_pairs == 0) {
        g_fem.grid.face_pairs = 0u; /* the whole-vector face passes, same bits */
    } else if (face_pairs > 0) {
        assert_int_equal(g_fem.grid.face_pairs, 1); /* the mesh takes the pair copies */
    }
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    uint32_t floor_frames = 0;
    float dmax = 0.0f;
    for (uint32_t step = 0; step < 40u; step++) {
        const int press = step < 25u;
        for (uint32_t i = 0; i < nx * ny; i++) {
            const uint32_t ix = i % nx;
            const int under = ix > nx / 3u && ix < 2u * nx / 3u;
            g_kin[i] = (uint8_t)(press && under);
            /* the probe moves 0.6 mm per frame into the block: 15 mm at the end */
            g_nodes.vz[i] = (press && under) ? 3.0f : g_nodes.vz[i];
            g_nodes.fx[i] = press && ix == 0u ? 2e-4f * (float)step : 0.0f;
        }
        if (method == 2) {
            sc_msds_implicit_step(&g_msds, &g_fem, &g_mesh, &g_nodes, 0.2f, 10u, g_kin);
        } else {
            sc_fem_step_kinematic(&g_fem, &g_mesh, &g_nodes, 0.2f, 10u, g_kin);
        }
        for (uint32_t i = 0; i < nx * ny; i++) {
            if (g_kin[i]) {
                g_nodes.vx[i] = g_nodes.vy[i] = g_nodes.vz[i] = 0.0f;
            }
        }
        floor_frames += g_fem.rest_k == 0u && method == 0 ? 1u : 0u;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            dmax = fmaxf(dmax, fabsf(g_mesh.rest_z[i] - g_nodes.z[i]));
        }
    }
    assert_int_equal(sc_fem_status(&g_fem), SC_OK);
    uint64_t h = 1469598103934665603ull;
    h = fnv_floats(h, g_nodes.x, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.y, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.z, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vx, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vy, g_mesh.node_count);
    h = fnv_floats(h, g_nodes.vz, g_mesh.node_count);
    printf("# implicit %ux%ux%u method %d: largest vertical displacement %.3f mm, "
           "%u linear frames assembled (floor)\n",
           nx, ny, nz, method, (double)dmax, floor_frames);
    assert_true(dmax > 2.0f);
    return h;
}

static uint64_t run_implicit_springs(uint32_t nx, uint32_t ny, uint32_t nz, int method,
                                     int springs_fused)
{
    return run_implicit_cfg(nx, ny, nz, method, springs_fused, -1);
}

static uint64_t run_implicit(uint32_t nx, uint32_t ny, uint32_t nz, int method)
{
    return run_implicit_springs(nx, ny, nz, method, -1);
}

/* The mat-vec's face sums by node pair (sc_grid.h: SC_GRID_PAIRS) give the whole-vector passes'
 * bits in every variant, for the three implicit solvers, on rows of one, two and three vectors
 * of pairs at x86-64-v3's width (nx 16, 32, 48: odd nodes at x = 0 on every other row, whose
 * blocks one step back in x are the pair copy's exception). Where a variant's vectors do not
 * fit the rows it takes the whole-vector passes: the comparison holds either way. */
static void face_sums_by_pair_give_the_whole_vector_bits(void **state)
{
    (void)state;
    const sc_simd best = sc_cpu_best_simd();
    static const uint32_t shapes[3][3] = {{32u, 6u, 5u}, {16u, 6u, 6u}, {48u, 4u, 4u}};
    int compared = 0;
    for (uint32_t sh = 0; sh < 3u; sh++) {
        for (int method = 0; method < 3; method++) {
            assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
            const uint64_t ref =
                run_implicit_cfg(shapes[sh][0], shapes[sh][1], shapes[sh][2], method, -1, 0);
            for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
                if (!sc_simd_built((sc_simd)v) || v > (int)best) {
                    continue;
                }
                assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
                const uint64_t h = run_implicit_cfg(shapes[sh][0], shapes[sh][1], shapes[sh][2],
                                                    method, -1, SC_GRID_PAIRS ? 1 : -1);
                printf("# face sums %ux%ux%u method %d: whole vectors (generic) %016llx, "
                       "by pair (%s) %016llx\n",
                       shapes[sh][0], shapes[sh][1], shapes[sh][2], method, (unsigned long long)ref,
                       sc_simd_name((sc_simd)v), (unsigned long long)h);
                assert_true(h == ref);
                compared++;
            }
        }
    }
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    assert_true(compared >= 6);
}

/* The stable MSDS's springs in one pass over the nodes (sc_grid.springs_fused, the meshes above
 * SC_GRID_SPRINGS_FUSED_NODES), run range by range with the cells (msds_assemble), give the bits
 * of the per-family passes followed by the cells' own pass, in every variant; on an odd grid too,
 * whose anti-diagonal blocks and first nodes take the masked lanes, on 40 x 16 x 28, whose 16
 * cell ranges each start with nodes whose springs the range before runs, and on rows of 64 and
 * 32 nodes, where the x86-64-v4 and -v3 variants take the face springs on the odd nodes alone
 * (springs_pair: rows of whole vectors of pairs; the generic one's 4 lanes on 40 x 16 x 28 too). */
static void springs_one_pass_gives_the_two_pass_bits(void **state)
{
    (void)state;
    const sc_simd best = sc_cpu_best_simd();
    static const uint32_t shapes[5][3] = {
        {12u, 8u, 8u}, {11u, 7u, 6u}, {40u, 16u, 28u}, {64u, 5u, 6u}, {32u, 7u, 9u}};
    int compared = 0;
    for (uint32_t sh = 0; sh < 5u; sh++) {
        assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
        const uint64_t ref = run_implicit_springs(shapes[sh][0], shapes[sh][1], shapes[sh][2], 2, 0);
        for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
            if (!sc_simd_built((sc_simd)v) || v > (int)best) {
                continue;
            }
            assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
            const uint64_t h =
                run_implicit_springs(shapes[sh][0], shapes[sh][1], shapes[sh][2], 2, 1);
            printf("# springs %ux%ux%u: two passes (generic) %016llx, one pass (%s) %016llx\n",
                   shapes[sh][0], shapes[sh][1], shapes[sh][2], (unsigned long long)ref,
                   sc_simd_name((sc_simd)v), (unsigned long long)h);
            assert_true(h == ref);
            compared++;
            if (shapes[sh][0] % 32u == 0u) {
                /* the same with the face springs over whole vectors (sc_msds.faces_odd 0) */
                g_no_face_pairs = 1;
                const uint64_t hw =
                    run_implicit_springs(shapes[sh][0], shapes[sh][1], shapes[sh][2], 2, 1);
                g_no_face_pairs = 0;
                assert_true(hw == ref);
            }
        }
    }
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    assert_true(compared >= 2);
}

/* Every variant gives the generic variant's bits for the implicit solvers too. */
static void implicit_solver_variants_give_identical_bits(void **state)
{
    (void)state;
    const sc_simd best = sc_cpu_best_simd();
    static const uint32_t shapes[2][3] = {{12u, 8u, 8u}, {11u, 7u, 6u}};
    int compared = 0;
    for (uint32_t sh = 0; sh < 2u; sh++) {
        for (int method = 0; method < 3; method++) {
            assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
            const uint64_t ref = run_implicit(shapes[sh][0], shapes[sh][1], shapes[sh][2], method);
            for (int v = 1; v < (int)SC_SIMD_COUNT; v++) {
                if (!sc_simd_built((sc_simd)v) || v > (int)best) {
                    continue;
                }
                assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
                const uint64_t h = run_implicit(shapes[sh][0], shapes[sh][1], shapes[sh][2], method);
                printf("# implicit %ux%ux%u method %d: generic %016llx, %s %016llx\n",
                       shapes[sh][0], shapes[sh][1], shapes[sh][2], method,
                       (unsigned long long)ref, sc_simd_name((sc_simd)v), (unsigned long long)h);
                assert_true(h == ref);
                compared++;
            }
        }
    }
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    printf("# %d implicit comparisons (best variant here: %s)\n", compared, sc_simd_name(best));
}

/* The skin (sc_skin_kern.inc) pressed by a sphere, held and lifted, on a grid whose rows and
 * spring families are no multiple of any vector width (the tails run). Returns the hash of the
 * positions and velocities; *dent_mm: the deepest displacement while pressed. */
static uint64_t run_skin(uint32_t nx, uint32_t ny, float *dent_mm)
{
    sc_skin_def d = sc_skin_default_def();
    d.nx = nx;
    d.ny = ny;
    assert_int_equal(sc_skin_init(&g_skin, &d), SC_OK);
    sc_collider_def cd = sc_collider_default_def();
    cd.shape = SC_COLLIDER_SPHERE;
    cd.sphere_radius_mm = 8.0f;
    sc_collider c;
    assert_int_equal(sc_collider_init(&c, &cd), SC_OK);
    *dent_mm = 0.0f;
    for (int f = 0; f < 60; f++) {
        sc_pose p = sc_pose_identity();
        p.pos_mm[0] = 17.0f + 0.1f * (float)f; /* sliding sideways as it presses */
        p.pos_mm[1] = 9.0f;
        p.pos_mm[2] = f < 40 ? -0.5f + 3.0f * (float)(f + 1) / 40.0f : -5.0f;
        assert_int_equal(sc_collider_set_pose(&c, &p), SC_OK);
        sc_skin_step(&g_skin, &c);
        if (f < 40) {
            const float m = sc_skin_max_displacement_mm(&g_skin);
            *dent_mm = m > *dent_mm ? m : *dent_mm;
        }
    }
    uint64_t h = 1469598103934665603ull;
    h = fnv_floats(h, g_skin.x, g_skin.count);
    h = fnv_floats(h, g_skin.y, g_skin.count);
    h = fnv_floats(h, g_skin.z, g_skin.count);
    h = fnv_floats(h, g_skin.vx, g_skin.count);
    h = fnv_floats(h, g_skin.vy, g_skin.count);
    return fnv_floats(h, g_skin.vz, g_skin.count);
}

/* Every variant gives the generic variant's bits for the skin's substep. */
static void skin_variants_give_identical_bits(void **state)
{
    (void)state;
    const sc_simd best = sc_cpu_best_simd();
    static const uint32_t shapes[2][2] = {{32u, 16u}, {37u, 19u}};
    int compared = 0;
    for (uint32_t sh = 0; sh < 2u; sh++) {
        assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
        float dent = 0.0f;
        const uint64_t ref = run_skin(shapes[sh][0], shapes[sh][1], &dent);
        assert_true(dent > 1.0f); /* the sphere did press the skin */
        for (int v = 1; v < (int)SC_SIMD_COUNT; v++) {
            if (!sc_simd_built((sc_simd)v) || v > (int)best) {
                continue;
            }
            assert_int_equal(sc_simd_select((sc_simd)v), SC_OK);
            float dv = 0.0f;
            const uint64_t h = run_skin(shapes[sh][0], shapes[sh][1], &dv);
            printf("# skin %ux%u: generic %016llx (dent %.3f mm), %s %016llx\n", shapes[sh][0],
                   shapes[sh][1], (unsigned long long)ref, (double)dent,
                   sc_simd_name((sc_simd)v), (unsigned long long)h);
            assert_true(h == ref);
            compared++;
        }
    }
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    printf("# %d skin comparisons (best variant here: %s)\n", compared, sc_simd_name(best));
}

static void selection_refuses_what_is_not_there(void **state)
{
    (void)state;
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    assert_int_equal(sc_simd_selected(), SC_SIMD_GENERIC);
    assert_int_equal(sc_simd_select(SC_SIMD_COUNT), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_select((sc_simd)-1), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_selected(), SC_SIMD_GENERIC);
    assert_int_equal(sc_simd_built(SC_SIMD_GENERIC), 1);
    assert_int_equal(sc_simd_built(SC_SIMD_COUNT), 0);
    assert_string_equal(sc_simd_name(SC_SIMD_COUNT), "?");
    for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
        const int rc = sc_simd_select((sc_simd)v);
        assert_int_equal(rc, sc_simd_built((sc_simd)v) ? SC_OK : SC_ERR_NOT_SUPPORTED);
        assert_int_equal(sc_simd_selected(), rc == SC_OK ? (sc_simd)v : SC_SIMD_GENERIC);
        assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
    }
    /* the host helper: the best is built, and an unknown override is refused (best kept) */
    const sc_simd best = sc_cpu_best_simd();
    assert_int_equal(sc_simd_built(best), 1);
    assert_int_equal(setenv("SONOCOMP_SIMD", "no-such-level", 1), 0);
    assert_int_equal(sc_cpu_select_simd(), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_selected(), best);
    assert_int_equal(setenv("SONOCOMP_SIMD", "generic", 1), 0);
    assert_int_equal(sc_cpu_select_simd(), SC_OK);
    assert_int_equal(sc_simd_selected(), SC_SIMD_GENERIC);
    assert_int_equal(unsetenv("SONOCOMP_SIMD"), 0);
    assert_int_equal(sc_cpu_select_simd(), SC_OK);
    assert_int_equal(sc_simd_selected(), best);
    assert_int_equal(sc_simd_select(SC_SIMD_GENERIC), SC_OK);
}

/* The mat-vec's prefetch choice: an invalid one is refused and leaves the selection; the host
 * helper takes SONOCOMP_PREFETCH (an unknown value refused, the mesh rule kept), and measured,
 * reports both times and picks by its own margin rule (what it picks is this CPU's, not
 * asserted). */
static void prefetch_selection_refuses_what_is_not_there(void **state)
{
    (void)state;
    assert_int_equal(sc_simd_selected_prefetch(), SC_SIMD_PREFETCH_MESH);
    assert_int_equal(sc_simd_select_prefetch(SC_SIMD_PREFETCH_OFF), SC_OK);
    assert_int_equal(sc_simd_select_prefetch(SC_SIMD_PREFETCH_COUNT), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_select_prefetch((sc_simd_prefetch)-1), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_selected_prefetch(), SC_SIMD_PREFETCH_OFF);
    assert_string_equal(sc_simd_prefetch_name(SC_SIMD_PREFETCH_MESH), "mesh");
    assert_string_equal(sc_simd_prefetch_name(SC_SIMD_PREFETCH_COUNT), "?");
    sc_cpu_prefetch pf;
    char line[160];
    assert_int_equal(setenv("SONOCOMP_PREFETCH", "sometimes", 1), 0);
    assert_int_equal(sc_cpu_select_prefetch(1, &pf), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_simd_selected_prefetch(), SC_SIMD_PREFETCH_MESH);
    assert_int_equal(pf.measured, 0);
    assert_int_equal(pf.forced, 0);
    assert_int_equal(setenv("SONOCOMP_PREFETCH", "on", 1), 0);
    assert_int_equal(sc_cpu_select_prefetch(1, &pf), SC_OK);
    assert_int_equal(sc_simd_selected_prefetch(), SC_SIMD_PREFETCH_ON);
    assert_int_equal(pf.forced, 1);
    assert_int_equal(pf.measured, 0);
    sc_cpu_prefetch_describe(&pf, line, sizeof line);
    assert_non_null(strstr(line, "SONOCOMP_PREFETCH"));
    assert_int_equal(unsetenv("SONOCOMP_PREFETCH"), 0);
    assert_int_equal(sc_cpu_select_prefetch(0, &pf), SC_OK);
    assert_int_equal(sc_simd_selected_prefetch(), SC_SIMD_PREFETCH_MESH);
    assert_int_equal(sc_cpu_select_prefetch(1, &pf), SC_OK);
#if !SC_GRID_COARSE
    /* a build without sc_grid_init_box (the small limits) does not measure: the mesh rule */
    assert_int_equal(pf.measured, 0);
    assert_int_equal(pf.chosen, SC_SIMD_PREFETCH_MESH);
    return;
#endif
    assert_int_equal(pf.measured, 1);
    assert_true(pf.on_ms > 0.0 && pf.on_ms < 1e3 && pf.off_ms > 0.0 && pf.off_ms < 1e3);
    const sc_simd_prefetch want = pf.off_ms < pf.on_ms * (1.0 - SC_CPU_PREFETCH_MARGIN)
                                      ? SC_SIMD_PREFETCH_OFF
                                      : SC_SIMD_PREFETCH_MESH; /* never on for every mesh */
    assert_int_equal(pf.chosen, want);
    assert_int_equal(sc_simd_selected_prefetch(), want);
    sc_cpu_prefetch_describe(&pf, line, sizeof line);
    print_message("%s\n", line);
    assert_non_null(strstr(line, "measured"));
    assert_int_equal(sc_simd_select_prefetch(SC_SIMD_PREFETCH_MESH), SC_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(variants_give_identical_bits),
        cmocka_unit_test(implicit_solver_variants_give_identical_bits),
        cmocka_unit_test(skin_variants_give_identical_bits),
        cmocka_unit_test(springs_one_pass_gives_the_two_pass_bits),
        cmocka_unit_test(face_sums_by_pair_give_the_whole_vector_bits),
        cmocka_unit_test(selection_refuses_what_is_not_there),
        cmocka_unit_test(prefetch_selection_refuses_what_is_not_there),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
