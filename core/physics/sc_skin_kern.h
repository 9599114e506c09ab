/*
 * sc_skin_kern.h: the skin's Euler substep in its instruction-set variants (internal to
 * sc_skin.c and the kernel units; sc_simd.h selects). Each variant is the same C source,
 * sc_skin_kern.inc, compiled with the variant's flags; the results are bit-identical.
 */
#ifndef SC_SKIN_KERN_H
#define SC_SKIN_KERN_H

#include "sc_skin.h"

/* added to |d|^2 in the edge springs' force law (mm^2): guards 1/|d| in a collapsed edge */
#define SC_SKIN_MIN_LEN2_MM2 1e-12f
/* springs per chunk of the spring pass (stack: 3 x 4 x SC_SKIN_CHUNK bytes) */
#define SC_SKIN_CHUNK 64u
/* the largest spring offset, nx + 1 (the diagonal family) */
#define SC_SKIN_OFF_MAX (SC_MAX_SKIN_NX + 1u)

/* Portable variant (every target). */
void sc_skin_substep_generic(sc_skin *s);
/* x86-64 microarchitecture levels, where built (sc_simd.h) */
#if defined(SC_SIMD_X86_64_V3_BUILT)
void sc_skin_substep_x86_64_v3(sc_skin *s);
#endif
#if defined(SC_SIMD_X86_64_V4_BUILT)
void sc_skin_substep_x86_64_v4(sc_skin *s);
#endif

#endif /* SC_SKIN_KERN_H */
