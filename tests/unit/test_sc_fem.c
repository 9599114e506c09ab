/* test_sc_fem.c: FEM soft tissue: pattern, element stiffness, solver, corotation, clinical
 * behaviour under a prescribed-displacement indentation, determinism. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_err.h"
#include "sc_fem.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_msds.h"
#include "sc_springs.h"

static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_fem g_fem;
static sc_fem g_fem2;
static sc_nodes g_nodes2;
static sc_material_table g_mat;
static uint8_t g_kin[SC_MAX_NODES];
static sc_springs g_springs;
static sc_msds g_msds;

/* Box of the default mesh definition (40 x 20 x 30 mm), nx x ny x nz nodes, all fat, bottom
 * and sides fixed (sc_material_assign without a label map). */
static void make_mesh(uint32_t nx, uint32_t ny, uint32_t nz)
{
    sc_mesh_def d = sc_mesh_default_def();
    d.nx = nx;
    d.ny = ny;
    d.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    sc_material_table_default(&g_mat);
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &g_mat, SC_LABEL_FAT), SC_OK);
    /* these tests hold the sides whole (sc_material_assign puts them on rollers since the
     * rollers came; the explicit MSDS of the comparison holds any flagged node whole) */
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = g_mesh.node_fixed[i] != 0u ? (uint8_t)SC_MESH_FIXED_ALL : 0u;
    }
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
}

static void tet_centroid(const sc_mesh *m, uint32_t e, float c[3])
{
    c[0] = c[1] = c[2] = 0.0f;
    for (uint32_t v = 0; v < 4u; v++) {
        const uint32_t i = m->tet[e][v];
        c[0] += 0.25f * m->rest_x[i];
        c[1] += 0.25f * m->rest_y[i];
        c[2] += 0.25f * m->rest_z[i];
    }
}

/* y = K x with the FEM's grid matrix (sc_grid_apply_ref: every stored block, double
 * accumulation, interleaved xyz): the test's oracle. */
static void k_times(const sc_fem *f, const double *x, double *y)
{
    sc_grid_apply_ref(&f->grid, 0.0f, 1.0f, x, y);
}

/* node on the top (skin) layer, k = 0 */
static int is_top(const sc_mesh *m, uint32_t i)
{
    return i < m->nx * m->ny;
}

/* bitwise float equality (the values must be exactly unchanged) */
static int same(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static double g_u[3u * SC_MAX_NODES], g_ku[3u * SC_MAX_NODES];

/* ---- init and pattern ---------------------------------------------------------------------- */

static void init_rejects_invalid_inputs(void **state)
{
    (void)state;
    make_mesh(5, 4, 3);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(NULL, &g_mesh, &g_mat, &def), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_fem_init(&g_fem, NULL, &g_mat, &def), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, NULL, &def), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, NULL), SC_ERR_INVALID_ARG);

    def.rayleigh_beta_s = NAN;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_ERR_NOT_FINITE);
    def = sc_fem_default_def();
    def.rayleigh_alpha_per_s = -1.0f;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_ERR_RANGE);
    def = sc_fem_default_def();
    def.corotated = 2u;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_ERR_INVALID_ARG);
    def = sc_fem_default_def();

    sc_material_table bad = g_mat;
    bad.row[SC_LABEL_VEIN].poisson = 0.5f; /* incompressible: lambda infinite */
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &bad, &def), SC_ERR_CASE_MATERIAL);
    bad = g_mat;
    bad.row[SC_LABEL_FAT].e_pa = 0.0f;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &bad, &def), SC_ERR_CASE_MATERIAL);
    bad = g_mat;
    bad.count = 2u; /* fat (2) has no row */
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &bad, &def), SC_ERR_CASE_LABEL);

    /* a tet edge that is not between grid neighbours cannot be in the stencil pattern */
    const uint32_t keep = g_mesh.tet[0][3];
    g_mesh.tet[0][3] = g_mesh.node_count - 1u;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_ERR_FEM_PATTERN);
    g_mesh.tet[0][3] = keep;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
}

/* The grid matrix stores exactly one block per mesh edge (either order of the pair) and
 * none for any other pair of grid neighbours. */
static void grid_stores_one_block_per_mesh_edge_and_none_elsewhere(void **state)
{
    (void)state;
    static const uint32_t dims[3][3] = {{5u, 4u, 3u}, {2u, 2u, 2u}, {3u, 2u, 4u}};
    for (uint32_t dsz = 0; dsz < 3u; dsz++) {
        make_mesh(dims[dsz][0], dims[dsz][1], dims[dsz][2]);
        sc_fem_def def = sc_fem_default_def();
        assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
        static uint8_t adj[60][60];
        memset(adj, 0, sizeof adj);
        uint32_t edges = 0;
        assert_true(g_mesh.node_count <= 60u);
        for (uint32_t e = 0; e < g_mesh.tet_count; e++) {
            for (uint32_t a = 0; a < 4u; a++) {
                for (uint32_t b = 0; b < 4u; b++) {
                    const uint32_t i = g_mesh.tet[e][a], j = g_mesh.tet[e][b];
                    if (i < j && !adj[i][j]) {
                        adj[i][j] = adj[j][i] = 1u;
                        edges++;
                    }
                }
            }
        }
        uint32_t found = 0;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            float b[9];
            assert_int_equal(sc_grid_block(&g_fem.grid, i, i, b), 1);
            for (uint32_t j = i + 1u; j < g_mesh.node_count; j++) {
                const int stored = sc_grid_block(&g_fem.grid, i, j, b);
                assert_int_equal(stored, adj[i][j] ? 1 : 0);
                found += stored ? 1u : 0u;
                float bt[9];
                assert_int_equal(sc_grid_block(&g_fem.grid, j, i, bt), stored);
                for (uint32_t r = 0; r < 3u; r++) {
                    for (uint32_t c = 0; c < 3u; c++) {
                        assert_true(same(b[3u * r + c], bt[3u * c + r])); /* K_ji = K_ij^T */
                    }
                }
            }
        }
        assert_int_equal(found, edges);
    }
    make_mesh(SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    print_message("grid at %ux%ux%u: row stride %u floats, sizeof(sc_fem) %zu B\n", g_mesh.nx,
                  g_mesh.ny, g_mesh.nz, (unsigned)SC_GRID_ROW, sizeof(sc_fem));
}

/* sc_grid_row_disp (the probe's force per contact node) against the sum its caller formed from
 * sc_grid_block over the 3x3x3 neighbourhood in z, y, x order: the same bits at every node of
 * grids whose smallest sides make the offsets coincide (nx = 2: the anti diagonal one node apart),
 * with a displacement of both signs. (Both find a block by its offset; the blocks themselves are
 * checked against the mesh's edges and K_ji = K_ij^T above.) */
static void row_displacement_product_equals_the_block_lookups(void **state)
{
    (void)state;
    static const uint32_t dims[4][3] = {{5u, 4u, 3u}, {2u, 2u, 2u}, {3u, 2u, 4u}, {6u, 5u, 7u}};
    for (uint32_t dsz = 0; dsz < 4u; dsz++) {
        make_mesh(dims[dsz][0], dims[dsz][1], dims[dsz][2]);
        sc_fem_def def = sc_fem_default_def();
        assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
        const uint32_t nn = g_mesh.node_count, nx = g_mesh.nx, ny = g_mesh.ny, nz = g_mesh.nz;
        uint32_t seed = 12345u + dsz;
        for (uint32_t i = 0; i < nn; i++) {
            float *p[3] = {&g_nodes.x[i], &g_nodes.y[i], &g_nodes.z[i]};
            for (uint32_t c = 0; c < 3u; c++) {
                seed = seed * 1664525u + 1013904223u;
                *p[c] += ((float)(seed >> 8) / 16777216.0f - 0.5f) * 0.8f;
            }
        }
        const float *const x[3] = {g_nodes.x, g_nodes.y, g_nodes.z};
        const float *const x0[3] = {g_mesh.rest_x, g_mesh.rest_y, g_mesh.rest_z};
        uint32_t nonzero = 0;
        for (uint32_t i = 0; i < nn; i++) {
            const uint32_t ci[3] = {i % nx, (i / nx) % ny, i / (nx * ny)};
            float want[3] = {0.0f, 0.0f, 0.0f}, got[3] = {0.0f, 0.0f, 0.0f};
            for (int dz = -1; dz <= 1; dz++) {
                for (int dy = -1; dy <= 1; dy++) {
                    for (int dx = -1; dx <= 1; dx++) {
                        const int jx = (int)ci[0] + dx, jy = (int)ci[1] + dy, jz = (int)ci[2] + dz;
                        if (jx < 0 || jy < 0 || jz < 0 || jx >= (int)nx || jy >= (int)ny ||
                            jz >= (int)nz) {
                            continue;
                        }
                        const uint32_t j = (uint32_t)jx + nx * ((uint32_t)jy + ny * (uint32_t)jz);
                        float k[9];
                        if (!sc_grid_block(&g_fem.grid, i, j, k)) {
                            continue;
                        }
                        const float u[3] = {x[0][j] - x0[0][j], x[1][j] - x0[1][j],
                                            x[2][j] - x0[2][j]};
                        for (uint32_t c = 0; c < 3u; c++) {
                            want[c] += k[3u * c] * u[0] + k[3u * c + 1u] * u[1] +
                                       k[3u * c + 2u] * u[2];
                        }
                    }
                }
            }
            sc_grid_row_disp(&g_fem.grid, i, ci, x, x0, got);
            for (uint32_t c = 0; c < 3u; c++) {
                assert_true(same(want[c], got[c]));
                nonzero += fabsf(want[c]) > 0.0f ? 1u : 0u;
            }
        }
        assert_true(nonzero > nn); /* the displacement did load the rows */
        sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    }
}

/* ---- element stiffness ------------------------------------------------------------------- */

static double max_abs(const double *v, uint32_t count)
{
    double m = 0.0;
    for (uint32_t i = 0; i < count; i++) {
        m = fmax(m, fabs(v[i]));
    }
    return m;
}

static void stiffness_annihilates_rigid_motions_and_diagonal_blocks_are_symmetric(void **state)
{
    (void)state;
    make_mesh(6, 5, 4);
    /* mixed materials: symmetry and rigid-body invariance hold per element */
    for (uint32_t e = 0; e < g_mesh.tet_count; e++) {
        g_mesh.tet_label[e] = (uint8_t)(1u + e % 7u);
    }
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    const uint32_t n = g_mesh.node_count;
    double kmax = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        float D[9];
        assert_int_equal(sc_grid_block(&g_fem.grid, i, i, D), 1);
        for (uint32_t r = 0; r < 3u; r++) {
            assert_true(D[4u * r] > 0.0f); /* positive diagonal */
            for (uint32_t c = 0; c < 3u; c++) {
                assert_true(same(D[3u * r + c], D[3u * c + r])); /* stored symmetric */
            }
        }
        for (uint32_t j = 0; j < n; j++) {
            float b[9];
            if (sc_grid_block(&g_fem.grid, i, j, b)) {
                for (uint32_t k = 0; k < 9u; k++) {
                    kmax = fmax(kmax, fabs((double)b[k]));
                }
            }
        }
    }
    /* translations and infinitesimal rotations: K u = 0 up to float rounding of the blocks
     * (relative 1e-5 of |K| |u|: a block sum of ~19 float terms of size |K|) */
    const double w[3] = {0.3, -0.2, 0.5};
    for (uint32_t mode = 0; mode < 4u; mode++) {
        for (uint32_t i = 0; i < n; i++) {
            const double X[3] = {g_mesh.rest_x[i], g_mesh.rest_y[i], g_mesh.rest_z[i]};
            for (uint32_t d = 0; d < 3u; d++) {
                g_u[3u * i + d] = (mode < 3u) ? (d == mode ? 1.0 : 0.0) : 0.0;
            }
            if (mode == 3u) { /* w x X */
                g_u[3u * i] = w[1] * X[2] - w[2] * X[1];
                g_u[3u * i + 1u] = w[2] * X[0] - w[0] * X[2];
                g_u[3u * i + 2u] = w[0] * X[1] - w[1] * X[0];
            }
        }
        k_times(&g_fem, g_u, g_ku);
        const double bound = 1.0e-5 * kmax * max_abs(g_u, 3u * n) * 19.0;
        assert_true(max_abs(g_ku, 3u * n) <= bound);
    }
    /* and a stretch is not in the kernel (the check above can fail) */
    for (uint32_t i = 0; i < n; i++) {
        g_u[3u * i] = 0.01 * g_mesh.rest_x[i];
        g_u[3u * i + 1u] = 0.0;
        g_u[3u * i + 2u] = 0.0;
    }
    k_times(&g_fem, g_u, g_ku);
    assert_true(max_abs(g_ku, 3u * n) > 1.0e-3 * kmax * max_abs(g_u, 3u * n));
}

/* Patch test: for a homogeneous material, K applied to any linear displacement field gives zero
 * force at interior nodes (linear tets reproduce constant strain), and u . K u is exactly twice
 * the strain energy of the constant stress over the box: V (lambda tr(eps)^2 + 2 mu eps:eps). */
static void linear_field_gives_no_interior_force_and_exact_energy(void **state)
{
    (void)state;
    make_mesh(7, 6, 5);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    const double G[9] = {0.010, 0.004, -0.002, 0.003, -0.006, 0.001, 0.005, 0.002, -0.012};
    const uint32_t n = g_mesh.node_count;
    for (uint32_t i = 0; i < n; i++) {
        const double X[3] = {g_mesh.rest_x[i], g_mesh.rest_y[i], g_mesh.rest_z[i]};
        for (uint32_t r = 0; r < 3u; r++) {
            g_u[3u * i + r] = G[3u * r] * X[0] + G[3u * r + 1u] * X[1] + G[3u * r + 2u] * X[2];
        }
    }
    k_times(&g_fem, g_u, g_ku);
    const sc_material *fat = &g_mat.row[SC_LABEL_FAT];
    const double e = fat->e_pa * 1e-6, nu = fat->poisson;
    const double lam = e * nu / ((1 + nu) * (1 - 2 * nu)), mu = e / (2 * (1 + nu));
    double eps[9];
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t c = 0; c < 3u; c++) {
            eps[3u * r + c] = 0.5 * (G[3u * r + c] + G[3u * c + r]);
        }
    }
    const double tr = eps[0] + eps[4] + eps[8];
    double ee = 0.0;
    for (uint32_t k = 0; k < 9u; k++) {
        ee += eps[k] * eps[k];
    }
    const double energy2 = 40.0 * 20.0 * 30.0 * (lam * tr * tr + 2.0 * mu * ee);
    double fint = 0.0, fbnd = 0.0, uku = 0.0;
    for (uint32_t k = 0; k < g_mesh.nz; k++) {
        for (uint32_t j = 0; j < g_mesh.ny; j++) {
            for (uint32_t i = 0; i < g_mesh.nx; i++) {
                const uint32_t id = i + g_mesh.nx * (j + g_mesh.ny * k);
                const int interior = i > 0 && j > 0 && k > 0 && i + 1u < g_mesh.nx &&
                                     j + 1u < g_mesh.ny && k + 1u < g_mesh.nz;
                for (uint32_t d = 0; d < 3u; d++) {
                    const double v = fabs(g_ku[3u * id + d]);
                    if (interior) {
                        fint = fmax(fint, v);
                    } else {
                        fbnd = fmax(fbnd, v);
                    }
                    uku += g_u[3u * id + d] * g_ku[3u * id + d];
                }
            }
        }
    }
    print_message("patch test: interior |f| %.2e N vs boundary %.2e N; u.Ku %.6e vs %.6e\n", fint,
                  fbnd, uku, energy2);
    /* float blocks: relative rounding ~1e-7 per term, ~20 terms of boundary-force size */
    assert_true(fbnd > 0.0);
    assert_true(fint < 1.0e-5 * fbnd);
    assert_true(fabs(uku - energy2) < 1.0e-5 * energy2);
}

/* ---- solver ---------------------------------------------------------------------------------- */

static float max_dev_from_rest_mm(const sc_mesh *m, const sc_nodes *n)
{
    float w = 0.0f;
    for (uint32_t i = 0; i < m->node_count; i++) {
        w = fmaxf(w, fabsf(n->x[i] - m->rest_x[i]));
        w = fmaxf(w, fabsf(n->y[i] - m->rest_y[i]));
        w = fmaxf(w, fabsf(n->z[i] - m->rest_z[i]));
    }
    return w;
}

/* Boundary nodes held on a linear field (kinematic, v = 0), interior started at rest: the
 * implicit steps converge to the exact linear field inside (the static solution). */
static void solver_converges_to_the_static_patch_solution(void **state)
{
    (void)state;
    make_mesh(9, 7, 7);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = 0u;
    }
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    const float G[9] = {0.02f, 0.01f, 0.0f, -0.01f, 0.03f, 0.0f, 0.0f, 0.005f, -0.05f};
    for (uint32_t k = 0; k < g_mesh.nz; k++) {
        for (uint32_t j = 0; j < g_mesh.ny; j++) {
            for (uint32_t i = 0; i < g_mesh.nx; i++) {
                const uint32_t id = i + g_mesh.nx * (j + g_mesh.ny * k);
                const int hull = i == 0 || j == 0 || k == 0 || i + 1u == g_mesh.nx ||
                                 j + 1u == g_mesh.ny || k + 1u == g_mesh.nz;
                g_kin[id] = hull ? 1u : 0u;
                if (hull) {
                    const float X[3] = {g_mesh.rest_x[id], g_mesh.rest_y[id], g_mesh.rest_z[id]};
                    g_nodes.x[id] += G[0] * X[0] + G[1] * X[1] + G[2] * X[2];
                    g_nodes.y[id] += G[3] * X[0] + G[4] * X[1] + G[5] * X[2];
                    g_nodes.z[id] += G[6] * X[0] + G[7] * X[1] + G[8] * X[2];
                }
            }
        }
    }
    float err = 0.0f, umax = 0.0f;
    for (uint32_t frame = 0; frame < 200u; frame++) {
        sc_fem_step_kinematic(&g_fem, &g_mesh, &g_nodes, 1.0f / 60.0f, 20u, g_kin);
    }
    for (uint32_t id = 0; id < g_mesh.node_count; id++) {
        const float X[3] = {g_mesh.rest_x[id], g_mesh.rest_y[id], g_mesh.rest_z[id]};
        const float ex = X[0] + G[0] * X[0] + G[1] * X[1] + G[2] * X[2];
        const float ey = X[1] + G[3] * X[0] + G[4] * X[1] + G[5] * X[2];
        const float ez = X[2] + G[6] * X[0] + G[7] * X[1] + G[8] * X[2];
        err = fmaxf(err, fmaxf(fabsf(g_nodes.x[id] - ex),
                               fmaxf(fabsf(g_nodes.y[id] - ey), fabsf(g_nodes.z[id] - ez))));
        umax = fmaxf(umax, fabsf(ez - X[2]));
    }
    print_message("patch solution: max error %.2e mm of max displacement %.3f mm\n", (double)err,
                  (double)umax);
    /* 1e-3 of the displacement: far below a pixel, far above float rounding (1e-6) */
    assert_true(err < 1.0e-3f * umax);
    assert_int_equal(sc_fem_status(&g_fem), SC_OK);
}

/* A displaced state released without forces returns to rest without oscillating: the
 * tracked displacement never changes sign and shrinks monotonically (over-damped), both with
 * the frame period as step and with the facade's step (20 x 0.01 s = 0.2 s per frame). */
static void released_displacement_returns_to_rest_over_damped(void **state)
{
    (void)state;
    const float dts[2] = {1.0f / 60.0f, 0.2f};
    for (uint32_t run = 0; run < 2u; run++) {
        make_mesh(16, 8, 8);
        sc_fem_def def = sc_fem_default_def();
        def.corotated = (uint8_t)run; /* both models */
        assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
        uint32_t probe = 0;
        float best = 1e9f;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            if (g_mesh.node_fixed[i]) {
                continue;
            }
            const float dx = g_mesh.rest_x[i] - 20.0f, dy = g_mesh.rest_y[i] - 10.0f,
                        dz = g_mesh.rest_z[i];
            const float r2 = dx * dx + dy * dy + dz * dz;
            g_nodes.z[i] += 3.0f * expf(-r2 / 50.0f); /* smooth dent of 3 mm under the top */
            if (r2 < best) {
                best = r2;
                probe = i;
            }
        }
        float prev = g_nodes.z[probe] - g_mesh.rest_z[probe];
        assert_true(prev > 2.0f);
        const float start = prev;
        for (uint32_t frame = 0; frame < 120u; frame++) {
            sc_fem_step(&g_fem, &g_mesh, &g_nodes, dts[run], 20u);
            const float u = g_nodes.z[probe] - g_mesh.rest_z[probe];
            assert_true(u >= -0.01f * start); /* no overshoot through rest beyond 1% */
            assert_true(u <= prev + 1e-6f);   /* monotonic decay */
            prev = u;
        }
        const float dev = max_dev_from_rest_mm(&g_mesh, &g_nodes);
        print_message("released dent (%s, dt %.3f s): %.3f mm -> max deviation %.2e mm after "
                      "120 frames\n",
                      run ? "corotated" : "linear", (double)dts[run], (double)start, (double)dev);
        assert_true(dev < 0.01f * start);
    }
}

static void fixed_nodes_never_move_and_forces_push_free_nodes(void **state)
{
    (void)state;
    make_mesh(8, 6, 6);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    uint32_t free_top = 0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_nodes.fz[i] = 1.0e-3f; /* 1 mN down on every node, fixed ones included */
        if (!g_mesh.node_fixed[i] && is_top(&g_mesh, i)) {
            free_top = i;
        }
    }
    for (uint32_t frame = 0; frame < 30u; frame++) {
        sc_fem_step(&g_fem, &g_mesh, &g_nodes, 0.01f, 20u);
    }
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        if (g_mesh.node_fixed[i]) {
            assert_true(same(g_nodes.x[i], g_mesh.rest_x[i]) &&
                        same(g_nodes.y[i], g_mesh.rest_y[i]) &&
                        same(g_nodes.z[i], g_mesh.rest_z[i]));
            assert_true(same(g_nodes.vx[i], 0.0f) && same(g_nodes.vz[i], 0.0f));
        }
    }
    assert_true(g_nodes.z[free_top] > g_mesh.rest_z[free_top] + 0.01f);
}

/* Rigid rotation of the whole (unconstrained) block by 40 degrees: the corotated model sees
 * no strain and produces (almost) no motion, the linear model produces spurious forces. */
static void corotated_model_is_invariant_under_rigid_rotation(void **state)
{
    (void)state;
    make_mesh(8, 6, 6);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = 0u;
    }
    const float c = cosf(0.698f), s = sinf(0.698f);
    float drift[2];
    for (uint32_t mode = 0; mode < 2u; mode++) {
        sc_fem_def def = sc_fem_default_def();
        def.corotated = (uint8_t)(1u - mode);
        assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
        sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            const float x = g_mesh.rest_x[i] - 20.0f, y = g_mesh.rest_y[i] - 10.0f;
            g_nodes.x[i] = 20.0f + c * x - s * y;
            g_nodes.y[i] = 10.0f + s * x + c * y;
            g_nodes2.x[i] = g_nodes.x[i];
            g_nodes2.y[i] = g_nodes.y[i];
            g_nodes2.z[i] = g_nodes.z[i];
        }
        for (uint32_t frame = 0; frame < 5u; frame++) {
            sc_fem_step(&g_fem, &g_mesh, &g_nodes, 1.0f / 60.0f, 20u);
        }
        float d = 0.0f;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            d = fmaxf(d, fabsf(g_nodes.x[i] - g_nodes2.x[i]));
            d = fmaxf(d, fabsf(g_nodes.y[i] - g_nodes2.y[i]));
            d = fmaxf(d, fabsf(g_nodes.z[i] - g_nodes2.z[i]));
        }
        drift[mode] = d;
    }
    print_message(
        "rigid 40 deg rotation, drift after 5 frames: corotated %.2e mm, linear %.3f mm\n",
        (double)drift[0], (double)drift[1]);
    /* corotated: rounding only (positions ~40 mm, float eps 4e-6 mm, amplified by the polar
     * iteration): 1e-3 mm; linear: the rotation looks like a ~30% strain, mm-scale motion */
    assert_true(drift[0] < 1.0e-3f);
    assert_true(drift[1] > 0.5f);
    assert_int_equal(g_fem.stats.degenerate_tets, 0u);
}

/* ---- clinical scene ------------------------------------------------------------------------ */

/* Phantom in the default box (x lateral 0..40, y along the vessels 0..20, z depth 0..30 mm):
 * fat; muscle below 20 mm; a vessel of radius 3 mm at (x 13, z 10) with vessel_a's label and
 * one at (x 27, z 10) with vessel_b's. Bottom and sides fixed. */
#define SCENE_VEIN_X_MM   13.0f
#define SCENE_ART_X_MM    27.0f
#define SCENE_VESSEL_Z_MM 10.0f
#define SCENE_VESSEL_R_MM 3.0f
/* Probe footprint: a linear probe, 36 mm aperture (x 2..38) x 12 mm elevation (y 4..16). */
/* The scenes' mesh: the resolution their geometry and thresholds were set for (the appliance's
 * limits allow larger meshes; these tests do not scale with them) */
#define SCENE_NX 32u
#define SCENE_NY 16u
#define SCENE_NZ 16u
_Static_assert(SCENE_NX <= SC_MAX_MESH_NX && SCENE_NY <= SC_MAX_MESH_NY &&
                   SCENE_NZ <= SC_MAX_MESH_NZ,
               "the scene mesh fits the limits");
#define SCENE_PROBE_X0 2.0f
#define SCENE_PROBE_X1 38.0f
#define SCENE_PROBE_Y0 4.0f
#define SCENE_PROBE_Y1 16.0f
/* Tets "under the probe": centroid inside the central part of the footprint in y. */
#define SCENE_MEAS_Y0 7.0f
#define SCENE_MEAS_Y1 13.0f

static void label_scene(sc_mesh *m, uint8_t label_a, uint8_t label_b)
{
    for (uint32_t e = 0; e < m->tet_count; e++) {
        float c[3];
        tet_centroid(m, e, c);
        uint8_t lab = c[2] > 20.0f ? SC_LABEL_MUSCLE : SC_LABEL_FAT;
        const float za = c[2] - SCENE_VESSEL_Z_MM;
        const float xa = c[0] - SCENE_VEIN_X_MM, xb = c[0] - SCENE_ART_X_MM;
        const float r2 = SCENE_VESSEL_R_MM * SCENE_VESSEL_R_MM;
        if (xa * xa + za * za <= r2) {
            lab = label_a;
        } else if (xb * xb + za * za <= r2) {
            lab = label_b;
        }
        m->tet_label[e] = lab;
    }
}

/* Sum of the deformed volumes of the tets with label lab under the probe, and of their rest. */
static void label_volume(const sc_mesh *m, const sc_nodes *n, uint8_t lab, float x0, float x1,
                         double *vol, double *rest)
{
    *vol = 0.0;
    *rest = 0.0;
    for (uint32_t e = 0; e < m->tet_count; e++) {
        float c[3];
        tet_centroid(m, e, c);
        if (m->tet_label[e] != lab || c[1] < SCENE_MEAS_Y0 || c[1] > SCENE_MEAS_Y1 || c[0] < x0 ||
            c[0] > x1) {
            continue;
        }
        *vol += (double)sc_mesh_tet_volume_mm3(n->x, n->y, n->z, m->tet[e]);
        *rest += (double)sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[e]);
    }
}

typedef struct scene_result {
    double shrink_a; /* relative volume loss of vessel a under the probe */
    double shrink_b;
    float dev_after_lift_mm; /* max |x - X| 2 s after the lift */
    float box_mm;
} scene_result;

#define SCENE_FRAME_DT_S   0.01f /* the FEM step per frame (SC_PHYS_DT_DEFAULT_S) */
#define SCENE_PRESS_FRAMES 30u
#define SCENE_HOLD_FRAMES  20u
#define SCENE_LIFT_FRAMES  120u /* 2 s at 60 Hz frames */

/* Prescribed-displacement indentation: the top nodes in the footprint are driven 15% of the
 * box depth down over SCENE_PRESS_FRAMES, held, then released. */
static scene_result run_scene(sc_fem *f, sc_nodes *n, uint8_t label_a, uint8_t label_b,
                              int corotated, uint32_t nx, uint32_t ny, uint32_t nz)
{
    make_mesh(nx, ny, nz);
    label_scene(&g_mesh, label_a, label_b);
    sc_nodes_reset_to_rest(n, &g_mesh);
    sc_fem_def def = sc_fem_default_def();
    def.corotated = (uint8_t)corotated;
    assert_int_equal(sc_fem_init(f, &g_mesh, &g_mat, &def), SC_OK);
    const float depth_mm = 30.0f;
    const float press_mm = 0.15f * depth_mm;
    const float v_press = press_mm / ((float)SCENE_PRESS_FRAMES * SCENE_FRAME_DT_S);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float x = g_mesh.rest_x[i], y = g_mesh.rest_y[i];
        g_kin[i] = (is_top(&g_mesh, i) && x >= SCENE_PROBE_X0 && x <= SCENE_PROBE_X1 &&
                    y >= SCENE_PROBE_Y0 && y <= SCENE_PROBE_Y1)
                       ? 1u
                       : 0u;
    }
    for (uint32_t frame = 0; frame < SCENE_PRESS_FRAMES + SCENE_HOLD_FRAMES; frame++) {
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            if (g_kin[i]) {
                n->vx[i] = 0.0f;
                n->vy[i] = 0.0f;
                n->vz[i] = frame < SCENE_PRESS_FRAMES ? v_press : 0.0f;
            }
        }
        sc_fem_step_kinematic(f, &g_mesh, n, SCENE_FRAME_DT_S, SC_PHYS_ITERATIONS_DEFAULT, g_kin);
    }
    scene_result res;
    double v, r;
    label_volume(&g_mesh, n, label_a, 0.0f, 20.0f, &v, &r);
    assert_true(r > 0.0);
    res.shrink_a = 1.0 - v / r;
    label_volume(&g_mesh, n, label_b, 20.0f, 40.0f, &v, &r);
    assert_true(r > 0.0);
    res.shrink_b = 1.0 - v / r;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        n->vz[i] = g_kin[i] ? 0.0f : n->vz[i]; /* the probe leaves the skin at rest */
    }
    for (uint32_t frame = 0; frame < SCENE_LIFT_FRAMES; frame++) {
        sc_fem_step(f, &g_mesh, n, SCENE_FRAME_DT_S, SC_PHYS_ITERATIONS_DEFAULT);
    }
    res.dev_after_lift_mm = max_dev_from_rest_mm(&g_mesh, n);
    res.box_mm = 40.0f;
    assert_int_equal(sc_fem_status(f), SC_OK);
    return res;
}

/* The thrombosed-vein scene runs in the default (linear) model only: it is the same solver
 * path as the vein scene, and the corotated scenes cost the most test time. */
static void check_clinical(int corotated)
{
    scene_result a = run_scene(&g_fem, &g_nodes, SC_LABEL_VEIN, SC_LABEL_ARTERY, corotated,
                               SCENE_NX, SCENE_NY, SCENE_NZ);
    print_message("FEM %s, 15%% indentation: vein -%.1f%%, artery -%.1f%%; 2 s after lift max "
                  "deviation %.2e mm (1%% box = %.2f mm)\n",
                  corotated ? "corotated" : "linear", 100.0 * a.shrink_a, 100.0 * a.shrink_b,
                  (double)a.dev_after_lift_mm, (double)(0.01f * a.box_mm));
    assert_true(a.shrink_a >= 0.60);
    assert_true(a.shrink_b <= 0.20);
    assert_true(a.dev_after_lift_mm <= 0.01f * a.box_mm);
    if (!corotated) {
        scene_result b = run_scene(&g_fem, &g_nodes, SC_LABEL_THROMBUS, SC_LABEL_ARTERY, corotated,
                                   SCENE_NX, SCENE_NY, SCENE_NZ);
        print_message("FEM linear: thrombosed vein -%.1f%%, artery -%.1f%%; after lift %.2e mm\n",
                      100.0 * b.shrink_a, 100.0 * b.shrink_b, (double)b.dev_after_lift_mm);
        assert_true(b.shrink_a <= 0.20);
        assert_true(b.shrink_b <= 0.20);
        assert_true(b.dev_after_lift_mm <= 0.01f * b.box_mm);
    }
}

static void clinical_vein_collapses_artery_and_thrombus_resist_linear(void **state)
{
    (void)state;
    check_clinical(0);
}

static void clinical_vein_collapses_artery_and_thrombus_resist_corotated(void **state)
{
    (void)state;
    check_clinical(1);
}

/* The same release with only 3 CG iterations per frame (an overloaded frame budget): the
 * relaxation is slower but still over-damped (no overshoot through rest, monotonic) at both
 * step lengths, and reaches rest within 120 frames. A warm start from the stale velocity
 * (v0 = v) fails this: the unconverged modes coast and overshoot by up to a third of the
 * dent. */
static void few_cg_iterations_still_relax_without_overshoot(void **state)
{
    (void)state;
    const float dts[2] = {1.0f / 60.0f, 0.2f};
    for (uint32_t run = 0; run < 2u; run++) {
        make_mesh(16, 8, 8);
        label_scene(&g_mesh, SC_LABEL_VEIN, SC_LABEL_ARTERY);
        sc_fem_def def = sc_fem_default_def();
        assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
        uint32_t probe = 0;
        float best = 1e9f;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            if (g_mesh.node_fixed[i]) {
                continue;
            }
            const float dx = g_mesh.rest_x[i] - 13.0f, dy = g_mesh.rest_y[i] - 10.0f,
                        dz = g_mesh.rest_z[i];
            const float r2 = dx * dx + dy * dy + dz * dz;
            g_nodes.z[i] += 4.0f * expf(-r2 / 50.0f);
            if (r2 < best) {
                best = r2;
                probe = i;
            }
        }
        const float start = g_nodes.z[probe] - g_mesh.rest_z[probe];
        float prev = start, lowest = start, rise = 0.0f;
        uint32_t rise_frame = 0;
        for (uint32_t frame = 0; frame < 120u; frame++) {
            sc_fem_step(&g_fem, &g_mesh, &g_nodes, dts[run], 3u);
            const float u = g_nodes.z[probe] - g_mesh.rest_z[probe];
            if (u - prev > rise) {
                rise = u - prev;
                rise_frame = frame;
            }
            lowest = fminf(lowest, u);
            prev = u;
        }
        const float dev = max_dev_from_rest_mm(&g_mesh, &g_nodes);
        print_message("3 CG iterations, dt %.3f s: dent %.3f mm, lowest %.2e mm, largest rise "
                      "%.2e mm (frame %u), max deviation %.2e mm after 120 frames\n",
                      (double)dts[run], (double)start, (double)lowest, (double)rise,
                      (unsigned)rise_frame, (double)dev);
        assert_true(rise <= 1e-3f * start);    /* monotonic (a rise of 0.1% at most) */
        assert_true(lowest >= -0.01f * start); /* no overshoot beyond 1% */
        assert_true(dev < 0.01f * start);
    }
}

/* ---- corotation: the element rotation and the folded residual ------------------------------ */

/* c = a b, row-major 3x3 */
static void mat3_mul(const double a[9], const double b[9], double c[9])
{
    for (uint32_t r = 0; r < 3u; r++) {
        for (uint32_t k = 0; k < 3u; k++) {
            c[3u * r + k] =
                a[3u * r] * b[k] + a[3u * r + 1u] * b[3u + k] + a[3u * r + 2u] * b[6u + k];
        }
    }
}

/* rotation by angle (rad) about the unit vector along ax (Rodrigues) */
static void rotation(const double ax[3], double angle, double q[9])
{
    const double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    const double u[3] = {ax[0] / n, ax[1] / n, ax[2] / n};
    const double c = cos(angle), s = sin(angle), t = 1.0 - c;
    q[0] = c + t * u[0] * u[0];
    q[1] = t * u[0] * u[1] - s * u[2];
    q[2] = t * u[0] * u[2] + s * u[1];
    q[3] = t * u[0] * u[1] + s * u[2];
    q[4] = c + t * u[1] * u[1];
    q[5] = t * u[1] * u[2] - s * u[0];
    q[6] = t * u[0] * u[2] - s * u[1];
    q[7] = t * u[1] * u[2] + s * u[0];
    q[8] = c + t * u[2] * u[2];
}

static int is_identity(const float r[9])
{
    for (uint32_t i = 0; i < 9u; i++) {
        if (!same(r[i], (i % 4u == 0u) ? 1.0f : 0.0f)) {
            return 0;
        }
    }
    return 1;
}

/* F = Q S with Q a rotation and S symmetric positive definite (principal stretches s along
 * the axes of another rotation P: S = P diag(s) P^T): the step's rotation is Q, a proper
 * rotation (R^T R = I, det R = 1), from no strain to a 3:1 stretch and a compression to 30%
 * (a squashed vein), and at angles up to 150 degrees. */
static void element_rotation_is_the_polar_factor_of_a_rotated_stretch(void **state)
{
    (void)state;
    static const double stretch[5][3] = {
        {1.0, 1.0, 1.0}, {1.1, 0.95, 1.02}, {3.0, 1.0, 0.5}, {0.3, 1.0, 1.2}, {0.3, 0.4, 2.5}};
    static const double angle[3] = {0.0, 0.4, 2.6};
    const double ax_q[3] = {1.0, 2.0, -0.5}, ax_p[3] = {-0.3, 0.2, 1.0};
    double worst_q = 0.0, worst_orth = 0.0;
    for (uint32_t si = 0; si < 5u; si++) {
        for (uint32_t ai = 0; ai < 3u; ai++) {
            double q[9], p[9], pt[9], d[9] = {0}, ps[9], sm[9], fm[9];
            rotation(ax_q, angle[ai], q);
            rotation(ax_p, 0.7 + (double)si, p);
            for (uint32_t r = 0; r < 3u; r++) {
                d[4u * r] = stretch[si][r];
                for (uint32_t c = 0; c < 3u; c++) {
                    pt[3u * r + c] = p[3u * c + r];
                }
            }
            mat3_mul(p, d, ps);
            mat3_mul(ps, pt, sm);
            mat3_mul(q, sm, fm);
            float F[9], R[9];
            for (uint32_t i = 0; i < 9u; i++) {
                F[i] = (float)fm[i];
            }
            assert_int_equal(sc_fem_polar_rotation(F, R), 1);
            for (uint32_t i = 0; i < 9u; i++) {
                worst_q = fmax(worst_q, fabs((double)R[i] - q[i]));
            }
            for (uint32_t r = 0; r < 3u; r++) {
                for (uint32_t c = 0; c < 3u; c++) {
                    const double rr = (double)R[r] * R[c] + (double)R[3u + r] * R[3u + c] +
                                      (double)R[6u + r] * R[6u + c];
                    worst_orth = fmax(worst_orth, fabs(rr - (r == c ? 1.0 : 0.0)));
                }
            }
            const double det = (double)R[0] * ((double)R[4] * R[8] - (double)R[5] * R[7]) +
                               (double)R[1] * ((double)R[5] * R[6] - (double)R[3] * R[8]) +
                               (double)R[2] * ((double)R[3] * R[7] - (double)R[4] * R[6]);
            assert_true(fabs(det - 1.0) < 1.0e-5);
        }
    }
    print_message("element rotation: max |R - Q| %.2e, max |R^T R - I| %.2e\n", worst_q,
                  worst_orth);
    /* float F (rounding 6e-8 relative), amplified at most by the 10:1 stretch ratio */
    assert_true(worst_q < 2.0e-5);
    assert_true(worst_orth < 2.0e-6);
}

/* No proper rotation exists for a flat (det F = 0) or inverted (det F < 0) element, or one
 * squashed below det F = 1e-3, or a non-finite F: the rotation is exactly I and flagged, so
 * that the element acts as a linear one (which pushes it back towards its rest shape). Just
 * above the threshold the rotation is still the polar factor. */
static void element_rotation_of_flat_inverted_or_broken_element_is_identity(void **state)
{
    (void)state;
    double q[9];
    const double ax[3] = {0.2, -1.0, 0.4};
    rotation(ax, 1.1, q);
    float F[9], R[9];
    /* reflections and flattening, plain and rotated */
    static const float diag[4][3] = {
        {1.0f, 1.0f, -1.0f}, {1.0f, 1.0f, 0.0f}, {0.5f, -0.2f, 1.5f}, {0.1f, 0.1f, 0.09f}};
    for (uint32_t k = 0; k < 4u; k++) {
        for (uint32_t rot = 0; rot < 2u; rot++) {
            for (uint32_t r = 0; r < 3u; r++) {
                for (uint32_t c = 0; c < 3u; c++) {
                    F[3u * r + c] = rot ? (float)(q[3u * r + c] * (double)diag[k][c])
                                        : (r == c ? diag[k][r] : 0.0f);
                }
            }
            memset(R, 0, sizeof R);
            assert_int_equal(sc_fem_polar_rotation(F, R), 0);
            assert_true(is_identity(R));
        }
    }
    for (uint32_t i = 0; i < 9u; i++) {
        F[i] = (float)(0.13 * q[i]); /* det 2.2e-3: above the threshold */
    }
    assert_int_equal(sc_fem_polar_rotation(F, R), 1);
    for (uint32_t i = 0; i < 9u; i++) {
        assert_true(fabs((double)R[i] - q[i]) < 1.0e-5);
    }
    F[4] = NAN;
    assert_int_equal(sc_fem_polar_rotation(F, R), 0);
    assert_true(is_identity(R));
}

/* Tets pushed through themselves by a displaced node: the corotated step counts exactly the
 * tets with det F <= 1e-3 (volume ratio), stays finite, and the released mesh recovers (no
 * tet stays inverted). */
static void corotated_step_counts_inverted_tets_and_recovers(void **state)
{
    (void)state;
    make_mesh(8, 6, 6);
    sc_fem_def def = sc_fem_default_def();
    def.corotated = 1u;
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    /* an interior node 2 cells up into the skin: its tets below fold over */
    const uint32_t c = 4u + g_mesh.nx * (3u + g_mesh.ny * 3u);
    assert_true(!g_mesh.node_fixed[c]);
    const float cell_z = g_mesh.rest_z[c + g_mesh.nx * g_mesh.ny] - g_mesh.rest_z[c];
    g_nodes.z[c] -= 1.5f * cell_z;
    uint32_t expect = 0;
    for (uint32_t e = 0; e < g_mesh.tet_count; e++) {
        const float v = sc_mesh_tet_volume_mm3(g_nodes.x, g_nodes.y, g_nodes.z, g_mesh.tet[e]);
        const float v0 =
            sc_mesh_tet_volume_mm3(g_mesh.rest_x, g_mesh.rest_y, g_mesh.rest_z, g_mesh.tet[e]);
        expect += (v <= 1.0e-3f * v0) ? 1u : 0u;
    }
    assert_true(expect > 0u);
    sc_fem_step(&g_fem, &g_mesh, &g_nodes, 0.01f, 20u);
    print_message("inverted tets: %u counted, %u expected\n", g_fem.stats.degenerate_tets, expect);
    assert_int_equal(g_fem.stats.degenerate_tets, expect);
    for (uint32_t frame = 0; frame < 60u; frame++) {
        sc_fem_step(&g_fem, &g_mesh, &g_nodes, 0.01f, 20u);
    }
    assert_int_equal(sc_fem_status(&g_fem), SC_OK);
    assert_int_equal(g_fem.stats.degenerate_tets, 0u);
    assert_true(max_dev_from_rest_mm(&g_mesh, &g_nodes) < 0.1f * cell_z);
}

/* Near rest the corotated model is the linear one (R = I + O(strain)). The corotated step
 * computes the residual r0 = dt (f_ext - f_int) - ck K v0 - ... element by element (with
 * K v0 folded into the assembly), the linear step with a mat-vec of the rest K: both steps
 * from the same slightly deformed, moving state must agree. A sign or scale error in the
 * elastic or the damping term of the folded residual moves the result by O(1). */
static void corotated_step_equals_linear_step_near_rest(void **state)
{
    (void)state;
    make_mesh(10, 6, 8);
    label_scene(&g_mesh, SC_LABEL_VEIN, SC_LABEL_ARTERY);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    def.corotated = 1u;
    assert_int_equal(sc_fem_init(&g_fem2, &g_mesh, &g_mat, &def), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes2, &g_mesh);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float x = g_mesh.rest_x[i], y = g_mesh.rest_y[i], z = g_mesh.rest_z[i];
        const float u = 1.0e-4f * sinf(0.3f * x + 0.2f * z) * cosf(0.25f * y); /* mm */
        g_nodes.x[i] = g_nodes2.x[i] = x + u;
        g_nodes.z[i] = g_nodes2.z[i] = z - 0.5f * u;
        g_nodes.vx[i] = g_nodes2.vx[i] = 3.0f * cosf(0.2f * x - 0.1f * z); /* mm/s */
        g_nodes.vy[i] = g_nodes2.vy[i] = 2.0f * sinf(0.15f * z + 0.1f * y);
        g_nodes.vz[i] = g_nodes2.vz[i] = -4.0f * sinf(0.1f * x) * cosf(0.2f * y);
        g_nodes.fz[i] = g_nodes2.fz[i] = is_top(&g_mesh, i) ? 2.0e-4f : 0.0f;
    }
    float vin[3u * SC_MAX_NODES];
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        vin[3u * i] = g_nodes.vx[i];
        vin[3u * i + 1u] = g_nodes.vy[i];
        vin[3u * i + 2u] = g_nodes.vz[i];
    }
    sc_fem_step(&g_fem, &g_mesh, &g_nodes, 0.01f, 20u);
    sc_fem_step(&g_fem2, &g_mesh, &g_nodes2, 0.01f, 20u);
    double diff = 0.0, change = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float a[3] = {g_nodes.vx[i], g_nodes.vy[i], g_nodes.vz[i]};
        const float b[3] = {g_nodes2.vx[i], g_nodes2.vy[i], g_nodes2.vz[i]};
        for (uint32_t d = 0; d < 3u; d++) {
            diff = fmax(diff, fabs((double)a[d] - (double)b[d]));
            change = fmax(change, fabs((double)a[d] - (double)vin[3u * i + d]));
        }
    }
    print_message("near rest: corotated vs linear velocity %.2e mm/s of a change %.3f mm/s\n", diff,
                  change);
    assert_int_equal(g_fem2.stats.degenerate_tets, 0u);
    assert_true(change > 0.5);
    assert_true(diff < 1.0e-3 * change);
}

/* ---- determinism ----------------------------------------------------------------------------- */

static uint64_t hash_nodes(const sc_nodes *n, uint32_t count)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a 64 */
    const float *arrs[6] = {n->x, n->y, n->z, n->vx, n->vy, n->vz};
    for (uint32_t a = 0; a < 6u; a++) {
        const uint8_t *p = (const uint8_t *)arrs[a];
        for (size_t i = 0; i < (size_t)count * sizeof(float); i++) {
            h ^= p[i];
            h *= 1099511628211ull;
        }
    }
    return h;
}

static void steps_are_bitwise_deterministic(void **state)
{
    (void)state;
    uint64_t h[2][2];
    for (uint32_t corot = 0; corot < 2u; corot++) {
        for (uint32_t run = 0; run < 2u; run++) {
            sc_fem *f = run ? &g_fem2 : &g_fem;
            sc_nodes *n = run ? &g_nodes2 : &g_nodes;
            make_mesh(12, 6, 8);
            label_scene(&g_mesh, SC_LABEL_VEIN, SC_LABEL_ARTERY);
            sc_nodes_reset_to_rest(n, &g_mesh);
            sc_fem_def def = sc_fem_default_def();
            def.corotated = (uint8_t)corot;
            assert_int_equal(sc_fem_init(f, &g_mesh, &g_mat, &def), SC_OK);
            for (uint32_t frame = 0; frame < 40u; frame++) {
                for (uint32_t i = 0; i < g_mesh.node_count; i++) {
                    const float dx = g_mesh.rest_x[i] - 20.0f, dy = g_mesh.rest_y[i] - 10.0f;
                    n->fz[i] = (frame < 20u && is_top(&g_mesh, i) && dx * dx + dy * dy < 64.0f)
                                   ? 2.0e-4f
                                   : 0.0f;
                }
                sc_fem_step(f, &g_mesh, n, 0.01f, 20u);
            }
            h[corot][run] = hash_nodes(n, g_mesh.node_count);
        }
        assert_true(h[corot][0] == h[corot][1]);
    }
    print_message("state hash after 40 frames: linear %016llx corotated %016llx\n",
                  (unsigned long long)h[0][0], (unsigned long long)h[1][0]);
    /* Stored values: the same in Debug (-O1, sanitizers) and Release (-O3) on x86-64, with
     * every instruction-set variant (test_sc_simd) and with one-lane vectors (-DSC_VEC_SCALAR,
     * the MCU's build of sc_grid_kern.c), since the core is built with -ffp-contract=off,
     * every reduction has a fixed order and the cell kernels add into a node in the order of
     * the cells (sc_grid.h). A change here is a change of the numerics (FEM, mesh, materials or fixed
     * nodes): update the values deliberately, in the same commit, saying why. Last changed when
     * the FEM moved to the grid matrix (template gradients, element-wise r0 for both models,
     * the grid's PCG and the unloaded warm start toward rest; were 0xebcf32bae8caa610 and
     * 0x1189f04920bf6f8a); then when the artery's material became the wall's share of a lumen
     * held open by the lumen law (config/sc_materials.h: 300 -> 30 kPa; were
     * 0x278682b11d0e4003 and 0xc59ad4b441628d65); then when the cell kernels stopped going
     * through a block buffer and add each cell vector straight into the matrix, so a node's
     * sums run in cell order instead of target by target per 16 cells (the same terms, summed
     * in another order; were 0x58b41fbf1a603f79 and 0x3b36656df22db08c). */
    assert_true(h[0][0] == UINT64_C(0xba78d9d32a13524b));
    assert_true(h[1][0] == UINT64_C(0x0550a3c053a9e757));
}

/* ---- run-time switches -------------------------------------------------------------------- */

/* Corotation switched on and off in the middle of a compression: in the switch frame no node
 * moves more than 1 mm (a normal frame moves the probe nodes 0.15 mm). */
static void corotation_switch_mid_compression_does_not_jump(void **state)
{
    (void)state;
    make_mesh(16, 8, 12);
    label_scene(&g_mesh, SC_LABEL_VEIN, SC_LABEL_ARTERY);
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float x = g_mesh.rest_x[i], y = g_mesh.rest_y[i];
        g_kin[i] = (is_top(&g_mesh, i) && x >= SCENE_PROBE_X0 && x <= SCENE_PROBE_X1 &&
                    y >= SCENE_PROBE_Y0 && y <= SCENE_PROBE_Y1);
    }
    float worst = 0.0f;
    for (uint32_t frame = 0; frame < 40u; frame++) {
        if (frame == 15u) {
            sc_fem_set_corotated(&g_fem, 1);
        }
        if (frame == 30u) {
            sc_fem_set_corotated(&g_fem, 0);
        }
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            if (g_kin[i]) {
                g_nodes.vz[i] = 15.0f; /* 0.15 mm per 0.01 s frame */
            }
            g_nodes2.x[i] = g_nodes.x[i];
            g_nodes2.y[i] = g_nodes.y[i];
            g_nodes2.z[i] = g_nodes.z[i];
        }
        sc_fem_step_kinematic(&g_fem, &g_mesh, &g_nodes, 0.01f, 20u, g_kin);
        float d = 0.0f;
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            d = fmaxf(d, fabsf(g_nodes.x[i] - g_nodes2.x[i]));
            d = fmaxf(d, fabsf(g_nodes.y[i] - g_nodes2.y[i]));
            d = fmaxf(d, fabsf(g_nodes.z[i] - g_nodes2.z[i]));
        }
        if (frame == 15u || frame == 30u) {
            worst = fmaxf(worst, d);
        }
    }
    print_message("largest node move in a corotation switch frame: %.3f mm\n", (double)worst);
    assert_true(worst <= 1.0f);
}

/* ---- MSDS vs FEM ------------------------------------------------------------------------ */

typedef struct compare_result {
    double rms_mm, max_mm;    /* node displacement difference MSDS - FEM over the free nodes */
    double uz6_msds, uz6_fem; /* vertical displacement under the probe centre at 6 mm depth */
} compare_result;

/* The same prescribed indentation on the same mesh and labels: the top nodes under the
 * footprint are driven press_mm down over 10 frames (continuously: a little before every
 * MSDS substep), then held 50 frames, by which both methods have settled. MSDS: Algorithm 1
 * springs, 20 explicit Euler steps of 0.01 s per frame; FEM: linear, one implicit step of
 * 0.2 s per frame with 20 CG iterations (as sc_tissue runs it). The probe nodes are fixed
 * nodes moved by the test: the same Dirichlet data for both methods. */
static compare_result compare_indentation(uint8_t label_a, uint8_t label_b, float press_mm)
{
    make_mesh(SCENE_NX, SCENE_NY, SCENE_NZ);
    label_scene(&g_mesh, label_a, label_b);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float x = g_mesh.rest_x[i], y = g_mesh.rest_y[i];
        g_kin[i] = (is_top(&g_mesh, i) && x >= SCENE_PROBE_X0 && x <= SCENE_PROBE_X1 &&
                    y >= SCENE_PROBE_Y0 && y <= SCENE_PROBE_Y1);
        if (g_kin[i]) {
            g_mesh.node_fixed[i] = 1u;
        }
    }
    assert_int_equal(
        sc_springs_from_tets(&g_springs, g_mesh.tet, g_mesh.tet_label, g_mesh.tet_count, &g_mat),
        SC_OK);
    const sc_msds_def md = sc_msds_default_def();
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_springs, &g_mat, &md), SC_OK);
    const sc_fem_def fd = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &fd), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);  /* MSDS */
    sc_nodes_reset_to_rest(&g_nodes2, &g_mesh); /* FEM */
    const float frame_dt_s = md.dt_s * (float)md.iterations;
    const float per_sub_mm = press_mm / (10.0f * (float)md.iterations);
    for (uint32_t frame = 0; frame < 60u; frame++) {
        for (uint32_t sub = 0; sub < md.iterations; sub++) {
            for (uint32_t i = 0; frame < 10u && i < g_mesh.node_count; i++) {
                g_nodes.z[i] += g_kin[i] ? per_sub_mm : 0.0f;
            }
            sc_msds_substep(&g_msds, &g_nodes);
        }
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            g_nodes2.z[i] = g_kin[i] ? g_nodes.z[i] : g_nodes2.z[i];
        }
        sc_fem_step(&g_fem, &g_mesh, &g_nodes2, frame_dt_s, md.iterations);
    }
    compare_result r;
    double sum2 = 0.0;
    uint32_t count = 0;
    r.max_mm = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        if (g_mesh.node_fixed[i]) {
            continue;
        }
        const double dx = (double)g_nodes.x[i] - (double)g_nodes2.x[i];
        const double dy = (double)g_nodes.y[i] - (double)g_nodes2.y[i];
        const double dz = (double)g_nodes.z[i] - (double)g_nodes2.z[i];
        const double d2 = dx * dx + dy * dy + dz * dz;
        sum2 += d2;
        r.max_mm = fmax(r.max_mm, sqrt(d2));
        count++;
    }
    r.rms_mm = sqrt(sum2 / (double)count);
    const uint32_t c6 = g_mesh.nx / 2u + g_mesh.nx * (g_mesh.ny / 2u + g_mesh.ny * 3u);
    r.uz6_msds = (double)(g_nodes.z[c6] - g_mesh.rest_z[c6]);
    r.uz6_fem = (double)(g_nodes2.z[c6] - g_mesh.rest_z[c6]);
    assert_int_equal(sc_fem_status(&g_fem), SC_OK);
    return r;
}

/* Indentation of one cell height (2 mm, 6.7% of the depth): both fields are driven by the
 * same boundary displacement and the same stiffness ratios between labels (k = 0.002 E per
 * spring); they differ through the constitutive models: a central-force spring lattice has
 * its own effective Poisson ratio (about 0.25) where the FEM uses 0.45 (vein 0.3), so the
 * lateral bulge around the probe differs. Measured: RMS 4-5% of the indentation; asserted:
 * at most 10%, homogeneous and with the vessels.
 * At the clinical 15% (4.5 mm, more than two cell heights) the MSDS's top layer of springs
 * snaps through (the probe nodes pass the nodes below them: a mirrored, nearly unstressed
 * configuration of the springs) and the two methods disagree; printed, not asserted (a
 * limitation of the MSDS, reported, not something the FEM can fix). */
static void msds_and_fem_respond_alike_to_the_same_indentation(void **state)
{
    (void)state;
    const float press_mm = 2.0f;
    const compare_result h = compare_indentation(SC_LABEL_FAT, SC_LABEL_FAT, press_mm);
    const compare_result c = compare_indentation(SC_LABEL_VEIN, SC_LABEL_ARTERY, press_mm);
    const compare_result deep = compare_indentation(SC_LABEL_VEIN, SC_LABEL_ARTERY, 4.5f);
    print_message("MSDS vs FEM, %.1f mm indentation: difference RMS %.3f mm (%.1f%%), max %.3f mm "
                  "(homogeneous); RMS %.3f mm (%.1f%%), max %.3f mm (vein + artery); u_z at 6 mm "
                  "under the probe %.3f / %.3f mm\n",
                  (double)press_mm, h.rms_mm, 100.0 * h.rms_mm / (double)press_mm, h.max_mm,
                  c.rms_mm, 100.0 * c.rms_mm / (double)press_mm, c.max_mm, c.uz6_msds, c.uz6_fem);
    print_message("MSDS vs FEM, 4.5 mm (15%%) indentation: difference RMS %.3f mm (%.1f%%), u_z "
                  "at 6 mm under the probe MSDS %.3f mm, FEM %.3f mm (MSDS top layer snaps "
                  "through)\n",
                  deep.rms_mm, 100.0 * deep.rms_mm / 4.5, deep.uz6_msds, deep.uz6_fem);
    assert_true(h.rms_mm <= 0.10 * (double)press_mm);
    assert_true(c.rms_mm <= 0.10 * (double)press_mm);
    /* the comparison can fail: the two methods do see the indentation at depth */
    assert_true(c.uz6_fem > 0.3 * (double)press_mm && c.uz6_msds > 0.3 * (double)press_mm);
}

/* ---- the two-grid correction (sc_grid.h, sc_grid_coarse) ----------------------------------- */

#if SC_GRID_COARSE
/* A mesh above SC_GRID_COARSE_NODES gets the coarse grid (every other node: 40x16x16 ->
 * 20x8x8, the masses restricted whole), one at or below it none; at rest and unloaded the
 * correction is zero: the nodes stay exactly at rest. */
static void two_grid_correction_above_the_threshold_and_none_at_rest(void **state)
{
    (void)state;
    sc_fem_def def = sc_fem_default_def();
    make_mesh(32, 16, 16);
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    assert_null(g_fem.grid.coarse);
    make_mesh(40, 16, 16);
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    assert_non_null(g_fem.grid.coarse);
    const sc_grid *gc = &g_fem.grid.coarse->grid;
    assert_int_equal(gc->nx, 20);
    assert_int_equal(gc->ny, 8);
    assert_int_equal(gc->nz, 8);
    double mf = 0.0, mc = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        mf += (double)g_fem.grid.mass[SC_GRID_HEAD + i];
    }
    for (uint32_t i = 0; i < gc->node_count; i++) {
        mc += (double)gc->mass[SC_GRID_HEAD + i];
    }
    assert_true(mf > 0.0 && fabs(mc - mf) < 1.0e-4 * mf);
    for (uint32_t f = 0; f < 3u; f++) {
        sc_fem_step(&g_fem, &g_mesh, &g_nodes, 1.0f / 60.0f, 10u);
    }
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        assert_true(same(g_nodes.x[i], g_mesh.rest_x[i]) && same(g_nodes.y[i], g_mesh.rest_y[i]) &&
                    same(g_nodes.z[i], g_mesh.rest_z[i]) && same(g_nodes.vz[i], 0.0f));
    }
}

/* One step of a press (a patch of the top moved 1 mm into the block) from rest: with a count of
 * 10 (the correction and 9 CG iterations) the corrected step is much nearer the solved one (200)
 * than the plain Jacobi CG's 10, whose error is the far field they have not reached; solved with
 * or without the correction, the step is the same. */
static double press_step_error(int coarse, uint32_t iterations, const sc_nodes *ref)
{
    sc_fem_def def = sc_fem_default_def();
    assert_int_equal(sc_fem_init(&g_fem, &g_mesh, &g_mat, &def), SC_OK);
    if (!coarse) {
        g_fem.grid.coarse = NULL;
    }
    sc_nodes_reset_to_rest(&g_nodes2, &g_mesh);
    memset(g_kin, 0, sizeof g_kin);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const uint32_t x = i % g_mesh.nx, y = (i / g_mesh.nx) % g_mesh.ny;
        if (is_top(&g_mesh, i) && !g_mesh.node_fixed[i] && x >= 15u && x < 25u && y >= 5u &&
            y < 11u) {
            g_kin[i] = 1u;
            g_nodes2.vz[i] = 60.0f; /* 1 mm down (+z) in the step */
        }
    }
    sc_fem_step_kinematic(&g_fem, &g_mesh, &g_nodes2, 1.0f / 60.0f, iterations, g_kin);
    assert_int_equal(sc_fem_status(&g_fem), SC_OK);
    double e = 0.0;
    if (ref != NULL) {
        for (uint32_t i = 0; i < g_mesh.node_count; i++) {
            const double d[3] = {(double)g_nodes2.vx[i] - (double)ref->vx[i],
                                 (double)g_nodes2.vy[i] - (double)ref->vy[i],
                                 (double)g_nodes2.vz[i] - (double)ref->vz[i]};
            e += d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        }
    }
    return sqrt(e);
}

static void two_grid_correction_brings_a_press_step_near_the_solved_one(void **state)
{
    (void)state;
    make_mesh(40, 16, 16);
    (void)press_step_error(1, SC_PHYS_ITERATIONS_MAX, NULL);
    g_nodes = g_nodes2; /* the solved step */
    double vref = 0.0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        vref += (double)g_nodes.vx[i] * g_nodes.vx[i] + (double)g_nodes.vy[i] * g_nodes.vy[i] +
                (double)g_nodes.vz[i] * g_nodes.vz[i];
    }
    vref = sqrt(vref);
    const double solved_plain = press_step_error(0, SC_PHYS_ITERATIONS_MAX, &g_nodes);
    const double with = press_step_error(1, 10u, &g_nodes);
    const float alpha = g_fem.grid.coarse->alpha;
    const double without = press_step_error(0, 10u, &g_nodes);
    print_message("press step, |v| %.1f mm/s: error with the correction %.2f (scaled %.3f), "
                  "without %.2f, solved without %.3f\n",
                  vref, with, (double)alpha, without, solved_plain);
    /* the coarse K is a discretisation of the same tissue: the energy-minimising scale of its
     * answer is near 1 (a coarse grid that misread the fine one's units or supports is not) */
    assert_true(alpha > 0.5f && alpha < 2.0f);
    assert_true(solved_plain < 0.01 * vref);
    assert_true(without > 0.05 * vref); /* the case the correction is for */
    assert_true(with < 0.5 * without);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_rejects_invalid_inputs),
        cmocka_unit_test(grid_stores_one_block_per_mesh_edge_and_none_elsewhere),
        cmocka_unit_test(row_displacement_product_equals_the_block_lookups),
        cmocka_unit_test(stiffness_annihilates_rigid_motions_and_diagonal_blocks_are_symmetric),
        cmocka_unit_test(linear_field_gives_no_interior_force_and_exact_energy),
        cmocka_unit_test(solver_converges_to_the_static_patch_solution),
        cmocka_unit_test(released_displacement_returns_to_rest_over_damped),
        cmocka_unit_test(few_cg_iterations_still_relax_without_overshoot),
        cmocka_unit_test(fixed_nodes_never_move_and_forces_push_free_nodes),
        cmocka_unit_test(corotated_model_is_invariant_under_rigid_rotation),
        cmocka_unit_test(element_rotation_is_the_polar_factor_of_a_rotated_stretch),
        cmocka_unit_test(element_rotation_of_flat_inverted_or_broken_element_is_identity),
        cmocka_unit_test(corotated_step_counts_inverted_tets_and_recovers),
        cmocka_unit_test(corotated_step_equals_linear_step_near_rest),
        cmocka_unit_test(steps_are_bitwise_deterministic),
        cmocka_unit_test(corotation_switch_mid_compression_does_not_jump),
        cmocka_unit_test(clinical_vein_collapses_artery_and_thrombus_resist_linear),
        cmocka_unit_test(clinical_vein_collapses_artery_and_thrombus_resist_corotated),
        cmocka_unit_test(msds_and_fem_respond_alike_to_the_same_indentation),
#if SC_GRID_COARSE
        cmocka_unit_test(two_grid_correction_above_the_threshold_and_none_at_rest),
        cmocka_unit_test(two_grid_correction_brings_a_press_step_near_the_solved_one),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
