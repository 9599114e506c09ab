/*
 * sc_test_case.h: small case files made in memory for whole-engine tests, from the clinical
 * block scene (sc_test_tissue_scene.h): fat over muscle, a soft vein and a stiff artery side
 * by side. The mannequin registration is a half turn about x (tracker Z up, as the tracker
 * emulator reports), so the emulator's "press down" presses into the block.
 * Test code: the case bytes are malloc'd once per call; free them with free().
 */
#ifndef SC_TEST_CASE_H
#define SC_TEST_CASE_H

#include <stddef.h>
#include <stdint.h>

#include "sc_engine.h"
#include "sc_test_tissue_scene.h"

typedef struct sc_test_case {
    uint8_t *bytes;
    size_t size;
    sc_test_scene scene;
    float vein_tracker_mm[3]; /* the skin point over the vein, tracker frame */
    float centre_tracker_mm[3]; /* the skin point over the middle of the block */
} sc_test_case;

/* Build a case: mesh nx x ny x nz over the block, vein label SC_LABEL_VEIN or
 * SC_LABEL_THROMBUS. Returns 0 or a negative sc_err. */
int sc_test_case_make(sc_test_case *tc, uint32_t nx, uint32_t ny, uint32_t nz,
                      uint8_t vein_label, const char *name);

/* An engine definition sized for fast tests: a 64-line x 128-sample linear image 30 mm deep
 * and 36 mm wide, MSDS. */
sc_engine_def sc_test_engine_def(void);

#endif /* SC_TEST_CASE_H */
