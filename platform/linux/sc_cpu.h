/*
 * sc_cpu.h: the host CPU's kernel variant (core/physics/sc_simd.h) for host programs.
 *
 * The core never probes the CPU; a host program (sonocomp, sc-hostsim, the benchmarks, the
 * tests that want the fast path) calls sc_cpu_select_simd() once at start. On x86-64 it
 * asks the CPU through the compiler's __builtin_cpu_supports (cpuid and, for AVX, the OS's
 * XSAVE state via xgetbv), elsewhere it keeps the portable variant.
 * SONOCOMP_SIMD=generic (or a lower x86-64 level) in the environment forces that variant (to
 * compare, or to rule the vector code out when hunting a fault).
 *
 * The grid mat-vec's software prefetch (sc_simd.h) is chosen the same way, once at start, by
 * measuring it: sc_cpu_select_prefetch times the selected variant's mat-vec on a box grid of
 * the largest mesh the build takes (at most 64x32x32, its matrix rows filled with a stiffness
 * pattern) with and without the prefetch, alternated, and turns it off when that is faster
 * by more than SC_CPU_PREFETCH_MARGIN; else the mesh decides, as before (a measured gain is
 * not taken as "on" for every mesh: the box is the largest mesh, and the L2-resident ones lost
 * by the prefetch on the EPYC hosts, sc_grid.h). A hint changes no
 * result, so a wrong pick costs time only. It allocates the grid (sizeof(sc_grid), about 47 MB
 * of address space, the rows of the box touched: about 20 MB) and frees it; about 30 ms.
 * SONOCOMP_PREFETCH=mesh|on|off forces the choice without measuring.
 */
#ifndef SC_CPU_H
#define SC_CPU_H

#include "sc_simd.h"

/* How sc_cpu_select_prefetch chose. */
typedef struct sc_cpu_prefetch {
    sc_simd_prefetch chosen;
    int measured;          /* 1: timed (below) */
    int forced;            /* 1: SONOCOMP_PREFETCH chose */
    unsigned nx, ny, nz;   /* the box timed */
    double on_ms, off_ms;  /* the fastest mat-vec with and without the prefetch */
} sc_cpu_prefetch;

/* a prefetch choice is taken only when it is this much faster than the other */
#define SC_CPU_PREFETCH_MARGIN 0.05

/* The best variant this CPU runs and this build has. */
sc_simd sc_cpu_best_simd(void);

/* Select sc_cpu_best_simd() (or the SONOCOMP_SIMD override: a name of sc_simd_name() up
 * to the best; an unknown or unavailable name keeps the best and is reported in the return
 * value).
 * Returns SC_OK, or SC_ERR_INVALID_ARG when the override was refused. */
int sc_cpu_select_simd(void);

/* Select the mat-vec's prefetch (above) for the variant selected now (call after
 * sc_cpu_select_simd), reporting how in *out (may be NULL). measure 0 skips the timing: the
 * override or the mesh rule (sc-hostsim, whose time is virtual). Returns SC_OK;
 * SC_ERR_INVALID_ARG when SONOCOMP_PREFETCH is not mesh, on or off (the mesh rule is kept);
 * SC_ERR_NO_SPACE when the grid could not be allocated (the mesh rule is kept). */
int sc_cpu_select_prefetch(int measure, sc_cpu_prefetch *out);

/* One line for logs and final statistics: "prefetch off (measured on 64x32x32: mat-vec
 * 0.660 ms without, 0.850 ms with)". */
void sc_cpu_prefetch_describe(const sc_cpu_prefetch *p, char *buf, unsigned size);

#endif /* SC_CPU_H */
