/* test_sc_mesh.c: regular 5-tet mesh: counts, orientation, conformity, volumes, neighbours. */
#include "sc_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_mesh.h"

/* bit-exact float equality (the build forbids ==) */
static int feq(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static sc_mesh g_mesh;
static sc_nodes g_nodes;

static sc_mesh_def def_of(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def d = sc_mesh_default_def();
    d.nx = nx;
    d.ny = ny;
    d.nz = nz;
    d.origin_mm[0] = -3.0f;
    d.origin_mm[1] = 7.0f;
    d.origin_mm[2] = 1.5f;
    d.size_mm[0] = 40.0f;
    d.size_mm[1] = 20.0f;
    d.size_mm[2] = 30.0f;
    return d;
}

static void counts_match_the_paper_table(void **state)
{
    (void)state;
    static const uint32_t c[][5] = {{5, 5, 5, 125, 320},          {20, 10, 10, 2000, 7695},
                                    {24, 12, 12, 3456, 13915},    {28, 14, 14, 5488, 22815},
                                    {32, 16, 16, 8192, 34875}};
    for (size_t r = 0; r < sizeof c / sizeof c[0]; r++) {
        sc_mesh_def d = def_of(c[r][0], c[r][1], c[r][2]);
        assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
        assert_int_equal(g_mesh.node_count, c[r][3]);
        assert_int_equal(g_mesh.tet_count, c[r][4]);
    }
}

static void every_tet_positive_and_volumes_sum_to_box(void **state)
{
    (void)state;
    static const uint32_t dims[][3] = {{5, 5, 5}, {2, 2, 2}, {3, 4, 5}, {32, 16, 16}};
    for (size_t r = 0; r < sizeof dims / sizeof dims[0]; r++) {
        sc_mesh_def d = def_of(dims[r][0], dims[r][1], dims[r][2]);
        assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
        double sum = 0.0;
        double minv = 1e30;
        for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
            const double v = (double)sc_mesh_tet_volume_mm3(g_mesh.rest_x, g_mesh.rest_y,
                                                            g_mesh.rest_z, g_mesh.tet[t]);
            sum += v;
            minv = v < minv ? v : minv;
        }
        /* the smallest tet is a corner tet: 1/6 of a cell */
        const double cell = (double)g_mesh.cell_mm[0] * (double)g_mesh.cell_mm[1] *
                            (double)g_mesh.cell_mm[2];
        assert_true(minv > 0.16 * cell);
        /* float32 positions (~1e-7 relative) and per-tet rounding of 35k terms: 1e-4 */
        assert_true(fabs(sum - 40.0 * 20.0 * 30.0) < 1e-4 * 24000.0);
    }
}

typedef struct face_rec {
    uint32_t n[3];
    uint32_t tet;
    uint32_t v;
} face_rec;

static int face_cmp(const void *a, const void *b)
{
    const face_rec *x = a, *y = b;
    for (int i = 0; i < 3; i++) {
        if (x->n[i] != y->n[i]) {
            return x->n[i] < y->n[i] ? -1 : 1;
        }
    }
    return 0;
}

static void sort3(uint32_t n[3])
{
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 2 - i; j++) {
            if (n[j] > n[j + 1]) {
                uint32_t s = n[j];
                n[j] = n[j + 1];
                n[j + 1] = s;
            }
        }
    }
}

/* Brute force independent of the library: sort all faces; each interior face occurs exactly
 * twice, each hull face once and lies on the box surface; tet_nbr agrees with the pairs. */
static void check_faces(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def d = def_of(nx, ny, nz);
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    const uint32_t nf = g_mesh.tet_count * 4u;
    face_rec *f = malloc(nf * sizeof *f);
    assert_non_null(f);
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        for (uint32_t v = 0; v < 4u; v++) {
            face_rec *r = &f[t * 4u + v];
            uint32_t k = 0;
            for (uint32_t w = 0; w < 4u; w++) {
                if (w != v) {
                    r->n[k++] = g_mesh.tet[t][w];
                }
            }
            sort3(r->n);
            r->tet = t;
            r->v = v;
        }
    }
    qsort(f, nf, sizeof *f, face_cmp);
    uint32_t hull = 0, interior = 0;
    for (uint32_t i = 0; i < nf;) {
        uint32_t j = i + 1u;
        while (j < nf && face_cmp(&f[i], &f[j]) == 0) {
            j++;
        }
        const uint32_t mult = j - i;
        assert_true(mult == 1u || mult == 2u);
        if (mult == 2u) {
            interior++;
            assert_int_equal(g_mesh.tet_nbr[f[i].tet][f[i].v], (int32_t)f[i + 1u].tet);
            assert_int_equal(g_mesh.tet_nbr[f[i + 1u].tet][f[i + 1u].v], (int32_t)f[i].tet);
        } else {
            hull++;
            assert_int_equal(g_mesh.tet_nbr[f[i].tet][f[i].v], -1);
            /* a hull face lies on one side of the box: its three nodes share a boundary
             * coordinate */
            int on_side = 0;
            const uint32_t lim[3] = {nx - 1u, ny - 1u, nz - 1u};
            for (uint32_t ax = 0; ax < 3u; ax++) {
                uint32_t c[3];
                for (uint32_t a = 0; a < 3u; a++) {
                    const uint32_t n = f[i].n[a];
                    c[a] = ax == 0u ? n % nx : (ax == 1u ? (n / nx) % ny : n / (nx * ny));
                }
                if (c[0] == c[1] && c[1] == c[2] && (c[0] == 0u || c[0] == lim[ax])) {
                    on_side = 1;
                }
            }
            assert_true(on_side);
        }
        i = j;
    }
    /* every cell face of the box surface is split into two triangles */
    const uint32_t expect_hull =
        4u * ((nx - 1u) * (ny - 1u) + (nx - 1u) * (nz - 1u) + (ny - 1u) * (nz - 1u));
    assert_int_equal(hull, expect_hull);
    assert_int_equal(2u * interior + hull, nf);
    free(f);
}

static void interior_faces_shared_by_exactly_two_tets_and_nbr_agrees(void **state)
{
    (void)state;
    check_faces(5, 5, 5);
    check_faces(2, 3, 4);
    check_faces(20, 10, 10);
    check_faces(32, 16, 16);
}

static void nodes_on_grid_and_reset_copies_rest(void **state)
{
    (void)state;
    sc_mesh_def d = def_of(5, 4, 3);
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    /* node index i + nx (j + ny k) */
    const uint32_t n = 2u + 5u * (3u + 4u * 1u);
    assert_true(fabsf(g_mesh.rest_x[n] - (-3.0f + 2.0f * 10.0f)) < 1e-5f);
    assert_true(fabsf(g_mesh.rest_y[n] - (7.0f + 3.0f * 20.0f / 3.0f)) < 1e-5f);
    assert_true(fabsf(g_mesh.rest_z[n] - (1.5f + 15.0f)) < 1e-5f);
    /* the far corner is exactly the box corner */
    const uint32_t last = g_mesh.node_count - 1u;
    assert_true(feq(g_mesh.rest_x[last], 37.0f) && feq(g_mesh.rest_y[last], 27.0f) &&
                feq(g_mesh.rest_z[last], 31.5f));
    memset(&g_nodes, 0x7f, sizeof g_nodes);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        assert_true(feq(g_nodes.x[i], g_mesh.rest_x[i]) && feq(g_nodes.y[i], g_mesh.rest_y[i]) &&
                    feq(g_nodes.z[i], g_mesh.rest_z[i]));
        assert_true(feq(g_nodes.vx[i], 0.0f) && feq(g_nodes.vy[i], 0.0f) &&
                    feq(g_nodes.vz[i], 0.0f));
        assert_true(feq(g_nodes.fx[i], 0.0f) && feq(g_nodes.fy[i], 0.0f) &&
                    feq(g_nodes.fz[i], 0.0f));
    }
}

static void bad_definitions_are_refused_with_named_errors(void **state)
{
    (void)state;
    sc_mesh_def d = def_of(5, 5, 5);
    assert_int_equal(sc_mesh_build(NULL, &d), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_mesh_build(&g_mesh, NULL), SC_ERR_INVALID_ARG);
    d.nx = 1;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_ERR_MESH_DIMS);
    d.nx = SC_MAX_MESH_NX + 1u;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_ERR_MESH_DIMS);
    d = def_of(5, 5, 5);
    d.size_mm[1] = 0.0f;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_ERR_RANGE);
    d = def_of(5, 5, 5);
    d.origin_mm[2] = NAN;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_ERR_NOT_FINITE);
    d = def_of(5, 5, 5);
    d.size_mm[0] = INFINITY;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_ERR_NOT_FINITE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(counts_match_the_paper_table),
        cmocka_unit_test(every_tet_positive_and_volumes_sum_to_box),
        cmocka_unit_test(interior_faces_shared_by_exactly_two_tets_and_nbr_agrees),
        cmocka_unit_test(nodes_on_grid_and_reset_copies_rest),
        cmocka_unit_test(bad_definitions_are_refused_with_named_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
