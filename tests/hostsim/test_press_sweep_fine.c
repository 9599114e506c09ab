/* test_press_sweep_fine.c: test_press_sweep.c's sweeps on the 32x16x16 mesh, as their own test
 * (about 3 min in the release build, longer under the sanitizers: its own time limit,
 * tests/press_sweep.cmake). */
#define SC_PRESS_SWEEP_FINE 1
#include "test_press_sweep.c"
