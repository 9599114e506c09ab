/* sc_msds_kern_x86_64_v3.c: the MSDS substep (sc_msds_kern.inc) for the x86-64-v3 level
 * (AVX2: 8-float vectors), built with -march=x86-64-v3 where the compiler
 * takes it (SC_SIMD_X86_64_V3_BUILT); elsewhere this unit is empty. The same source, so
 * the same results bit for bit: the level only widens the vectors; -ffp-contract=off keeps
 * FMA out. */
#if defined(SC_SIMD_X86_64_V3_BUILT)
#define SC_MSDS_SUBSTEP_FN sc_msds_substep_x86_64_v3
#include "sc_msds_kern.inc"
#else
typedef int sc_msds_kern_x86_64_v3_unused; /* ISO C: a translation unit is not empty */
#endif
