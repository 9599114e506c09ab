/* test_sc_lumen.c: the vessel lumens (core/physics/sc_lumen.h) on a labelled 12x12x8 mesh with a
 * vein tube and an artery tube along y: the regions found, their rest volumes, the law's
 * direction (a compressed lumen pushes its wall out, a distended one pulls it in, nothing at
 * rest), the forces' balance (a closed lumen's boundary forces sum to zero), the drive's
 * period and validation, determinism and the reset. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_lumen.h"
#include "sc_material.h"
#include "sc_mesh.h"

static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_lumen g_lumen;
static sc_material_table g_mat;

#define NX 12u
#define NY 12u
#define NZ 8u

/* label each tet by its rest centroid: a vein (radius 3 mm) around (8, ., 6), an artery
 * (radius 2.5 mm) around (16, ., 6), fat elsewhere; `closed`: the tubes end 2 mm inside the box
 * in y (a closed lumen) */
static void build(int closed)
{
    const sc_mesh_def md = {NX, NY, NZ, {0.0f, 0.0f, 0.0f}, {24.0f, 24.0f, 14.0f}};
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_material_table_default(&g_mat);
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &g_mat, SC_LABEL_FAT), SC_OK);
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        float c[3] = {0.0f, 0.0f, 0.0f};
        for (uint32_t v = 0; v < 4u; v++) {
            const uint32_t i = g_mesh.tet[t][v];
            c[0] += 0.25f * g_mesh.rest_x[i];
            c[1] += 0.25f * g_mesh.rest_y[i];
            c[2] += 0.25f * g_mesh.rest_z[i];
        }
        const int in_y = !closed || (c[1] > 4.0f && c[1] < 20.0f);
        const float dv = (c[0] - 8.0f) * (c[0] - 8.0f) + (c[2] - 6.0f) * (c[2] - 6.0f);
        const float da = (c[0] - 16.0f) * (c[0] - 16.0f) + (c[2] - 6.0f) * (c[2] - 6.0f);
        g_mesh.tet_label[t] = (uint8_t)(in_y && dv < 9.0f    ? SC_LABEL_VEIN
                                        : in_y && da < 6.25f ? SC_LABEL_ARTERY
                                                             : SC_LABEL_FAT);
    }
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    assert_int_equal(sc_lumen_init(&g_lumen, &g_mesh, &g_mat), SC_OK);
}

static float label_volume(uint8_t lab)
{
    float v = 0.0f;
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        if (g_mesh.tet_label[t] == lab) {
            v += sc_mesh_tet_volume_mm3(g_mesh.rest_x, g_mesh.rest_y, g_mesh.rest_z, g_mesh.tet[t]);
        }
    }
    return v;
}

static void finds_one_vessel_per_tube_with_its_rest_volume(void **state)
{
    (void)state;
    build(0);
    assert_int_equal(g_lumen.count, 2u);
    assert_int_equal(g_lumen.dropped, 0u);
    for (uint32_t k = 0; k < 2u; k++) {
        const sc_lumen_vessel *v = &g_lumen.v[k];
        assert_true(v->kind == (v->label == SC_LABEL_VEIN ? SC_LUMEN_VEIN : SC_LUMEN_ARTERY));
        assert_true(fabsf(v->v0_mm3 - label_volume(v->label)) <= 1e-3f * v->v0_mm3);
        assert_true(v->theta > 0.0f && v->theta <= 1.0f);
        assert_true(fabsf(sc_lumen_volume_mm3(&g_lumen, &g_mesh, g_nodes.x, g_nodes.y, g_nodes.z,
                                              k + 1u) -
                          v->v0_mm3) <= 1e-3f * v->v0_mm3);
    }
    /* theta = 1 / (1 + B c), c the lumen's compliance bound: the hole in the softest
     * material around in parallel with the lumen's own tets. The vein's filler (0.15 kPa)
     * adds little to the fat around it (B 10 kPa over ~1.35 kPa: ~0.12); the artery's wall
     * share (30 kPa, nu 0.45: lambda + mu 103 kPa) carries most of its law (B 60 kPa: ~0.63) */
    const uint32_t vi = g_lumen.v[0].label == SC_LABEL_VEIN ? 0u : 1u;
    assert_true(g_lumen.v[vi].theta > 0.08f && g_lumen.v[vi].theta < 0.2f);
    assert_true(g_lumen.v[1u - vi].theta > 0.5f && g_lumen.v[1u - vi].theta < 0.8f);
}

/* push every lumen node by `scale` about the tube's axis (x, z) and return the sum of the radial
 * components of the lumen forces (outward positive) after one pass */
static double radial_force_after(float scale, uint32_t vessel)
{
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    const float cx = g_lumen.v[vessel].label == SC_LABEL_VEIN ? 8.0f : 16.0f;
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        if (g_lumen.region[t] != vessel + 1u) {
            continue;
        }
        for (uint32_t v = 0; v < 4u; v++) {
            const uint32_t i = g_mesh.tet[t][v];
            g_nodes.x[i] = cx + scale * (g_mesh.rest_x[i] - cx);
            g_nodes.z[i] = 6.0f + scale * (g_mesh.rest_z[i] - 6.0f);
        }
    }
    sc_lumen_reset(&g_lumen);
    sc_lumen_drive d = sc_lumen_drive_default();
    d.heart_rate_bpm = 0.0f;
    d.resp_rate_bpm = 0.0f;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &d), SC_OK);
    memset(g_nodes.fx, 0, sizeof g_nodes.fx);
    memset(g_nodes.fz, 0, sizeof g_nodes.fz);
    sc_lumen_apply(&g_lumen, &g_mesh, &g_nodes);
    double radial = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        radial += (double)g_nodes.fx[i] * (double)(g_nodes.x[i] - cx) +
                  (double)g_nodes.fz[i] * (double)(g_nodes.z[i] - 6.0f);
    }
    sc_lumen_clear(&g_lumen, &g_mesh, &g_nodes);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        assert_true(fabsf(g_nodes.fx[i]) + fabsf(g_nodes.fy[i]) + fabsf(g_nodes.fz[i]) <= 0.0f);
    }
    return radial;
}

static void compressed_lumen_pushes_out_distended_pulls_in_rest_is_free(void **state)
{
    (void)state;
    build(0);
    for (uint32_t k = 0; k < 2u; k++) {
        assert_true(fabs(radial_force_after(1.0f, k)) <= 0.0);
        assert_true(radial_force_after(0.8f, k) > 0.0);
        assert_true(radial_force_after(1.1f, k) < 0.0);
        assert_true(g_lumen.faces > 0u);
    }
}

static void closed_lumen_forces_balance(void **state)
{
    (void)state;
    build(1);
    assert_int_equal(g_lumen.count, 2u);
    (void)radial_force_after(0.8f, 0u);
    sc_lumen_apply(&g_lumen, &g_mesh, &g_nodes); /* the same state again: forces in place */
    double s[3] = {0.0, 0.0, 0.0}, mag = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        s[0] += g_nodes.fx[i];
        s[1] += g_nodes.fy[i];
        s[2] += g_nodes.fz[i];
        mag += fabs((double)g_nodes.fx[i]) + fabs((double)g_nodes.fy[i]) + fabs((double)g_nodes.fz[i]);
    }
    assert_true(mag > 0.0);
    for (uint32_t c = 0; c < 3u; c++) {
        assert_true(fabs(s[c]) <= 1e-4 * mag);
    }
    sc_lumen_clear(&g_lumen, &g_mesh, &g_nodes);
}

static void drive_follows_the_heart_rate_and_validates(void **state)
{
    (void)state;
    build(0);
    assert_int_equal(sc_lumen_set_frame_s(&g_lumen, 0.01f), SC_OK);
    sc_lumen_drive d = sc_lumen_drive_default();
    d.heart_rate_bpm = 60.0f;
    d.resp_rate_bpm = 0.0f;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &d), SC_OK);
    /* 1 Hz at 100 frames/s: the artery's drive repeats every 100 frames, and over a cycle its
     * mean is ~0 and its swing the pulse pressure */
    float p[300];
    for (uint32_t f = 0; f < 300u; f++) {
        sc_lumen_apply(&g_lumen, &g_mesh, &g_nodes);
        sc_lumen_clear(&g_lumen, &g_mesh, &g_nodes);
        p[f] = sc_lumen_drive_pa(&g_lumen, SC_LUMEN_ARTERY);
    }
    float lo = p[0], hi = p[0], mean = 0.0f;
    for (uint32_t f = 100u; f < 200u; f++) {
        assert_true(fabsf(p[f] - p[f + 100u]) <= 50.0f);
        lo = fminf(lo, p[f]);
        hi = fmaxf(hi, p[f]);
        mean += p[f] / 100.0f;
    }
    assert_true(fabsf(mean) <= 0.05f * d.pulse_pa);
    assert_true(hi - lo >= 0.9f * d.pulse_pa && hi - lo <= 1.01f * d.pulse_pa);
    /* the vein: Valsalva raises its pressure; a thrombus (no law) never moves */
    const float v0 = sc_lumen_drive_pa(&g_lumen, SC_LUMEN_VEIN);
    sc_lumen_set_valsalva(&g_lumen, 1);
    assert_true(sc_lumen_drive_pa(&g_lumen, SC_LUMEN_VEIN) >= v0 + 0.99f * d.valsalva_pa);
    assert_true(fabsf(sc_lumen_drive_pa(&g_lumen, SC_LUMEN_NONE)) <= 0.0f);
    /* validation */
    sc_lumen_drive b = d;
    b.heart_rate_bpm = 300.0f;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &b), SC_ERR_RANGE);
    b = d;
    b.pulse_pa = NAN;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &b), SC_ERR_NOT_FINITE);
    b = d;
    b.wave = 7u;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &b), SC_ERR_INVALID_ARG);
    b = d;
    b.resp_rate_bpm = -1.0f;
    assert_int_equal(sc_lumen_set_drive(&g_lumen, &b), SC_ERR_RANGE);
    assert_int_equal(sc_lumen_set_frame_s(&g_lumen, 0.0f), SC_ERR_RANGE);
    assert_true(fabsf(g_lumen.drive.heart_rate_bpm - 60.0f) <= 0.0f); /* the old drive stays */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(finds_one_vessel_per_tube_with_its_rest_volume),
        cmocka_unit_test(compressed_lumen_pushes_out_distended_pulls_in_rest_is_free),
        cmocka_unit_test(closed_lumen_forces_balance),
        cmocka_unit_test(drive_follows_the_heart_rate_and_validates),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
