/* sc_grid_kern_x86_64_v4.c: the grid solver's hot loops (sc_grid_kern.inc) for the x86-64-v4
 * level, built with -march=x86-64-v4 where the compiler takes it (SC_SIMD_X86_64_V4_BUILT);
 * elsewhere this unit is empty. 16-float vectors (AVX-512: measured 10-15% faster than 8 in the
 * cell and spring assembly here, the same in the mat-vec); the same source and per-lane
 * operations as the portable variant, so the same results bit for bit. */
#if defined(SC_SIMD_X86_64_V4_BUILT)
#define SC_VEC_W 16u
#define SC_GRID_KERN_NAME sc_grid_kern_x86_64_v4
#include "sc_grid_kern.inc"
#else
typedef int sc_grid_kern_x86_64_v4_unused; /* ISO C: a translation unit is not empty */
#endif
