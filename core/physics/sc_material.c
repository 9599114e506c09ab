/* sc_material.c: material table and per-tet labels, see sc_material.h. */
#include "sc_material.h"

#include <math.h>
#include <stddef.h>

#include "sc_err.h"
#include "sc_labels.h"
#include "sc_materials.h"

_Static_assert(SC_LABEL_COUNT <= SC_MAX_LABELS, "material table smaller than the label list");

void sc_material_table_default(sc_material_table *t)
{
    static const sc_material rows[] = {
#define SC_MAT_ROW_(label, e, nu, rho) [label] = {(e), (nu), (rho)},
        SC_MATERIAL_LIST(SC_MAT_ROW_)
#undef SC_MAT_ROW_
    };
    _Static_assert(sizeof rows / sizeof rows[0] == SC_LABEL_COUNT, "one material per label");
    t->count = SC_LABEL_COUNT;
    for (uint32_t i = 0; i < SC_MAX_LABELS; i++) {
        t->row[i] = i < SC_LABEL_COUNT ? rows[i] : rows[SC_LABEL_FAT];
    }
}

int sc_material_table_validate(const sc_material_table *t)
{
    if (t == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (t->count < 1u || t->count > SC_MAX_LABELS) {
        return SC_ERR_CASE_MATERIAL;
    }
    for (uint32_t i = 0; i < t->count; i++) {
        const sc_material *r = &t->row[i];
        if (!isfinite(r->e_pa) || !isfinite(r->poisson) || !isfinite(r->density_kg_m3)) {
            return SC_ERR_CASE_MATERIAL;
        }
        if (!(r->e_pa > 0.0f) || !(r->poisson >= 0.0f) || !(r->poisson < 0.5f) ||
            !(r->density_kg_m3 > 0.0f)) {
            return SC_ERR_CASE_MATERIAL;
        }
    }
    return SC_OK;
}

uint8_t sc_material_label_at(const sc_volume *vol, const float p_mm[3])
{
    if (vol == NULL || vol->labels == NULL) {
        return SC_LABEL_OUTSIDE;
    }
    uint32_t idx[3];
    for (uint32_t d = 0; d < 3u; d++) {
        const float g = floorf((p_mm[d] - vol->origin_mm[d]) / vol->spacing_mm[d] + 0.5f);
        if (!(g >= 0.0f) || !(g < (float)vol->dim[d])) {
            return SC_LABEL_OUTSIDE;
        }
        idx[d] = (uint32_t)g;
    }
    const uint64_t at = (uint64_t)idx[0] + (uint64_t)vol->dim[0] *
                                               ((uint64_t)idx[1] + (uint64_t)vol->dim[1] * idx[2]);
    return vol->labels[at];
}

int sc_material_assign(sc_mesh *m, const sc_volume *vol, const sc_material_table *t,
                       uint8_t default_label)
{
    if (m == NULL || t == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int have_labels = vol != NULL && vol->labels != NULL;
    if (!have_labels && default_label >= t->count) {
        return SC_ERR_CASE_LABEL;
    }
    for (uint32_t e = 0; e < m->tet_count; e++) {
        uint8_t lab = default_label;
        if (have_labels) {
            uint32_t votes[SC_MAX_LABELS] = {0};
            const uint32_t *tv = m->tet[e];
            /* order-3 barycentric lattice, shifted inside: (a + 1/4) / 4, sum of weights 1 */
            for (uint32_t a = 0; a <= 3u; a++) {
                for (uint32_t b = 0; a + b <= 3u; b++) {
                    for (uint32_t c = 0; a + b + c <= 3u; c++) {
                        const uint32_t d = 3u - a - b - c;
                        const float w[4] = {((float)a + 0.25f) * 0.25f, ((float)b + 0.25f) * 0.25f,
                                            ((float)c + 0.25f) * 0.25f, ((float)d + 0.25f) * 0.25f};
                        float p[3] = {0.0f, 0.0f, 0.0f};
                        for (uint32_t v = 0; v < 4u; v++) {
                            p[0] += w[v] * m->rest_x[tv[v]];
                            p[1] += w[v] * m->rest_y[tv[v]];
                            p[2] += w[v] * m->rest_z[tv[v]];
                        }
                        const uint8_t l = sc_material_label_at(vol, p);
                        if (l >= t->count) {
                            return SC_ERR_CASE_LABEL;
                        }
                        votes[l]++;
                    }
                }
            }
            uint32_t best = 0;
            for (uint32_t l = 1; l < t->count; l++) {
                if (votes[l] > votes[best]) {
                    best = l;
                }
            }
            lab = (uint8_t)best;
        }
        m->tet_label[e] = lab;
    }
    for (uint32_t k = 0; k < m->nz; k++) {
        for (uint32_t j = 0; j < m->ny; j++) {
            for (uint32_t i = 0; i < m->nx; i++) {
                const uint32_t n = i + m->nx * (j + m->ny * k);
                /* bottom: fixed; sides: on rollers (the normal axis held, the tissue slides
                 * along the cut of the body; the FEM and the implicit MSDS honour the
                 * rollers, the explicit MSDS holds the whole node as before) */
                uint8_t fixed = 0u;
                if (k + 1u == m->nz) {
                    fixed = SC_MESH_FIXED_ALL;
                } else {
                    if (i == 0u || i + 1u == m->nx) {
                        fixed |= SC_MESH_ROLLER_X;
                    }
                    if (j == 0u || j + 1u == m->ny) {
                        fixed |= SC_MESH_ROLLER_Y;
                    }
                }
                if (have_labels) {
                    const float p[3] = {m->rest_x[n], m->rest_y[n], m->rest_z[n]};
                    if (sc_material_label_at(vol, p) == SC_LABEL_BONE) {
                        fixed = SC_MESH_FIXED_ALL;
                    }
                }
                m->node_fixed[n] = fixed;
            }
        }
    }
    return SC_OK;
}
