/*
 * sc_msds_kern.h: the MSDS substep's instruction-set variants (internal to sc_msds.c and the
 * kernel units; sc_simd.h selects). Each variant is the same C source, sc_msds_kern.inc,
 * compiled with the variant's flags; the results are bit-identical.
 */
#ifndef SC_MSDS_KERN_H
#define SC_MSDS_KERN_H

#include "sc_mesh.h"
#include "sc_msds.h"

/* added to |d|^2 in the force law (mm^2): guards 1/|d| in a collapsed spring */
#define SC_MSDS_MIN_LEN2_MM2 1e-12f
/* velocities below this are set to 0 (see integrate in sc_msds_kern.inc) */
#define SC_MSDS_V_FLUSH_MM_S 1e-12f

/* Before a loop whose stores provably do not overlap its loads (distinct arrays) although the
 * compiler cannot see it through many derived pointers: no run-time alias checks (GCC gives
 * up vectorising beyond 10 of them). */
#if defined(__clang__)
/* clang's "loop vectorize(assume_safety)" warns (an error under -Werror) where it still cannot
 * vectorise, as in the cell loop: no hint there */
#define SC_MSDS_IVDEP
#elif defined(__GNUC__)
#define SC_MSDS_IVDEP _Pragma("GCC ivdep")
#else
#define SC_MSDS_IVDEP
#endif

/* The five tets of a grid cell (sc_mesh.h), as the kernel's tet loop and sc_msds_init use them. */
#define SC_MSDS_CELL_TETS SC_MESH_CELL_TETS

/* Node offsets of the 8 corners of the grid cell at its origin node (corner bit 0: +x,
 * bit 1: +y, bit 2: +z), for nx nodes per row and nxy per plane. */
static inline void sc_msds_cell_offsets(uint32_t nx, uint32_t nxy, uint32_t oc[8])
{
    for (uint32_t c = 0; c < 8u; c++) {
        oc[c] =
            ((c & 1u) != 0u ? 1u : 0u) + ((c & 2u) != 0u ? nx : 0u) + ((c & 4u) != 0u ? nxy : 0u);
    }
}

/* Portable variant (every target). */
void sc_msds_substep_generic(sc_msds *s, sc_nodes *n);

/* x86-64 microarchitecture levels (built with -march=x86-64-v3 / -v4 where CMake finds an
 * x86-64 compiler that takes them); only for a CPU and OS that run them (sc_simd.h). */
#if defined(SC_SIMD_X86_64_V3_BUILT)
void sc_msds_substep_x86_64_v3(sc_msds *s, sc_nodes *n);
#endif
#if defined(SC_SIMD_X86_64_V4_BUILT)
void sc_msds_substep_x86_64_v4(sc_msds *s, sc_nodes *n);
#endif

#endif /* SC_MSDS_KERN_H */
