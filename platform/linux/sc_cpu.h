/*
 * sc_cpu.h: the host CPU's kernel variant (core/physics/sc_simd.h) for host programs.
 *
 * The core never probes the CPU; a host program (sonocomp, sc-hostsim, the benchmarks, the
 * tests that want the fast path) calls sc_cpu_select_simd() once at start. On x86-64 it
 * asks the CPU through the compiler's __builtin_cpu_supports (cpuid and, for AVX, the OS's
 * XSAVE state via xgetbv), elsewhere it keeps the portable variant.
 * SONOCOMP_SIMD=generic (or a lower x86-64 level) in the environment forces that variant (to
 * compare, or to rule the vector code out when hunting a fault).
 */
#ifndef SC_CPU_H
#define SC_CPU_H

#include "sc_simd.h"

/* The best variant this CPU runs and this build has. */
sc_simd sc_cpu_best_simd(void);

/* Select sc_cpu_best_simd() (or the SONOCOMP_SIMD override: a name of sc_simd_name() up
 * to the best; an unknown or unavailable name keeps the best and is reported in the return
 * value).
 * Returns SC_OK, or SC_ERR_INVALID_ARG when the override was refused. */
int sc_cpu_select_simd(void);

#endif /* SC_CPU_H */
