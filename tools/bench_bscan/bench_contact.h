/* bench_contact.h: the engine's contact case of bench_bscan (see bench_contact.c). */
#ifndef BENCH_CONTACT_H
#define BENCH_CONTACT_H

#include "sc_engine.h"

/* A host-simulated engine with the case <cases_dir>/<case_name>.scase, pressed by the tracker
 * emulator's press script (depth_mm), run until stop_s seconds. method: -1 the default, else
 * sc_tissue_method. Returns SC_OK or the load error. */
int bench_contact_setup(const char *cases_dir, const char *case_name, int method, float depth_mm,
                        double stop_s);
const sc_engine *bench_contact_engine(void);
sc_engine *bench_contact_engine_mut(void);
const sc_display_dev *bench_contact_display(void);

/* Print the contact table (imaging alone, walker and region path; whole frames of the hold).
 * Returns 0, or 1 when the case cannot be loaded. */
int bench_contact_run(const char *cases_dir, const char *case_name, int method, int frames);

/* For instruction counts: the engine's walker imaging (the engine's settings) of the deepest
 * point, `frames` times inside bench_contact_walker_frames, nothing else timed or run after it:
 *   valgrind --tool=callgrind --toggle-collect=bench_contact_walker_frames bench_bscan
 *   contact-walker CASES CASE N   (the collected instructions / N: one walker frame).
 * Returns 0, or 1 when the case cannot be loaded. */
int bench_contact_walker(const char *cases_dir, const char *case_name, int frames);
void bench_contact_walker_frames(int frames);

#endif
