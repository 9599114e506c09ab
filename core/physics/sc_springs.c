/* sc_springs.c: Algorithm 1 (FEM tets -> MSDS springs), see sc_springs.h. */
#include "sc_springs.h"

#include <stddef.h>

#include "sc_err.h"

_Static_assert(SC_SPRINGS_HASH_SLOTS >= 2u * SC_MAX_SPRINGS, "spring hash load factor > 1/2");

static uint32_t hash_pair(uint32_t a, uint32_t b)
{
    uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u;
    h ^= h >> 15;
    h *= 0xC2B2AE3Du;
    h ^= h >> 13;
    return h & (SC_SPRINGS_HASH_SLOTS - 1u);
}

int32_t sc_springs_find(const sc_springs *s, uint32_t a, uint32_t b)
{
    if (a > b) {
        uint32_t t = a;
        a = b;
        b = t;
    }
    uint32_t h = hash_pair(a, b);
    for (uint32_t probe = 0; probe < SC_SPRINGS_HASH_SLOTS; probe++) {
        const uint32_t v = s->slot[h];
        if (v == 0u) {
            return -1;
        }
        if (s->a[v - 1u] == a && s->b[v - 1u] == b) {
            return (int32_t)(v - 1u);
        }
        h = (h + 1u) & (SC_SPRINGS_HASH_SLOTS - 1u);
    }
    return -1;
}

int sc_springs_from_tets(sc_springs *s, const uint32_t (*tets)[4], const uint8_t *tet_label,
                         uint32_t tet_count, const sc_material_table *mat)
{
    static const uint8_t edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    if (s == NULL || (tet_count > 0u && (tets == NULL || tet_label == NULL)) || mat == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    s->count = 0;
    for (uint32_t i = 0; i < SC_SPRINGS_HASH_SLOTS; i++) {
        s->slot[i] = 0u;
    }
    for (uint32_t t = 0; t < tet_count; t++) {             /* forall tetrahedra T */
        if (tet_label[t] >= mat->count) {
            return SC_ERR_CASE_LABEL;
        }
        const float k = SC_SPRINGS_K_PER_E_M * mat->row[tet_label[t]].e_pa; /* line 5 */
        const float gamma = SC_SPRINGS_GAMMA_PER_K_S * k;                  /* line 6 */
        for (uint32_t e = 0; e < 6u; e++) {                 /* forall edges E in T */
            uint32_t a = tets[t][edge[e][0]], b = tets[t][edge[e][1]];
            if (a == b) {
                return SC_ERR_INVALID_ARG;
            }
            if (a > b) {
                uint32_t tmp = a;
                a = b;
                b = tmp;
            }
            uint32_t h = hash_pair(a, b);
            for (;;) {
                const uint32_t v = s->slot[h];
                if (v == 0u) {                               /* line 10-11: add S_E */
                    if (s->count >= SC_MAX_SPRINGS) {
                        return SC_ERR_MESH_SPRINGS;
                    }
                    const uint32_t i = s->count++;
                    s->a[i] = a;
                    s->b[i] = b;
                    s->k_n_per_m[i] = k;
                    s->gamma_n_s_per_m[i] = gamma;
                    s->slot[h] = i + 1u;
                    break;
                }
                if (s->a[v - 1u] == a && s->b[v - 1u] == b) { /* line 7-9: sum */
                    s->k_n_per_m[v - 1u] += k;
                    s->gamma_n_s_per_m[v - 1u] += gamma;
                    break;
                }
                /* the table is at most half full: an empty slot is always reached */
                h = (h + 1u) & (SC_SPRINGS_HASH_SLOTS - 1u);
            }
        }
    }
    return SC_OK;
}
