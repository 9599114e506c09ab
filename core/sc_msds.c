/* sc_msds.c: mass-spring-damper system, appendix eqs. 1-5; see sc_msds.h. */
#include "sc_msds.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_err.h"

/* grid direction (di, dj, dk) of each family, all with a positive index offset */
static const int8_t s_dir[SC_MSDS_FAMILIES][3] = {
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {-1, 1, 0},
    {1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, -1, 1},
};

/* added to |d|^2 in the force law (mm^2): guards 1/|d| in a collapsed spring */
#define SC_MSDS_MIN_LEN2_MM2 1e-12f
/* velocities below this are set to 0 (see integrate) */
#define SC_MSDS_V_FLUSH_MM_S 1e-12f

sc_msds_def sc_msds_default_def(void)
{
    sc_msds_def d;
    d.dt_s = SC_PHYS_DT_DEFAULT_S;
    d.iterations = SC_PHYS_ITERATIONS_DEFAULT;
    d.mass_per_stiffness_s2 = 2e-3f;
    d.drag_per_s = 0.0f;
    d.contact_stiffness_ratio = 0.5f;
    return d;
}

int sc_msds_def_validate(const sc_msds_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->dt_s) || !isfinite(d->mass_per_stiffness_s2) || !isfinite(d->drag_per_s) ||
        !isfinite(d->contact_stiffness_ratio)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!(d->dt_s > 0.0f) || d->dt_s > 1.0f || d->iterations < 1u ||
        d->iterations > SC_PHYS_ITERATIONS_MAX || !(d->mass_per_stiffness_s2 > 0.0f) ||
        d->drag_per_s < 0.0f || d->contact_stiffness_ratio < 0.0f) {
        return SC_ERR_RANGE;
    }
    /* explicit stability (sc_msds.h): largest eigenvalue of M^-1 K incl. contact, and the
     * largest damping rate */
    const float lam = (2.0f + d->contact_stiffness_ratio) / d->mass_per_stiffness_s2;
    const float a = d->dt_s * (SC_SPRINGS_GAMMA_PER_K_S * 2.0f / d->mass_per_stiffness_s2 +
                               d->drag_per_s);
    const float b = d->dt_s * d->dt_s * lam;
    if (!(a < 2.0f) || !(2.0f * a + b < 4.0f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

static void compute_masses(sc_msds *s)
{
    for (uint32_t i = 0; i < s->node_count; i++) {
        /* ksum in N/mm -> N/m (x 1e3) times s^2 gives kg */
        const float scaled = s->def.mass_per_stiffness_s2 * s->ksum_n_per_mm[i] * 1e3f;
        const float m = scaled > s->phys_mass_kg[i] ? scaled : s->phys_mass_kg[i];
        s->mass_kg[i] = m;
    }
}

static void compute_inv_mass(sc_msds *s, const sc_mesh *m)
{
    for (uint32_t i = 0; i < s->node_count; i++) {
        s->inv_mass[i] = (m->node_fixed[i] != 0u || !(s->mass_kg[i] > 0.0f))
                             ? 0.0f
                             : 1e3f / s->mass_kg[i];
    }
}

int sc_msds_init(sc_msds *s, const sc_mesh *m, const sc_springs *sp,
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
    s->energy_limit_j = (float)energy_ref;
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
    }
    compute_masses(s);
    compute_inv_mass(s, m);
    /* keep the fixed flags: inv_mass is 0 there; remember them through inv_mass only */
    return SC_OK;
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
    const int remass = !(s->def.mass_per_stiffness_s2 <= def->mass_per_stiffness_s2 &&
                         s->def.mass_per_stiffness_s2 >= def->mass_per_stiffness_s2);
    s->def = *def;
    if (remass) {
        for (uint32_t i = 0; i < s->node_count; i++) {
            const int fixed = !(s->inv_mass[i] > 0.0f);
            const float scaled = s->def.mass_per_stiffness_s2 * s->ksum_n_per_mm[i] * 1e3f;
            s->mass_kg[i] = scaled > s->phys_mass_kg[i] ? scaled : s->phys_mass_kg[i];
            s->inv_mass[i] = fixed || !(s->mass_kg[i] > 0.0f) ? 0.0f : 1e3f / s->mass_kg[i];
        }
    }
    return SC_OK;
}

/* Spring forces of one family: t = force on node n from spring (n, n + o); accumulated
 * into f[n] (+t) here and into f[n + o] (-t) by the caller's second pass. */
static void family_forces(uint32_t cnt, uint32_t o, float gk, const float *restrict k,
                          const float *restrict l0, const float *restrict x,
                          const float *restrict y, const float *restrict z,
                          const float *restrict vx, const float *restrict vy,
                          const float *restrict vz, float *restrict tx, float *restrict ty,
                          float *restrict tz, float *restrict fx, float *restrict fy,
                          float *restrict fz)
{
    for (uint32_t i = 0; i < cnt; i++) {
        const float dx = x[i + o] - x[i];
        const float dy = y[i + o] - y[i];
        const float dz = z[i + o] - z[i];
        const float len2 = dx * dx + dy * dy + dz * dz;
        /* guard of 1/|d| for a collapsed spring without a branch or fmaxf (either stops the
         * vectoriser); the same formula gives the rest lengths in sc_msds_init */
        const float len = sqrtf(len2 + SC_MSDS_MIN_LEN2_MM2);
        const float inv = 1.0f / len;
        const float dvx = vx[i + o] - vx[i];
        const float dvy = vy[i + o] - vy[i];
        const float dvz = vz[i + o] - vz[i];
        const float rate = (dx * dvx + dy * dvy + dz * dvz) * inv; /* d|d|/dt, mm/s */
        /* Voigt element (eq. 1): k (|d| - L0) + gamma d|d|/dt with gamma = 0.1 k */
        const float mag = k[i] * ((len - l0[i]) + gk * rate);
        const float sc = mag * inv;
        const float ax = sc * dx, ay = sc * dy, az = sc * dz;
        tx[i] = ax;
        ty[i] = ay;
        tz[i] = az;
        fx[i] += ax;
        fy[i] += ay;
        fz[i] += az;
    }
}

static void scatter_back(uint32_t cnt, const float *restrict tx, const float *restrict ty,
                         const float *restrict tz, float *restrict fx, float *restrict fy,
                         float *restrict fz)
{
    for (uint32_t i = 0; i < cnt; i++) {
        fx[i] -= tx[i];
        fy[i] -= ty[i];
        fz[i] -= tz[i];
    }
}

static void integrate(uint32_t cnt, float dt, float drag, const float *restrict inv_m,
                      const float *restrict fx, const float *restrict fy,
                      const float *restrict fz, float *restrict vx, float *restrict vy,
                      float *restrict vz, float *restrict x, float *restrict y,
                      float *restrict z)
{
    const float keep = 1.0f - dt * drag;
    for (uint32_t i = 0; i < cnt; i++) {
        const float w = inv_m[i] * dt;
        /* eq. 3-4: v += dt (f - s) / m  (f*: external + spring forces, sign included);
         * the drag is an external force -c m v; fixed nodes have w = 0, and their v is 0
         * (reset and never written), so it stays 0 */
        float nvx = keep * vx[i] + w * fx[i];
        float nvy = keep * vy[i] + w * fy[i];
        float nvz = keep * vz[i] + w * fz[i];
        /* a settling velocity decays geometrically into subnormal floats, which cost ~100x
         * per operation on x86 without flush-to-zero; 1e-12 mm/s is physically zero (a
         * select of two computed values: the loop still vectorises) */
        nvx = fabsf(nvx) < SC_MSDS_V_FLUSH_MM_S ? 0.0f : nvx;
        nvy = fabsf(nvy) < SC_MSDS_V_FLUSH_MM_S ? 0.0f : nvy;
        nvz = fabsf(nvz) < SC_MSDS_V_FLUSH_MM_S ? 0.0f : nvz;
        vx[i] = nvx;
        vy[i] = nvy;
        vz[i] = nvz;
        /* eq. 5: with the new velocity */
        x[i] += dt * nvx;
        y[i] += dt * nvy;
        z[i] += dt * nvz;
    }
}

void sc_msds_substep(sc_msds *s, sc_nodes *n)
{
    SC_ASSERT(s != NULL && n != NULL);
    const uint32_t nn = s->node_count;
    for (uint32_t i = 0; i < nn; i++) {
        s->fx[i] = n->fx[i];
        s->fy[i] = n->fy[i];
        s->fz[i] = n->fz[i];
    }
    for (uint32_t d = 0; d < SC_MSDS_FAMILIES; d++) {
        const uint32_t o = s->off[d];
        if (o >= nn) {
            continue;
        }
        const uint32_t cnt = nn - o;
        family_forces(cnt, o, s->gamma_per_k_s, s->k_n_per_mm[d], s->l0_mm[d], n->x, n->y,
                      n->z, n->vx, n->vy, n->vz, s->tx, s->ty, s->tz, s->fx, s->fy, s->fz);
        scatter_back(cnt, s->tx, s->ty, s->tz, s->fx + o, s->fy + o, s->fz + o);
    }
    integrate(nn, s->def.dt_s, s->def.drag_per_s, s->inv_mass, s->fx, s->fy, s->fz, n->vx,
              n->vy, n->vz, n->x, n->y, n->z);
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
                          (double)n->vy[i] * (double)n->vy[i] +
                          (double)n->vz[i] * (double)n->vz[i];
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
    return (float)e;
}
