/* sc_grid_kern.c: the portable variant of the grid solver's hot loops (sc_grid_kern.inc):
 * 4-float vectors where the compiler has 128-bit SIMD (SSE2, NEON), plain floats elsewhere. */
#define SC_VEC_W 4u
#define SC_GRID_KERN_NAME sc_grid_kern_generic
#include "sc_grid_kern.inc"
