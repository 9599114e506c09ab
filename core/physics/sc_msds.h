/*
 * sc_msds.h: mass-spring-damper soft tissue, the paper's appendix (eqs. 1-5).
 *
 * The defaults are not the paper's: the springs are derived from the tets (springs, below:
 * SC_MSDS_SPRINGS_DERIVED, volume ratio 1) and the tissue facade integrates them with the
 * stable backward Euler of sc_msds_implicit.h (integrator SC_MSDS_IMPLICIT), with the volume
 * floor (floor_*). The paper's MSDS is def.springs = SC_MSDS_SPRINGS_PAPER, def.integrator =
 * SC_MSDS_EXPLICIT and volume_stiffness_ratio 0 (6 was the former default calibration); what
 * follows describes the explicit path and its springs, which this module's step runs.
 *
 * Voigt springs from Algorithm 1 (sc_springs.h) on the regular 5-tet grid; per particle
 *   s_i = sum over its springs of [k (|d| - L0) + gamma d|d|/dt] * (-u),  u = d / |d|   (eq. 1)
 *   a_i = (f_i - s_i) / m_i                                                      (eqs. 2, 3)
 *   v_i += dt a_i;  x_i += dt v_i  (new velocity, exactly eqs. 4, 5)
 * dt = 0.01 s and 20 iterations per frame by default, both runtime settings (sc_msds_def).
 * Units: mm, s, N, kg. Spring constants are Algorithm 1's N/m converted to N/mm (x 1e-3);
 * a [mm/s^2] = 1e3 * F [N] / m [kg].
 *
 * Volume term (an extension of the paper, default on; the appendix itself notes that
 * "generalized springs may be employed to preserve areas and volumes"): Algorithm 1's springs
 * are kept exactly, and every tet adds the volume spring of Teschner et al. 2004,
 *   f_a = -k_vol (V - V0) grad_a V,  k_vol = volume_stiffness_ratio * lambda / V0,
 * lambda = E nu / ((1 + nu)(1 - 2 nu)) of the tet's material (energy 1/2 lambda V0 (dV/V0)^2).
 * Without it the spring lattice has no resistance to a tet turning inside out (a folded mesh
 * is a spring equilibrium) and behaves like Poisson ratio 1/4, so the tissue around the vein
 * gives way instead of the vein; the clinical test fails (vein -17%, 7.9 mm left 2 s after
 * the lift). The default ratio 6 (with drag 2.5 / s and mass scaling 1.2e-3 s^2) is a
 * calibration against the clinical scene and the FEM (tests/unit/test_sc_tissue.c): lambda
 * alone on top of the lattice leaves the block more compressible than the FEM's nu = 0.45.
 * volume_stiffness_ratio = 0 gives the paper's MSDS exactly. The volume term is undamped.
 *
 * Masses: explicit Euler is stable only if dt^2 k/m and dt gamma/m are small. With the
 * paper's constants (k = 0.002 E, gamma = 0.1 k, dt = 0.01 s) and real tissue masses (a few mg
 * per node) it diverges at once, so, as the paper says ("we choose appropriately small time
 * steps and we overdamp"), the particle mass is scaled: m_i = max(physical mass,
 * mass_per_stiffness_s2 * sigma * w_i), w_i = (sum of k_ij over the springs at i) + (the
 * volume term's block-Gershgorin row sum at i) / 2, so that by Gershgorin every eigenvalue of
 * W^-1 K is <= 2. Gershgorin is loose on this mesh (the true largest eigenvalue mu of W^-1 K
 * is 0.5..0.95 of the bound), which made the masses, and the block's response, needlessly
 * slow; sigma = min(1, 1.1 mu / 2) with mu estimated at load time by 100 power iterations
 * (deterministic; Rayleigh quotients approach mu from below, within 0.5% here; the 1.1
 * covers the rest). Then every eigenvalue lambda of M^-1 K is <= 2 / mass_per_stiffness_s2
 * as before, and the springs' damping (gamma = 0.1 k, a part of K) too, and the damped
 * explicit scheme is stable for (0.1 dt + dt^2) lambda < 2 (per mode: z^2 - (2 - a - b) z +
 * 1 - a = 0, a = 0.1 dt lambda, b = dt^2 lambda), i.e. mass_per_stiffness_s2 > 1.05e-3 s^2 at
 * dt = 0.01 s; the default 1.2e-3 s^2 with sigma's 1.1 leaves a factor ~1.25 (the volume
 * modes are undamped and stable up to dt^2 lambda < 4). sc_msds_def_validate() refuses
 * settings outside the stable region (with the contact stiffness of sc_tissue included: the
 * penalty contact uses kref = m / mps, so its eigenvalue is contact_stiffness_ratio / mps).
 * The mass-proportional drag (friction with the surroundings, an external force of eq. 2)
 * damps the slow modes that gamma = 0.1 k leaves under-damped (default 2.5 / s).
 *
 * Layout (hot data, float32 SoA): the springs of the regular grid fall into 9 families by
 * grid direction (x, y, z and the six face diagonals); spring (n, n + off[d]) of family d is
 * stored at index n of family d's arrays (k = 0 where the grid has no such spring), so the
 * springs are straight, vectorisable loops with no gather/scatter by index. The volume term
 * runs per grid cell (origin node n): the 8 corners are loaded from straight rows, an odd
 * cell is mirrored in x by exact selects, so one branch-free body computes all five tets, and
 * the corner forces are added back by 8 straight loops per block of SC_MSDS_CELL_BLOCK cells.
 * A substep is one sweep over the nodes in blocks of SC_MSDS_SWEEP_BLOCK (256): the block's
 * springs (as origins), its cells, then its integration; a node's last force comes from its
 * own block and no block reads a node behind it, so this is exactly the explicit step, with
 * the block's data in cache (one pass over memory per substep instead of about 20).
 * The substep is one C source (sc_msds_kern.inc) built per instruction-set variant
 * (sc_simd.h: generic, x86-64-v3, x86-64-v4), bit-identical; the platform picks the variant.
 * Cost at 32x16x16, 20 substeps (bench-physics prints the table): on x86-64-v4 (AMD Zen 5
 * here, a shared 2-core VM) best 1.56-1.69 ms, median 1.64-2.14 ms per frame over repeated
 * runs; x86-64-v3 about 2.2 ms, generic (SSE2) 4.3-4.9 ms; 27.7M
 * instructions per frame on v3, 76.7M generic (callgrind). Tried, measured no faster here:
 * packing the six half-empty diagonal families densely (selects of the ends), moving them into
 * the cell pass, a sqrt- and divide-free 1/|d| (Newton from a bit-pattern seed), fusing each
 * family's far-end pass into the next, 512-bit or 256-bit vectors for x86-64-v4: the springs
 * are bound by their loads and stores more than by their arithmetic.
 * Memory (N = SC_MAX_NODES, T = SC_MAX_TETS): springs 72 B, masses/sums 24 B, scratch 24 B,
 * cells 44 B, roller axes 1 B per node; per tet 24 B (k, V0, nodes: load time and energy only):
 * sizeof(sc_msds) about 2.2 MB at 8,192 nodes.
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
/* cells per block of the cell pass: its force buffer is 96 B per cell (24 KB at 256; a
 * block of 256 measured 8% faster than 64 on x86-64, the MCU build takes 64). The block sizes
 * set the order in which a node's forces are summed, so they are part of what makes a state
 * hash: builds with the same sizes agree bit for bit. */
#ifndef SC_MSDS_CELL_BLOCK
#define SC_MSDS_CELL_BLOCK 256u
#endif
/* nodes per block of a substep's sweep (a multiple of SC_MSDS_CELL_BLOCK; sc_msds_kern.inc) */
#ifndef SC_MSDS_SWEEP_BLOCK
#define SC_MSDS_SWEEP_BLOCK 256u
#endif
_Static_assert(SC_MSDS_SWEEP_BLOCK % SC_MSDS_CELL_BLOCK == 0u,
               "a sweep block holds whole cell blocks");

/* Time integrator of the MSDS (sc_tissue runs it): */
typedef enum sc_msds_integrator {
    SC_MSDS_IMPLICIT = 0, /* default: backward Euler, one step per frame (sc_msds_implicit.h) */
    SC_MSDS_EXPLICIT = 1, /* the paper's explicit Euler, `iterations` substeps of dt */
} sc_msds_integrator;

/* Spring constants of the MSDS:
 * SC_MSDS_SPRINGS_DERIVED (default): from each tet's material, volume and edge lengths, so
 *   that the MSDS's static stiffness follows the FEM's at every mesh resolution and cell shape.
 *   Under a homogeneous strain a grid cell's springs and the volume term store an orthotropic
 *   energy whose moduli are linear in three per-family shares (axis edges e_i, face diagonals
 *   s_ij, volume term l); at load time these 7 numbers are fitted per material (sc_msds.c,
 *   derived_fit: projected Levenberg-Marquardt in double, 60 steps, + - * / only) to the
 *   FEM's three uniaxial Young's moduli and bulk modulus and, weighted 0.1, its shear modulus,
 *   and shared out to the tets by volume (k ~ mu V / L^2 per axis edge, mu V Ld^2 / (L_i^2
 *   L_j^2) per face diagonal: E x length, so a finer mesh keeps the material). On cubic cells
 *   the fit is exact (e = s = mu, l = lambda - mu: the Cauchy lattice plus the rest of lambda).
 *   On the default 40 x 20 x 30 mm box (cells 1 : 1 : 1.5) a central-spring lattice cannot
 *   hold all of the FEM's moduli (the long axis's face diagonals alone exceed its normal
 *   modulus); the fit keeps the uniaxial and bulk moduli within 1.3% and lets the shear of the
 *   two planes across the long axis fall to about 0.5 mu. Measured on the uniaxial block
 *   (tests/unit/test_sc_stiffness.c), MSDS / FEM: 0.98-1.01 on the default box at 20x10x10
 *   to 64x32x32 and on cubic cells (the former k = 2 mu V / L^2 per
 *   edge: 1.44 on the box).
 * SC_MSDS_SPRINGS_PAPER: Algorithm 1's k = 0.002 E per tet edge (sc_springs.h) and the
 *   volume term on lambda (the former calibration: ratio 6), for the paper's tables. */
typedef enum sc_msds_springs {
    SC_MSDS_SPRINGS_DERIVED = 0,
    SC_MSDS_SPRINGS_PAPER = 1,
} sc_msds_springs;

typedef struct sc_msds_def {
    float dt_s;                    /* explicit Euler step, > 0 (default SC_PHYS_DT_DEFAULT_S) */
    uint32_t iterations;           /* Euler steps per frame, 1..SC_PHYS_ITERATIONS_MAX */
    float mass_per_stiffness_s2;   /* mass scaling (see above), > 0 */
    float drag_per_s;              /* mass-proportional drag, >= 0 */
    float contact_stiffness_ratio; /* contact spring per node / its summed spring k, >= 0 */
    float volume_stiffness_ratio;  /* volume term (see above) / Lame lambda, 0..100; 0: off */
    uint8_t integrator;            /* sc_msds_integrator; the stability bound above applies
                                      to SC_MSDS_EXPLICIT only */
    uint8_t springs;               /* sc_msds_springs; read by sc_msds_init only */
    float floor_volume_ratio;      /* implicit: a tet below this fraction of its rest volume
                                      meets the floor term (walls that meet do not pass
                                      through each other), 0..0.5; 0: off */
    float floor_pa;                /* implicit: the floor term's bulk modulus, >= 0 */
} sc_msds_def;

typedef struct sc_msds {
    sc_msds_def def;
    uint32_t node_count;
    uint32_t spring_count;          /* springs of Algorithm 1 mapped into the families */
    uint32_t off[SC_MSDS_FAMILIES]; /* node index offset of each family, > 0 */
    float gamma_per_k_s;            /* gamma / k, the same for every spring (0.1 s) */
    float energy_limit_j;           /* runaway bound, see sc_msds_energy_ok() */
    SC_ALIGN_HOT float k_n_per_mm[SC_MSDS_FAMILIES][SC_MAX_NODES];
    SC_ALIGN_HOT float l0_mm[SC_MSDS_FAMILIES][SC_MAX_NODES];
    SC_ALIGN_HOT float mass_kg[SC_MAX_NODES];
    SC_ALIGN_HOT float inv_mass[SC_MAX_NODES];      /* 1e3 / m (mm/s^2 per N); 0: fixed node */
    uint8_t roller[SC_MAX_NODES]; /* explicit: the held axes of a node on rollers (the mesh's
                                     SC_MESH_ROLLER_* bits; 0: free, or fixed by inv_mass 0) */
    SC_ALIGN_HOT float ksum_n_per_mm[SC_MAX_NODES]; /* sum of spring k at each node */
    SC_ALIGN_HOT float phys_mass_kg[SC_MAX_NODES];  /* density x volume / 4 per tet corner */
    SC_ALIGN_HOT float fx[SC_MAX_NODES];            /* scratch: net force of the current step, N */
    SC_ALIGN_HOT float fy[SC_MAX_NODES];
    SC_ALIGN_HOT float fz[SC_MAX_NODES];
    SC_ALIGN_HOT float tx[SC_MAX_NODES]; /* scratch: spring forces of one family, N */
    SC_ALIGN_HOT float ty[SC_MAX_NODES];
    SC_ALIGN_HOT float tz[SC_MAX_NODES];
    /* volume term (extension, see above): tets with a non-zero volume stiffness */
    uint32_t vol_count;
    SC_ALIGN_HOT float kvol36[SC_MAX_TETS];          /* k_vol / 36, N/mm^5 (6V and its gradient) */
    SC_ALIGN_HOT float d0_mm3[SC_MAX_TETS];          /* rest 6V, mm^3 */
    SC_ALIGN_HOT uint32_t tv[4][SC_MAX_TETS];        /* node indices (the mesh's tet, SoA) */
    SC_ALIGN_HOT float kvsum_n_per_mm[SC_MAX_NODES]; /* volume term's Gershgorin share per node */
    SC_ALIGN_HOT float kref_n_per_mm[SC_MAX_NODES];  /* mass-equivalent stiffness m / mps */
    /* the volume term per grid cell (hot): cell with origin node n, its tet q (mesh order) */
    SC_ALIGN_HOT float cell_k[5][SC_MAX_NODES];          /* k_vol / 36 at ratio 1; 0: no cell */
    SC_ALIGN_HOT float cell_d0[5][SC_MAX_NODES];         /* rest 6V in the kernel's corner order */
    SC_ALIGN_HOT float cell_par[SC_MAX_NODES];           /* 1: odd cell (mirrored template), 0 */
    uint32_t cell_end;                                   /* origins 0..cell_end-1 are visited */
    SC_ALIGN_HOT float cell_g[8][3][SC_MSDS_CELL_BLOCK]; /* scratch: corner forces (mirrored) */
    float mass_scale; /* sigma (see above): 1.1 x spectral estimate / Gershgorin, <= 1 */
    uint32_t scale_it; /* power iterations of sigma done (init in slices) */
    double scale_mu;   /* their Rayleigh quotient so far */
    uint32_t nx, nxy; /* grid shape and cell (rest geometry for the spectral estimate) */
    float cell_mm[3];
    uint8_t faces_odd; /* 1: every face-diagonal spring (families 3-8) has its origin at a node of
                          odd i + j + k (sc_mesh.c: a face diagonal joins the face's odd corners),
                          k = 0 at every even one; the stable MSDS's springs may then skip the
                          even nodes' face lanes (sc_grid_kern.inc, springs_pair) */
} sc_msds;

/* dt 0.01 s, 20 iterations (paper), mass scaling 1.2e-3 s^2, drag 2.5 / s, contact ratio
 * 0.5, volume term ratio 6, the implicit integrator (SC_MSDS_IMPLICIT). */
sc_msds_def sc_msds_default_def(void);

/* Finite, ranges, and the explicit stability bound above. O(1).
 * Errors: SC_ERR_INVALID_ARG (NULL), SC_ERR_NOT_FINITE, SC_ERR_RANGE (incl. unstable). */
int sc_msds_def_validate(const sc_msds_def *def);

/* Map Algorithm 1's springs into the grid families, compute rest lengths and rest volumes
 * from the mesh's rest positions with the step's own float operations (so the rest state is
 * an exact equilibrium), the volume term per tet and per cell, masses from the material
 * densities, the mass scaling and sigma (power iterations). Call at case load.
 * O(springs + 100 (9 N + tets)). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL, mesh/spring mismatch, a mesh that is not the regular
 * 5-tet grid of sc_mesh_build), the def's errors,
 * SC_ERR_MESH_SPRINGS (a spring that is not between grid neighbours, or gamma / k not the same
 * for all springs), SC_ERR_CASE_LABEL. */
int sc_msds_init(sc_msds *s, const sc_mesh *m, const sc_springs *sp, const sc_material_table *mat,
                 const sc_msds_def *def);

/* sc_msds_init in slices (a case switch between frames): begin does everything but sigma's
 * power iterations (O(springs + N + tets)); each step runs at most `iterations` of them
 * (O(iterations (9 N + tets))) and returns 0 (more to do) or 1 (masses final: the same bits as
 * sc_msds_init). Errors: those of sc_msds_init (begin); SC_ERR_INVALID_ARG (step: NULL, 0). */
int sc_msds_init_begin(sc_msds *s, const sc_mesh *m, const sc_springs *sp,
                       const sc_material_table *mat, const sc_msds_def *def);
int sc_msds_init_step(sc_msds *s, const sc_mesh *m, uint32_t iterations);

/* Change the settings at run time: masses recomputed if the mass scaling or the volume
 * ratio changes (O(N); a new volume ratio also re-estimates sigma, O(100 (9 N + tets))).
 * Errors: as sc_msds_def_validate (the old settings stay). */
int sc_msds_set_def(sc_msds *s, const sc_msds_def *def);

/* One explicit Euler step (eqs. 3-5) with the external forces in n->f*, spring forces and
 * the volume term; fixed nodes do not move. O(9 N + 5 N). Never allocates, cannot fail
 * (divergence is detected by the caller). */
void sc_msds_substep(sc_msds *s, sc_nodes *n);

/* def.iterations substeps with constant external forces. O(iterations * 9 N). */
void sc_msds_step(sc_msds *s, sc_nodes *n);

/* Kinetic energy 1/2 sum m v^2 (J, scaled masses). O(N). */
float sc_msds_kinetic_energy_j(const sc_msds *s, const sc_nodes *n);

/* Elastic energy 1/2 sum k (|d| - L0)^2 + 1/2 sum k_vol (V - V0)^2 (J). O(9 N + tets). */
float sc_msds_elastic_energy_j(const sc_msds *s, const sc_nodes *n);

#endif /* SC_MSDS_H */
