/*
 * test_press_sweep.c: the compression exam on the three phantom cases (neck-ijv, femoral,
 * femoral-dvt, built by the `cases` target into the build tree), whole engine on the host
 * simulator, both methods: the probe presses over the vessels from 0 to the deepest press in
 * 2 mm steps (ramp 0.25 s, hold 0.5 s), then lifts. Checked: no physics fault and no guard
 * reset at any step, every state finite, and 1 s after the lift every node back within
 * 0.4 mm of rest (on every mesh, 32x16x16 too); at 16 mm a normal vein coapts (image-area ratio <= 0.05), the artery keeps
 * >= 0.75 of its area and a thrombosed vein >= 0.8; the ratios fall monotonically with the
 * press (tolerance 0.01). Printed (the issue's press table): the image-area ratios of the
 * vein, the artery and the thrombus at the end of each hold.
 */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_engine.h"
#include "sc_health.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_test_press.h"
#include "sc_labels.h"
#include "sc_storage_linux.h"
#include "sc_tissue.h"
#include "sc_trkemu.h"
#include "sc_bscan.h"

static sc_hs_rig rig;
static sc_emu emu;
static sc_storage_linux storage;
#define MAX_ROWS 256u
static sc_emu_row rows[MAX_ROWS];

#define STEP_MM  2.0f
#define RAMP_S   0.25
#define HOLD_S   0.5
#define HOVER_MM 3.0f

typedef struct sweep_point {
    float depth_mm, vein, artery, thrombus;
    uint32_t inverted;     /* tets with V <= 0 at the end of the hold */
    uint32_t inverted_max; /* most in any frame of the step (ramp and hold) */
} sweep_point;

/* tets turned inside out (V <= 0) in the active tissue */
static uint32_t inverted_tets(void)
{
    const sc_tissue *t = &rig.engine.tissue[rig.engine.active];
    uint32_t inv = 0;
    for (uint32_t k = 0; k < t->mesh.tet_count; k++) {
        inv += sc_mesh_tet_volume_mm3(t->nodes.x, t->nodes.y, t->nodes.z, t->mesh.tet[k]) > 0.0f
                   ? 0u
                   : 1u;
    }
    return inv;
}

/* the compression exam without pulse and breathing (the lumen pressures at their means) */
static void drive_off(void)
{
    sc_lumen_drive d = sc_lumen_drive_default();
    d.heart_rate_bpm = 0.0f;
    d.resp_rate_bpm = 0.0f;
    assert_int_equal(sc_tissue_set_drive(&rig.engine.tissue[rig.engine.active], &d), SC_OK);
}

static void rig_up(const char *case_file, sc_tissue_method m)
{
    sc_test_press_rig_up(&rig, &storage, SC_BINARY_DIR "/cases", case_file, m);
    drive_off();
}

static void frame(uint64_t t0, int *more)
{
    sc_test_press_frame(&rig, &emu, t0, more);
}

static int state_finite(void)
{
    return sc_test_press_state_finite(&rig);
}

static float max_dev_from_rest_mm(void)
{
    return sc_test_press_max_dev_mm(&rig);
}

static float ratio(const sc_bscan_status *b, uint32_t label)
{
    return b->areas_valid ? b->area_ratio[label] : -1.0f;
}

/* diagnosis (SC_PRESS_DEBUG): the largest displacement, its node, inverted tets by label */
static void debug_frame(uint32_t step, uint32_t f)
{
    const sc_tissue *t = &rig.engine.tissue[rig.engine.active];
    const sc_mesh *m = &t->mesh;
    const sc_nodes *n = &t->nodes;
    float best = 0.0f;
    uint32_t bi = 0;
    for (uint32_t i = 0; i < m->node_count; i++) {
        const float dx = n->x[i] - m->rest_x[i], dy = n->y[i] - m->rest_y[i],
                    dz = n->z[i] - m->rest_z[i];
        const float d = sqrtf(dx * dx + dy * dy + dz * dz);
        if (d > best) {
            best = d;
            bi = i;
        }
    }
    uint32_t inv[16] = {0};
    uint32_t near_inv = 0;
    uint32_t lab_of_best = 0xFF;
    for (uint32_t k = 0; k < m->tet_count; k++) {
        const float v = sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[k]);
        const int has = m->tet[k][0] == bi || m->tet[k][1] == bi || m->tet[k][2] == bi ||
                        m->tet[k][3] == bi;
        if (has) {
            lab_of_best = m->tet_label[k];
        }
        if (!(v > 0.0f)) {
            inv[m->tet_label[k] & 15u]++;
            near_inv += has ? 1u : 0u;
        }
    }
    if (f == 40u && getenv("SC_PRESS_HIST") != NULL) {
        /* where the inverted tets are: rest centroid histogram in z (2 mm bins) and |y| */
        uint32_t hz_[20] = {0}, hy_[12] = {0};
        for (uint32_t k = 0; k < m->tet_count; k++) {
            if (sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[k]) > 0.0f) {
                continue;
            }
            float cy = 0.0f, cz = 0.0f;
            for (uint32_t a = 0; a < 4u; a++) {
                cy += 0.25f * m->rest_y[m->tet[k][a]];
                cz += 0.25f * m->rest_z[m->tet[k][a]];
            }
            hz_[(uint32_t)fminf(19.0f, fmaxf(0.0f, cz / 2.0f))]++;
            hy_[(uint32_t)fminf(11.0f, fabsf(cy))]++;
        }
        print_message("hist step %u z:", step);
        for (uint32_t b = 0; b < 20u; b++) {
            print_message(" %u", hz_[b]);
        }
        print_message(" | |y|:");
        for (uint32_t b = 0; b < 12u; b++) {
            print_message(" %u", hy_[b]);
        }
        print_message("\n");
    }
    if (f % 8u == 0u || best > 0.8f * t->box_diag_mm || step == 999u) {
        print_message("dbg step %u f %u maxd %.2f (diag %.1f) node %u rest %.1f %.1f %.1f -> "
                      "%.1f %.1f %.1f lab %u inv-adj %u fixed %u | inv vein %u art %u fat %u "
                      "mus %u thr %u other %u | faults %u\n",
                      step, f, (double)best, (double)t->box_diag_mm, bi, (double)m->rest_x[bi],
                      (double)m->rest_y[bi], (double)m->rest_z[bi], (double)n->x[bi],
                      (double)n->y[bi], (double)n->z[bi], lab_of_best, near_inv,
                      m->node_fixed[bi], inv[SC_LABEL_VEIN], inv[SC_LABEL_ARTERY],
                      inv[SC_LABEL_FAT], inv[SC_LABEL_MUSCLE], inv[SC_LABEL_THROMBUS],
                      inv[SC_LABEL_SKIN] + inv[SC_LABEL_NERVE], t->stats.faults);
    }
}

/* The loaded case's tissue again on a finer mesh (the same box, nx x ny x nz nodes), as the
 * engine builds it at case load. */
static void remesh(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_tissue_def td = rig.engine.tissue[rig.engine.active].def;
    td.mesh.nx = nx;
    td.mesh.ny = ny;
    td.mesh.nz = nz;
    if (getenv("SC_PRESS_WIDE_Y") != NULL) {
        /* diagnosis: the box widened in y (the probe's elevation axis) */
        const float w = (float)atof(getenv("SC_PRESS_WIDE_Y"));
        td.mesh.origin_mm[1] -= 0.5f * (w - td.mesh.size_mm[1]);
        td.mesh.size_mm[1] = w;
    }
    const sc_material_table mat = rig.engine.tissue[rig.engine.active].mat;
    assert_int_equal(sc_tissue_init(&rig.engine.tissue[rig.engine.active], &td, &rig.engine.slot.c.volume, &mat,
                                    (uint8_t)SC_LABEL_FAT),
                     SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&rig.engine.bscan, &rig.engine.tissue[rig.engine.active].mesh), SC_OK);
    drive_off();
}

static void sweep_mesh(const char *case_name, sc_tissue_method m, uint32_t fine)
{
    char file[64];
    snprintf(file, sizeof file, "%s.scase", case_name);
    rig_up(file, m);
    if (fine) {
        remesh(32u, 16u, 16u);
    }
    const sc_case *cs = &rig.engine.slot.c;
    /* the probe over the middle of the mesh's top (the phantoms centre their vessels there),
     * beam down; the deepest press stops 8 mm above the mesh's fixed bottom */
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_emu_def ed = sc_emu_default_def();
    float top[3];
    sc_xform_apply(&v2t, p_vol, top);
    const uint32_t steps = (uint32_t)((cs->mesh.size_mm[2] - 8.0f) / STEP_MM);
    size_t n = 0;
    double t = 0.0;
    for (uint32_t s = 0; s <= steps && n + 3u < MAX_ROWS; s++) {
        /* tracker frame: pressing is -z (sc_trkemu's press script) */
        const float d = (s == 0u ? -HOVER_MM : STEP_MM * (float)s);
        sc_emu_row r = {t, {top[0], top[1], top[2] - d}, {0, 0, 0, 0}, -1.0f};
        memcpy(r.q, ed.base_q, sizeof r.q);
        rows[n++] = r;
        t += HOLD_S;
        r.t_s = t;
        rows[n++] = r;
        t += RAMP_S;
    }
    sc_emu_row up = rows[0];
    up.t_s = t;
    rows[n++] = up;
    up.t_s = t + 2.0;
    rows[n++] = up;
    ed.script = SC_EMU_CSV;
    ed.rows = rows;
    ed.n_rows = n;
    ed.duration_s = t + 2.0;
    assert_int_equal(sc_emu_init(&emu, &ed), SC_OK);

    const uint64_t t0 = rig.clock.now_ns;
    int more = 1;
    const uint32_t hz = rig.engine.def.sched.rate_hz;
    sweep_point pts[64];
    uint32_t np = 0;
    for (uint32_t s = 0; s <= steps && s < 64u; s++) {
        const uint32_t frames = (uint32_t)((s == 0u ? HOLD_S : RAMP_S + HOLD_S) * hz);
        uint32_t inv_max = 0;
        for (uint32_t f = 0; f < frames; f++) {
            frame(t0, &more);
            assert_true(state_finite());
            const uint32_t inv = inverted_tets();
            inv_max = inv > inv_max ? inv : inv_max;
            if (getenv("SC_PRESS_DEBUG") != NULL) {
                debug_frame(s, f);
            }
        }
        const sc_bscan_status *b = sc_bscan_status_get(&rig.engine.bscan);
        if (getenv("SC_LUMEN_DEBUG") != NULL) {
            const sc_lumen *lu = &rig.engine.tissue[rig.engine.active].lumen;
            for (uint32_t k = 0; k < lu->count; k++) {
                print_message("    vessel %u label %u tets %u theta %.3f V0 %.0f V %.0f p %.0f\n",
                              k, lu->v[k].label, lu->v[k].tets, (double)lu->v[k].theta,
                              (double)lu->v[k].v0_mm3, (double)lu->v[k].v_mm3,
                              (double)lu->v[k].p_pa);
            }
        }
        pts[np++] = (sweep_point){s == 0u ? 0.0f : STEP_MM * (float)s, ratio(b, SC_LABEL_VEIN),
                                  ratio(b, SC_LABEL_ARTERY), ratio(b, SC_LABEL_THROMBUS),
                                  inverted_tets(), inv_max};
    }
    /* the lift (ramp) and 1 s without contact */
    for (uint32_t f = 0; f < (uint32_t)(RAMP_S * hz) + hz; f++) {
        frame(t0, &more);
        if (getenv("SC_PRESS_DEBUG") != NULL) {
            debug_frame(999u, f);
        }
    }
    const float dev = max_dev_from_rest_mm();
    for (uint32_t f = 0; f < hz; f++) {
        frame(t0, &more);
    }
    const float dev2 = max_dev_from_rest_mm();
    sc_engine_status st;
    sc_engine_get_status(&rig.engine, &st);
    print_message("%s %s, mesh %ux%ux%u: press mm / vein / artery / thrombus image-area ratio "
                  "(-1: not in view) / inverted tets at the hold's end (most in any frame)\n",
                  case_name, m == SC_TISSUE_MSDS ? "msds" : "fem", rig.engine.tissue[rig.engine.active].mesh.nx,
                  rig.engine.tissue[rig.engine.active].mesh.ny, rig.engine.tissue[rig.engine.active].mesh.nz);
    for (uint32_t i = 0; i < np; i++) {
        print_message("  %5.1f  %6.3f  %6.3f  %6.3f  %5u (%u)\n", (double)pts[i].depth_mm,
                      (double)pts[i].vein, (double)pts[i].artery, (double)pts[i].thrombus,
                      pts[i].inverted, pts[i].inverted_max);
    }
    print_message("  1 s after the lift: largest node distance from rest %.3f mm (2 s: %.3f mm); "
                  "resets %llu (last guard %u), faults 0x%04x\n",
                  (double)dev, (double)dev2, (unsigned long long)rig.engine.counters.phys_resets,
                  (unsigned)rig.engine.tissue[rig.engine.active].stats.last_fault,
                  (unsigned)st.faults);
    /* the compression exam at a firm press (16 mm): a normal vein coapts, the artery keeps
     * its area, a thrombosed vein does not collapse; every ratio falls with the press (within
     * 0.01: the image's pixel counts move by a few pixels between steps) */
    int at16 = 0;
    for (uint32_t i = 0; i < np; i++) {
        if (fabsf(pts[i].depth_mm - 16.0f) < 0.01f) {
            at16 = 1;
            assert_true(pts[i].artery >= 0.75f);
            if (pts[i].thrombus >= 0.0f) {
                assert_true(pts[i].thrombus >= 0.8f);
            } else {
                assert_true(pts[i].vein >= 0.0f && pts[i].vein <= 0.05f);
            }
        }
        if (i >= 2u) {
            assert_true(pts[i].vein <= pts[i - 1u].vein + 0.01f);
            assert_true(pts[i].artery <= pts[i - 1u].artery + 0.01f);
            assert_true(pts[i].thrombus <= pts[i - 1u].thrombus + 0.01f);
        }
    }
    assert_true(at16);
    assert_true(rig.engine.counters.phys_resets == 0u);
    assert_true(rig.engine.tissue[rig.engine.active].stats.faults == 0u);
    assert_true((st.faults & ((1u << SC_FAULT_PHYS_UNSTABLE) | (1u << SC_FAULT_PHYS_REPEATED))) ==
                0u);
    /* back to rest within 1 s on every mesh (the unloaded warm start, sc_grid.h; with the plain
     * one the 32x16x16 neck-ijv MSDS was still 0.55 mm off at 1 s) */
    assert_true(dev <= 0.4f);
}

static void sweep(const char *case_name, sc_tissue_method m)
{
    sweep_mesh(case_name, m, 0u);
}

/* the three cases on the 32x16x16 mesh (the paper's largest), both methods */
static void fine_mesh_press_sweeps_have_no_fault_and_show_the_vessels(void **state)
{
    (void)state;
    static const char *const cases[3] = {"neck-ijv", "femoral", "femoral-dvt"};
    const char *only = getenv("SC_PRESS_CASE"); /* one case alone (diagnosis) */
    for (int c = 0; c < 3; c++) {
        if (only != NULL && strcmp(only, cases[c]) != 0) {
            continue;
        }
        const char *meth = getenv("SC_PRESS_METHOD"); /* msds or fem alone (diagnosis) */
        if (meth == NULL || strcmp(meth, "fem") != 0) {
            sweep_mesh(cases[c], SC_TISSUE_MSDS, 1u);
        }
        if (meth == NULL || strcmp(meth, "msds") != 0) {
            sweep_mesh(cases[c], SC_TISSUE_FEM, 1u);
        }
    }
}

static void neck_ijv_msds_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("neck-ijv", SC_TISSUE_MSDS);
}
static void neck_ijv_fem_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("neck-ijv", SC_TISSUE_FEM);
}
static void femoral_msds_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("femoral", SC_TISSUE_MSDS);
}
static void femoral_fem_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("femoral", SC_TISSUE_FEM);
}
static void femoral_dvt_msds_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("femoral-dvt", SC_TISSUE_MSDS);
}
static void femoral_dvt_fem_press_sweep_has_no_fault_and_returns_to_rest(void **state)
{
    (void)state;
    sweep("femoral-dvt", SC_TISSUE_FEM);
}

int main(void)
{
#if defined(SC_PRESS_SWEEP_FINE)
    /* test_press_sweep_fine.c: the 32x16x16 sweeps alone (their own time limit) */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fine_mesh_press_sweeps_have_no_fault_and_show_the_vessels),
    };
    (void)neck_ijv_msds_press_sweep_has_no_fault_and_returns_to_rest;
    (void)neck_ijv_fem_press_sweep_has_no_fault_and_returns_to_rest;
    (void)femoral_msds_press_sweep_has_no_fault_and_returns_to_rest;
    (void)femoral_fem_press_sweep_has_no_fault_and_returns_to_rest;
    (void)femoral_dvt_msds_press_sweep_has_no_fault_and_returns_to_rest;
    (void)femoral_dvt_fem_press_sweep_has_no_fault_and_returns_to_rest;
#else
    (void)fine_mesh_press_sweeps_have_no_fault_and_show_the_vessels;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(neck_ijv_msds_press_sweep_has_no_fault_and_returns_to_rest),
        cmocka_unit_test(neck_ijv_fem_press_sweep_has_no_fault_and_returns_to_rest),
        cmocka_unit_test(femoral_msds_press_sweep_has_no_fault_and_returns_to_rest),
        cmocka_unit_test(femoral_fem_press_sweep_has_no_fault_and_returns_to_rest),
        cmocka_unit_test(femoral_dvt_msds_press_sweep_has_no_fault_and_returns_to_rest),
        cmocka_unit_test(femoral_dvt_fem_press_sweep_has_no_fault_and_returns_to_rest),
    };
#endif
    return cmocka_run_group_tests(tests, NULL, NULL);
}
