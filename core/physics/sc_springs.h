/*
 * sc_springs.h: the paper's Algorithm 1: convert an FEM tet mesh into MSDS springs.
 *
 * Every edge of every tet becomes a Voigt spring (spring + damper in parallel) between its two
 * nodes with spring constant k = 0.002 * E_tet and damping constant gamma = 0.1 * k; a spring
 * that already exists (an edge shared by several tets) gets both constants summed.
 * Units, stated once: E in Pa, k in N/m, gamma in N s/m, i.e. the paper's factor 0.002 is a
 * length of 0.002 m (2 mm) and 0.1 a time of 0.1 s: k = E * 0.002 m has the dimension of a
 * bar's axial stiffness E A / L with A / L = 2 mm. The MSDS converts to N/mm where it uses them.
 *
 * The list is built at case load. "Exists in Springs" is found through an open-addressing hash
 * table inside the caller's sc_springs (deterministic: the list keeps first-encounter order,
 * node pair (a, b) with a < b). Memory: everything in the caller's struct, sized by
 * SC_MAX_SPRINGS (config/sc_config.h). Never allocates, never calls the OS. Threads: one writer.
 */
#ifndef SC_SPRINGS_H
#define SC_SPRINGS_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_material.h"

/* Algorithm 1 constants (paper section III-A, line 5 and 6). */
#define SC_SPRINGS_K_PER_E_M 0.002f      /* k = 0.002 * E: N/m per Pa, i.e. metres */
#define SC_SPRINGS_GAMMA_PER_K_S 0.1f    /* gamma = 0.1 * k: seconds */

/* Hash slots: a power of two at least twice the spring capacity (load factor <= 1/2). */
#define SC_SPRINGS_HASH_SLOTS (1u << SC_SPRINGS_HASH_BITS)

typedef struct sc_springs {
    uint32_t count;
    uint32_t a[SC_MAX_SPRINGS];          /* node indices, a < b */
    uint32_t b[SC_MAX_SPRINGS];
    float k_n_per_m[SC_MAX_SPRINGS];     /* summed spring constants, N/m */
    float gamma_n_s_per_m[SC_MAX_SPRINGS]; /* summed damping constants, N s/m */
    uint32_t slot[SC_SPRINGS_HASH_SLOTS]; /* spring index + 1, 0 = empty (build-time only) */
} sc_springs;

/* Algorithm 1 over tets[0..tet_count): E of tet t is mat->row[tet_label[t]].e_pa.
 * O(tet_count) expected (hash with load factor <= 1/2), bounded by SC_MAX_SPRINGS probes per
 * edge in the worst case. Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL, a tet with a repeated node), SC_ERR_CASE_LABEL (a label
 * without a table row), SC_ERR_MESH_SPRINGS (more than SC_MAX_SPRINGS springs). */
int sc_springs_from_tets(sc_springs *s, const uint32_t (*tets)[4], const uint8_t *tet_label,
                         uint32_t tet_count, const sc_material_table *mat);

/* Index of the spring between nodes a and b (either order), or -1. O(1) expected. */
int32_t sc_springs_find(const sc_springs *s, uint32_t a, uint32_t b);

#endif /* SC_SPRINGS_H */
