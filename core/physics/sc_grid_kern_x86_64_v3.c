/* sc_grid_kern_x86_64_v3.c: the grid solver's hot loops (sc_grid_kern.inc) for the x86-64-v3
 * level, built with -march=x86-64-v3 where the compiler takes it (SC_SIMD_X86_64_V3_BUILT);
 * elsewhere this unit is empty. 8-float vectors (measured as fast as 16 on AVX-512 here, at
 * half the register pressure); the same source and per-lane operations as the portable variant,
 * so the same results bit for bit. */
#if defined(SC_SIMD_X86_64_V3_BUILT)
#define SC_VEC_W 8u
#define SC_GRID_KERN_NAME sc_grid_kern_x86_64_v3
#include "sc_grid_kern.inc"
#else
typedef int sc_grid_kern_x86_64_v3_unused; /* ISO C: a translation unit is not empty */
#endif
