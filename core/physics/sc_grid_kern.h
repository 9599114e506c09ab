/*
 * sc_grid_kern.h: the implicit solvers' hot loops (internal to sc_grid.c, sc_fem.c and
 * sc_msds_implicit.c). One C source, sc_grid_kern.inc, compiled per instruction-set variant
 * (sc_simd.h: generic with 4-float vectors, x86-64-v3 and -v4 with 8) with bit-identical
 * results; sc_grid_kern_selected() returns the selected variant's table.
 */
#ifndef SC_GRID_KERN_H
#define SC_GRID_KERN_H

#include <stdint.h>

#include "sc_grid.h"
#include "sc_msds.h"

/* The CG's start and end: r.z before and after, iterations run. */
typedef struct sc_grid_cg_out {
    uint32_t iterations;
    float rz0, rz;
} sc_grid_cg_out;

typedef struct sc_grid_kern {
    /* p from r; cg_iterations PCG iterations on v, r (A = cm M + ck K); z is not stored. */
    void (*cg)(sc_grid *g, float cm, float ck, uint32_t iterations, sc_grid_cg_out *out);
    /* q = (cm M + ck K) p (the CG's mat-vec, exposed for tests and benchmarks). */
    void (*matvec)(sc_grid *g, float cm, float ck);
    /* FEM element blocks and r -= dt f_int(x) + ck K v0, added to g (blocks zeroed by
     * sc_grid_begin); returns the tets with det F <= 1e-3 (corotated: R = I there). */
    uint32_t (*fem_cells)(sc_grid *g, const sc_grid_fem_in *in, float dt, float ck);
    /* The existing tets below the floor volume (sc_grid_fem_in.floor_ratio; 0 if off). */
    uint32_t (*fem_below)(sc_grid *g, const sc_grid_fem_in *in);
    /* The MSDS springs: every edge and face block written, the diagonal and r added. */
    void (*msds_springs)(sc_grid *g, const sc_msds *s, float dt, float ck);
    /* The MSDS volume and floor terms, added. */
    void (*msds_cells)(sc_grid *g, const sc_msds *s, float dt, float ck);
    /* The stable MSDS's step matrix: msds_springs, then msds_cells if cells != 0, with the same
     * bits; on the large meshes (sc_grid.springs_fused) in one pass, range by range. */
    void (*msds_assemble)(sc_grid *g, const sc_msds *s, float dt, float ck, int cells);
    /* The polar rotation of one element by the kernels' lane code (tests): 1, or 0 with
     * R = I when det F <= 1e-3. */
    int (*polar)(const float F[9], float R[9]);
} sc_grid_kern;

const sc_grid_kern *sc_grid_kern_selected(void);

/* the variants (sc_grid_kern.inc) */
extern const sc_grid_kern sc_grid_kern_generic;
#if defined(SC_SIMD_X86_64_V3_BUILT)
extern const sc_grid_kern sc_grid_kern_x86_64_v3;
#endif
#if defined(SC_SIMD_X86_64_V4_BUILT)
extern const sc_grid_kern sc_grid_kern_x86_64_v4;
#endif

/* det F at or below this: the element is flat or inverted; polar factor undefined: R = I */
#define SC_GRID_DET_MIN 1.0e-3f
/* Newton iterations of the polar decomposition at most (scaled Newton, quadratic: a stretch
 * of 3:1 converges to float precision in about 6) */
#define SC_GRID_POLAR_MAX_ITER 8u

#endif /* SC_GRID_KERN_H */
