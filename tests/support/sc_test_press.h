/* sc_test_press.h: the host-simulator rig of the physics tests (press sweep, robustness,
 * vessel drive): the whole engine with one phantom case from the build tree, the tracker
 * emulator feeding it frame by frame, and checks on the tissue's state. */
#ifndef SC_TEST_PRESS_H
#define SC_TEST_PRESS_H

#include <stdint.h>

#include "sc_hs_rig.h"
#include "sc_storage_linux.h"
#include "sc_tissue.h"
#include "sc_trkemu.h"

/* The engine on rig with the case case_file from cases_dir (the `cases` target's output),
 * watchdog off, method m; asserts (cmocka) that it loads and runs m. */
void sc_test_press_rig_up(sc_hs_rig *rig, sc_storage_linux *storage, const char *cases_dir,
                          const char *case_file, sc_tissue_method m);

/* One frame: the emulator's samples due before the engine's next release (t0: the rig clock
 * when the emulator started; *more cleared when it has no more), then the engine's step. */
void sc_test_press_frame(sc_hs_rig *rig, sc_emu *emu, uint64_t t0, int *more);

/* The loaded case's tissue again on an nx x ny x nz mesh of the same box, as the engine builds
 * it at case load, the case's vessel drive kept; asserts (cmocka) that it builds. */
void sc_test_press_remesh(sc_hs_rig *rig, uint32_t nx, uint32_t ny, uint32_t nz);

/* The active tissue. */
sc_tissue *sc_test_press_tissue(sc_hs_rig *rig);

/* 1 if every node's position and velocity is finite. */
int sc_test_press_state_finite(sc_hs_rig *rig);

/* Largest node distance from rest, mm. */
float sc_test_press_max_dev_mm(sc_hs_rig *rig);

#endif /* SC_TEST_PRESS_H */
