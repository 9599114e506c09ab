/* sc_skin_kern_x86_64_v3.c: the skin's substep (sc_skin_kern.inc) for the x86-64-v3 level
 * (AVX2: 8-float vectors), built with -march=x86-64-v3 where the compiler takes it
 * (SC_SIMD_X86_64_V3_BUILT); elsewhere this unit is empty. The same source, so the same bits. */
#if defined(SC_SIMD_X86_64_V3_BUILT)
#define SC_VEC_W           8u
#define SC_SKIN_SUBSTEP_FN sc_skin_substep_x86_64_v3
#include "sc_skin_kern.inc"
#else
typedef int sc_skin_kern_x86_64_v3_unused; /* ISO C: a translation unit is not empty */
#endif
