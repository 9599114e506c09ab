/*
 * sc_fem.h: finite-element soft tissue: isotropic linear elasticity with Cauchy strain on the
 * linear tets of sc_mesh, optionally corotated (stiffness warping), integrated with a linearly
 * implicit backward Euler step solved by a fixed number of warm-started Jacobi-preconditioned
 * conjugate-gradient iterations (paper section III / VI: OpenTissue's FEM, 20 CG iterations,
 * 0.01 s step).
 *
 * Model (units: mm, N, s; E in Pa is converted to N/mm^2 = 1e-6 Pa at init):
 *   M a + C v + f_int(x) = f_ext,   C = alpha M + beta K  (Rayleigh damping)
 *   linear:     f_int = K (x - X)                          (K: rest stiffness)
 *   corotated:  f_int = sum_e R_e K_e (R_e^T x_e - X_e)     (R_e: polar factor of the element's
 *               deformation gradient F = Ds Dm^-1, K_e warped to R_e K_e R_e^T every step)
 * One step of length dt solves for the new velocity v+ (backward Euler linearised at x):
 *   (M + dt C + dt^2 K) v+ = M v + dt (f_ext - f_int(x)),   x+ = x + dt v+.
 * M is the lumped mass (density x volume / 4 per tet corner).
 *
 * Why this design (the brief asks for an over-damped response comparable to the MSDS):
 * - The MSDS of the paper (Algorithm 1) gives every spring a damper gamma = 0.1 k: damping
 *   proportional to stiffness. Rayleigh damping with beta = 0.1 s (default) is the same law in
 *   FEM form, so every elastic mode relaxes with a time constant of about beta = 0.1 s whatever
 *   its stiffness (tissue masses are tiny: the modes are over-damped above 2/beta = 20 rad/s,
 *   and the lowest mode of a 30 mm block of 1 kPa tissue is ~50 rad/s).
 * - Backward Euler is unconditionally stable, so the step may be the frame period; an
 *   unconverged CG (fixed count) only slows the relaxation, it cannot blow it up. Warm start:
 *   the CG starts from the previous frame's solution, the current velocity, decayed by
 *   beta / (beta + dt) (the exact one-step decay of an over-damped mode), so convergence
 *   accumulates over frames (paper: "quasi-static ... CG") while modes the CG has not
 *   resolved keep relaxing instead of coasting (a plain v0 = v overshoots and oscillates
 *   with 1-5 CG iterations per frame). Unloaded (no kinematic node, no external force) the
 *   warm start is the quasi-static step toward rest, -(x - X) / (beta + dt) (sc_grid.h).
 * - Solving for v+ keeps the whole state in sc_nodes (x, v): the FEM has no hidden state
 *   besides its matrix, so switching MSDS <-> FEM at run time keeps the shape and velocity and
 *   needs no reallocation; toggling corotation is equally seamless.
 * - Fixed nodes (mesh node_fixed) and caller-driven kinematic nodes are Dirichlet DOFs: the
 *   preconditioner is zero on them, which projects the CG onto the free DOFs (their velocity
 *   stays the prescribed one: 0 for fixed nodes).
 * - Storage and solver: the grid matrix and step of sc_grid.h (shared with the stable MSDS:
 *   the two methods never run in the same frame): every block of a node pair is a row entry of
 *   the regular grid's stencil, the CG is the grid's fixed-count Jacobi PCG.
 * - Element work per grid cell, vectorised across cells (sc_grid_kern.inc, one lane per cell,
 *   4 or 8 lanes by instruction-set variant, all bitwise the same): every cell of the regular
 *   grid is the same box (an odd one mirrored in x), so the five tets' rest shape gradients and
 *   volumes are the template's, per cell parity: no per-tet rest data is kept, only each tet's
 *   lambda V and mu V (its label's material). The displacement gradient is formed from the
 *   displacements x - X (exact zero force at rest). The corotated model assembles every step,
 *   and the step's r0 needs K times the warm start v0: with sigma linear and isotropic,
 *   dt f_int(x) + ck K v0 is per element R sigma(R^T (dt F + ck L) - dt I) n_a V (L: velocity
 *   gradient of v0), computed in the same element pass instead of by a mat-vec. The linear
 *   model keeps its rest K in the grid and forms r0 with one mat-vec, K (dt (x - X) + ck v0),
 *   after a volume check of every tet (O(T), no blocks); it assembles (R = I) only when a tet
 *   is below the floor volume or the matrix holds something else.
 * - Corotated: the polar factor is the exact one (scaled Newton to convergence, per lane), not
 *   an approximation: no per-tet state is kept between frames.
 * - Use from the facade: sc_tissue runs one FEM step per frame of length iterations x dt
 *   (the simulated time of the MSDS's frame) with def.cg_iterations CG iterations, and holds
 *   the nodes in contact with the probe as kinematic nodes.
 *
 * Memory (float32; R = SC_GRID_ROW, ~SC_MAX_NODES + 2 (nx ny + nx)): the grid (sc_grid.h,
 * 3.1 MB at 32x16x16) and lambda V, mu V of the 5 tets of every cell (10 R floats, 0.35 MB):
 * sizeof(sc_fem) is printed by bench-fem. The MCU build shrinks the limits (all arrays scale).
 *
 * Thread rules: one writer; an sc_fem is used by one thread. Never allocates, never calls the
 * OS or stdio. Deterministic: fixed loop orders and fixed iteration counts give bit-identical
 * results for the same inputs on the same build.
 */
#ifndef SC_FEM_H
#define SC_FEM_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_grid.h"
#include "sc_material.h"
#include "sc_mesh.h"

typedef struct sc_fem_def {
    float rayleigh_beta_s;      /* stiffness-proportional damping, >= 0 (MSDS: gamma = 0.1 k) */
    float rayleigh_alpha_per_s; /* mass-proportional damping, >= 0 */
    uint8_t corotated;          /* 1: stiffness warping for large rotations; 0: linear */
    float floor_volume_ratio;   /* a tet below this fraction of its rest volume meets the
                                   floor term (see below), 0..0.5; 0: off */
    float floor_pa;             /* the floor term's bulk modulus, Pa, >= 0 */
    uint32_t cg_iterations;     /* CG iterations per frame of the implicit step (FEM and the
                                   stable MSDS, sc_tissue.h), 1..SC_PHYS_ITERATIONS_MAX */
} sc_fem_def;

/* Diagnostics of the last step, for tests, benchmarks and health reporting. */
typedef struct sc_fem_stats {
    uint32_t cg_iterations_run; /* <= requested (early only on r.z = 0 or p.Ap <= 0) */
    float residual_ratio;       /* sqrt(r.z) after / before the CG of the last step */
    uint32_t degenerate_tets;   /* corotated: tets with det F <= 1e-3 (flat/inverted: R = I) */
    uint32_t unstable_steps;    /* steps refused because the solution was not finite */
} sc_fem_stats;

typedef struct sc_fem {
    /* ---- cold: definition, sizes, template ---- */
    sc_fem_def def;
    uint32_t node_count;
    uint32_t tet_count;
    uint8_t unstable; /* a step produced a non-finite solution (sticky until init) */
    uint8_t rest_k;   /* the grid holds the rest K alone (the linear model's matrix): a linear
                         step with no tet below the floor keeps it (0 after a corotated or MSDS
                         step, or a floor term) */
    sc_fem_stats stats;
    float lambda_nmm2[SC_MAX_LABELS]; /* Lame parameters per label, N/mm^2 */
    float mu_nmm2[SC_MAX_LABELS];
    sc_grid_fem_in element; /* template gradients, volumes, floor (lamv/muv set per step) */
    /* ---- hot: lambda V and mu V of tet q of the cell with lowest node t at [q][HEAD + t] ---- */
    SC_ALIGN_HOT float lamv[5][SC_GRID_ROW];
    SC_ALIGN_HOT float muv[5][SC_GRID_ROW];
    sc_grid grid; /* matrix, lumped masses, solver vectors */
#if SC_GRID_COARSE
    sc_grid_coarse coarse; /* the two-grid correction (grid.coarse: meshes of more than
                              SC_GRID_COARSE_NODES nodes) */
#endif
} sc_fem;

/* Floor term (an extension: walls that meet do not pass through each other): a tet whose
 * volume V falls below V_f = floor_volume_ratio V0 gets the energy 1/2 K_f V0 ((V - V_f) / V0)^2
 * (K_f = floor_pa) on top of its elastic energy, with the Gauss-Newton stiffness
 * K_f / V0 grad V grad V^T; a collapsed lumen's tets flatten to V_f instead of turning inside
 * out (an inverted tet overlaps its neighbours, and the B-scan then shows the lumen again).
 * Its deficit V - V_f is clamped at -floor_step |grad V| (the shortest cell edge): the step of
 * a sliver crushed far through its floor is about a cell, not deficit / |grad V| (64x32x32: 72
 * mm). The same term runs in the implicit MSDS (sc_msds_implicit.h). Every free node's step is
 * held to two cell diagonals by sc_grid_solve (sc_grid.h: step_max_mm). */

/* Defaults: beta 0.1 s (the MSDS damper ratio of Algorithm 1), alpha 0, linear (paper), floor
 * at 1% of the rest volume with 100 kPa, SC_PHYS_CG_ITERATIONS_DEFAULT CG iterations. */
sc_fem_def sc_fem_default_def(void);

/* Check a definition: finite, non-negative damping, corotated 0 or 1, CG iterations in range.
 * O(1). Errors: SC_ERR_INVALID_ARG (NULL, corotated not 0/1), SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_fem_def_validate(const sc_fem_def *def);

/* Build the grid layout (sc_grid.h), the lumped masses, the template's shape gradients and
 * each tet's lambda V and mu V from the material row of its label (E, Poisson, density;
 * sc_material.h, the same table the MSDS uses), and assemble the rest K (sc_grid_block reads
 * it; the steps assemble their own). Call at case load (not at frame time). The mesh (labels,
 * fixed nodes) must stay unchanged while f is used with it.
 * Cost: O(N + T), bounded by SC_MAX_NODES / SC_MAX_TETS. Never allocates. Errors:
 * SC_ERR_INVALID_ARG (NULL, mesh counts above the limits), the definition's errors
 * (sc_fem_def_validate), SC_ERR_CASE_MATERIAL (table invalid, see
 * sc_material_table_validate), SC_ERR_CASE_LABEL (a tet label without a table row),
 * SC_ERR_FEM_PATTERN (the mesh's tets are not the regular grid's of sc_mesh_build). */
int sc_fem_init(sc_fem *f, const sc_mesh *m, const sc_material_table *mat, const sc_fem_def *def);

/* Advance the nodes by dt_s: reads n->x, n->v (warm start) and the external forces n->f*,
 * writes n->x and n->v. Fixed nodes keep their position with zero velocity. Runs exactly
 * cg_iterations CG iterations (fewer only if r.z is exactly 0 or p.Ap <= 0, e.g. no free
 * DOF); on a mesh with the two-grid correction (sc_grid.h, sc_grid_coarse) the correction
 * and cg_iterations - 1 of them (at least 1).
 * Cost: one element pass over the cells, O(T) (corotated: with a polar decomposition per tet,
 * at most 8 Newton iterations), plus cg_iterations grid mat-vecs, O(N) each.
 * Never allocates, cannot fail by contract: a non-finite solution leaves n unchanged, counts
 * stats.unstable_steps and sets the sticky status read by sc_fem_status().
 * Preconditions (SC_ASSERT): f initialised with m; dt_s finite and > 0;
 * 1 <= cg_iterations <= SC_PHYS_ITERATIONS_MAX. */
void sc_fem_step(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s, uint32_t cg_iterations);

/* As sc_fem_step, and nodes with kinematic[i] != 0 are driven by the caller: they move with
 * their current velocity n->v (x += dt v) and act as Dirichlet constraints on the others
 * (prescribed-displacement indentation; kinematic == NULL is sc_fem_step). Same cost. */
void sc_fem_step_kinematic(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic);

/* Switch corotation on or off at run time; takes effect in the next step. O(1). */
void sc_fem_set_corotated(sc_fem *f, int on);

/* 0, or SC_ERR_PHYS_UNSTABLE once a step produced a non-finite solution. O(1). */
int sc_fem_status(const sc_fem *f);

/* The corotated step's rotation of one element, exposed for tests: R = the rotation of the
 * polar decomposition F = R S (row-major 3x3), by the same lane code the step runs. Returns
 * 1, or 0 with R = I when det F <= 1e-3 (flat or inverted: no proper rotation). O(1)
 * (at most 8 Newton iterations), never allocates. Precondition (SC_ASSERT): F, R non-NULL. */
int sc_fem_polar_rotation(const float F[9], float R[9]);

#endif /* SC_FEM_H */
