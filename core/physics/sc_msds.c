/* sc_msds.c: mass-spring-damper system, appendix eqs. 1-5; see sc_msds.h. */
#include "sc_msds.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_msds_kern.h"
#include "sc_simd.h"

/* grid direction (di, dj, dk) of each family, all with a positive index offset */
static const int8_t s_dir[SC_MSDS_FAMILIES][3] = {
    {1, 0, 0}, {0, 1, 0},  {0, 0, 1}, {1, 1, 0},  {-1, 1, 0},
    {1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, -1, 1},
};

/* power iterations of the spectral mass scale (see compute_mass_scale) */
#define SC_MSDS_POWER_ITERATIONS 100u

sc_msds_def sc_msds_default_def(void)
{
    sc_msds_def d;
    d.dt_s = SC_PHYS_DT_DEFAULT_S;
    d.iterations = SC_PHYS_ITERATIONS_DEFAULT;
    d.mass_per_stiffness_s2 = 1.2e-3f;
    d.drag_per_s = 2.5f;
    d.contact_stiffness_ratio = 0.5f;
    d.volume_stiffness_ratio = 1.0f; /* derived springs: the FEM's lambda (sc_msds.h) */
    d.integrator = (uint8_t)SC_MSDS_IMPLICIT;
    d.springs = (uint8_t)SC_MSDS_SPRINGS_DERIVED;
    d.floor_volume_ratio = 0.01f;
    d.floor_pa = 100.0e3f;
    return d;
}

int sc_msds_def_validate(const sc_msds_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->dt_s) || !isfinite(d->mass_per_stiffness_s2) || !isfinite(d->drag_per_s) ||
        !isfinite(d->contact_stiffness_ratio) || !isfinite(d->volume_stiffness_ratio) ||
        !isfinite(d->floor_volume_ratio) || !isfinite(d->floor_pa)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(d->dt_s > 0.0f) || d->dt_s > 1.0f || d->iterations < 1u ||
        d->iterations > SC_PHYS_ITERATIONS_MAX || !(d->mass_per_stiffness_s2 > 0.0f) ||
        d->drag_per_s < 0.0f || d->contact_stiffness_ratio < 0.0f ||
        d->volume_stiffness_ratio < 0.0f || d->volume_stiffness_ratio > 100.0f ||
        d->floor_volume_ratio < 0.0f || d->floor_volume_ratio > 0.5f || d->floor_pa < 0.0f) {
        return SC_ERR_RANGE;
    }
    if ((d->integrator != (uint8_t)SC_MSDS_IMPLICIT &&
         d->integrator != (uint8_t)SC_MSDS_EXPLICIT) ||
        (d->springs != (uint8_t)SC_MSDS_SPRINGS_DERIVED &&
         d->springs != (uint8_t)SC_MSDS_SPRINGS_PAPER)) {
        return SC_ERR_RANGE;
    }
    if (d->integrator == (uint8_t)SC_MSDS_IMPLICIT) {
        return SC_OK; /* unconditionally stable (sc_msds_implicit.h) */
    }
    /* explicit stability (sc_msds.h): largest eigenvalue of M^-1 K incl. contact, and the
     * largest damping rate */
    const float lam = (2.0f + d->contact_stiffness_ratio) / d->mass_per_stiffness_s2;
    const float a =
        d->dt_s * (SC_SPRINGS_GAMMA_PER_K_S * 2.0f / d->mass_per_stiffness_s2 + d->drag_per_s);
    const float b = d->dt_s * d->dt_s * lam;
    if (!(a < 2.0f) || !(2.0f * a + b < 4.0f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* stiffness bound of node i (N/mm): its springs plus the volume term's Gershgorin share */
static float node_stiffness(const sc_msds *s, uint32_t i)
{
    return s->ksum_n_per_mm[i] + s->def.volume_stiffness_ratio * s->kvsum_n_per_mm[i];
}

static void compute_masses(sc_msds *s)
{
    for (uint32_t i = 0; i < s->node_count; i++) {
        /* stiffness in N/mm -> N/m (x 1e3) times s^2 gives kg */
        const float kref = s->mass_scale * node_stiffness(s, i);
        const float scaled = s->def.mass_per_stiffness_s2 * kref * 1e3f;
        const float m = scaled > s->phys_mass_kg[i] ? scaled : s->phys_mass_kg[i];
        s->mass_kg[i] = m;
        s->kref_n_per_mm[i] = m / (s->def.mass_per_stiffness_s2 * 1e3f);
    }
}

/* rest position of grid node i relative to the grid origin (mm) */
static void rest_pos(const sc_msds *s, uint32_t i, float p[3])
{
    p[0] = (float)(i % s->nx) * s->cell_mm[0];
    p[1] = (float)((i / s->nx) % (s->nxy / s->nx)) * s->cell_mm[1];
    p[2] = (float)(i / s->nxy) * s->cell_mm[2];
}

/* 6 grad V of the corners of tet t at rest (mm^2) */
static void rest_gradients(const sc_msds *s, uint32_t t, float g[4][3])
{
    float p[4][3];
    for (uint32_t v = 0; v < 4u; v++) {
        rest_pos(s, s->tv[v][t], p[v]);
    }
    float e[3][3];
    for (uint32_t a = 0; a < 3u; a++) {
        for (uint32_t c = 0; c < 3u; c++) {
            e[a][c] = p[a + 1u][c] - p[0][c];
        }
    }
    for (uint32_t a = 0; a < 3u; a++) {
        const float *u = e[(a + 1u) % 3u], *w = e[(a + 2u) % 3u];
        g[a + 1u][0] = u[1] * w[2] - u[2] * w[1];
        g[a + 1u][1] = u[2] * w[0] - u[0] * w[2];
        g[a + 1u][2] = u[0] * w[1] - u[1] * w[0];
    }
    for (uint32_t c = 0; c < 3u; c++) {
        g[0][c] = -(g[1][c] + g[2][c] + g[3][c]);
    }
}

/* y = K u at rest (springs k e e^T, volume term k_vol grad V grad V^T), u in tx/ty/tz, y in
 * fx/fy/fz (both scratch). O(9 N + tets). */
static void stiffness_apply(sc_msds *s)
{
    const uint32_t nn = s->node_count;
    for (uint32_t i = 0; i < nn; i++) {
        s->fx[i] = s->fy[i] = s->fz[i] = 0.0f;
    }
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        const uint32_t o = s->off[d];
        float e[3] = {(float)s_dir[d][0] * s->cell_mm[0], (float)s_dir[d][1] * s->cell_mm[1],
                      (float)s_dir[d][2] * s->cell_mm[2]};
        const float len = sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        for (uint32_t c = 0; c < 3u; c++) {
            e[c] /= len;
        }
        for (uint32_t i = 0; o < nn && i < nn - o; i++) {
            const float k = s->k_n_per_mm[d][i];
            const uint32_t j = i + o;
            const float f = k * ((s->tx[j] - s->tx[i]) * e[0] + (s->ty[j] - s->ty[i]) * e[1] +
                                 (s->tz[j] - s->tz[i]) * e[2]);
            s->fx[i] -= f * e[0];
            s->fy[i] -= f * e[1];
            s->fz[i] -= f * e[2];
            s->fx[j] += f * e[0];
            s->fy[j] += f * e[1];
            s->fz[j] += f * e[2];
        }
    }
    const float vr = s->def.volume_stiffness_ratio;
    for (uint32_t t = 0; vr > 0.0f && t < s->vol_count; t++) {
        float g[4][3];
        rest_gradients(s, t, g);
        float dd = 0.0f;
        for (uint32_t v = 0; v < 4u; v++) {
            const uint32_t a = s->tv[v][t];
            dd += g[v][0] * s->tx[a] + g[v][1] * s->ty[a] + g[v][2] * s->tz[a];
        }
        const float c = vr * s->kvol36[t] * dd;
        for (uint32_t v = 0; v < 4u; v++) {
            const uint32_t a = s->tv[v][t];
            s->fx[a] += c * g[v][0];
            s->fy[a] += c * g[v][1];
            s->fz[a] += c * g[v][2];
        }
    }
}

/* mass_scale sigma: the largest eigenvalue mu of W^-1 K (free nodes; W = diag of the
 * Gershgorin weights node_stiffness) by a fixed number of power iterations on the symmetric
 * W^-1/2 K W^-1/2 from a fixed start (Rayleigh quotients approach mu from below; 100
 * iterations reach it within 0.5% on the default mesh, the factor 1.1 covers that), then
 * sigma = min(1, max(0.05, 1.1 mu / 2)); Gershgorin guarantees mu <= 2. Deterministic.
 * Uses the scratch arrays. O(SC_MSDS_POWER_ITERATIONS (9 N + tets)), resumable: begin, then
 * any number of runs of a few iterations (a case switch between frames), the same bits as in
 * one go. */
static void mass_scale_begin(sc_msds *s)
{
    const uint32_t nn = s->node_count;
    uint32_t r = 12345u;
    for (uint32_t i = 0; i < nn; i++) {
        float v[3];
        for (uint32_t c = 0; c < 3u; c++) {
            r = r * 1664525u + 1013904223u;
            v[c] = (float)(r >> 8) * (1.0f / 16777216.0f) - 0.5f;
        }
        const int free_node = s->inv_mass[i] > 0.0f;
        s->tx[i] = free_node ? v[0] : 0.0f;
        s->ty[i] = free_node ? v[1] : 0.0f;
        s->tz[i] = free_node ? v[2] : 0.0f;
    }
    s->scale_mu = 0.0;
    s->scale_it = 0u;
}

/* Up to max_its more power iterations; 1 when sigma is set (the scratch cleared). */
static int mass_scale_run(sc_msds *s, uint32_t max_its)
{
    const uint32_t nn = s->node_count;
    double mu = s->scale_mu;
    uint32_t it = s->scale_it;
    for (uint32_t n = 0; n < max_its && it < SC_MSDS_POWER_ITERATIONS; n++, it++) {
        double xx = 0.0;
        for (uint32_t i = 0; i < nn; i++) {
            xx += (double)s->tx[i] * (double)s->tx[i] + (double)s->ty[i] * (double)s->ty[i] +
                  (double)s->tz[i] * (double)s->tz[i];
            const float w = node_stiffness(s, i);
            const float dsc = (s->inv_mass[i] > 0.0f && w > 0.0f) ? 1.0f / sqrtf(w) : 0.0f;
            s->tx[i] *= dsc;
            s->ty[i] *= dsc;
            s->tz[i] *= dsc;
        }
        stiffness_apply(s);
        double uy = 0.0, yy = 0.0;
        for (uint32_t i = 0; i < nn; i++) {
            uy += (double)s->tx[i] * (double)s->fx[i] + (double)s->ty[i] * (double)s->fy[i] +
                  (double)s->tz[i] * (double)s->fz[i];
            const float w = node_stiffness(s, i);
            const float dsc = (s->inv_mass[i] > 0.0f && w > 0.0f) ? 1.0f / sqrtf(w) : 0.0f;
            s->tx[i] = dsc * s->fx[i];
            s->ty[i] = dsc * s->fy[i];
            s->tz[i] = dsc * s->fz[i];
            yy += (double)s->tx[i] * (double)s->tx[i] + (double)s->ty[i] * (double)s->ty[i] +
                  (double)s->tz[i] * (double)s->tz[i];
        }
        if (!(xx > 0.0) || !(yy > 0.0)) {
            mu = 2.0; /* nothing to estimate: keep the Gershgorin bound */
            it = SC_MSDS_POWER_ITERATIONS;
            break;
        }
        mu = uy / xx;
        const float inv = (float)(1.0 / sqrt(yy));
        for (uint32_t i = 0; i < nn; i++) {
            s->tx[i] *= inv;
            s->ty[i] *= inv;
            s->tz[i] *= inv;
        }
    }
    s->scale_mu = mu;
    s->scale_it = it;
    if (it < SC_MSDS_POWER_ITERATIONS) {
        return 0;
    }
    float sigma = 1.1f * (float)mu * 0.5f;
    sigma = sigma > 1.0f ? 1.0f : sigma;
    sigma = sigma < 0.05f ? 0.05f : sigma;
    s->mass_scale = sigma;
    for (uint32_t i = 0; i < nn; i++) {
        s->fx[i] = s->fy[i] = s->fz[i] = 0.0f;
        s->tx[i] = s->ty[i] = s->tz[i] = 0.0f;
    }
    return 1;
}

static void compute_mass_scale(sc_msds *s)
{
    mass_scale_begin(s);
    (void)mass_scale_run(s, SC_MSDS_POWER_ITERATIONS);
}

/* inv_mass 0 on fully fixed nodes; a node on rollers keeps its mass and its held axes in
 * roller[] (the explicit step zeroes only those components of its velocity, as the implicit
 * solvers' per-axis constraints do) */
static void compute_inv_mass(sc_msds *s, const sc_mesh *m)
{
    const uint8_t axes = (uint8_t)(SC_MESH_ROLLER_X | SC_MESH_ROLLER_Y | SC_MESH_ROLLER_Z);
    for (uint32_t i = 0; i < s->node_count; i++) {
        const uint8_t f = m->node_fixed[i];
        const int fixed = (f & SC_MESH_FIXED_ALL) != 0u || (f & axes) == axes;
        s->inv_mass[i] = (fixed || !(s->mass_kg[i] > 0.0f)) ? 0.0f : 1e3f / s->mass_kg[i];
        s->roller[i] = fixed ? 0u : (uint8_t)(f & axes);
    }
}

/* 6 V of a tet, exactly as volume_forces computes it */
static inline float tet_d6(const float *x, const float *y, const float *z, uint32_t a0, uint32_t a1,
                           uint32_t a2, uint32_t a3)
{
    const float x0 = x[a0], y0 = y[a0], z0 = z[a0];
    const float e1x = x[a1] - x0, e1y = y[a1] - y0, e1z = z[a1] - z0;
    const float e2x = x[a2] - x0, e2y = y[a2] - y0, e2z = z[a2] - z0;
    const float e3x = x[a3] - x0, e3y = y[a3] - y0, e3z = z[a3] - z0;
    const float g1x = e2y * e3z - e2z * e3y, g1y = e2z * e3x - e2x * e3z,
                g1z = e2x * e3y - e2y * e3x;
    return e1x * g1x + e1y * g1y + e1z * g1z;
}

/* |grad V| of each corner of tet (mm^2) */
static void volume_gradients(const float *x, const float *y, const float *z, const uint32_t tet[4],
                             float gn[4])
{
    const float e1x = x[tet[1]] - x[tet[0]], e1y = y[tet[1]] - y[tet[0]],
                e1z = z[tet[1]] - z[tet[0]];
    const float e2x = x[tet[2]] - x[tet[0]], e2y = y[tet[2]] - y[tet[0]],
                e2z = z[tet[2]] - z[tet[0]];
    const float e3x = x[tet[3]] - x[tet[0]], e3y = y[tet[3]] - y[tet[0]],
                e3z = z[tet[3]] - z[tet[0]];
    const float g1[3] = {e2y * e3z - e2z * e3y, e2z * e3x - e2x * e3z, e2x * e3y - e2y * e3x};
    const float g2[3] = {e3y * e1z - e3z * e1y, e3z * e1x - e3x * e1z, e3x * e1y - e3y * e1x};
    const float g3[3] = {e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x};
    const float g0[3] = {-g1[0] - g2[0] - g3[0], -g1[1] - g2[1] - g3[1], -g1[2] - g2[2] - g3[2]};
    const float *g[4] = {g0, g1, g2, g3};
    for (uint32_t v = 0; v < 4u; v++) {
        gn[v] = sqrtf(g[v][0] * g[v][0] + g[v][1] * g[v][1] + g[v][2] * g[v][2]) / 6.0f;
    }
}

/* the kernel's tets (sc_msds_kern.h) as a table */
#define SC_MSDS_TET_ROW(q, a, b, c, d) {a, b, c, d},
static const uint8_t s_cell_tet[5][4] = {SC_MSDS_CELL_TETS(SC_MSDS_TET_ROW)};
#undef SC_MSDS_TET_ROW

static int same_node_set(const uint32_t a[4], const uint32_t b[4])
{
    for (uint32_t i = 0; i < 4u; i++) {
        int hit = 0;
        for (uint32_t j = 0; j < 4u; j++) {
            hit |= a[i] == b[j];
        }
        if (!hit) {
            return 0;
        }
    }
    return 1;
}

/* Fill the per-cell volume data from the per-tet data (kvol36, labels). O(N). */
static int init_cells(sc_msds *s, const sc_mesh *m)
{
    const uint32_t nx = m->nx, ny = m->ny, nz = m->nz, nxy = nx * ny;
    uint32_t oc[8];
    sc_msds_cell_offsets(nx, nxy, oc);
    for (uint32_t q = 0; q < 5u; q++) {
        for (uint32_t i = 0; i < SC_MAX_NODES; i++) {
            s->cell_k[q][i] = 0.0f;
            s->cell_d0[q][i] = 0.0f;
        }
    }
    for (uint32_t i = 0; i < SC_MAX_NODES; i++) {
        s->cell_par[i] = 0.0f;
    }
    s->cell_end = (nx < 2u || ny < 2u || nz < 2u) ? 0u : m->node_count - oc[7];
    for (uint32_t k = 0; k + 1u < nz; k++) {
        for (uint32_t j = 0; j + 1u < ny; j++) {
            for (uint32_t i = 0; i + 1u < nx; i++) {
                const uint32_t n = i + nx * (j + ny * k);
                const uint32_t par = (i + j + k) & 1u;
                const uint32_t cell = i + (nx - 1u) * (j + (ny - 1u) * k);
                s->cell_par[n] = par != 0u ? 1.0f : 0.0f;
                for (uint32_t q = 0; q < 5u; q++) {
                    const uint32_t t = 5u * cell + q;
                    uint32_t v[4];
                    for (uint32_t a = 0; a < 4u; a++) {
                        v[a] = n + oc[s_cell_tet[q][a] ^ par];
                    }
                    if (t >= m->tet_count || !same_node_set(v, m->tet[t])) {
                        return SC_ERR_INVALID_ARG; /* not the mesh of sc_mesh_build */
                    }
                    s->cell_k[q][n] = s->kvol36[t];
                    /* the kernel's formula on the rest positions: exact equilibrium */
                    s->cell_d0[q][n] =
                        tet_d6(m->rest_x, m->rest_y, m->rest_z, v[0], v[1], v[2], v[3]);
                }
            }
        }
    }
    return SC_OK;
}

/* Family and origin node of the grid edge (a, b), a < b; SC_MSDS_FAMILIES if none. */
static uint32_t edge_family(const sc_mesh *m, uint32_t a, uint32_t b)
{
    const uint32_t nx = m->nx, nxy = m->nx * m->ny;
    const int32_t ia = (int32_t)(a % nx), ja = (int32_t)((a / nx) % m->ny), ka = (int32_t)(a / nxy);
    const int32_t ib = (int32_t)(b % nx), jb = (int32_t)((b / nx) % m->ny), kb = (int32_t)(b / nxy);
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        if (ib - ia == s_dir[d][0] && jb - ja == s_dir[d][1] && kb - ka == s_dir[d][2]) {
            return d;
        }
    }
    return SC_MSDS_FAMILIES;
}

/* ---- derived springs: the lattice fit (sc_msds.h, SC_MSDS_SPRINGS_DERIVED) ------------------
 * Under a homogeneous strain eps the springs of one grid cell (a box L0 x L1 x L2, in the bulk:
 * one spring per axis family and one face diagonal per plane) and the volume term store the
 * energy 1/2 C eps eps with, in units of mu, the orthotropic normal block
 *   A_ii = e_i + l + sum_j s_ij L_i^2 / L_j^2,  A_ij = s_ij + l   (i != j),
 * shear moduli s_ij (a lattice of central springs is fully symmetric: C_iijj = C_ijij), where
 * e_i is the axis springs' share, s_ij the face diagonals' and l the volume term's modulus. The
 * FEM's isotropic material is e_i = 1, s_ij = 1, l = lambda / mu - 1: reachable on cubic cells
 * only, since e_i >= 0 needs sum_j s_ij L_i^2 / L_j^2 <= 3 (a cell 1.5 x longer along z than
 * across has 4.7 there: the former k ~ V / L^2 springs were 1.44 x the FEM along z). So the 7
 * non-negative parameters are fitted, by a fixed number of projected Levenberg-Marquardt steps
 * in double, to the three uniaxial Young's moduli (1 / (A^-1)_ii = E / mu), the bulk modulus
 * (sum A_ij / 9 = lambda / mu + 2/3) and, weighted 0.1, the shear moduli (s_ij = 1): on cubes
 * the exact answer, on the default box's cells (1 : 1 : 1.5) the moduli within 1.3% with the
 * shear of the planes across the long axis at about 0.5 mu. Only + - * /, so every target
 * computes the same bits. */
#define SC_MSDS_FIT_P 7u
#define SC_MSDS_FIT_STEPS 60u

/* residuals of parameters p (sxy sxz syz ex ey ez l) for cell sides L; 0 if A is not positive */
static int fit_residuals(const double L[3], const double p[SC_MSDS_FIT_P], double lam, double e,
                         double r[SC_MSDS_FIT_P])
{
    const double s[3][3] = {{0.0, p[0], p[1]}, {p[0], 0.0, p[2]}, {p[1], p[2], 0.0}};
    double a[3][3];
    double ksum = 0.0;
    for (uint32_t i = 0; i < 3u; i++) {
        a[i][i] = p[3u + i] + p[6];
        for (uint32_t j = 0; j < 3u; j++) {
            if (j != i) {
                a[i][i] += s[i][j] * (L[i] * L[i]) / (L[j] * L[j]);
                a[i][j] = s[i][j] + p[6];
            }
        }
    }
    for (uint32_t i = 0; i < 3u; i++) {
        for (uint32_t j = 0; j < 3u; j++) {
            ksum += a[i][j];
        }
    }
    const double c0 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    const double c1 = a[0][0] * a[2][2] - a[0][2] * a[2][0];
    const double c2 = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    const double det = a[0][0] * c0 - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(det > 0.0) || !(c0 > 0.0) || !(c1 > 0.0) || !(c2 > 0.0)) {
        return 0;
    }
    /* uniaxial modulus along i: det / cofactor_ii */
    r[0] = det / (c0 * e) - 1.0;
    r[1] = det / (c1 * e) - 1.0;
    r[2] = det / (c2 * e) - 1.0;
    r[3] = (ksum / 9.0) / (lam + 2.0 / 3.0) - 1.0;
    for (uint32_t k = 0; k < 3u; k++) {
        r[4u + k] = 0.1 * (p[k] - 1.0);
    }
    return 1;
}

static double fit_cost(const double r[SC_MSDS_FIT_P])
{
    double c = 0.0;
    for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
        c += r[i] * r[i];
    }
    return c;
}

/* The fit above for Poisson ratio nu on cells of sides cell_mm: p in units of mu. O(1). */
static void derived_fit(float nu, const float cell_mm[3], double p[SC_MSDS_FIT_P])
{
    const double L[3] = {(double)cell_mm[0], (double)cell_mm[1], (double)cell_mm[2]};
    const double lam = 2.0 * (double)nu / (1.0 - 2.0 * (double)nu);
    const double e = 2.0 * (1.0 + (double)nu);
    /* start: s_ij = 1 scaled down until every axis can have e_i >= 0, l = lambda - mu */
    double s[3][3] = {{0.0, 1.0, 1.0}, {1.0, 0.0, 1.0}, {1.0, 1.0, 0.0}};
    for (uint32_t pass = 0; pass < 2u; pass++) {
        for (uint32_t i = 0; i < 3u; i++) {
            double tot = 0.0;
            for (uint32_t j = 0; j < 3u; j++) {
                tot += j != i ? s[i][j] * (L[i] * L[i]) / (L[j] * L[j]) : 0.0;
            }
            if (tot > 3.0) {
                for (uint32_t j = 0; j < 3u; j++) {
                    s[i][j] *= j != i ? 3.0 / tot : 1.0;
                    s[j][i] = s[i][j];
                }
            }
        }
    }
    p[0] = s[0][1];
    p[1] = s[0][2];
    p[2] = s[1][2];
    for (uint32_t i = 0; i < 3u; i++) {
        double tot = 0.0;
        for (uint32_t j = 0; j < 3u; j++) {
            tot += j != i ? s[i][j] * (L[i] * L[i]) / (L[j] * L[j]) : 0.0;
        }
        p[3u + i] = tot < 3.0 ? 3.0 - tot : 0.0;
    }
    p[6] = lam > 1.0 ? lam - 1.0 : 0.0;
    double r[SC_MSDS_FIT_P];
    if (!fit_residuals(L, p, lam, e, r)) {
        return; /* the start itself (not reached for 0 <= nu < 0.5 and positive sides) */
    }
    double cost = fit_cost(r), damp = 1e-3;
    for (uint32_t it = 0; it < SC_MSDS_FIT_STEPS && cost > 0.0; it++) {
        double jac[SC_MSDS_FIT_P][SC_MSDS_FIT_P]; /* jac[k][i] = d r_i / d p_k */
        for (uint32_t k = 0; k < SC_MSDS_FIT_P; k++) {
            double q[SC_MSDS_FIT_P], r2[SC_MSDS_FIT_P];
            const double h = 1e-6 * (p[k] > 1.0 ? p[k] : 1.0);
            for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
                q[i] = p[i];
            }
            q[k] += h;
            if (!fit_residuals(L, q, lam, e, r2)) {
                q[k] = p[k] - h; /* one-sided the other way at the boundary */
                if (!fit_residuals(L, q, lam, e, r2)) {
                    return;
                }
                for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
                    jac[k][i] = (r[i] - r2[i]) / h;
                }
                continue;
            }
            for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
                jac[k][i] = (r2[i] - r[i]) / h;
            }
        }
        double n[SC_MSDS_FIT_P][SC_MSDS_FIT_P], g[SC_MSDS_FIT_P];
        for (uint32_t a = 0; a < SC_MSDS_FIT_P; a++) {
            g[a] = 0.0;
            for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
                g[a] += jac[a][i] * r[i];
            }
            for (uint32_t b = 0; b < SC_MSDS_FIT_P; b++) {
                n[a][b] = 0.0;
                for (uint32_t i = 0; i < SC_MSDS_FIT_P; i++) {
                    n[a][b] += jac[a][i] * jac[b][i];
                }
            }
        }
        int accepted = 0;
        while (!accepted && damp <= 1e8) {
            double m[SC_MSDS_FIT_P][SC_MSDS_FIT_P + 1u];
            for (uint32_t a = 0; a < SC_MSDS_FIT_P; a++) {
                for (uint32_t b = 0; b < SC_MSDS_FIT_P; b++) {
                    m[a][b] = n[a][b] + (a == b ? damp * (n[a][a] + 1e-9) : 0.0);
                }
                m[a][SC_MSDS_FIT_P] = -g[a];
            }
            /* Gaussian elimination: m is symmetric positive definite (damped normal matrix) */
            for (uint32_t c = 0; c < SC_MSDS_FIT_P; c++) {
                for (uint32_t row = c + 1u; row < SC_MSDS_FIT_P; row++) {
                    const double f = m[row][c] / m[c][c];
                    for (uint32_t k = c; k <= SC_MSDS_FIT_P; k++) {
                        m[row][k] -= f * m[c][k];
                    }
                }
            }
            double dp[SC_MSDS_FIT_P], q[SC_MSDS_FIT_P], r2[SC_MSDS_FIT_P];
            for (uint32_t row = SC_MSDS_FIT_P; row-- > 0u;) {
                double v = m[row][SC_MSDS_FIT_P];
                for (uint32_t k = row + 1u; k < SC_MSDS_FIT_P; k++) {
                    v -= m[row][k] * dp[k];
                }
                dp[row] = v / m[row][row];
            }
            for (uint32_t k = 0; k < SC_MSDS_FIT_P; k++) {
                q[k] = p[k] + dp[k] > 0.0 ? p[k] + dp[k] : 0.0; /* projected on p >= 0 */
            }
            if (fit_residuals(L, q, lam, e, r2) && fit_cost(r2) < cost) {
                for (uint32_t k = 0; k < SC_MSDS_FIT_P; k++) {
                    p[k] = q[k];
                    r[k] = r2[k];
                }
                cost = fit_cost(r2);
                damp = damp * 0.3 > 1e-9 ? damp * 0.3 : 1e-9;
                accepted = 1;
            } else {
                damp *= 10.0;
            }
        }
        if (!accepted) {
            break;
        }
    }
}

/* Derived spring constants (sc_msds.h, SC_MSDS_SPRINGS_DERIVED): the families' k replaced by
 * the fit above, shared out to the tets. A cell's axis edge (one tet of the cell holds it,
 * V = Vc / 6) gets e_i mu Vc / (4 L_i^2) from the cell (four cells share it), a face diagonal
 * s_ij mu Vc Ld^2 / (2 L_i^2 L_j^2) (two cells share it; its three tets hold 2 Vc / 3), split
 * by tet volume, so that a tet of volume V gives k = 1.5 e_i mu V / L_i^2 to an axis edge and
 * 0.75 s_ij mu V Ld^2 / (L_i^2 L_j^2) to a diagonal. fit[label] is derived_fit's p. O(tets). */
static int derive_springs(sc_msds *s, const sc_mesh *m, const sc_material_table *mat,
                          const double (*fit)[SC_MSDS_FIT_P], double *energy_ref)
{
    static const uint8_t pa[6] = {0u, 0u, 0u, 1u, 1u, 2u};
    static const uint8_t pb[6] = {1u, 2u, 3u, 2u, 3u, 3u};
    /* family -> fit parameter: axes x y z -> e (3..5), planes xy xz yz -> s (0..2) */
    static const uint8_t fam_par[SC_MSDS_FAMILIES] = {3u, 4u, 5u, 0u, 0u, 1u, 1u, 2u, 2u};
    static const uint8_t fam_ax[SC_MSDS_FAMILIES][2] = {{0u, 0u}, {1u, 1u}, {2u, 2u},
                                                        {0u, 1u}, {0u, 1u}, {0u, 2u},
                                                        {0u, 2u}, {1u, 2u}, {1u, 2u}};
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        for (uint32_t i = 0; i < s->node_count; i++) {
            s->k_n_per_mm[d][i] = 0.0f;
        }
    }
    for (uint32_t i = 0; i < s->node_count; i++) {
        s->ksum_n_per_mm[i] = 0.0f;
    }
    const double cell2[3] = {(double)m->cell_mm[0] * (double)m->cell_mm[0],
                             (double)m->cell_mm[1] * (double)m->cell_mm[1],
                             (double)m->cell_mm[2] * (double)m->cell_mm[2]};
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (m->tet_label[t] >= mat->count) {
            return SC_ERR_CASE_LABEL;
        }
        const sc_material *r = &mat->row[m->tet_label[t]];
        const double mu_n_mm2 = (double)r->e_pa / (2.0 * (1.0 + (double)r->poisson)) * 1e-6;
        const float v_mm3 = sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[t]);
        for (uint32_t p = 0; p < 6u; p++) {
            uint32_t a = m->tet[t][pa[p]], b = m->tet[t][pb[p]];
            if (a > b) {
                const uint32_t tmp = a;
                a = b;
                b = tmp;
            }
            const uint32_t fam = edge_family(m, a, b);
            if (fam == SC_MSDS_FAMILIES) {
                return SC_ERR_MESH_SPRINGS;
            }
            const float dx = m->rest_x[b] - m->rest_x[a], dy = m->rest_y[b] - m->rest_y[a],
                        dz = m->rest_z[b] - m->rest_z[a];
            const float l2 = dx * dx + dy * dy + dz * dz;
            if (!(l2 > 0.0f) || !(v_mm3 > 0.0f)) {
                return SC_ERR_MESH_SPRINGS;
            }
            const double q = fit[m->tet_label[t]][fam_par[fam]];
            const uint32_t i = fam_ax[fam][0], j = fam_ax[fam][1];
            const double kd = fam < 3u ? 1.5 * q * mu_n_mm2 * (double)v_mm3 / (double)l2
                                       : 0.75 * q * mu_n_mm2 * (double)v_mm3 * (double)l2 /
                                             (cell2[i] * cell2[j]);
            const float k = (float)kd;
            s->k_n_per_mm[fam][a] += k;
            s->ksum_n_per_mm[a] += k;
            s->ksum_n_per_mm[b] += k;
        }
    }
    double e = 0.0;
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        for (uint32_t i = 0; i < s->node_count; i++) {
            const double l = (double)s->l0_mm[d][i];
            e += 0.5 * (double)s->k_n_per_mm[d][i] * l * l * 1e-3;
        }
    }
    *energy_ref = e;
    return SC_OK;
}

/* 1 if no face-diagonal family has a spring at a node of even i + j + k (sc_msds.faces_odd) */
static uint8_t faces_on_odd_nodes(const sc_msds *s)
{
    const uint32_t nx = s->nx, ny = s->nxy / s->nx;
    for (uint32_t i = 0; i < s->node_count; i++) {
        if (((i % nx + (i / nx) % ny + i / s->nxy) & 1u) != 0u) {
            continue;
        }
        for (uint32_t d = 3u; d < SC_MSDS_FAMILIES; d++) {
            if (s->k_n_per_mm[d][i] > 0.0f || s->k_n_per_mm[d][i] < 0.0f) {
                return 0u;
            }
        }
    }
    return 1u;
}

int sc_msds_init_begin(sc_msds *s, const sc_mesh *m, const sc_springs *sp,
                       const sc_material_table *mat, const sc_msds_def *def)
{
    if (s == NULL || m == NULL || sp == NULL || mat == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = sc_msds_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    s->def = *def;
    s->node_count = m->node_count;
    const uint32_t nx = m->nx, nxy = m->nx * m->ny;
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        s->off[d] = (uint32_t)((int32_t)s_dir[d][0] + (int32_t)nx * s_dir[d][1] +
                               (int32_t)nxy * s_dir[d][2]);
        for (uint32_t i = 0; i < SC_MAX_NODES; i++) {
            s->k_n_per_mm[d][i] = 0.0f;
            s->l0_mm[d][i] = 1.0f; /* harmless where k = 0 */
        }
    }
    for (uint32_t i = 0; i < SC_MAX_NODES; i++) {
        s->ksum_n_per_mm[i] = 0.0f;
        s->kvsum_n_per_mm[i] = 0.0f;
        s->phys_mass_kg[i] = 0.0f;
        s->fx[i] = s->fy[i] = s->fz[i] = 0.0f;
        s->tx[i] = s->ty[i] = s->tz[i] = 0.0f;
    }
    s->gamma_per_k_s = SC_SPRINGS_GAMMA_PER_K_S;
    double energy_ref = 0.0;
    for (uint32_t q = 0; q < sp->count; q++) {
        const uint32_t a = sp->a[q], b = sp->b[q];
        if (a >= m->node_count || b >= m->node_count || a >= b) {
            return SC_ERR_INVALID_ARG;
        }
        const int32_t ia = (int32_t)(a % nx), ja = (int32_t)((a / nx) % m->ny),
                      ka = (int32_t)(a / nxy);
        const int32_t ib = (int32_t)(b % nx), jb = (int32_t)((b / nx) % m->ny),
                      kb = (int32_t)(b / nxy);
        uint32_t fam = SC_MSDS_FAMILIES;
        for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
            if (ib - ia == s_dir[d][0] && jb - ja == s_dir[d][1] && kb - ka == s_dir[d][2]) {
                fam = d;
                break;
            }
        }
        const float k = sp->k_n_per_m[q];
        /* Algorithm 1 sums k and gamma alike: gamma / k is 0.1 up to float rounding */
        if (fam == SC_MSDS_FAMILIES || !(k > 0.0f) ||
            !(fabsf(sp->gamma_n_s_per_m[q] - SC_SPRINGS_GAMMA_PER_K_S * k) <= 1e-5f * k)) {
            return SC_ERR_MESH_SPRINGS;
        }
        const float kmm = k * 1e-3f;
        const float dx = m->rest_x[b] - m->rest_x[a], dy = m->rest_y[b] - m->rest_y[a],
                    dz = m->rest_z[b] - m->rest_z[a];
        const float len = sqrtf(dx * dx + dy * dy + dz * dz + SC_MSDS_MIN_LEN2_MM2);
        s->k_n_per_mm[fam][a] = kmm;
        s->l0_mm[fam][a] = len;
        s->ksum_n_per_mm[a] += kmm;
        s->ksum_n_per_mm[b] += kmm;
        /* every spring stretched by its own length: J = N/mm * mm^2 * 1e-3 */
        energy_ref += 0.5 * (double)kmm * (double)len * (double)len * 1e-3;
    }
    s->spring_count = sp->count;
    const int derived = def->springs == (uint8_t)SC_MSDS_SPRINGS_DERIVED;
    double fit[SC_MAX_LABELS][SC_MSDS_FIT_P] = {{0.0}};
    if (derived) {
        if (mat->count > SC_MAX_LABELS) {
            return SC_ERR_CASE_LABEL;
        }
        for (uint32_t l = 0; l < mat->count; l++) {
            derived_fit(mat->row[l].poisson, m->cell_mm, fit[l]);
        }
        rc = derive_springs(s, m, mat, (const double(*)[SC_MSDS_FIT_P])fit, &energy_ref);
        if (rc != SC_OK) {
            return rc;
        }
    }
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (m->tet_label[t] >= mat->count) {
            return SC_ERR_CASE_LABEL;
        }
        const float v_mm3 = sc_mesh_tet_volume_mm3(m->rest_x, m->rest_y, m->rest_z, m->tet[t]);
        /* kg/m^3 * mm^3 * 1e-9 */
        const float quarter = 0.25f * mat->row[m->tet_label[t]].density_kg_m3 * v_mm3 * 1e-9f;
        for (uint32_t v = 0; v < 4u; v++) {
            s->phys_mass_kg[m->tet[t][v]] += quarter;
        }
        /* volume term at ratio 1: energy 1/2 lambda V0 (dV / V0)^2 = 1/2 k_vol dV^2 with
         * k_vol = lambda / V0 (lambda: Pa -> N/mm^2 x 1e-6) */
        const sc_material *r = &mat->row[m->tet_label[t]];
        float lam_n_mm2 =
            r->e_pa * r->poisson / ((1.0f + r->poisson) * (1.0f - 2.0f * r->poisson)) * 1e-6f;
        if (derived) {
            /* the springs carry a part of lambda (Cauchy lattice), the volume term the fitted
             * rest (derived_fit's l, in units of mu) */
            const double mu_n_mm2 = (double)r->e_pa / (2.0 * (1.0 + (double)r->poisson)) * 1e-6;
            lam_n_mm2 = (float)(fit[m->tet_label[t]][6] * mu_n_mm2);
        }
        const float kvol = v_mm3 > 0.0f ? lam_n_mm2 / v_mm3 : 0.0f;
        s->kvol36[t] = kvol / 36.0f;
        /* the step's own formula (same float operations): the rest state is an exact
         * equilibrium of the volume term too */
        s->d0_mm3[t] = tet_d6(m->rest_x, m->rest_y, m->rest_z, m->tet[t][0], m->tet[t][1],
                              m->tet[t][2], m->tet[t][3]);
        float gn[4];
        volume_gradients(m->rest_x, m->rest_y, m->rest_z, m->tet[t], gn);
        const float gsum = gn[0] + gn[1] + gn[2] + gn[3];
        for (uint32_t v = 0; v < 4u; v++) {
            s->tv[v][t] = m->tet[t][v];
            /* block Gershgorin: |K_ij| = k_vol |g_i| |g_j| (g = grad V); the springs' bound
             * is 2 ksum, so half of the row sum is added to ksum's place */
            s->kvsum_n_per_mm[m->tet[t][v]] += 0.5f * kvol * gn[v] * gsum;
        }
        energy_ref += 0.5 * (double)kvol * (double)v_mm3 * (double)v_mm3 * 1e-3;
    }
    s->vol_count = m->tet_count;
    s->energy_limit_j = (float)energy_ref;
    s->nx = m->nx;
    s->nxy = m->nx * m->ny;
    for (uint32_t c = 0; c < 3u; c++) {
        s->cell_mm[c] = m->cell_mm[c];
    }
    rc = init_cells(s, m);
    if (rc != SC_OK) {
        return rc;
    }
    s->faces_odd = faces_on_odd_nodes(s);
    /* free-node flags first (inv_mass > 0), then sigma (sc_msds_init_step), then the masses */
    s->mass_scale = 1.0f;
    compute_masses(s);
    compute_inv_mass(s, m);
    mass_scale_begin(s);
    return SC_OK;
}

int sc_msds_init_step(sc_msds *s, const sc_mesh *m, uint32_t iterations)
{
    if (s == NULL || m == NULL || iterations == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    if (mass_scale_run(s, iterations) == 0) {
        return 0;
    }
    compute_masses(s);
    compute_inv_mass(s, m);
    /* keep the fixed flags: inv_mass is 0 there; remember them through inv_mass only */
    return 1;
}

int sc_msds_init(sc_msds *s, const sc_mesh *m, const sc_springs *sp, const sc_material_table *mat,
                 const sc_msds_def *def)
{
    const int rc = sc_msds_init_begin(s, m, sp, mat, def);
    return rc != SC_OK ? rc : (sc_msds_init_step(s, m, SC_MSDS_POWER_ITERATIONS) == 1 ? SC_OK
                                                                                      : SC_ERR_STATE);
}

int sc_msds_set_def(sc_msds *s, const sc_msds_def *def)
{
    if (s == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_msds_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    if (def->springs != s->def.springs) {
        return SC_ERR_RANGE; /* the spring model is built at init (case load) only */
    }
    const int remass = !(s->def.mass_per_stiffness_s2 <= def->mass_per_stiffness_s2 &&
                         s->def.mass_per_stiffness_s2 >= def->mass_per_stiffness_s2 &&
                         s->def.volume_stiffness_ratio <= def->volume_stiffness_ratio &&
                         s->def.volume_stiffness_ratio >= def->volume_stiffness_ratio);
    const int new_vr = !(s->def.volume_stiffness_ratio <= def->volume_stiffness_ratio &&
                         s->def.volume_stiffness_ratio >= def->volume_stiffness_ratio);
    s->def = *def;
    if (new_vr) {
        compute_mass_scale(s); /* uses the free-node flags (inv_mass > 0) only */
    }
    if (remass) {
        compute_masses(s);
        for (uint32_t i = 0; i < s->node_count; i++) {
            const int fixed = !(s->inv_mass[i] > 0.0f);
            s->inv_mass[i] = fixed || !(s->mass_kg[i] > 0.0f) ? 0.0f : 1e3f / s->mass_kg[i];
        }
    }
    return SC_OK;
}

void sc_msds_substep(sc_msds *s, sc_nodes *n)
{
    SC_ASSERT(s != NULL && n != NULL);
    const sc_simd v = sc_simd_selected();
    (void)v;
#if defined(SC_SIMD_X86_64_V4_BUILT)
    if (v == SC_SIMD_X86_64_V4) {
        sc_msds_substep_x86_64_v4(s, n);
        return;
    }
#endif
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (v == SC_SIMD_X86_64_V3) {
        sc_msds_substep_x86_64_v3(s, n);
        return;
    }
#endif
    sc_msds_substep_generic(s, n);
}

void sc_msds_step(sc_msds *s, sc_nodes *n)
{
    for (uint32_t it = 0; it < s->def.iterations; it++) {
        sc_msds_substep(s, n);
    }
}

float sc_msds_kinetic_energy_j(const sc_msds *s, const sc_nodes *n)
{
    double e = 0.0;
    for (uint32_t i = 0; i < s->node_count; i++) {
        const double v2 = (double)n->vx[i] * (double)n->vx[i] +
                          (double)n->vy[i] * (double)n->vy[i] + (double)n->vz[i] * (double)n->vz[i];
        e += 0.5 * (double)s->mass_kg[i] * v2 * 1e-6; /* (mm/s)^2 -> (m/s)^2 */
    }
    return (float)e;
}

float sc_msds_elastic_energy_j(const sc_msds *s, const sc_nodes *n)
{
    double e = 0.0;
    const uint32_t nn = s->node_count;
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        const uint32_t o = s->off[d];
        for (uint32_t i = 0; o < nn && i < nn - o; i++) {
            const float dx = n->x[i + o] - n->x[i], dy = n->y[i + o] - n->y[i],
                        dz = n->z[i + o] - n->z[i];
            const double ext = (double)sqrtf(dx * dx + dy * dy + dz * dz + SC_MSDS_MIN_LEN2_MM2) -
                               (double)s->l0_mm[d][i];
            e += 0.5 * (double)s->k_n_per_mm[d][i] * ext * ext * 1e-3;
        }
    }
    for (uint32_t t = 0; t < s->vol_count; t++) {
        const uint32_t tet[4] = {s->tv[0][t], s->tv[1][t], s->tv[2][t], s->tv[3][t]};
        const double dv =
            (double)sc_mesh_tet_volume_mm3(n->x, n->y, n->z, tet) - (double)s->d0_mm3[t] / 6.0;
        /* k_vol = 36 kvol36 */
        e += 0.5 * (double)s->def.volume_stiffness_ratio * 36.0 * (double)s->kvol36[t] * dv * dv *
             1e-3;
    }
    return (float)e;
}
