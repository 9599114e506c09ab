/* test_sc_tissue.c: the soft-tissue facade: rest, clinical behaviour (MSDS and FEM), MSDS/FEM
 * comparison, determinism, method switch, stability guard. Scene: sc_test_tissue_scene.h. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

static sc_tissue g_t;    /* ~13 MB: static */
static sc_nodes g_snap;  /* a saved node state */
static sc_nodes g_snap2;
static sc_test_scene g_scene;

static void init_scene_n(uint8_t vein_label, sc_tissue_method m, uint32_t nx, uint32_t ny,
                         uint32_t nz)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.vein_label = vein_label;
    p.nx = nx;
    p.ny = ny;
    p.nz = nz;
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d = sc_test_scene_tissue_def(&g_scene, m);
    sc_material_table mat;
    sc_material_table_default(&mat);
    assert_int_equal(sc_tissue_init(&g_t, &d, &g_scene.vol, &mat, SC_LABEL_FAT), SC_OK);
}

static void init_scene(uint8_t vein_label, sc_tissue_method m)
{
    init_scene_n(vein_label, m, 32u, 16u, 16u);
}

static float box_max_mm(void)
{
    const float *s = g_scene.p.size_mm;
    return fmaxf(s[0], fmaxf(s[1], s[2]));
}

static float max_dev_from_rest_mm(void)
{
    float m = 0.0f;
    for (uint32_t i = 0; i < g_t.mesh.node_count; i++) {
        const float dx = g_t.nodes.x[i] - g_t.mesh.rest_x[i];
        const float dy = g_t.nodes.y[i] - g_t.mesh.rest_y[i];
        const float dz = g_t.nodes.z[i] - g_t.mesh.rest_z[i];
        m = fmaxf(m, sqrtf(dx * dx + dy * dy + dz * dz));
    }
    return m;
}

static float max_jump_mm(const sc_nodes *a, const sc_nodes *b)
{
    float m = 0.0f;
    for (uint32_t i = 0; i < g_t.mesh.node_count; i++) {
        const float dx = a->x[i] - b->x[i], dy = a->y[i] - b->y[i], dz = a->z[i] - b->z[i];
        m = fmaxf(m, sqrtf(dx * dx + dy * dy + dz * dz));
    }
    return m;
}

/* Deformed / rest volume of the tets with this label whose rest centroid is under the probe
 * (inside its face in x, within the middle half of its elevation in y). */
static double label_volume_ratio(uint8_t label)
{
    double v = 0.0, r = 0.0;
    const sc_test_scene_params *p = &g_scene.p;
    for (uint32_t e = 0; e < g_t.mesh.tet_count; e++) {
        if (g_t.mesh.tet_label[e] != label) {
            continue;
        }
        const uint32_t *tv = g_t.mesh.tet[e];
        float cx = 0.0f, cy = 0.0f;
        for (int a = 0; a < 4; a++) {
            cx += 0.25f * g_t.mesh.rest_x[tv[a]];
            cy += 0.25f * g_t.mesh.rest_y[tv[a]];
        }
        if (fabsf(cx - p->probe_x_mm) > p->probe_half_mm[0] ||
            fabsf(cy - p->probe_y_mm) > 0.5f * p->probe_half_mm[1]) {
            continue;
        }
        r += (double)sc_mesh_tet_volume_mm3(g_t.mesh.rest_x, g_t.mesh.rest_y, g_t.mesh.rest_z,
                                            tv);
        v += (double)sc_mesh_tet_volume_mm3(g_t.nodes.x, g_t.nodes.y, g_t.nodes.z, tv);
    }
    assert_true(r > 0.0);
    return v / r;
}

/* Press the probe from 0.5 mm above the skin to press_mm below it over ramp frames, then hold
 * for hold frames (each frame is 20 x 0.01 s = 0.2 s of simulated time). */
static void press(float press_mm, int ramp, int hold)
{
    for (int f = 0; f < ramp + hold; f++) {
        const float k = f < ramp ? (float)(f + 1) / (float)ramp : 1.0f;
        const sc_pose pose = sc_test_scene_probe(&g_scene, -0.5f + (press_mm + 0.5f) * k);
        const int rc = sc_tissue_step(&g_t, &pose);
        assert_int_equal(rc, SC_OK);
    }
}

/* ---- rest ---------------------------------------------------------------------------------- */

/* No probe, 1,000 frames: no node moves more than 1e-5 of the box size (the rest state is an
 * exact equilibrium of both solvers; the bound leaves room for rounding only). The scene at
 * 16 x 8 x 8 nodes (same materials, same code paths) keeps the sanitizer build fast. The
 * lumens' drive is off (blood pressures at their means): pulse and breath move the vessels by
 * design (test_vessel_drive). */
static void rest_stays_rest_for_1000_frames_msds_and_fem(void **state)
{
    (void)state;
    for (int m = 0; m < 2; m++) {
        init_scene_n(SC_LABEL_VEIN, m ? SC_TISSUE_FEM : SC_TISSUE_MSDS, 16u, 8u, 8u);
        sc_lumen_drive d = sc_lumen_drive_default();
        d.heart_rate_bpm = 0.0f;
        d.resp_rate_bpm = 0.0f;
        assert_int_equal(sc_tissue_set_drive(&g_t, &d), SC_OK);
        for (int f = 0; f < 1000; f++) {
            assert_int_equal(sc_tissue_step(&g_t, NULL), SC_OK);
        }
        assert_true(max_dev_from_rest_mm() <= 1e-5f * box_max_mm());
        assert_int_equal(g_t.stats.faults, 0);
    }
}

/* ---- clinical behaviour --------------------------------------------------------------------- */

typedef struct clinical {
    double vein, artery;   /* volume ratios under the probe at full press */
    float dev_after_2s_mm; /* max |x - X| 1 s (60 frames) after the probe lifted */
} clinical;

static clinical run_clinical(uint8_t vein_label, sc_tissue_method m)
{
    init_scene(vein_label, m);
    /* 15% of the block's depth over 40 frames (8 s simulated, 2/3 s real time at 60 Hz),
     * held 20 frames (4 s simulated: both methods settle within ~1 s) */
    press(0.15f * g_scene.p.size_mm[2], 40, 20);
    clinical c;
    c.vein = label_volume_ratio(vein_label);
    c.artery = label_volume_ratio(SC_LABEL_ARTERY);
    for (int f = 0; f < 60; f++) { /* 1 s at 60 Hz */
        (void)sc_tissue_step(&g_t, NULL);
    }
    c.dev_after_2s_mm = max_dev_from_rest_mm();
    return c;
}

static void check_clinical(sc_tissue_method m, int *ok)
{
    const clinical a = run_clinical(SC_LABEL_VEIN, m);
    const clinical b = run_clinical(SC_LABEL_THROMBUS, m);
    const float tol = 0.4f; /* the issue's recovery criterion: 0.4 mm within 1 s */
    print_message("%s, 15%% press: vein -%.0f%%, artery -%.0f%%, thrombosed vein -%.0f%% "
                  "(artery -%.0f%%); 1 s (60 frames) after lift max deviation %.3f / %.3f mm "
                  "(limit %.2f)\n",
                  m == SC_TISSUE_MSDS ? "MSDS" : "FEM", 100.0 * (1.0 - a.vein),
                  100.0 * (1.0 - a.artery), 100.0 * (1.0 - b.vein), 100.0 * (1.0 - b.artery),
                  (double)a.dev_after_2s_mm, (double)b.dev_after_2s_mm, (double)tol);
    *ok = 1.0 - a.vein >= 0.60 && 1.0 - a.artery <= 0.20 && 1.0 - b.vein <= 0.20 &&
          a.dev_after_2s_mm <= tol && b.dev_after_2s_mm <= tol;
}

/* The brief's criteria: the vein's tets under the probe lose at least 60% of their volume,
 * the artery's at most 20%, a thrombosed vein's at most 20%; 1 s (60 frames) after the lift
 * every node is within 0.4 mm of its rest position (issue 12's recovery criterion; it was 10
 * frames and 1% of the box, 0.4 mm, before the sides went on rollers, which relax more
 * slowly under the fixed CG count). */
static void clinical_fem_vein_collapses_artery_and_thrombus_resist(void **state)
{
    (void)state;
    int ok = 0;
    check_clinical(SC_TISSUE_FEM, &ok);
    assert_true(ok);
}

static void clinical_msds_vein_collapses_artery_and_thrombus_resist(void **state)
{
    (void)state;
    /* default MSDS: Algorithm 1's springs plus the volume term (sc_msds.h); without the
     * volume term the top cell layer folds and this fails (vein -17%, 7.9 mm after 2 s) */
    int ok = 0;
    check_clinical(SC_TISSUE_MSDS, &ok);
    assert_true(ok);
}

/* ---- MSDS vs FEM ---------------------------------------------------------------------------- */

/* The paper's claim (section III-A): with k = 0.002 E the MSDS responds like the FEM. Same
 * scene, same 1.5 mm (5%) press where neither method inverts elements: compare the settled
 * displacement fields, node by node. */
static void msds_and_fem_give_a_similar_indentation_response(void **state)
{
    (void)state;
    const float press_mm = 0.05f * 30.0f;
    init_scene(SC_LABEL_VEIN, SC_TISSUE_FEM);
    press(press_mm, 20, 30);
    g_snap = g_t.nodes;
    init_scene(SC_LABEL_VEIN, SC_TISSUE_MSDS);
    press(press_mm, 20, 30);
    double num = 0.0, den = 0.0, uf_max = 0.0, um_max = 0.0;
    double depth_f = 0.0, depth_m = 0.0; /* mean displacement along z of the nodes at 10 mm */
    uint32_t nd = 0;
    for (uint32_t i = 0; i < g_t.mesh.node_count; i++) {
        const double uf[3] = {(double)g_snap.x[i] - g_t.mesh.rest_x[i],
                              (double)g_snap.y[i] - g_t.mesh.rest_y[i],
                              (double)g_snap.z[i] - g_t.mesh.rest_z[i]};
        const double um[3] = {(double)g_t.nodes.x[i] - g_t.mesh.rest_x[i],
                              (double)g_t.nodes.y[i] - g_t.mesh.rest_y[i],
                              (double)g_t.nodes.z[i] - g_t.mesh.rest_z[i]};
        for (int a = 0; a < 3; a++) {
            num += (um[a] - uf[a]) * (um[a] - uf[a]);
            den += uf[a] * uf[a];
        }
        uf_max = fmax(uf_max, fabs(uf[2]));
        um_max = fmax(um_max, fabs(um[2]));
        if (fabsf(g_t.mesh.rest_z[i] - 10.0f) < 1.0f &&
            fabsf(g_t.mesh.rest_x[i] - 20.0f) < 16.0f && fabsf(g_t.mesh.rest_y[i] - 10.0f) < 3.0f) {
            depth_f += uf[2];
            depth_m += um[2];
            nd++;
        }
    }
    const double rel = sqrt(num / den);
    print_message("5%% press: relative L2 difference MSDS vs FEM displacement %.2f; max |uz| "
                  "FEM %.2f MSDS %.2f mm; mean uz at 10 mm depth under the probe FEM %.2f MSDS "
                  "%.2f mm\n", rel, uf_max, um_max, depth_f / nd, depth_m / nd);
    /* Bound: the two models still differ by construction (a spring lattice with a volume
     * term against linear tets; measured: L2 difference 0.15, depth ratio 1.12), so
     * "similar" is asserted as: the press transmitted to 10 mm depth within 25% (ratio
     * 0.8..1.25) and a field difference below 30% of the FEM field (a sign error, a 2x
     * scale error or a missing load path all break one of them). */
    assert_true(depth_f > 0.0 && depth_m > 0.0);
    assert_true(depth_m / depth_f >= 0.8 && depth_m / depth_f <= 1.25);
    assert_true(rel < 0.3);
}

/* ---- determinism, switch, guard --------------------------------------------------------------- */

static uint64_t scripted_run(void)
{
    init_scene(SC_LABEL_VEIN, SC_TISSUE_MSDS);
    press(1.5f, 10, 5);
    assert_int_equal(sc_tissue_set_method(&g_t, SC_TISSUE_FEM), SC_OK);
    press(2.0f, 5, 5);
    assert_int_equal(sc_tissue_set_method(&g_t, SC_TISSUE_MSDS), SC_OK);
    for (int f = 0; f < 5; f++) {
        (void)sc_tissue_step(&g_t, NULL);
    }
    return sc_tissue_state_hash(&g_t);
}

/* The same inputs twice from a fresh init: bit-identical state. */
static void same_inputs_give_a_bit_identical_state_hash(void **state)
{
    (void)state;
    const uint64_t a = scripted_run();
    const uint64_t b = scripted_run();
    print_message("state hash %016llx\n", (unsigned long long)a);
    assert_true(a == b);
    /* and the hash sees a change of a single bit of state */
    g_t.nodes.x[100] = nextafterf(g_t.nodes.x[100], 1e9f);
    assert_true(sc_tissue_state_hash(&g_t) != b);
}

/* MSDS only (the FEM's numerics belong to its own test): a fixed press-and-lift script gives
 * a stored hash in every build type, so that a change in the MSDS/collider/skin numerics is a
 * visible decision (update the constant with the printed value when it is intended). */
/* last changed: the cell kernels adding straight into the matrix, a node's sums in cell order
 * (sc_grid.h; was 0xe58b5e38327c322f); before: the implicit step's matrix keeping a compressed spring's transverse stiffness
 * as its magnitude (sc_msds_implicit.h; was 0xa85e0a65090c3628); before: the lumen law's relaxation bound counting the lumen's own tets and an
 * artery's law per section (sc_lumen.h; was 0x98ba99b323b4b2d8); before: the derived springs
 * fitted to the cell's shape (sc_msds.c derived_fit; was 0x0f04ba6a7df745dc); before: the vessel lumens' pressure-volume law and drive (sc_lumen.h; the scene's
 * vessels are lumens now, the artery's material 30 kPa; was 0xbdf8e7a95468d602); before: the
 * stable MSDS on the grid matrix (sc_grid.h) with 10 CG iterations per frame and the unloaded
 * warm start toward rest (was 0x788e35cb4030fa42) */
#define SC_TISSUE_MSDS_HASH UINT64_C(0x20e4144ec5e46309)
static void msds_script_matches_the_stored_state_hash(void **state)
{
    (void)state;
    init_scene(SC_LABEL_VEIN, SC_TISSUE_MSDS);
    press(1.5f, 10, 5);
    for (int f = 0; f < 5; f++) {
        (void)sc_tissue_step(&g_t, NULL);
    }
    const uint64_t h = sc_tissue_state_hash(&g_t);
    print_message("MSDS script state hash %016llx\n", (unsigned long long)h);
    assert_true(h == SC_TISSUE_MSDS_HASH);
}

/* The same script with the paper's explicit Euler and Algorithm 1's springs (kept
 * selectable so its tables can be reproduced): its own stored hash. */
/* last changed: the explicit step's per-axis supports (a node on rollers keeps its free axes,
 * sc_msds.h roller) and the lumen changes above (was 0x4acf9dda9b9ca19b); before: the lumen
 * law and drive, as above (was 0x888047e7dd91e1a4) */
#define SC_TISSUE_MSDS_EXPLICIT_HASH UINT64_C(0xbb5b87ac520322b3)
static void explicit_msds_script_matches_the_stored_state_hash(void **state)
{
    (void)state;
    sc_test_scene_params p = sc_test_scene_default_params();
    p.vein_label = SC_LABEL_VEIN;
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def td = sc_test_scene_tissue_def(&g_scene, SC_TISSUE_MSDS);
    td.msds.integrator = (uint8_t)SC_MSDS_EXPLICIT;
    td.msds.springs = (uint8_t)SC_MSDS_SPRINGS_PAPER;
    td.msds.volume_stiffness_ratio = 6.0f; /* the former calibration of the paper's springs */
    sc_material_table mat;
    sc_material_table_default(&mat);
    assert_int_equal(sc_tissue_init(&g_t, &td, &g_scene.vol, &mat, SC_LABEL_FAT), SC_OK);
    press(1.5f, 10, 5);
    for (int f = 0; f < 5; f++) {
        (void)sc_tissue_step(&g_t, NULL);
    }
    const uint64_t h = sc_tissue_state_hash(&g_t);
    print_message("explicit MSDS script state hash %016llx\n", (unsigned long long)h);
    assert_true(h == SC_TISSUE_MSDS_EXPLICIT_HASH);
}

/* Switching the method mid-compression keeps the shape: in the frame of the switch no node
 * moves more than 1 mm (with the probe held still). Both directions. */
static void method_switch_mid_compression_does_not_jump(void **state)
{
    (void)state;
    for (int dir = 0; dir < 2; dir++) {
        const sc_tissue_method from = dir ? SC_TISSUE_FEM : SC_TISSUE_MSDS;
        const sc_tissue_method to = dir ? SC_TISSUE_MSDS : SC_TISSUE_FEM;
        init_scene(SC_LABEL_VEIN, from);
        const float press_mm = 1.5f; /* 5% of the depth: both methods stay inversion-free */
        press(press_mm, 20, 40); /* settled: the sides on rollers relax more slowly */
        g_snap2 = g_t.nodes;
        const sc_pose still = sc_test_scene_probe(&g_scene, press_mm);
        assert_int_equal(sc_tissue_step(&g_t, &still), SC_OK);
        const float before = max_jump_mm(&g_snap2, &g_t.nodes);
        const sc_nodes *addr = &g_t.nodes;
        g_snap = g_t.nodes;
        assert_int_equal(sc_tissue_set_method(&g_t, to), SC_OK);
        const sc_pose pose = sc_test_scene_probe(&g_scene, press_mm);
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
        const float jump = max_jump_mm(&g_snap, &g_t.nodes);
        g_snap2 = g_t.nodes;
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
        print_message("switch %s -> %s at %.1f mm press: largest node move in the frame before "
                      "%.3f mm, in the switch frame %.3f mm, after %.3f mm\n", dir ? "FEM" : "MSDS",
                      dir ? "MSDS" : "FEM", (double)press_mm, (double)before, (double)jump,
                      (double)max_jump_mm(&g_snap2, &g_t.nodes));
        assert_true(jump <= 1.0f);
        assert_ptr_equal(addr, &g_t.nodes); /* same storage, nothing rebuilt */
    }
}

/* A NaN or an infinity resets the tissue to rest with a named fault, and the diverged values
 * never stay in the state that the image reads. A finite runaway (every free node at 10 m/s)
 * needs no reset with the implicit step: its step clamp holds every free node to two cell
 * diagonals per step (the explicit MSDS's runaway bound: test_sc_msds). */
static void guard_resets_on_nan_or_inf_and_the_step_clamp_holds_a_runaway(void **state)
{
    (void)state;
    init_scene(SC_LABEL_VEIN, SC_TISSUE_MSDS);
    press(1.0f, 5, 0);
    {
        for (uint32_t j = 0; j < g_t.mesh.node_count; j++) {
            if (!g_t.mesh.node_fixed[j]) {
                g_t.nodes.vz[j] = 1e4f;
            }
        }
        g_snap2 = g_t.nodes;
        const uint32_t faults = g_t.stats.faults;
        const sc_pose pose = sc_test_scene_probe(&g_scene, 1.0f);
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
        assert_int_equal(g_t.stats.faults, faults);
        assert_true(g_t.fem.grid.stats.clamped_nodes > 0u);
        const float moved = max_jump_mm(&g_snap2, &g_t.nodes);
        print_message("runaway: %u nodes clamped, largest move %.3f mm (bound %.3f mm)\n",
                      g_t.fem.grid.stats.clamped_nodes, (double)moved,
                      (double)g_t.fem.grid.step_max_mm);
        assert_true(moved <= g_t.fem.grid.step_max_mm * 1.001f + 1e-3f);
    }
    for (int k = 0; k < 2; k++) {
        const uint32_t i = 1000u + (uint32_t)k * 7u;
        if (k == 0) {
            g_t.nodes.x[i] = NAN;
        } else if (k == 1) {
            g_t.nodes.vz[i] = INFINITY;
        } else {
            /* finite but runaway: kinetic energy far above every spring at 100% strain */
            for (uint32_t j = 0; j < g_t.mesh.node_count; j++) {
                if (!g_t.mesh.node_fixed[j]) {
                    g_t.nodes.vz[j] = 1e4f;
                }
            }
        }
        const uint32_t faults = g_t.stats.faults;
        const sc_pose pose = sc_test_scene_probe(&g_scene, 1.0f);
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_ERR_PHYS_UNSTABLE);
        assert_int_equal(g_t.stats.faults, faults + 1u);
        assert_true(max_dev_from_rest_mm() <= 0.0f);
        for (uint32_t j = 0; j < g_t.mesh.node_count; j++) {
            assert_true(isfinite(g_t.nodes.x[j]) && isfinite(g_t.nodes.vz[j]));
        }
        assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK); /* and it runs on */
    }
    /* FEM side */
    init_scene(SC_LABEL_VEIN, SC_TISSUE_FEM);
    press(1.0f, 5, 0);
    g_t.nodes.z[2000] = INFINITY;
    const sc_pose pose = sc_test_scene_probe(&g_scene, 1.0f);
    assert_int_equal(sc_tissue_step(&g_t, &pose), SC_ERR_PHYS_UNSTABLE);
    assert_true(max_dev_from_rest_mm() <= 0.0f);
    assert_int_equal(sc_tissue_step(&g_t, &pose), SC_OK);
}

static void implausible_pose_runs_the_frame_without_contact(void **state)
{
    (void)state;
    init_scene(SC_LABEL_VEIN, SC_TISSUE_MSDS);
    sc_lumen_drive d = sc_lumen_drive_default(); /* the vessels at their mean pressures */
    d.heart_rate_bpm = 0.0f;
    d.resp_rate_bpm = 0.0f;
    assert_int_equal(sc_tissue_set_drive(&g_t, &d), SC_OK);
    sc_pose pose = sc_test_scene_probe(&g_scene, 2.0f);
    pose.q[0] = 0.5f; /* not a unit quaternion */
    assert_int_equal(sc_tissue_step(&g_t, &pose), SC_ERR_POSE_IMPLAUSIBLE);
    assert_int_equal(g_t.stats.contacts, 0);
    assert_true(max_dev_from_rest_mm() <= 0.0f);
    assert_int_equal(sc_tissue_set_method(&g_t, (sc_tissue_method)7), SC_ERR_INVALID_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rest_stays_rest_for_1000_frames_msds_and_fem),
        cmocka_unit_test(clinical_fem_vein_collapses_artery_and_thrombus_resist),
        cmocka_unit_test(clinical_msds_vein_collapses_artery_and_thrombus_resist),
        cmocka_unit_test(msds_and_fem_give_a_similar_indentation_response),
        cmocka_unit_test(same_inputs_give_a_bit_identical_state_hash),
        cmocka_unit_test(msds_script_matches_the_stored_state_hash),
        cmocka_unit_test(explicit_msds_script_matches_the_stored_state_hash),
        cmocka_unit_test(method_switch_mid_compression_does_not_jump),
        cmocka_unit_test(guard_resets_on_nan_or_inf_and_the_step_clamp_holds_a_runaway),
        cmocka_unit_test(implausible_pose_runs_the_frame_without_contact),
    };
    const char *filter = getenv("SC_TEST_FILTER"); /* e.g. "method_switch*" */
    if (filter != NULL) {
        cmocka_set_test_filter(filter);
    }
    return cmocka_run_group_tests(tests, NULL, NULL);
}
