/*
 * sc_fem.h: finite-element soft tissue: isotropic linear elasticity with Cauchy strain on the
 * linear tets of sc_mesh, optionally corotated (stiffness warping), integrated with a linearly
 * implicit backward Euler step solved by a fixed number of warm-started Jacobi-preconditioned
 * conjugate-gradient iterations (paper section III / VI: OpenTissue's FEM, 20 CG iterations,
 * 0.01 s step).
 *
 * Model (units: mm, N, s; E in Pa is converted to N/mm^2 = 1e-6 Pa at init):
 *   M a + C v + f_int(x) = f_ext,   C = alpha M + beta K  (Rayleigh damping)
 *   linear:     f_int = K (x - X)                          (K: rest stiffness, assembled once)
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
 *   with 1-5 CG iterations per frame).
 * - Solving for v+ keeps the whole state in sc_nodes (x, v): the FEM has no hidden state
 *   besides its matrix, so switching MSDS <-> FEM at run time keeps the shape and velocity and
 *   needs no reallocation; toggling corotation is equally seamless.
 * - Fixed nodes (mesh node_fixed) and caller-driven kinematic nodes are Dirichlet DOFs: the
 *   preconditioner is zero on them, which projects the CG onto the free DOFs (their velocity
 *   stays the prescribed one: 0 for fixed nodes).
 * - Storage: symmetric 3x3 block CSR over nodes: row i holds its diagonal block, then one
 *   block per mesh edge (i, j > i), columns sorted (a node has at most 18 neighbours in the
 *   5-tet grid, 12 on average: 6.5 blocks per row). Each off-diagonal block serves both
 *   (i, j) and (j, i)^T in the mat-vec, which halves the bytes streamed per CG iteration.
 *   Blocks are 3 rows of 4 floats and the solver vectors interleaved x, y, z, 0, so that a
 *   block's work is 3 + 3 four-lane multiply-adds (SIMD via the GCC/Clang vector extension,
 *   scalar elsewhere, bitwise the same) and the gather of p_j is one 16-byte load. Per-tet
 *   rest data (Dm^-1, volume, 6 block indices) lets the corotated step re-assemble the
 *   warped matrix in place without any search.
 * - Corotated re-assembly (the cost of that model: 34,875 tets per frame at 32x16x16): the
 *   element work (F, polar factor, stress, rotated gradients, the 10 blocks) runs on 4 tets
 *   at once, one per SIMD lane (SSE2/NEON targets; one tet at a time elsewhere, e.g. on the
 *   Cortex-M7), on rest data stored 4 tets to a row; the results are added tet by tet, so
 *   the one-lane build gives bitwise the same sums. The polar factor is the
 *   exact one (scaled Newton to convergence, per lane), not an approximation: no per-tet
 *   state is kept between frames. The step's r0 needs the warped K times v0; with sigma
 *   linear and isotropic, dt f_int(x) + ck K v0 is per element R sigma(R^T (dt F + ck L) -
 *   dt I) n_a V (L: velocity gradient), so it is computed in the same element pass instead
 *   of by an extra mat-vec over the freshly assembled matrix.
 * - Use from the facade: sc_tissue runs one FEM step per frame of length iterations x dt
 *   (the simulated time of the MSDS's frame) with `iterations` CG iterations, and holds the
 *   nodes in contact with the probe as kinematic nodes.
 *
 * Memory (float32, uint32; N = SC_MAX_NODES, T = SC_MAX_TETS, B = SC_MAX_FEM_NNZ_BLOCKS):
 *   per block: 48 B + column 4 B = 52 B     (B = 7 (N + 1) = 57,351: 2.98 MB at 32x16x16;
 *                                             53,568 used by the 32x16x16 mesh)
 *   per node: row start, mass 8 B + 8 solver vectors of 4 floats 128 B + flags 2 B = 138 B
 *                                                                      (1.13 MB at 8,192)
 *   per tet: Dm^-1 + volume 40 B + 6 block indices 24 B = 64 B       (2.23 MB at 34,875;
 *            the first two in groups of 4 tets, the last group padded)
 *   total 6.35 MB at the default limits (sizeof(sc_fem) = 6,345,216 B on x86-64, printed by
 *   the benchmark and the tests). The MCU build shrinks the limits (all arrays scale).
 *
 * Thread rules: one writer; an sc_fem is used by one thread. Never allocates, never calls the
 * OS or stdio. Deterministic: fixed loop orders and fixed iteration counts give bit-identical
 * results for the same inputs on the same build.
 */
#ifndef SC_FEM_H
#define SC_FEM_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_material.h"
#include "sc_mesh.h"

/* A 3x3 block is stored as 3 rows of 4 floats (element (r, c) at [4 r + c], [4 r + 3] = 0):
 * one SIMD register per row. */
#define SC_FEM_BLK_FLOATS 12u
/* Per-tet rest data is stored in groups of 4 tets (padded: lanes past the last tet are 0). */
#define SC_FEM_TET_LANES  4u
#define SC_FEM_TET_GROUPS ((SC_MAX_TETS + SC_FEM_TET_LANES - 1u) / SC_FEM_TET_LANES)

typedef struct sc_fem_def {
    float rayleigh_beta_s;      /* stiffness-proportional damping, >= 0 (MSDS: gamma = 0.1 k) */
    float rayleigh_alpha_per_s; /* mass-proportional damping, >= 0 */
    uint8_t corotated;          /* 1: stiffness warping for large rotations; 0: linear */
    float floor_volume_ratio;   /* a tet below this fraction of its rest volume meets the
                                   floor term (see below), 0..0.5; 0: off */
    float floor_pa;             /* the floor term's bulk modulus, Pa, >= 0 */
} sc_fem_def;

/* Diagnostics of the last step, for tests, benchmarks and health reporting. */
typedef struct sc_fem_stats {
    uint32_t cg_iterations_run; /* <= requested (early only on r.z = 0 or p.Ap <= 0) */
    float residual_ratio;       /* sqrt(r.z) after / before the CG of the last step */
    uint32_t degenerate_tets;   /* corotated: tets with det F <= 1e-3 (flat/inverted: R = I) */
    uint32_t unstable_steps;    /* steps refused because the solution was not finite */
} sc_fem_stats;

typedef struct sc_fem {
    /* ---- cold: definition and sizes ---- */
    sc_fem_def def;
    uint32_t node_count;
    uint32_t tet_count;
    uint32_t nnz_blocks;
    uint8_t matrix_is_rest; /* blocks hold the rest K (linear mode) */
    uint8_t unstable;       /* a step produced a non-finite solution (sticky until init) */
    sc_fem_stats stats;
    float lambda_nmm2[SC_MAX_LABELS]; /* Lame parameters per label, N/mm^2 */
    float mu_nmm2[SC_MAX_LABELS];

    /* ---- hot: upper-triangle 3x3 block CSR of K (row-major blocks), rows = nodes; the
     * first block of row i is (i, i) ---- */
    SC_ALIGN_HOT float blk[SC_MAX_FEM_NNZ_BLOCKS][SC_FEM_BLK_FLOATS];
    SC_ALIGN_HOT uint32_t col[SC_MAX_FEM_NNZ_BLOCKS];
    SC_ALIGN_HOT uint32_t row_start[SC_MAX_NODES + 1u];
    SC_ALIGN_HOT float mass[SC_MAX_NODES]; /* lumped mass, N s^2 / mm (= kg * 1e-3) */

    /* ---- hot: solver vectors, interleaved x, y, z, 0 (4 floats per node) ---- */
    SC_ALIGN_HOT float rest3[4u * SC_MAX_NODES];     /* rest positions, mm */
    SC_ALIGN_HOT float x3[4u * SC_MAX_NODES];        /* positions at the start of the step, mm */
    SC_ALIGN_HOT float v3[4u * SC_MAX_NODES];        /* unknown v+, mm/s (warm start: v) */
    SC_ALIGN_HOT float r3[4u * SC_MAX_NODES];        /* residual, N s */
    SC_ALIGN_HOT float z3[4u * SC_MAX_NODES];        /* preconditioned residual */
    SC_ALIGN_HOT float p3[4u * SC_MAX_NODES];        /* search direction */
    SC_ALIGN_HOT float q3[4u * SC_MAX_NODES];        /* A p */
    SC_ALIGN_HOT float inv_diag3[4u * SC_MAX_NODES]; /* Jacobi, 0 on Dirichlet DOFs */
    uint8_t constrained[SC_MAX_NODES];               /* this step: 1 fixed, 2 kinematic, 0 free,
                                                        0x80 | SC_MESH_ROLLER_* bits: rollers */
    uint8_t node_used[SC_MAX_NODES];                 /* node belongs to at least one tet */

    /* ---- per tet rest data (corotated re-assembly), in groups of SC_FEM_TET_LANES tets with
     * one float per tet in a row (tet e: [e / 4][k][e % 4]) so that the element work loads
     * 4 tets' values as one SIMD register ---- */
    /* Dm^-1, k = 3 row + column; rows: grad N1, grad N2, grad N3 (1/mm) */
    SC_ALIGN_HOT float tet_dmi[SC_FEM_TET_GROUPS][9][SC_FEM_TET_LANES];
    SC_ALIGN_HOT float tet_vol[SC_FEM_TET_GROUPS][1][SC_FEM_TET_LANES]; /* rest volume, mm^3 */
    SC_ALIGN_HOT uint32_t tet_blk[SC_MAX_TETS][6]; /* block of each vertex pair, see sc_fem.c */
} sc_fem;

/* Floor term (an extension: walls that meet do not pass through each other): a tet whose
 * volume V falls below V_f = floor_volume_ratio V0 gets the energy 1/2 K_f V0 ((V - V_f) / V0)^2
 * (K_f = floor_pa) on top of its elastic energy, with the Gauss-Newton stiffness
 * K_f / V0 grad V grad V^T; a collapsed lumen's tets flatten to V_f instead of turning inside
 * out (an inverted tet overlaps its neighbours, and the B-scan then shows the lumen again).
 * The same term runs in the implicit MSDS (sc_msds_implicit.h). While it is active the linear
 * model's matrix is re-assembled each step (O(T)). */

/* Defaults: beta 0.1 s (the MSDS damper ratio of Algorithm 1), alpha 0, linear (paper), floor
 * at 1% of the rest volume with 100 kPa. */
sc_fem_def sc_fem_default_def(void);

/* Check a definition: finite, non-negative damping, corotated 0 or 1. O(1).
 * Errors: SC_ERR_INVALID_ARG (NULL, corotated not 0/1), SC_ERR_NOT_FINITE, SC_ERR_RANGE. */
int sc_fem_def_validate(const sc_fem_def *def);

/* Build the fixed sparse pattern from the mesh's tets, the per-tet rest data, the lumped
 * masses and the rest stiffness K, with the material row of each tet's label (E, Poisson,
 * density; sc_material.h, the same table the MSDS uses). Call at case load (not at frame
 * time). The mesh (labels, fixed nodes) must stay unchanged while f is used with it.
 * Cost: O(T) plus O(N * 27) for the pattern, bounded by SC_MAX_TETS / SC_MAX_NODES. Never
 * allocates. Errors: SC_ERR_INVALID_ARG (NULL, mesh counts above the limits), the
 * definition's errors (sc_fem_def_validate), SC_ERR_CASE_MATERIAL (table invalid, see
 * sc_material_table_validate), SC_ERR_CASE_LABEL (a tet label without a table row),
 * SC_ERR_FEM_PATTERN (a tet edge not between grid neighbours, or more blocks than
 * SC_MAX_FEM_NNZ_BLOCKS), SC_ERR_MESH_ORIENTATION (a tet with non-positive rest volume). */
int sc_fem_init(sc_fem *f, const sc_mesh *m, const sc_material_table *mat, const sc_fem_def *def);

/* Advance the nodes by dt_s: reads n->x, n->v (warm start) and the external forces n->f*,
 * writes n->x and n->v. Fixed nodes keep their position with zero velocity. Runs exactly
 * cg_iterations CG iterations (fewer only if r.z is exactly 0 or p.Ap <= 0, e.g. no free
 * DOF).
 * Cost: linear: (cg_iterations + 1) block mat-vecs, O(B) each, plus O(N); corotated:
 * cg_iterations mat-vecs plus one O(T) re-assembly with a polar decomposition per tet
 * (at most 8 Newton iterations) that also yields r0.
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

/* A caller-supplied stiffness for sc_fem_step_custom (the stable MSDS, sc_msds_implicit.h):
 * assemble() receives the matrix zeroed and must add a symmetric positive semi-definite K(x)
 * of the positions f->x3 into f->blk in this pattern (diagonal block first in each row; a
 * tet's pairs through tet_blk, SC_FEM_BLK_TRANSPOSED marking a stored K_ba), and subtract
 * dt_s f_int(x) from r3 (4 floats per node, lane 3 untouched). Damping C = alpha M + beta K. */
typedef struct sc_fem_custom {
    void (*assemble)(void *ctx, sc_fem *f, float dt_s, float *r3);
    void *ctx;
    float beta_s;      /* stiffness-proportional damping, >= 0 */
    float alpha_per_s; /* mass-proportional damping, >= 0 */
} sc_fem_custom;

/* Vertex pair p of tet_blk[e][p]: (0,1) (0,2) (0,3) (1,2) (1,3) (2,3); the stored block is
 * (tet[a], tet[b]) if tet[a] < tet[b], else (tet[b], tet[a]) with this bit set. */
#define SC_FEM_BLK_TRANSPOSED 0x80000000u

/* sc_fem_step_kinematic with the stiffness, internal force and damping of cu instead of the
 * elastic element model (cu == NULL: the element model). The same backward Euler step, warm
 * start, Jacobi PCG with a fixed count and refusal of a non-finite solution; afterwards the
 * matrix no longer holds the rest K (the next linear FEM step re-assembles it, O(T)).
 * Cost: the caller's assembly plus (cg_iterations + 1) block mat-vecs. Never allocates. */
void sc_fem_step_custom(sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                        uint32_t cg_iterations, const uint8_t *kinematic, const sc_fem_custom *cu);

/* Switch corotation on or off at run time; takes effect in the next step (switching off
 * re-assembles the rest K there once, at the cost of a corotated step). O(1). */
void sc_fem_set_corotated(sc_fem *f, int on);

/* 0, or SC_ERR_PHYS_UNSTABLE once a step produced a non-finite solution. O(1). */
int sc_fem_status(const sc_fem *f);

/* The corotated step's rotation of one element, exposed for tests: R = the rotation of the
 * polar decomposition F = R S (row-major 3x3), by the same lane code the step runs. Returns
 * 1, or 0 with R = I when det F <= 1e-3 (flat or inverted: no proper rotation). O(1)
 * (at most 8 Newton iterations), never allocates. Precondition (SC_ASSERT): F, R non-NULL. */
int sc_fem_polar_rotation(const float F[9], float R[9]);

#endif /* SC_FEM_H */
