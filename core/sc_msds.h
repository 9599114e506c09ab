/*
 * sc_msds.h: mass-spring-damper soft tissue, the paper's appendix (eqs. 1-5).
 *
 * Voigt springs from Algorithm 1 (sc_springs.h) on the regular 5-tet grid; per particle
 *   s_i = sum over its springs of [k (|d| - L0) + gamma d|d|/dt] * (-u),  u = d / |d|   (eq. 1)
 *   a_i = (f_i - s_i) / m_i                                                      (eqs. 2, 3)
 *   v_i += dt a_i;  x_i += dt v_i  (new velocity, exactly eqs. 4, 5)
 * dt = 0.01 s and 20 iterations per frame by default, both runtime settings (sc_msds_def).
 * Units: mm, s, N, kg. Spring constants are Algorithm 1's N/m converted to N/mm (x 1e-3);
 * a [mm/s^2] = 1e3 * F [N] / m [kg].
 *
 * Masses: explicit Euler is stable only if dt^2 k/m and dt gamma/m are small. With the
 * paper's constants (k = 0.002 E, gamma = 0.1 k, dt = 0.01 s) and real tissue masses (a few mg
 * per node) it diverges at once, so, as the paper says ("we choose appropriately small time
 * steps and we overdamp"), the particle mass is scaled: m_i = max(physical mass,
 * mass_per_stiffness_s2 * sum of k_ij over the springs at i). With gamma = 0.1 k every
 * eigenvalue lambda of M^-1 K is <= 2 / mass_per_stiffness_s2 (Gershgorin), and the damped
 * explicit scheme is stable for (0.1 dt + dt^2) lambda < 2 (per mode: z^2 - (2 - a - b) z +
 * 1 - a = 0, a = 0.1 dt lambda, b = dt^2 lambda), i.e. mass_per_stiffness_s2 > 1.05e-3 s^2 at
 * dt = 0.01 s: the default 2e-3 s^2 leaves a factor ~1.9. sc_msds_def_validate() refuses
 * settings outside the stable region (with the contact stiffness of sc_tissue included).
 * An optional mass-proportional drag (friction with the surroundings, an external force of
 * eq. 2) damps the slow modes that gamma = 0.1 k leaves under-damped.
 *
 * Layout (hot data, float32 SoA): the springs of the regular grid fall into 9 families by
 * grid direction (x, y, z and the six face diagonals); spring (n, n + off[d]) of family d is
 * stored at index n of family d's arrays (k = 0 where the grid has no such spring). A step
 * is then 9 straight, vectorisable passes with no gather/scatter by index.
 * Memory (N = SC_MAX_NODES): k, L0: 9 x 2 x 4 B; mass, 1/m, sum k: 12 B; forces and spring
 * scratch 24 B: 108 B per node, 0.88 MB at 8,192 nodes.
 *
 * Thread rules: one writer. Never allocates, never calls the OS. Deterministic (fixed loop
 * order, no reductions across threads).
 */
#ifndef SC_MSDS_H
#define SC_MSDS_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_springs.h"

#define SC_MSDS_FAMILIES 9u

typedef struct sc_msds_def {
    float dt_s;                   /* explicit Euler step, > 0 (default SC_PHYS_DT_DEFAULT_S) */
    uint32_t iterations;          /* Euler steps per frame, 1..SC_PHYS_ITERATIONS_MAX */
    float mass_per_stiffness_s2;  /* mass scaling (see above), >= 0 */
    float drag_per_s;             /* mass-proportional drag, >= 0 */
    float contact_stiffness_ratio; /* contact spring per node / its summed spring k, >= 0 */
} sc_msds_def;

typedef struct sc_msds {
    sc_msds_def def;
    uint32_t node_count;
    uint32_t spring_count;              /* springs of Algorithm 1 mapped into the families */
    uint32_t off[SC_MSDS_FAMILIES];     /* node index offset of each family, > 0 */
    float gamma_per_k_s;                /* gamma / k, the same for every spring (0.1 s) */
    float energy_limit_j;               /* runaway bound, see sc_msds_energy_ok() */
    SC_ALIGN_HOT float k_n_per_mm[SC_MSDS_FAMILIES][SC_MAX_NODES];
    SC_ALIGN_HOT float l0_mm[SC_MSDS_FAMILIES][SC_MAX_NODES];
    SC_ALIGN_HOT float mass_kg[SC_MAX_NODES];
    SC_ALIGN_HOT float inv_mass[SC_MAX_NODES]; /* 1e3 / m (mm/s^2 per N); 0: fixed node */
    SC_ALIGN_HOT float ksum_n_per_mm[SC_MAX_NODES]; /* sum of spring k at each node */
    SC_ALIGN_HOT float phys_mass_kg[SC_MAX_NODES];  /* density x volume / 4 per tet corner */
    SC_ALIGN_HOT float fx[SC_MAX_NODES]; /* scratch: net force of the current step, N */
    SC_ALIGN_HOT float fy[SC_MAX_NODES];
    SC_ALIGN_HOT float fz[SC_MAX_NODES];
    SC_ALIGN_HOT float tx[SC_MAX_NODES]; /* scratch: spring forces of one family, N */
    SC_ALIGN_HOT float ty[SC_MAX_NODES];
    SC_ALIGN_HOT float tz[SC_MAX_NODES];
} sc_msds;

/* dt 0.01 s, 20 iterations (paper), mass scaling 2e-3 s^2, drag 0, contact ratio 0.5. */
sc_msds_def sc_msds_default_def(void);

/* Finite, ranges, and the explicit stability bound above. O(1).
 * Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_NOT_FINITE, SC_ERR_RANGE (incl. unstable). */
int sc_msds_def_validate(const sc_msds_def *def);

/* Map Algorithm 1's springs into the grid families, compute rest lengths from the mesh's rest
 * positions (so the rest state is an exact equilibrium), masses from the material densities
 * and the mass scaling. Call at case load. O(springs + tets + nodes). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL, mesh/spring mismatch), the def's errors,
 * SC_ERR_MESH_SPRINGS (a spring that is not between grid neighbours, or gamma / k not the same
 * for all springs), SC_ERR_CASE_LABEL. */
int sc_msds_init(sc_msds *s, const sc_mesh *m, const sc_springs *sp,
                 const sc_material_table *mat, const sc_msds_def *def);

/* Change dt / iterations / mass scaling / drag at run time (masses recomputed, O(N)).
 * Errors: as sc_msds_def_validate (the old settings stay). */
int sc_msds_set_def(sc_msds *s, const sc_msds_def *def);

/* One explicit Euler step (eqs. 3-5) with the external forces in n->f*; fixed nodes do not
 * move. O(9 N). Never allocates, cannot fail (divergence is detected by the caller). */
void sc_msds_substep(sc_msds *s, sc_nodes *n);

/* def.iterations substeps with constant external forces. O(iterations * 9 N). */
void sc_msds_step(sc_msds *s, sc_nodes *n);

/* Kinetic energy 1/2 sum m v^2 (J, scaled masses). O(N). */
float sc_msds_kinetic_energy_j(const sc_msds *s, const sc_nodes *n);

/* Elastic energy 1/2 sum k (|d| - L0)^2 (J). O(9 N). */
float sc_msds_elastic_energy_j(const sc_msds *s, const sc_nodes *n);

#endif /* SC_MSDS_H */
