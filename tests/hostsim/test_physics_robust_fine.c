/* test_physics_robust_fine.c: test_physics_robust.c's script (jumps, spins, tilts at and off
 * the box's centre, a rock, the deepest press with the largest force) on the 32x16x16 mesh, as
 * its own test (its own time limit, tests/press_sweep.cmake). */
#define SC_PHYSICS_ROBUST_FINE 1
#include "test_physics_robust.c"
