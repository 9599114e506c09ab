/*
 * sc_msds_implicit.h: the stable MSDS integrator (the default; the paper's explicit Euler of
 * sc_msds.h stays selectable as SC_MSDS_EXPLICIT so its tables can be reproduced).
 *
 * One linearly implicit backward Euler step per frame, of length iterations x dt (the
 * simulated time of the explicit frame), over the same springs and volume term as the
 * explicit MSDS (sc_msds.h: k, L0, k_vol, rest 6V), with the physical lumped masses:
 *   (M + dt C + dt^2 K(x)) v+ = M v + dt (f_ext - f_int(x)),   x+ = x + dt v+,
 *   C = beta K(x) + alpha M,  beta = Algorithm 1's gamma / k (0.1 s), alpha = drag_per_s,
 * solved by a fixed number of warm-started Jacobi-PCG iterations on the grid matrix the FEM
 * uses (sc_grid.h): the springs are exactly the tets' edges, so every spring is one of the
 * grid's stencil blocks.
 * K(x), per spring (d = x_j - x_i, L = |d|, u = d / L): k u u^T + k |1 - L0 / L| (I - u u^T).
 * A compressed spring's exact transverse stiffness k (1 - L0 / L) is negative (what lets an
 * explicit or a Newton step buckle); its absolute value keeps K positive semi-definite and
 * still gives a crushed node stiffness in the directions its springs push it. Dropping the
 * term instead (K's former form, max(0, 1 - L0 / L)) left a node squeezed between the probe
 * face's end and the fixed bottom with large spring forces and almost no stiffness against
 * them: one step threw it up to 59 mm sideways (a guard reset under a fast 35 degree tilt
 * at a 16 mm press; test_physics_robust). Only the matrix changed: the forces, and so the
 * rest and the pressed equilibria, are the same. Per tet of the volume term
 * (energy 1/2 k_vol (6V - 6V0)^2 / 36): k_vol / 36 g_a g_b^T, g = grad 6V (the Gauss-Newton
 * part; the (V - V0) Hess V part is left out for the same reason).
 * Why this integrator: backward Euler with a positive semi-definite K is unconditionally
 * stable (each step solves a symmetric positive definite system; a fixed-count CG from a warm
 * start only slows the relaxation, it cannot amplify it), so no mass scaling, no small step
 * and no stability bound are needed, and any press depth, probe speed or contact set gives a
 * bounded step. It reuses the FEM's grid (matrix, solver vectors, CG; the two methods never
 * run in the same frame), so it costs no memory of its own. Probe contacts are kinematic
 * (Dirichlet) nodes, exactly as for the FEM (sc_tissue.c); an unloaded frame starts from the
 * quasi-static step toward rest (sc_grid.h).
 *
 * Floor term (walls that meet do not pass through each other): a tet below floor_volume_ratio
 * of its rest volume gets 1/2 K_f V0 ((V - V_f) / V0)^2 (K_f = floor_pa) with its Gauss-Newton
 * stiffness, the same term as the FEM's (sc_fem.h): a collapsed vein flattens to the floor
 * instead of turning its tets inside out.
 *
 * Bounded steps on fine meshes: the floor term's deficit is clamped at the shortest cell
 * edge x |grad D| (a Gauss-Newton volume step moves a node by about deficit /
 * |grad D|: a sliver with tiny gradients threw one), and sc_grid_solve holds every free node's
 * step to two cell diagonals (the fixed-count CG's error in the soft, light lumen nodes when a
 * deep press is let go at once). docs/physics.md, "The finest meshes".
 *
 * Cost per frame: the springs, family by family (9 N with one sqrt and one divide each), and
 * the volume and floor terms cell by cell (5 tets, their 10 rank-1 blocks each), vectorised
 * (sc_grid_kern.inc), plus cg_iterations grid mat-vecs; K v0 of r0 is formed in the same
 * passes. Measured (bench-physics 100 stages, x86-64-v4, shared 2-core VM, minimum of 100
 * frames): 1.86 ms per tissue frame at 32x16x16 with 10 CG iterations: collision 0.25, step
 * start 0.07, assembly 0.68, CG 0.87 (the explicit MSDS: 3.7 ms).
 * Memory: none beyond sc_msds and sc_fem (the FEM's blocks are overwritten: the next linear
 * FEM step re-assembles its rest K once). Never allocates, never calls the OS; deterministic
 * (fixed loop orders and counts). Threads: one writer.
 */
#ifndef SC_MSDS_IMPLICIT_H
#define SC_MSDS_IMPLICIT_H

#include <stdint.h>

#include "sc_fem.h"
#include "sc_mesh.h"
#include "sc_msds.h"

/* One implicit step of length dt_s with cg_iterations CG iterations; nodes with
 * kinematic[i] != 0 move with their velocity and hold the others (kinematic may be NULL).
 * f must be initialised on the same mesh as s. Cannot fail by contract: a non-finite
 * solution leaves n unchanged and sets the FEM's sticky status (sc_fem_status).
 * Preconditions (SC_ASSERT): as sc_fem_step. */
void sc_msds_implicit_step(const sc_msds *s, sc_fem *f, const sc_mesh *m, sc_nodes *n, float dt_s,
                           uint32_t cg_iterations, const uint8_t *kinematic);

#endif /* SC_MSDS_IMPLICIT_H */
