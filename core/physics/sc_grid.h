/*
 * sc_grid.h: the stiffness matrix of the regular 5-tet grid (sc_mesh.h) stored by stencil
 * family, and the implicit step both solvers run on it: the FEM (sc_fem.h) and the stable MSDS
 * (sc_msds_implicit.h) assemble their K(x) and residual into one sc_grid, which then solves
 *   (M (1 + dt alpha) + (dt beta + dt^2) K) v+ = M v + dt (f_ext - f_int(x)),  x+ = x + dt v+
 * with a fixed number of warm-started Jacobi-preconditioned conjugate-gradient iterations.
 *
 * Why a grid matrix and not a general sparse one: the mesh is a regular grid, so every node has
 * the same neighbours at the same index offsets: +-1 (x), +-nx (y), +-nx ny (z) along the grid
 * edges, and, for the nodes of odd i + j + k only, the 12 face diagonals (sc_mesh.c: a face's
 * diagonal joins its two odd corners). The matrix is stored as float rows indexed by node (SoA),
 * one row per block entry and family, so every loop over it is a straight vector loop with no
 * index arrays and no gathers:
 *   d[6][.]     diagonal block of node t (symmetric: xx xy xz yy yz zz);
 *   e[a][9][.]  block K(t, t + o_a) of the grid edge along axis a (o = 1, nx, nx ny), row-major;
 *   f[w][9][.]  the face diagonal of the face with lowest corner t in plane w (w = 0: x-y,
 *               1: x-z, 2: y-z; d1 < d2 the offsets of its two axes): K(t, t + d1 + d2) if t is
 *               odd, K(t + d1, t + d2) if t is even (the diagonal that joins the odd corners).
 * A block that does not exist (past the grid's edge) is zero. That is 60 floats per node
 * against 6.5 blocks of 13 floats in a block-CSR (the former layout: 84 floats and an index per
 * block), and the mat-vec reads each stored block once from memory (the backward reuse of a
 * block hits the cache): measured 0.075 ms per mat-vec at 32x16x16 on x86-64-v4, a whole CG
 * iteration 0.09 ms against 0.11 ms with the former block-CSR.
 *
 * Layout: node t lives at index SC_GRID_HEAD + t of every row, so that a node's neighbours
 * t - nx ny - nx - 1 .. t + nx ny + nx + 1 are in the row for every node (zero past the mesh);
 * the row stride SC_GRID_ROW is an odd multiple of 16 floats, so that the 80-odd rows a loop
 * streams fall into different cache sets (with a stride that is a multiple of 4 KiB every row
 * maps to the same L1 set: measured 5x slower). Node loops run over SC_GRID_CHUNK-aligned
 * ranges (the padding lanes compute on zeros).
 *
 * Assembly by cell: a cell's five tets (SC_MSDS_CELL_TETS, an odd cell mirrored in x) give
 * the blocks of its 8 corners, 12 grid edges and 6 face diagonals; the cell kernels compute a
 * vector of cells in the template's (mirrored) frame, 9 values per template corner (6 diagonal
 * entries, 3 residual) and per template edge slot, pick per cell the value of its parity
 * (transposed where the mirror reverses the edge) and add it straight to its real target's row
 * (26 targets x 9 rows). A node's sums are formed in the order of the cells that add into it,
 * lowest first, within a vector as across vectors (write_cell's target order), so the result
 * does not depend on the vector width: every instruction-set variant of sc_grid_kern.inc gives
 * the same bits. (A block buffer, added target by target after each 16 cells, cost a store and
 * a load per value: 0.73 against 0.53 ms for the 32x16x16 MSDS cells.)
 *
 * The step (sc_grid_begin, the caller's assembly, sc_grid_solve):
 * - Dirichlet DOFs: fixed nodes (mesh node_fixed 1, nodes of no tet), the held axes of roller
 *   nodes and the caller's kinematic nodes (moved with their current velocity); the
 *   preconditioner is zero there, which projects the CG onto the free DOFs.
 * - Warm start: v0 = v beta / (beta + dt), the exact one-step decay of an over-damped,
 *   stiffness-damped mode (sc_fem.h). Unloaded (no kinematic node and no external force:
 *   the probe is off the skin), the equilibrium is the rest state and the warm start is the
 *   quasi-static answer toward it, v0 = -(x - X) / (beta + dt) (exact for the linear model when
 *   the masses are negligible, as they are: m << dt^2 k): the fixed-count CG starts from the
 *   release's solution instead of having to find it, so a released tissue is back at rest in a
 *   few frames on every mesh (with the plain warm start the 32x16x16 mesh took 2 s).
 * - r0 = b - A v0 is formed by the caller's assembly (element-wise: no extra mat-vec).
 * - A non-finite solution is refused: the node state is left unchanged and the step fails.
 *
 * Memory (R = SC_GRID_ROW floats, ~SC_MAX_NODES + 2 (nx ny + nx) + 48): matrix 60 rows, mass,
 * positions and rest 6, solver vectors v r z p q and the preconditioner 18, masks 2 (int32),
 * flags: 87 rows of 4 B and 1 B: 3.4 MB at 32x16x16 (sizeof(sc_fem) printed by bench-fem).
 * Builds with the rest copy add it (60 rows) and the pair copies (SC_GRID_PAIRS: 57 rows of
 * SC_GRID_PROW floats, 2.8 MB). Never allocates, never calls the OS. Deterministic.
 * Threads: one writer.
 */
#ifndef SC_GRID_H
#define SC_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_pool.h"
#include "sc_mesh.h"

/* node loops run over multiples of this many nodes (the widest vector of any variant) */
#define SC_GRID_CHUNK 16u
/* leading and trailing padding of every row: the farthest neighbour offset, nx ny + nx + 1,
 * rounded up to a chunk. That is enough: a node loop's vector at t (t + GW - 1 < node_end)
 * reads t - (nx ny + nx) .. t + GW - 1 + nx ny + nx + 1, a cell block's at n0
 * (n0 + GCB - 1 < cell_end <= node_count - (nx ny + nx + 1) + GCB - 1) reads up to
 * n0 + GCB - 1 + nx ny + nx + 1 < node_end + GCB (asserted by sc_grid_init). */
#define SC_GRID_PAD                                                                                \
    (((SC_MAX_MESH_NX * SC_MAX_MESH_NY + SC_MAX_MESH_NX + 1u + SC_GRID_CHUNK - 1u) /               \
      SC_GRID_CHUNK) *                                                                             \
     SC_GRID_CHUNK)
#define SC_GRID_HEAD SC_GRID_PAD
/* row stride: the smallest odd multiple of 16 floats that holds head, nodes and tail (see
 * above; the node offsets and the lanes of every sum are counted from SC_GRID_HEAD, so neither
 * the padding nor the stride changes a result) */
#define SC_GRID_ROW                                                                                \
    ((((SC_GRID_HEAD + SC_MAX_NODES + SC_GRID_PAD + 15u) / 16u) | 1u) * 16u)
_Static_assert(SC_MAX_NODES % SC_GRID_CHUNK == 0u, "node capacity a multiple of the chunk");
_Static_assert((SC_GRID_ROW / 16u) % 2u == 1u, "row stride an odd multiple of 16 floats");

/* The CG on the worker pool (hal/sc_hal_pool.h): element-wise loops and the mat-vec run over
 * ranges of SC_GRID_POOL_RANGE nodes, the dot products over blocks of SC_GRID_SUM_BLOCK nodes
 * whose partial sums are added in block order: both sizes are part of what makes a state hash
 * (a mesh of one sum block, up to 8192 nodes, sums exactly as one serial loop), the number of
 * workers is not. */
#define SC_GRID_POOL_RANGE 1024u
#define SC_GRID_SUM_BLOCK 8192u
/* A mesh of more than SC_GRID_SUM_BLOCK nodes cuts its node loops into a multiple of four
 * ranges of about SC_GRID_POOL_RANGE nodes (sc_grid.range, chosen by the mesh alone), so that
 * two or four workers take as many ranges each (48x24x24: 28 ranges of 992 nodes, where 27 of
 * 1,024 left one worker a range idle at every job's end; 64x32x32 keeps 64 of 1,024), and sums
 * its dot products over blocks of one range (sc_grid.sum_block = range): two workers share
 * the blocks evenly (with 8,192-node blocks a 48x24x24 mesh had four, the last 3,072 nodes: 3.4
 * blocks of work over two workers took the time of 2) and the p.Ap partials are formed in the
 * mat-vec's own job. */
#define SC_GRID_RANGES_MAX ((SC_MAX_NODES + SC_GRID_POOL_RANGE - 1u) / SC_GRID_POOL_RANGE + 3u)
#define SC_GRID_SUM_BLOCKS SC_GRID_RANGES_MAX
_Static_assert(SC_GRID_POOL_RANGE % SC_GRID_CHUNK == 0u && SC_GRID_SUM_BLOCK % 16u == 0u,
               "pool ranges and sum blocks are whole chunks and whole partial-sum groups");

/* The linear FEM's rest K kept aside (sc_grid_save_rest, sc_grid_load_rest), in every build whose
 * node capacity is above SC_GRID_REST_COPY_CAP (the appliance's and the host's; the MCU's limits
 * leave the copy out and re-assemble), for meshes of more than SC_GRID_REST_COPY_NODES nodes.
 * The linear model's matrix is the rest K but for the floor term of the tets below their floor
 * volume (a firm press that collapses a vein crushes 10^4 of a 64x32x32 mesh's tets). A step with
 * the floor met re-assembled every cell: at 64x32x32 with two workers the linear FEM's step took
 * 14.3 ms against 9.2 without (p50, the real loop pressing 8 mm and sweeping); at 32x16x16 on one
 * core the whole frame pressed 8 mm took 5.7-5.8 ms against 4.4-4.5 ms from the copy (min,
 * bench_bscan contact, a loaded machine). Such a step starts from the kept copy and adds the
 * floor's blocks and residual of the cell blocks that hold a tet below the floor
 * (sc_grid_fem_in.floor_only); the rest K's part of the residual is one mat-vec, as in a step
 * without the floor. The sums differ from the whole re-assembly's (the floor added after the
 * rest K, not inside each cell's sum: positions within 1.3e-5 mm, test_sc_pool), the same for
 * every worker count. */
#ifndef SC_GRID_REST_COPY_NODES
#define SC_GRID_REST_COPY_NODES 0u
#endif
#define SC_GRID_REST_COPY_CAP 16384u
#define SC_GRID_REST_COPY (SC_MAX_NODES > SC_GRID_REST_COPY_CAP)
/* The two-grid correction of the step's warm start (sc_grid_coarse below), in every build with
 * the rest copy (the MCU's SRAM holds no second grid), on meshes of more than
 * SC_GRID_COARSE_NODES nodes (48x24x24, 64x32x32: up to 32x16x16 the steps keep their bits).
 * Why: the Jacobi-preconditioned CG moves a correction about one node per iteration, so a
 * fixed count that settles a 32x16x16 press leaves a 64x32x32 one far from it (16 mm: the vein
 * at 0.140 of its area with 10 iterations, 0.010 with 30; docs/physics.md). The smooth part of
 * the error is what a grid of half the resolution solves well. */
#define SC_GRID_COARSE SC_GRID_REST_COPY
#ifndef SC_GRID_COARSE_NODES
#define SC_GRID_COARSE_NODES 8192u
#endif
#ifndef SC_GRID_COARSE_ITERATIONS
#define SC_GRID_COARSE_ITERATIONS 20u
#endif
/* The software prefetches of the mat-vec, the springs and the cell passes (sc_grid_kern.inc) run
 * only on meshes of more than this many nodes (sc_grid.prefetch, by the mesh alone; a hint changes
 * no result). On the x86-64-v4 EPYC of the earlier sessions they were worth 2x on the 64x32x32
 * mat-vec and 1.35x at 48x24x24, and nothing at 32x16x16. On the family 25 model 1 EPYC
 * (512 KiB L2) of the 25 Nov sessions they cost the L3-resident meshes issue slots: a 32x16x16
 * mat-vec took 0.112 ms with them and 0.098 ms without, and the stable MSDS frame 2.62-2.67 ms
 * against 2.45-2.48 ms (`bench-physics 100 stages`, alternated). 48x24x24 there: 0.42 against
 * 0.38 ms. 64x32x32 still needs them: 1.17-1.23 ms against 1.55-2.12 ms. The mat-vec's are the
 * CPU's choice above this rule (sc_simd.h, sc_simd_select_prefetch: on an Intel Xeon with 2 MiB
 * of L2 the 64x32x32 product took 0.85 ms with them and 0.66 ms without); the assembly's follow
 * this rule alone. */
#ifndef SC_GRID_PREFETCH_NODES
#define SC_GRID_PREFETCH_NODES 8192u
#endif
/* The stable MSDS's springs in one pass over the nodes (sc_grid_kern.inc, springs_range: each
 * spring evaluated at both its ends, no scratch rows) on meshes of more than this many nodes, per
 * family in two passes through scratch rows on the others: the same bits either way, a speed
 * choice by the mesh alone. The one pass reads and writes about a sixth of the rows and does
 * 2.3x the spring arithmetic: `bench-physics 20 stages 64x32x32`, one worker, springs 4.47 ->
 * 3.98 ms; `bench-physics 100 stages 32x16x16` 0.33-0.34 -> 0.43 ms (the rows stay in cache
 * there, the arithmetic shows). On these meshes the springs also run range by range with the
 * cells' volume terms (msds_assemble): the cells add into rows still in the
 * core's cache instead of reading the whole matrix back (same bits). */
#ifndef SC_GRID_SPRINGS_FUSED_NODES
#define SC_GRID_SPRINGS_FUSED_NODES 8192u
#endif
#define SC_GRID_MAT_ROWS 60u /* d 6, e 27, f 27: row k of the matrix at &d[0][0] + k ROW */
/* The mat-vec's face sums by node pairs (sc_grid_kern.inc, face_pairs): a face diagonal joins two
 * odd nodes (i + j + k odd), so the face passes over whole vectors of nodes did half their work
 * for even lanes they then dropped. Nodes 2m and 2m + 1 (a pair: on one grid row when nx is even,
 * one odd node and one even one) give the pair copies below: the face rows of each pair's odd
 * node (its main diagonals) and of its even node (its anti diagonals), and p at its odd node.
 * A vector of pairs is then a vector of odd nodes, every lane used, each with the same products
 * in the same order as before: the same bits. The face rows are copied once per CG (and per lone
 * mat-vec), p as the CG forms it. Meshes of up to SC_GRID_PAIRS_NODES nodes, whose matrix the
 * caches hold, with whole vectors of pairs in a row (nx a multiple of twice the kernel's vector
 * width): `bench-physics 300 cg 32x16x16`, CG of 10 iterations 0.88-0.92 -> 0.82-0.84 ms. On
 * the larger meshes the product waits on memory, where the copy's bytes cost more than the
 * lanes save (64x32x32, one thread: 9.9 -> 10.4-11.1 ms). Builds with the rest copy only (the
 * MCU's SRAM holds no 27 more rows). */
#define SC_GRID_PAIRS       SC_GRID_REST_COPY
#define SC_GRID_PAIRS_NODES 8192u
/* pair m at SC_GRID_PHEAD + m: the farthest neighbour pair of a mesh of at most
 * SC_GRID_PAIRS_NODES nodes (nz >= 2) is within (nx ny + nx + 1) / 2 + 1 <= 4096 pairs */
#define SC_GRID_PHEAD (SC_GRID_PAIRS_NODES / 2u)
#define SC_GRID_PROW  ((((3u * SC_GRID_PHEAD + 15u) / 16u) | 1u) * 16u)

/* The cell passes (FEM assembly, the MSDS's volume terms) on the worker pool: the cell origins
 * are cut into ranges of SC_GRID_ASM_SPAN origins (whole cell blocks); the even ranges run first
 * (at the same time: two ranges apart, their corner sets do not meet, since SC_GRID_ASM_SPAN > nx
 * ny + nx + SC_GRID_CELL_BLOCK), then the odd ones. A node on the seam after an odd range takes the
 * next (even) range's sums before the odd one's, so that order is part of what makes a state hash,
 * the number of workers is not; a mesh of one range (cell origins up to SC_GRID_ASM_SPAN: up to
 * 32x16x16) sums exactly as the serial loop did. */
#define SC_GRID_ASM_SPAN 8192u
/* A mesh of more than two such ranges (more than 16,384 cell origins: 48x24x24, 64x32x32) is cut
 * into ranges of sc_grid.asm_span origins instead, chosen by the mesh alone: the smallest whole
 * number of cell blocks above nx ny + nx + SC_GRID_CELL_BLOCK (the two-apart rule above), at
 * least SC_GRID_ASM_SPAN_MIN: about one z-plane of cells per range (four of 8,192 before: the
 * odd phase ran one full range beside a quarter one); then the count of ranges is taken down to
 * a multiple of four and the span widened to match (whole cell blocks), so that each phase has
 * an even number of ranges for two workers: 20 ranges of 1,328 origins at 48x24x24 (22 of
 * 1,216 before, 11 per phase), 28 of 2,272 at 64x32x32 (30 before), 16 at 40x16x28. */
#define SC_GRID_ASM_SPAN_MIN 1024u
#define SC_GRID_ASM_RANGES ((SC_MAX_NODES + SC_GRID_ASM_SPAN_MIN - 1u) / SC_GRID_ASM_SPAN_MIN)

/* cells per assembly block (a multiple of every variant's vector width): the unit of the
 * ranges, the write prefetch and the floor-only pass's skip; the sums do not depend on it */
#define SC_GRID_CELL_BLOCK 16u
/* assembly targets of a cell: 8 corners, 12 grid edges, 6 face diagonals */
#define SC_GRID_TARGETS 26u
_Static_assert(SC_GRID_ASM_SPAN % SC_GRID_CELL_BLOCK == 0u &&
                   SC_GRID_ASM_SPAN > SC_MAX_MESH_NX * SC_MAX_MESH_NY + SC_MAX_MESH_NX +
                                          SC_GRID_CELL_BLOCK,
               "assembly ranges are whole cell blocks, and two ranges apart write apart");

/* what a target of a cell is, where it lives and where its block comes from (sc_grid_init) */
typedef struct sc_grid_target {
    uint8_t kind;     /* 0: corner (d and r), 1: grid edge (e[axis]), 2: face diagonal (f[plane]) */
    uint8_t axis;     /* axis (kind 1) or plane (kind 2) */
    uint8_t corner;   /* corner (kind 0), else the corner whose node the block is stored at */
    uint8_t src[2];   /* template slot per cell parity: corner 0..7 or edge slot 0..17 */
    uint8_t tr[2];    /* 1: the template block is the transpose of the stored one */
} sc_grid_target;

/* the template's edge slots: corner pairs (a < b) of the even template's tets */
typedef struct sc_grid_slot {
    uint8_t a, b;
} sc_grid_slot;

/* Diagnostics of the last step. */
typedef struct sc_grid_stats {
    uint32_t cg_iterations_run; /* <= requested (early only on r.z = 0 or p.Ap <= 0); the
                                   two-grid correction counts as one */
    float residual_ratio;       /* sqrt(r.z) after / before the CG of the last step */
    uint32_t unloaded_steps;    /* steps that started from the release warm start */
    uint32_t unstable_steps;    /* steps refused because the solution was not finite */
    uint32_t clamped_nodes;     /* free nodes whose step was cut to step_max_mm, last step */
    uint32_t clamped_steps;     /* steps with such a node since sc_grid_init */
} sc_grid_stats;

typedef struct sc_grid {
    /* ---- layout (sc_grid_init) ---- */
    uint32_t nx, ny, nz, nxy;
    uint32_t node_count;
    uint32_t node_end;  /* node_count rounded up to SC_GRID_CHUNK */
    uint32_t cell_end;  /* cell origins 0 .. cell_end - 1 are visited (rounded up to a block) */
    uint32_t asm_span;  /* cell origins per range of the cell passes (SC_GRID_ASM_SPAN above) */
    uint32_t sum_block; /* nodes per block of the CG's dot products (SC_GRID_SUM_BLOCK above) */
    uint32_t range;     /* nodes per range of the node loops and the CG (SC_GRID_POOL_RANGE) */
    uint8_t rest_saved; /* 1: rest[] holds a rest K (sc_grid_save_rest; 0 after sc_grid_init) */
    uint8_t prefetch;   /* 1: the kernels prefetch (node_count > SC_GRID_PREFETCH_NODES) */
    uint8_t springs_fused; /* 1: the MSDS's springs in one pass (node_count >
                              SC_GRID_SPRINGS_FUSED_NODES; either value gives the same bits) */
    uint8_t face_pairs;   /* 1: the mat-vec takes the face sums by pair where it can (SC_GRID_PAIRS:
                             node_count <= SC_GRID_PAIRS_NODES); 0 (a test's): the whole-vector
                             passes. Either gives the same bits; set it to 0 only. */
    uint8_t rest_patched; /* 1: the matrix is the rest K but for a floor_only pass's additions in
                             the cell ranges marked in floor_dirty (0 after sc_grid_clear) */
    uint8_t floor_dirty[SC_GRID_ASM_RANGES];
    uint32_t below_n[SC_GRID_ASM_RANGES]; /* tets below the floor per cell range, as the last
                                             fem_below counted them */
    float step_max_mm;  /* the most a free node moves in one step: two cell diagonals */
    uint32_t off[8];    /* node offset of cell corner c (bit 0 +x, bit 1 +y, bit 2 +z) */
    sc_grid_slot slot[18];
    int8_t slot_of[8][8]; /* edge slot of a template corner pair, -1 if none */
    /* the template's tets at each corner (tet, vertex; 1 or 4 of them) and at each edge slot
     * (tet, vertex of slot.a, vertex of slot.b; 1 or 3), for the cell kernels' sums */
    uint8_t corner_n[8];
    uint8_t corner_tv[8][4][2];
    uint8_t slot_n[18];
    uint8_t slot_tv[18][3][3];
    sc_grid_target target[SC_GRID_TARGETS];
    sc_grid_stats stats;
    /* 1: the nodes' external forces of the next step are internal loads that vanish at rest
     * (lumen pressures, sc_lumen.h): they do not keep the release warm start off (the owner
     * sets it before sc_grid_begin; 0 after sc_grid_init) */
    uint8_t forces_vanish_at_rest;
    const sc_pool_dev *pool; /* workers of the CG and the assembly (NULL: serial); sc_grid_init
                              * sets NULL */
#if SC_GRID_COARSE
    struct sc_grid_coarse *coarse; /* the two-grid correction (NULL: none; sc_grid_init sets NULL,
                                      the owner builds it: sc_fem_init) */
#endif

    /* ---- hot: matrix rows (node t at SC_GRID_HEAD + t) ---- */
    SC_ALIGN_HOT float d[6][SC_GRID_ROW];
    SC_ALIGN_HOT float e[3][9][SC_GRID_ROW];
    SC_ALIGN_HOT float f[3][9][SC_GRID_ROW];
    SC_ALIGN_HOT float mass[SC_GRID_ROW]; /* lumped mass, N s^2 / mm (the owner fills it) */
    /* ---- hot: positions at the start of the step, rest positions, solver vectors (SoA) ---- */
    SC_ALIGN_HOT float x[3][SC_GRID_ROW];  /* mm */
    SC_ALIGN_HOT float x0[3][SC_GRID_ROW]; /* rest, mm */
    SC_ALIGN_HOT float v[3][SC_GRID_ROW];  /* unknown v+ (warm start v0), mm/s */
    SC_ALIGN_HOT float r[3][SC_GRID_ROW];  /* residual, N s */
    SC_ALIGN_HOT float z[3][SC_GRID_ROW];  /* preconditioned residual */
    SC_ALIGN_HOT float p[3][SC_GRID_ROW];  /* search direction */
    SC_ALIGN_HOT float q[3][SC_GRID_ROW];  /* A p */
    SC_ALIGN_HOT float pc[3][SC_GRID_ROW]; /* Jacobi, 0 on Dirichlet DOFs and padding */
    SC_ALIGN_HOT int32_t odd[SC_GRID_ROW];     /* -1: node of odd i + j + k (face diagonals) */
    SC_ALIGN_HOT int32_t cell_odd[SC_GRID_ROW]; /* -1: the cell at this origin is odd (mirrored) */
    SC_ALIGN_HOT int32_t cell_ok[SC_GRID_ROW];  /* -1: a cell has this origin */
    uint8_t con[SC_GRID_ROW]; /* this step: 1 fixed, 2 kinematic, 0 free, 0x80 | roller bits */
    uint8_t used[SC_MAX_NODES]; /* node belongs to at least one tet */
#if SC_GRID_PAIRS
    /* ---- the face rows and p by node pair (pair m at SC_GRID_PHEAD + m; SC_GRID_PAIRS) ---- */
    SC_ALIGN_HOT float fpair[3][9][2][SC_GRID_PROW]; /* [..][0]: the odd node's, [1]: the even's */
    SC_ALIGN_HOT float ppair[3][SC_GRID_PROW];       /* p at the pair's odd node */
#endif
#if SC_GRID_REST_COPY
    /* ---- the linear FEM's rest K, rows as d, e, f (above) ---- */
    SC_ALIGN_HOT float rest[SC_GRID_MAT_ROWS][SC_GRID_ROW];
#endif
} sc_grid;
_Static_assert(offsetof(sc_grid, e) == offsetof(sc_grid, d) + 6u * SC_GRID_ROW * sizeof(float) &&
                   offsetof(sc_grid, f) == offsetof(sc_grid, e) + 27u * SC_GRID_ROW * sizeof(float),
               "the matrix rows d, e, f follow each other: row k at &d[0][0] + k SC_GRID_ROW");

#if SC_GRID_COARSE
/* The coarse grid of the two-grid correction: every other node of the fine grid along each axis
 * (coarse node (a, b, c) at fine node (2a, 2b, 2c); a fine axis of n nodes gives (n + 1) / 2, the
 * last fine node of an even n outside it), cells twice the size, holding the linear FEM's rest K
 * of the fine materials averaged over each coarse cell and the fine masses restricted (the
 * owner builds it, sc_fem.c). Each step of the fine grid then, before its CG (sc_grid_solve):
 *   r_c = P^T r (free DOFs),  iterations coarse PCG iterations on A_c e_c = r_c from e_c = 0,
 *   v += P e_c,  r -= A P e_c (one fine mat-vec)
 * with P the trilinear interpolation (a fine node past the last coarse one takes its value) and
 * A_c = cm M_c + ck K_c with the step's cm and ck; the coarse DOFs held are those of their fine
 * nodes. The fine CG then starts from the corrected v: a warm start whose smooth error the
 * coarse grid has removed (a fine residual of zero gives a correction of zero: the fine step's
 * answer is still its own). Every loop is node-wise or the coarse grid's own CG, whose ranges
 * and sum blocks are split as a large mesh's whatever its size (sc_grid_coarse_init: so that
 * its dot products and updates run on the pool, not on the caller): the same bits for every
 * worker count. */
typedef struct sc_grid_coarse {
    uint32_t iterations; /* coarse CG iterations per step */
    float alpha;         /* the last step's scale of the correction (1: the coarse K's own) */
    sc_grid grid;        /* coarse matrix, masses, solver vectors */
    SC_ALIGN_HOT float lamv[5][SC_GRID_ROW]; /* lambda V, mu V per coarse cell (sc_grid_fem_in) */
    SC_ALIGN_HOT float muv[5][SC_GRID_ROW];
} sc_grid_coarse;

/* The layout of a full box grid of nx x ny x nz nodes (every cell present, every node used) at
 * origin_mm with cells of cell_mm: sc_grid_init without a mesh, for the coarse grid. Errors:
 * SC_ERR_INVALID_ARG (NULL, counts outside 2..limits). */
int sc_grid_init_box(sc_grid *g, uint32_t nx, uint32_t ny, uint32_t nz, const float origin_mm[3],
                     const float cell_mm[3]);

/* The coarse grid's layout for fine grid g (its nodes per axis (n + 1) / 2, cells twice g's,
 * cell_mm the fine cells') and its masses restricted from g's (g's masses filled). */
int sc_grid_coarse_init(sc_grid_coarse *c, const sc_grid *g, const float cell_mm[3]);
#endif

/* The FEM's element data for the cell kernel (sc_fem.c fills it at init). Tet q of the cell with
 * lowest node t (template order, SC_MESH_CELL_TETS) has lambda V and mu V at
 * lamv[q * SC_GRID_ROW + SC_GRID_HEAD + t] (0 where no cell is); its rest shape gradients and
 * volume are those of the template (every cell of the grid is the same box, an odd one
 * mirrored in x), per cell parity. */
typedef struct sc_grid_fem_in {
    const float *lamv;            /* [5][SC_GRID_ROW], N mm (N/mm^2 x mm^3) */
    const float *muv;             /* [5][SC_GRID_ROW] */
    float grad[2][5][4][3];       /* rest grad N_a of template corner a of tet q, 1/mm */
    float vol_mm3[5];             /* rest volume of tet q */
    float sign[2][5];             /* sign of the template order's 6V (the floor's volume) */
    float floor_ratio;            /* a tet below this fraction of its rest volume meets the
                                     floor term; 0: off */
    float floor_nmm2;             /* the floor's modulus, N/mm^2 */
    float floor_step_mm;          /* the most the floor's linearised step moves a node: its
                                     deficit is clamped at floor_step_mm |grad V| (> 0) */
    int corotated;                /* 1: R = polar(F); 0: R = I (linear) */
    int floor_only;               /* 1: the floor term alone (lambda = mu = 0), and only the cell
                                     blocks that hold a tet below it, in the cell ranges where the
                                     last fem_below counted one (sc_grid_save_rest) */
} sc_grid_fem_in;

/* The cell passes' range (sc_grid.asm_span) for a grid of nx x ny x nz nodes (each at least 2,
 * the node count within SC_MAX_NODES): SC_GRID_ASM_SPAN up to two such ranges, else whole cell
 * blocks, more than nx ny + nx + SC_GRID_CELL_BLOCK origins (two ranges apart write apart), at
 * most SC_GRID_ASM_RANGES ranges (test_sc_grid_split checks every mesh within the limits). */
uint32_t sc_grid_asm_span(uint32_t nx, uint32_t ny, uint32_t nz);

/* Layout for the mesh (which must be sc_mesh_build's regular grid: checked against its tets),
 * rest positions, masks; matrix, masses and vectors zero. O(N + tets). Never allocates.
 * Errors: SC_ERR_INVALID_ARG (NULL, counts above the limits or not the grid of sc_mesh_build). */
int sc_grid_init(sc_grid *g, const sc_mesh *m);

/* Start a step of length dt_s: the Dirichlet flags (kinematic may be NULL), positions, the
 * warm start v0 (above) and r = dt f_ext - dt alpha M v0; the matrix is left as it is. The
 * caller then sets the matrix to K(x) (sc_grid_clear and an assembly that adds, or a matrix
 * kept from an earlier step) and subtracts dt f_int(x) + (dt beta + dt^2) K(x) v0 from r.
 * O(N). Preconditions (SC_ASSERT): g initialised with m; dt_s > 0, beta, alpha >= 0, finite. */
void sc_grid_begin(sc_grid *g, const sc_mesh *m, const sc_nodes *n, float dt_s, float beta_s,
                   float alpha_per_s, const uint8_t *kinematic);

/* Keep the matrix (the linear FEM's rest K) aside, on a mesh of more than SC_GRID_REST_COPY_NODES
 * nodes (above); returns 1 if kept, 0 if the mesh keeps none. On the pool. */
int sc_grid_save_rest(sc_grid *g);

/* The matrix back to the kept rest K (bit for bit): only the nodes the last floor_only pass's
 * cell ranges reach when that pass was the only change (rest_patched), else every row; returns
 * 0 if none is kept. */
int sc_grid_load_rest(sc_grid *g);

/* Zero the diagonal blocks (SC_GRID_CLEAR_DIAG) and/or the edge and face blocks
 * (SC_GRID_CLEAR_BLOCKS). O(N). */
#define SC_GRID_CLEAR_DIAG   1u
#define SC_GRID_CLEAR_BLOCKS 2u
void sc_grid_clear(sc_grid *g, uint32_t which);

/* Finish the step begun with the same dt, beta and alpha: the preconditioner, cg_iterations
 * PCG iterations (fewer only if r.z is exactly 0 or p.Ap <= 0; with the two-grid correction,
 * sc_grid.coarse, the correction and cg_iterations - 1 of them, at least 1: the same count of
 * fine mat-vecs; stats.cg_iterations_run counts the correction as one), and n->x, n->v from the
 * solution; fixed DOFs keep their position with zero velocity. A free node's step is held to
 * step_max_mm (its free velocity components scaled together; counted in stats.clamped_nodes
 * and clamped_steps): the truncated CG's error, not motion. A non-finite solution leaves n
 * unchanged, counts stats.unstable_steps and returns SC_ERR_PHYS_UNSTABLE; else 0.
 * Cost: cg_iterations mat-vecs, O(N) each (bounded by SC_MAX_NODES), plus O(N).
 * Preconditions (SC_ASSERT): 1 <= cg_iterations <= SC_PHYS_ITERATIONS_MAX. */
int sc_grid_solve(sc_grid *g, sc_nodes *n, float dt_s, float beta_s, float alpha_per_s,
                  uint32_t cg_iterations);

/* The 3x3 block K(i, j) (row-major) of the assembled matrix: the diagonal block (i == j), a grid
 * edge or face diagonal between i and j in either order, else zeros (returns 0; 1 if the
 * pair is a stored block). For tests and tools. O(1). */
int sc_grid_block(const sc_grid *g, uint32_t i, uint32_t j, float out[9]);

/* f += sum over the nodes j of node i's 3x3x3 neighbourhood, in z, y, x order, of K(i, j)
 * (x_j - x0_j) (the probe's force per contact node, sc_tissue.h): sc_grid_block's blocks, each
 * found from its offset without dividing a node index. ci: i's grid coordinates; x, x0: current
 * and rest positions by axis. O(1). */
void sc_grid_row_disp(const sc_grid *g, uint32_t i, const uint32_t ci[3], const float *const x[3],
                      const float *const x0[3], float f[3]);

/* q = A p over node-interleaved double vectors (3 per node) with the current matrix, A = cm M +
 * ck K: the tests' oracle of the kernels' mat-vec. O(N). */
void sc_grid_apply_ref(const sc_grid *g, float cm, float ck, const double *p, double *q);

#endif /* SC_GRID_H */
