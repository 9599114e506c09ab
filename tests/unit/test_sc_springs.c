/* test_sc_springs.c: Algorithm 1 (FEM tets -> MSDS springs). */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_springs.h"

static sc_springs g_sp;
static sc_mesh g_mesh;

/* relative float tolerance: a sum of at most 6 float products, ~1e-6 relative */
static int near(float a, float b)
{
    return fabsf(a - b) <= 1e-5f * fabsf(b);
}

/* The paper's Fig. 4: two tets sharing the face (1, 2, 3): 5 nodes, 9 distinct edges; the 3
 * shared edges get k = 0.002 (E1 + E2), the others 0.002 E of their own tet; gamma = 0.1 k. */
static void two_tet_example_sums_shared_edges(void **state)
{
    (void)state;
    static const uint32_t tets[2][4] = {{0, 1, 2, 3}, {4, 3, 2, 1}};
    const uint8_t labels[2] = {SC_LABEL_FAT, SC_LABEL_MUSCLE};
    sc_material_table mat;
    sc_material_table_default(&mat);
    const float e1 = mat.row[SC_LABEL_FAT].e_pa, e2 = mat.row[SC_LABEL_MUSCLE].e_pa;
    assert_int_equal(sc_springs_from_tets(&g_sp, tets, labels, 2, &mat), SC_OK);
    assert_int_equal(g_sp.count, 9);
    static const uint32_t shared[3][2] = {{1, 2}, {1, 3}, {2, 3}};
    for (int i = 0; i < 3; i++) {
        const int32_t s = sc_springs_find(&g_sp, shared[i][1], shared[i][0]); /* any order */
        assert_true(s >= 0);
        assert_true(near(g_sp.k_n_per_m[s], 0.002f * e1 + 0.002f * e2));
        assert_true(near(g_sp.gamma_n_s_per_m[s], 0.1f * (0.002f * e1 + 0.002f * e2)));
    }
    static const uint32_t own1[3][2] = {{0, 1}, {0, 2}, {0, 3}};
    static const uint32_t own2[3][2] = {{4, 1}, {4, 2}, {4, 3}};
    for (int i = 0; i < 3; i++) {
        int32_t s = sc_springs_find(&g_sp, own1[i][0], own1[i][1]);
        assert_true(s >= 0 && near(g_sp.k_n_per_m[s], 0.002f * e1));
        assert_true(near(g_sp.gamma_n_s_per_m[s], 0.1f * 0.002f * e1));
        s = sc_springs_find(&g_sp, own2[i][0], own2[i][1]);
        assert_true(s >= 0 && near(g_sp.k_n_per_m[s], 0.002f * e2));
    }
    assert_int_equal(sc_springs_find(&g_sp, 0, 4), -1); /* the two apexes are not joined */
    for (uint32_t s = 0; s < g_sp.count; s++) {
        assert_true(g_sp.a[s] < g_sp.b[s]);
    }
}

/* On the regular mesh every tet edge is a grid edge or a face diagonal: the number of springs
 * is the number of grid edges plus grid faces, and the summed k over all springs equals
 * 6 tets-edges x 0.002 E per tet. */
static void regular_mesh_spring_count_and_total_stiffness(void **state)
{
    (void)state;
    static const uint32_t dims[][3] = {{5, 5, 5}, {4, 3, 6}, {32, 16, 16}};
    sc_material_table mat;
    sc_material_table_default(&mat);
    for (size_t r = 0; r < sizeof dims / sizeof dims[0]; r++) {
        sc_mesh_def d = sc_mesh_default_def();
        d.nx = dims[r][0];
        d.ny = dims[r][1];
        d.nz = dims[r][2];
        assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
        for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
            g_mesh.tet_label[t] = (uint8_t)(t % 2u ? SC_LABEL_FAT : SC_LABEL_ARTERY);
        }
        assert_int_equal(sc_springs_from_tets(&g_sp, (const uint32_t(*)[4])g_mesh.tet,
                                              g_mesh.tet_label, g_mesh.tet_count, &mat),
                         SC_OK);
        const uint32_t nx = d.nx, ny = d.ny, nz = d.nz;
        const uint32_t edges = (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1);
        const uint32_t faces = (nx - 1) * (ny - 1) * nz + (nx - 1) * ny * (nz - 1) +
                               nx * (ny - 1) * (nz - 1);
        assert_int_equal(g_sp.count, edges + faces);
        double total = 0.0, expect = 0.0;
        for (uint32_t s = 0; s < g_sp.count; s++) {
            total += (double)g_sp.k_n_per_m[s];
        }
        for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
            expect += 6.0 * 0.002 * (double)mat.row[g_mesh.tet_label[t]].e_pa;
        }
        /* float sums of up to ~10 terms per spring: 1e-5 relative */
        assert_true(fabs(total - expect) <= 1e-5 * expect);
    }
}

static void bad_inputs_are_refused(void **state)
{
    (void)state;
    sc_material_table mat;
    sc_material_table_default(&mat);
    static const uint32_t tets[1][4] = {{0, 1, 2, 3}};
    static const uint32_t degenerate[1][4] = {{0, 1, 1, 3}};
    const uint8_t ok_label[1] = {SC_LABEL_FAT};
    const uint8_t bad_label[1] = {SC_MAX_LABELS - 1u};
    assert_int_equal(sc_springs_from_tets(NULL, tets, ok_label, 1, &mat), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_springs_from_tets(&g_sp, tets, NULL, 1, &mat), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_springs_from_tets(&g_sp, degenerate, ok_label, 1, &mat),
                     SC_ERR_INVALID_ARG);
    assert_int_equal(sc_springs_from_tets(&g_sp, tets, bad_label, 1, &mat), SC_ERR_CASE_LABEL);
    assert_int_equal(sc_springs_from_tets(&g_sp, tets, ok_label, 0, &mat), SC_OK);
    assert_int_equal(g_sp.count, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(two_tet_example_sums_shared_edges),
        cmocka_unit_test(regular_mesh_spring_count_and_total_stiffness),
        cmocka_unit_test(bad_inputs_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
