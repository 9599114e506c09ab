/* sc_skin.c: anchored single-layer skin MSDS; see sc_skin.h. */
#include "sc_skin.h"

#include <math.h>
#include <stddef.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_simd.h"
#include "sc_skin_kern.h"
#include "sc_springs.h"

sc_skin_def sc_skin_default_def(void)
{
    sc_skin_def d;
    d.nx = 32u;
    d.ny = 16u;
    d.origin_mm[0] = 0.0f;
    d.origin_mm[1] = 0.0f;
    d.size_mm[0] = 40.0f;
    d.size_mm[1] = 20.0f;
    d.z_mm = 0.0f;
    d.k_edge_n_per_mm = 0.02f;
    d.k_anchor_n_per_mm = 0.01f;
    d.dt_s = SC_PHYS_DT_DEFAULT_S;
    d.iterations = SC_PHYS_ITERATIONS_DEFAULT;
    d.mass_per_stiffness_s2 = 2e-3f;
    d.contact_stiffness_ratio = 0.5f;
    d.drag_per_s = 10.0f;
    return d;
}

int sc_skin_def_validate(const sc_skin_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (d->nx < 2u || d->ny < 2u || d->nx > SC_MAX_SKIN_NX || d->ny > SC_MAX_SKIN_NY) {
        return SC_ERR_MESH_DIMS;
    }
    const float v[] = {d->origin_mm[0], d->origin_mm[1], d->size_mm[0], d->size_mm[1],
                       d->z_mm, d->k_edge_n_per_mm, d->k_anchor_n_per_mm, d->dt_s,
                       d->mass_per_stiffness_s2, d->contact_stiffness_ratio, d->drag_per_s};
    for (uint32_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        if (!isfinite(v[i])) {
            return SC_ERR_NOT_FINITE;
        }
    }
    if (!(d->size_mm[0] > 0.0f) || !(d->size_mm[1] > 0.0f) || !(d->k_edge_n_per_mm > 0.0f) ||
        !(d->k_anchor_n_per_mm > 0.0f) || !(d->dt_s > 0.0f) || d->dt_s > 1.0f ||
        d->iterations < 1u || d->iterations > SC_PHYS_ITERATIONS_MAX ||
        !(d->mass_per_stiffness_s2 > 0.0f) || d->contact_stiffness_ratio < 0.0f ||
        d->drag_per_s < 0.0f) {
        return SC_ERR_RANGE;
    }
    /* as sc_msds_def_validate: anchors count in the Gershgorin row sum once, edges twice */
    const float lam = (2.0f + d->contact_stiffness_ratio) / d->mass_per_stiffness_s2;
    const float a = d->dt_s * (SC_SPRINGS_GAMMA_PER_K_S * 2.0f / d->mass_per_stiffness_s2 +
                               d->drag_per_s);
    const float b = d->dt_s * d->dt_s * lam;
    if (!(a < 2.0f) || !(2.0f * a + b < 4.0f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

void sc_skin_reset(sc_skin *s)
{
    for (uint32_t i = 0; i < s->count; i++) {
        s->x[i] = s->rest_x[i];
        s->y[i] = s->rest_y[i];
        s->z[i] = s->rest_z[i];
        s->vx[i] = s->vy[i] = s->vz[i] = 0.0f;
        s->fx[i] = s->fy[i] = s->fz[i] = 0.0f;
    }
    s->contacts.count = 0u;
}

int sc_skin_init(sc_skin *s, const sc_skin_def *def)
{
    if (s == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_skin_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    s->def = *def;
    const uint32_t nx = def->nx, ny = def->ny;
    s->count = nx * ny;
    s->off[0] = 1u;
    s->off[1] = nx;
    s->off[2] = nx + 1u;
    const float cx = def->size_mm[0] / (float)(nx - 1u), cy = def->size_mm[1] / (float)(ny - 1u);
    for (uint32_t j = 0; j < ny; j++) {
        for (uint32_t i = 0; i < nx; i++) {
            const uint32_t n = i + nx * j;
            s->rest_x[n] = def->origin_mm[0] + (float)i * cx;
            s->rest_y[n] = def->origin_mm[1] + (float)j * cy;
            s->rest_z[n] = def->z_mm;
        }
    }
    for (uint32_t n = 0; n < s->count; n++) {
        s->ksum_n_per_mm[n] = def->k_anchor_n_per_mm;
    }
    for (uint32_t f = 0; f < SC_SKIN_FAMILIES; f++) {
        for (uint32_t n = 0; n < s->count; n++) {
            const uint32_t i = n % nx, j = n / nx;
            const int has = f == 0u ? (i + 1u < nx) : (f == 1u ? (j + 1u < ny)
                                                                : (i + 1u < nx && j + 1u < ny));
            s->k_fam[f][n] = has ? def->k_edge_n_per_mm : 0.0f;
            s->l0_fam[f][n] = 1.0f;
            if (has) {
                const uint32_t m = n + s->off[f];
                const float dx = s->rest_x[m] - s->rest_x[n], dy = s->rest_y[m] - s->rest_y[n];
                s->l0_fam[f][n] = sqrtf(dx * dx + dy * dy + SC_SKIN_MIN_LEN2_MM2);
                s->ksum_n_per_mm[n] += def->k_edge_n_per_mm;
                s->ksum_n_per_mm[m] += def->k_edge_n_per_mm;
            }
        }
    }
    for (uint32_t n = 0; n < s->count; n++) {
        s->mass_kg[n] = def->mass_per_stiffness_s2 * s->ksum_n_per_mm[n] * 1e3f;
        s->inv_mass[n] = 1e3f / s->mass_kg[n];
    }
    sc_skin_reset(s);
    return SC_OK;
}

/* one Euler substep in the variant sc_simd_selected() names (sc_skin_kern.inc) */
static void skin_substep(sc_skin *s)
{
    const sc_simd v = sc_simd_selected();
    (void)v;
#if defined(SC_SIMD_X86_64_V4_BUILT)
    if (v == SC_SIMD_X86_64_V4) {
        sc_skin_substep_x86_64_v4(s);
        return;
    }
#endif
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (v == SC_SIMD_X86_64_V3) {
        sc_skin_substep_x86_64_v3(s);
        return;
    }
#endif
    sc_skin_substep_generic(s);
}

float sc_skin_max_displacement_mm(const sc_skin *s)
{
    float m = 0.0f;
    for (uint32_t n = 0; n < s->count; n++) {
        const float dx = s->x[n] - s->rest_x[n], dy = s->y[n] - s->rest_y[n],
                    dz = s->z[n] - s->rest_z[n];
        const float d = sqrtf(dx * dx + dy * dy + dz * dz);
        if (!(d <= m)) {
            m = isfinite(d) ? d : INFINITY;
        }
    }
    return m;
}

int sc_skin_is_finite(const sc_skin *s)
{
    float acc = 0.0f;
    for (uint32_t n = 0; n < s->count; n++) {
        acc += s->x[n] * 0.0f + s->y[n] * 0.0f + s->z[n] * 0.0f + s->vx[n] * 0.0f +
               s->vy[n] * 0.0f + s->vz[n] * 0.0f;
    }
    return isfinite(acc) ? 1 : 0;
}

void sc_skin_step(sc_skin *s, const sc_collider *c)
{
    SC_ASSERT(s != NULL && c != NULL);
    const sc_collider_grid g = {
        .nx = s->def.nx,
        .ny = s->def.ny,
        .nz = 1u,
        .origin_mm = {s->def.origin_mm[0], s->def.origin_mm[1], s->def.z_mm},
        .cell_mm = {s->def.size_mm[0] / (float)(s->def.nx - 1u),
                    s->def.size_mm[1] / (float)(s->def.ny - 1u), 1.0f},
    };
    sc_contact_clear_forces(&s->contacts, s->fx, s->fy, s->fz);
    sc_collider_detect(c, &g, s->x, s->y, s->z, NULL, sc_skin_max_displacement_mm(s),
                       &s->contacts);
    for (uint32_t it = 0; it < s->def.iterations; it++) {
        sc_contact_clear_forces(&s->contacts, s->fx, s->fy, s->fz);
        sc_contact_add_forces(&s->contacts, s->x, s->y, s->z, s->ksum_n_per_mm,
                              s->def.contact_stiffness_ratio, s->fx, s->fy, s->fz);
        skin_substep(s);
    }
    sc_contact_clear_forces(&s->contacts, s->fx, s->fy, s->fz);
}
