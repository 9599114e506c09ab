/* test_sc_msds.c: mass-spring-damper system (appendix eqs. 1-5). */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_msds.h"
#include "sc_springs.h"

/* The module's explicit Euler and Algorithm 1's springs (the paper's MSDS, with the former
 * default volume term ratio 6): what these tests check against eqs. 1-5. The derived springs
 * are checked in test_sc_stiffness.c, the implicit integrator through sc_tissue. */
static sc_msds_def paper_def(void)
{
    sc_msds_def d = sc_msds_default_def();
    d.springs = (uint8_t)SC_MSDS_SPRINGS_PAPER;
    d.volume_stiffness_ratio = 6.0f;
    d.integrator = (uint8_t)SC_MSDS_EXPLICIT;
    return d;
}

static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_springs g_sp;
static sc_msds g_msds;
static sc_material_table g_mat;

static void build(uint32_t nx, uint32_t ny, uint32_t nz, int layered, int fix_sides)
{
    sc_mesh_def d = sc_mesh_default_def();
    d.nx = nx;
    d.ny = ny;
    d.nz = nz;
    assert_int_equal(sc_mesh_build(&g_mesh, &d), SC_OK);
    sc_material_table_default(&g_mat);
    assert_int_equal(sc_material_assign(&g_mesh, NULL, &g_mat, SC_LABEL_FAT), SC_OK);
    if (layered) {
        /* a mix of soft and stiff tets: the stiffness contrast of the clinical scene */
        static const uint8_t mix[] = {SC_LABEL_FAT, SC_LABEL_VEIN, SC_LABEL_MUSCLE, SC_LABEL_ARTERY,
                                      SC_LABEL_THROMBUS};
        for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
            g_mesh.tet_label[t] = mix[(t * 7u + t / 13u) % 5u];
        }
    }
    if (!fix_sides) {
        memset(g_mesh.node_fixed, 0, sizeof g_mesh.node_fixed);
    }
    assert_int_equal(sc_springs_from_tets(&g_sp, (const uint32_t(*)[4])g_mesh.tet, g_mesh.tet_label,
                                          g_mesh.tet_count, &g_mat),
                     SC_OK);
    sc_msds_def def = paper_def();
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &def), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
}

static float max_dev_mm(void)
{
    float m = 0.0f;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float dx = g_nodes.x[i] - g_mesh.rest_x[i], dy = g_nodes.y[i] - g_mesh.rest_y[i],
                    dz = g_nodes.z[i] - g_mesh.rest_z[i];
        const float d = sqrtf(dx * dx + dy * dy + dz * dz);
        m = d > m ? d : m;
    }
    return m;
}

/* No external force, 1,000 frames of 20 steps: no node moves more than 1e-5 of the box size
 * (rest lengths are computed from the rest positions with the same float operations as the
 * step, so the rest state is an exact equilibrium; 1e-5 allows for nothing but rounding).
 * 16 x 8 x 8 nodes keep the sanitizer build fast; the bench runs the full size. */
static void rest_stays_rest_for_1000_frames(void **state)
{
    (void)state;
    build(16, 8, 8, 1, 1);
    for (int f = 0; f < 1000; f++) {
        sc_msds_step(&g_msds, &g_nodes);
    }
    assert_true(max_dev_mm() <= 1e-5f * 40.0f);
}

/* One substep against the appendix written out in double precision: a node displaced and
 * moving, all others fixed: s from eq. 1 over its springs, a = (f - s) / m (eq. 3),
 * v += dt a (eq. 4), x += dt v_new (eq. 5). */
static void one_step_matches_equations_1_to_5(void **state)
{
    (void)state;
    build(3, 3, 3, 1, 0);
    const uint32_t c = 1u + 3u * (1u + 3u * 1u); /* the centre node, odd parity: 18 springs */
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = i == c ? 0u : 1u;
    }
    sc_msds_def def = paper_def();
    def.volume_stiffness_ratio = 0.0f; /* Algorithm 1's springs alone (the paper's MSDS) */
    def.drag_per_s = 0.0f;             /* and no drag: eqs. 1-5 exactly */
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &def), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    g_nodes.x[c] += 0.13f;
    g_nodes.y[c] -= 0.07f;
    g_nodes.z[c] += 0.21f;
    g_nodes.vx[c] = 2.0f;
    g_nodes.vy[c] = -1.0f;
    g_nodes.vz[c] = 0.5f;
    g_nodes.fx[c] = 0.001f; /* N */
    double s[3] = {0, 0, 0}, ksum = 0.0;
    int springs = 0;
    for (uint32_t q = 0; q < g_sp.count; q++) {
        if (g_sp.a[q] != c && g_sp.b[q] != c) {
            continue;
        }
        springs++;
        const uint32_t o = g_sp.a[q] == c ? g_sp.b[q] : g_sp.a[q];
        const double k = (double)g_sp.k_n_per_m[q] * 1e-3;       /* N/mm */
        const double g = (double)g_sp.gamma_n_s_per_m[q] * 1e-3; /* N s/mm */
        ksum += k;
        const double d[3] = {(double)g_nodes.x[c] - g_nodes.x[o],
                             (double)g_nodes.y[c] - g_nodes.y[o],
                             (double)g_nodes.z[c] - g_nodes.z[o]};
        const double r[3] = {(double)g_mesh.rest_x[c] - g_mesh.rest_x[o],
                             (double)g_mesh.rest_y[c] - g_mesh.rest_y[o],
                             (double)g_mesh.rest_z[c] - g_mesh.rest_z[o]};
        const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        const double l0 = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        const double rate =
            (d[0] * g_nodes.vx[c] + d[1] * g_nodes.vy[c] + d[2] * g_nodes.vz[c]) / len;
        const double mag = k * (len - l0) + g * rate; /* eq. 1 with the sign of s_i in eq. 2 */
        for (int a = 0; a < 3; a++) {
            s[a] += mag * d[a] / len;
        }
    }
    assert_int_equal(springs, 18);
    /* the mass scaling of sc_msds.h: mps x sigma x summed k; one free node: its 3 x 3 block
     * K_cc / ksum has its largest eigenvalue mu in (1/3, 1], sigma = 1.1 mu / 2 */
    const double sigma = (double)g_msds.mass_scale;
    assert_true(sigma >= 1.1 / 6.0 - 1e-6 && sigma <= 0.55 + 1e-6);
    const double m_kg = (double)def.mass_per_stiffness_s2 * sigma * ksum * 1e3;
    assert_true(fabs((double)g_msds.mass_kg[c] - m_kg) <= 1e-5 * m_kg);
    const double f[3] = {0.001, 0.0, 0.0};
    const double v0[3] = {2.0, -1.0, 0.5};
    const double x0[3] = {(double)g_nodes.x[c], (double)g_nodes.y[c], (double)g_nodes.z[c]};
    double v1[3], x1[3];
    for (int a = 0; a < 3; a++) {
        const double acc = (f[a] - s[a]) / m_kg * 1e3; /* eq. 3, m/s^2 -> mm/s^2 */
        v1[a] = v0[a] + 0.01 * acc;                    /* eq. 4 */
        x1[a] = x0[a] + 0.01 * v1[a];                  /* eq. 5: the new velocity */
    }
    sc_msds_substep(&g_msds, &g_nodes);
    const float got_v[3] = {g_nodes.vx[c], g_nodes.vy[c], g_nodes.vz[c]};
    const float got_x[3] = {g_nodes.x[c], g_nodes.y[c], g_nodes.z[c]};
    for (int a = 0; a < 3; a++) {
        /* float32 against double: 1e-4 relative on the velocity change (sums of 18 springs),
         * 1e-5 mm on the position */
        assert_true(fabs((double)got_v[a] - v1[a]) <= 1e-4 * (fabs(v1[a] - v0[a]) + 1e-3));
        assert_true(fabs((double)got_x[a] - x1[a]) <= 1e-5);
    }
    /* the fixed neighbours did not move */
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        if (i != c) {
            assert_true(fabsf(g_nodes.x[i] - g_mesh.rest_x[i]) <= 0.0f);
        }
    }
}

/* The volume term (extension, sc_msds.h): one free node, its springs switched off by a
 * comparison run: the velocity change of one substep with the term minus the one without
 * equals dt f_vol / m, f_vol = -sum over the node's tets of k_vol (V - V0) grad V with
 * k_vol = ratio x lambda / V0 (Teschner et al. 2004), written out in double precision. */
static void volume_term_matches_the_volume_spring_formula(void **state)
{
    (void)state;
    build(3, 3, 3, 1, 0);
    const uint32_t c = 1u + 3u * (1u + 3u * 1u);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = i == c ? 0u : 1u;
    }
    const float disp[3] = {0.31f, -0.22f, 0.45f};
    float dv[2][3];
    float mass[2];
    for (int with = 0; with < 2; with++) {
        sc_msds_def def = paper_def();
        assert_true(def.volume_stiffness_ratio > 0.0f); /* on by default */
        def.volume_stiffness_ratio = with ? def.volume_stiffness_ratio : 0.0f;
        assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &def), SC_OK);
        sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
        g_nodes.x[c] += disp[0];
        g_nodes.y[c] += disp[1];
        g_nodes.z[c] += disp[2];
        mass[with] = g_msds.mass_kg[c];
        sc_msds_substep(&g_msds, &g_nodes);
        dv[with][0] = g_nodes.vx[c];
        dv[with][1] = g_nodes.vy[c];
        dv[with][2] = g_nodes.vz[c];
    }
    /* expected volume force in double */
    const double ratio = (double)paper_def().volume_stiffness_ratio;
    double fv[3] = {0, 0, 0};
    int tets = 0;
    const double p[3] = {(double)g_mesh.rest_x[c] + disp[0], (double)g_mesh.rest_y[c] + disp[1],
                         (double)g_mesh.rest_z[c] + disp[2]};
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        int at = -1;
        for (int v = 0; v < 4; v++) {
            if (g_mesh.tet[t][v] == c) {
                at = v;
            }
        }
        if (at < 0) {
            continue;
        }
        tets++;
        double X[4][3], R[4][3];
        for (int v = 0; v < 4; v++) {
            const uint32_t a = g_mesh.tet[t][v];
            R[v][0] = g_mesh.rest_x[a];
            R[v][1] = g_mesh.rest_y[a];
            R[v][2] = g_mesh.rest_z[a];
            for (int q = 0; q < 3; q++) {
                X[v][q] = v == at ? p[q] : R[v][q];
            }
        }
        double vol[2], grad[3];
        for (int w = 0; w < 2; w++) {
            double(*P)[3] = w ? X : R;
            const double e1[3] = {P[1][0] - P[0][0], P[1][1] - P[0][1], P[1][2] - P[0][2]};
            const double e2[3] = {P[2][0] - P[0][0], P[2][1] - P[0][1], P[2][2] - P[0][2]};
            const double e3[3] = {P[3][0] - P[0][0], P[3][1] - P[0][1], P[3][2] - P[0][2]};
            vol[w] =
                (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) + e1[1] * (e2[2] * e3[0] - e2[0] * e3[2]) +
                 e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) /
                6.0;
        }
        /* grad of V at corner `at`: (1/6) (b - d) x (c - d) for the other corners in the
         * orientation of the tet: numerically by central differences in double */
        for (int q = 0; q < 3; q++) {
            double Pp[4][3], Pm[4][3];
            memcpy(Pp, X, sizeof Pp);
            memcpy(Pm, X, sizeof Pm);
            Pp[at][q] += 1e-4;
            Pm[at][q] -= 1e-4;
            double vv[2];
            for (int w = 0; w < 2; w++) {
                double(*P)[3] = w ? Pm : Pp;
                const double e1[3] = {P[1][0] - P[0][0], P[1][1] - P[0][1], P[1][2] - P[0][2]};
                const double e2[3] = {P[2][0] - P[0][0], P[2][1] - P[0][1], P[2][2] - P[0][2]};
                const double e3[3] = {P[3][0] - P[0][0], P[3][1] - P[0][1], P[3][2] - P[0][2]};
                vv[w] = (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) +
                         e1[1] * (e2[2] * e3[0] - e2[0] * e3[2]) +
                         e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) /
                        6.0;
            }
            grad[q] = (vv[0] - vv[1]) / 2e-4;
        }
        const sc_material *mt = &g_mat.row[g_mesh.tet_label[t]];
        const double nu = (double)mt->poisson;
        const double lam = (double)mt->e_pa * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) * 1e-6;
        const double kvol = ratio * lam / vol[0]; /* N/mm^5, V0 = vol[0] (rest) */
        for (int q = 0; q < 3; q++) {
            fv[q] -= kvol * (vol[1] - vol[0]) * grad[q];
        }
    }
    assert_true(tets >= 5);
    for (int q = 0; q < 3; q++) {
        /* v starts at 0: dv = dt * 1e3 * f / m per run; the difference isolates the term */
        const double got = (double)dv[1][q] - (double)dv[0][q] * (double)mass[0] / (double)mass[1];
        const double want = 0.01 * 1e3 * fv[q] / (double)mass[1];
        /* float32 against double (and a 1e-4 mm central difference, exact for the volume,
         * which is linear in each corner): 1e-3 relative of the largest component */
        const double scale =
            fmax(fabs(fv[0]), fmax(fabs(fv[1]), fabs(fv[2]))) * 0.01 * 1e3 / (double)mass[1];
        assert_true(fabs(got - want) <= 1e-3 * scale);
    }
    /* and it pushes back: the force opposes the volume change it caused (work < 0) */
    assert_true(fv[0] * disp[0] + fv[1] * disp[1] + fv[2] * disp[2] < 0.0);
}

/* A tet turned inside out is pushed back: one free node moved through the opposite face of
 * its tets returns to a state with every tet positive (springs alone may rest folded). */
static void inverted_tets_are_restored_by_the_volume_term(void **state)
{
    (void)state;
    build(3, 3, 3, 0, 0);
    const uint32_t c = 1u + 3u * (1u + 3u * 1u);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_mesh.node_fixed[i] = i == c ? 0u : 1u;
    }
    sc_msds_def def = paper_def();
    assert_int_equal(sc_msds_init(&g_msds, &g_mesh, &g_sp, &g_mat, &def), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    g_nodes.z[c] += 1.5f * g_mesh.cell_mm[2]; /* through the layer below */
    int inverted = 0;
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        inverted += sc_mesh_tet_volume_mm3(g_nodes.x, g_nodes.y, g_nodes.z, g_mesh.tet[t]) <= 0.0f;
    }
    assert_true(inverted > 0);
    for (int f = 0; f < 50; f++) {
        sc_msds_step(&g_msds, &g_nodes);
    }
    for (uint32_t t = 0; t < g_mesh.tet_count; t++) {
        assert_true(sc_mesh_tet_volume_mm3(g_nodes.x, g_nodes.y, g_nodes.z, g_mesh.tet[t]) > 0.0f);
    }
    assert_true(max_dev_mm() <= 1e-3f);
}

/* A pulled region released: the total energy (kinetic + elastic) never grows from frame to
 * frame (damped springs, stable step), and the block returns to rest. */
static void released_deformation_decays_and_returns_to_rest(void **state)
{
    (void)state;
    build(12, 8, 8, 1, 1);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        if (!g_mesh.node_fixed[i] && g_mesh.rest_z[i] < 10.0f) {
            g_nodes.z[i] += 0.5f; /* press the top layers down by 0.5 mm */
        }
    }
    float e_prev = sc_msds_elastic_energy_j(&g_msds, &g_nodes);
    assert_true(e_prev > 0.0f);
    for (int f = 0; f < 200; f++) {
        sc_msds_step(&g_msds, &g_nodes);
        const float e = sc_msds_elastic_energy_j(&g_msds, &g_nodes) +
                        sc_msds_kinetic_energy_j(&g_msds, &g_nodes);
        /* float rounding of the energy sums: 1e-6 relative of the initial energy */
        assert_true(e <= e_prev + 1e-6f * e_prev + 1e-12f);
        e_prev = e;
    }
    /* 200 frames = 40 s of simulated time: back to rest within 1 um */
    assert_true(max_dev_mm() <= 1e-3f);
}

/* Supports in the explicit step: a fixed node (node_fixed 1) never moves; a node on rollers
 * never moves along its held axes (SC_MESH_ROLLER_* bits) and does move along its free ones,
 * as in the implicit solvers (the block test, test_sc_stiffness, checks the static answer). */
static void fixed_nodes_never_move_under_force(void **state)
{
    (void)state;
    build(8, 6, 6, 0, 1);
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_nodes.fx[i] = 0.01f;
        g_nodes.fy[i] = 0.01f;
        g_nodes.fz[i] = 0.01f;
    }
    for (int f = 0; f < 20; f++) {
        sc_msds_step(&g_msds, &g_nodes);
    }
    static const uint8_t bit[3] = {SC_MESH_ROLLER_X, SC_MESH_ROLLER_Y, SC_MESH_ROLLER_Z};
    int moved_free = 0, moved_roller = 0, rollers = 0;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        const float d[3] = {fabsf(g_nodes.x[i] - g_mesh.rest_x[i]),
                            fabsf(g_nodes.y[i] - g_mesh.rest_y[i]),
                            fabsf(g_nodes.z[i] - g_mesh.rest_z[i])};
        const uint8_t fx = g_mesh.node_fixed[i];
        rollers += (fx != 0u && fx != SC_MESH_FIXED_ALL) ? 1 : 0;
        for (uint32_t a = 0; a < 3u; a++) {
            if (fx == SC_MESH_FIXED_ALL || (fx & bit[a]) != 0u) {
                assert_true(d[a] <= 0.0f);
            } else if (d[a] > 1e-3f) {
                moved_free = 1;
                moved_roller |= fx != 0u ? 1 : 0;
            }
        }
    }
    assert_true(moved_free);
    assert_true(rollers == 0 || moved_roller);
    print_message("%d nodes on rollers; one moved along a free axis: %d\n", rollers, moved_roller);
}

static void unstable_or_invalid_settings_are_refused(void **state)
{
    (void)state;
    sc_msds_def d = sc_msds_default_def();
    assert_int_equal(sc_msds_def_validate(&d), SC_OK);
    assert_int_equal(paper_def().integrator, SC_MSDS_EXPLICIT);
    assert_int_equal(sc_msds_def_validate(&d), SC_OK);
    /* the implicit default has no stability bound; the paper's explicit Euler has */
    d = paper_def();
    d.integrator = (uint8_t)SC_MSDS_IMPLICIT;
    d.dt_s = 0.05f;
    assert_int_equal(sc_msds_def_validate(&d), SC_OK);
    d.integrator = (uint8_t)SC_MSDS_EXPLICIT;
    /* (0.1 dt + dt^2) * 2 / mu = 5.5: unstable */
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_RANGE);
    d = paper_def();
    d.integrator = (uint8_t)SC_MSDS_EXPLICIT;
    d.mass_per_stiffness_s2 = 5e-4f; /* below the 1.05e-3 bound */
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_RANGE);
    d = paper_def();
    d.integrator = 7u;
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_RANGE);
    d = paper_def();
    d.iterations = 0;
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_RANGE);
    d = paper_def();
    d.drag_per_s = NAN;
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_NOT_FINITE);
    d = paper_def();
    d.volume_stiffness_ratio = NAN;
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_NOT_FINITE);
    d.volume_stiffness_ratio = -1.0f;
    assert_int_equal(sc_msds_def_validate(&d), SC_ERR_RANGE);
    assert_int_equal(sc_msds_def_validate(NULL), SC_ERR_INVALID_ARG);
    /* runtime change: the old settings stay on error */
    build(4, 4, 4, 0, 1);
    d = paper_def();
    d.integrator = (uint8_t)SC_MSDS_EXPLICIT;
    d.dt_s = 0.05f;
    assert_int_equal(sc_msds_set_def(&g_msds, &d), SC_ERR_RANGE);
    assert_true(fabsf(g_msds.def.dt_s - 0.01f) <= 0.0f);
    d = paper_def();
    d.iterations = 7;
    d.dt_s = 0.005f;
    assert_int_equal(sc_msds_set_def(&g_msds, &d), SC_OK);
    assert_int_equal(g_msds.def.iterations, 7);
    /* switching the volume term off at run time re-estimates sigma and the masses: the
     * springs alone are softer, so the interior node gets no heavier */
    const float m_before = g_msds.mass_kg[21];
    d.volume_stiffness_ratio = 0.0f;
    assert_int_equal(sc_msds_set_def(&g_msds, &d), SC_OK);
    assert_true(g_msds.mass_scale > 0.0f && g_msds.mass_scale <= 1.0f);
    assert_true(g_msds.mass_kg[21] > 0.0f && g_msds.mass_kg[21] <= m_before);
}

/* Deliberately unstable run (validation bypassed): the state diverges, which is what the
 * tissue guard must catch; shows the bound in sc_msds_def_validate is not vacuous. */
static void exceeding_the_stability_bound_diverges(void **state)
{
    (void)state;
    build(8, 6, 6, 0, 1);
    g_msds.def.dt_s = 0.06f;
    const uint32_t c = 3u + 8u * (3u + 6u * 3u);
    g_nodes.z[c] += 0.1f;
    for (int f = 0; f < 50; f++) {
        sc_msds_step(&g_msds, &g_nodes);
    }
    const float e = sc_msds_kinetic_energy_j(&g_msds, &g_nodes);
    assert_true(!isfinite(e) || e > g_msds.energy_limit_j);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rest_stays_rest_for_1000_frames),
        cmocka_unit_test(one_step_matches_equations_1_to_5),
        cmocka_unit_test(volume_term_matches_the_volume_spring_formula),
        cmocka_unit_test(inverted_tets_are_restored_by_the_volume_term),
        cmocka_unit_test(released_deformation_decays_and_returns_to_rest),
        cmocka_unit_test(fixed_nodes_never_move_under_force),
        cmocka_unit_test(unstable_or_invalid_settings_are_refused),
        cmocka_unit_test(exceeding_the_stability_bound_diverges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
