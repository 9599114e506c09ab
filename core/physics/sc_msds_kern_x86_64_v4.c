/* sc_msds_kern_x86_64_v4.c: the MSDS substep (sc_msds_kern.inc) for the x86-64-v4 level
 * (AVX-512: 8-float vectors with 32 registers and mask selects), built with -march=x86-64-v4 where
 * the compiler takes it (SC_SIMD_X86_64_V4_BUILT); elsewhere this unit is empty. The same source,
 * so the same results bit for bit: the level only widens the vectors; -ffp-contract=off keeps FMA
 * out. */
#if defined(SC_SIMD_X86_64_V4_BUILT)
#define SC_MSDS_SUBSTEP_FN sc_msds_substep_x86_64_v4
#include "sc_msds_kern.inc"
#else
typedef int sc_msds_kern_x86_64_v4_unused; /* ISO C: a translation unit is not empty */
#endif
