/* test_sc_material.c: material table and per-tet labels / fixed nodes from a label map. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_materials.h"
#include "sc_mesh.h"

static sc_mesh g_mesh;
static uint8_t g_labels[41 * 21 * 31];

static void default_table_has_a_valid_row_per_label(void **state)
{
    (void)state;
    sc_material_table t;
    sc_material_table_default(&t);
    assert_int_equal(t.count, SC_LABEL_COUNT);
    assert_int_equal(sc_material_table_validate(&t), SC_OK);
    /* the clinical ordering the tests rely on: vein softest, artery stiffer than muscle,
     * thrombus stiffer than fat */
    assert_true(t.row[SC_LABEL_VEIN].e_pa < t.row[SC_LABEL_FAT].e_pa);
    assert_true(t.row[SC_LABEL_ARTERY].e_pa > t.row[SC_LABEL_MUSCLE].e_pa);
    assert_true(t.row[SC_LABEL_THROMBUS].e_pa > t.row[SC_LABEL_FAT].e_pa);
    sc_material_table bad = t;
    bad.row[SC_LABEL_FAT].poisson = 0.5f;
    assert_int_equal(sc_material_table_validate(&bad), SC_ERR_CASE_MATERIAL);
    bad = t;
    bad.row[SC_LABEL_BONE].density_kg_m3 = NAN;
    assert_int_equal(sc_material_table_validate(&bad), SC_ERR_CASE_MATERIAL);
    bad = t;
    bad.count = 0;
    assert_int_equal(sc_material_table_validate(&bad), SC_ERR_CASE_MATERIAL);
    assert_int_equal(sc_material_table_validate(NULL), SC_ERR_INVALID_ARG);
}

/* Label map on a 1 mm grid over the default box: muscle, a bone slab below z = 20 mm on the
 * x < 10 mm side, a vein column; tets get the majority label, bone nodes and the bottom and
 * sides are fixed, the top (skin side) is free except at its edges. */
static void tets_get_majority_label_and_dirichlet_nodes_are_fixed(void **state)
{
    (void)state;
    sc_volume vol;
    memset(&vol, 0, sizeof vol);
    vol.dim[0] = 41;
    vol.dim[1] = 21;
    vol.dim[2] = 31;
    vol.spacing_mm[0] = vol.spacing_mm[1] = vol.spacing_mm[2] = 1.0f;
    for (uint32_t k = 0; k < 31; k++) {
        for (uint32_t j = 0; j < 21; j++) {
            for (uint32_t i = 0; i < 41; i++) {
                uint8_t l = SC_LABEL_MUSCLE;
                if (i < 10 && k > 20) {
                    l = SC_LABEL_BONE;
                } else if (i >= 25 && i <= 32) {
                    l = SC_LABEL_VEIN;
                }
                g_labels[i + 41 * (j + 21 * k)] = l;
            }
        }
    }
    vol.labels = g_labels;
    sc_mesh_def d = sc_mesh_default_def(); /* 40 x 20 x 30 mm at the origin */
    d.nx = 9;
    d.ny = 5;
    d.nz = 7; /* 5 mm cells */
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    sc_material_table t;
    sc_material_table_default(&t);
    assert_int_equal(sc_material_assign(&g_mesh, &vol, &t, SC_LABEL_FAT), SC_OK);
    uint32_t bone = 0, vein = 0, muscle = 0;
    for (uint32_t e = 0; e < g_mesh.tet_count; e++) {
        float c[3] = {0, 0, 0};
        for (int a = 0; a < 4; a++) {
            c[0] += 0.25f * g_mesh.rest_x[g_mesh.tet[e][a]];
            c[2] += 0.25f * g_mesh.rest_z[g_mesh.tet[e][a]];
        }
        const uint8_t l = g_mesh.tet_label[e];
        /* cells entirely inside one region carry its label */
        if (c[0] < 5.0f && c[2] > 25.0f) {
            assert_int_equal(l, SC_LABEL_BONE);
        }
        if (c[0] > 10.0f && c[0] < 20.0f) {
            assert_int_equal(l, SC_LABEL_MUSCLE);
        }
        bone += l == SC_LABEL_BONE;
        vein += l == SC_LABEL_VEIN;
        muscle += l == SC_LABEL_MUSCLE;
    }
    assert_true(bone > 0 && vein > 0 && muscle > 0);
    assert_int_equal(bone + vein + muscle, g_mesh.tet_count);
    for (uint32_t n = 0; n < g_mesh.node_count; n++) {
        const uint32_t i = n % 9u, j = (n / 9u) % 5u, k = n / 45u;
        /* bottom and bone: fixed; the sides on rollers (the normal axis held) */
        const int in_bone = g_mesh.rest_x[n] < 9.5f && g_mesh.rest_z[n] > 20.5f;
        uint32_t want = 0u;
        if (k == 6 || in_bone) {
            want = SC_MESH_FIXED_ALL;
        } else {
            want |= (i == 0 || i == 8) ? SC_MESH_ROLLER_X : 0u;
            want |= (j == 0 || j == 4) ? SC_MESH_ROLLER_Y : 0u;
        }
        assert_int_equal(g_mesh.node_fixed[n], want);
    }
    /* a label without a table row is refused */
    g_labels[0] = SC_MAX_LABELS - 1u;
    g_labels[1] = SC_MAX_LABELS - 1u;
    assert_int_equal(sc_material_assign(&g_mesh, &vol, &t, SC_LABEL_FAT), SC_ERR_CASE_LABEL);
    /* no label map: every tet gets the default */
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &t, SC_LABEL_FAT), SC_OK);
    for (uint32_t e = 0; e < g_mesh.tet_count; e++) {
        assert_int_equal(g_mesh.tet_label[e], SC_LABEL_FAT);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(default_table_has_a_valid_row_per_label),
        cmocka_unit_test(tets_get_majority_label_and_dirichlet_nodes_are_fixed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
