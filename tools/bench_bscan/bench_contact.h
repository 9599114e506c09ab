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
/* Workers of the engine's pool (1: none, the default) for the following setups. */
void bench_contact_set_workers(uint32_t workers);

int bench_contact_run(const char *cases_dir, const char *case_name, int method, int frames);

/* For instruction counts: the engine's walker imaging (the engine's settings) of the deepest
 * point, `frames` times inside bench_contact_walker_frames, nothing else timed or run after it:
 *   valgrind --tool=callgrind --toggle-collect=bench_contact_walker_frames bench_bscan
 *   contact-walker CASES CASE N [acoustics|no-acoustics]   (the collected instructions / N:
 *   one walker frame; the acoustics as the engine runs the case unless asked).
 * Returns 0, or 1 when the case cannot be loaded. */
int bench_contact_walker(const char *cases_dir, const char *case_name, int frames, int acoustics);
void bench_contact_walker_frames(int frames);

/* For instruction counts of whole frames: the engine run to the hold at the bottom of the press
 * (t = 1.55 s), then `frames` engine steps (rx + physics + imaging + status + state stream +
 * control, the host simulator's display included) inside bench_contact_hold_frames:
 *   valgrind --tool=callgrind --toggle-collect=bench_contact_hold_frames bench_bscan
 *   contact-hold CASES CASE N   (the collected instructions / N: one whole frame).
 * Prints the state hash after the frames. Returns 0, or 1 when the case cannot be loaded. */
int bench_contact_hold(const char *cases_dir, const char *case_name, int frames);
void bench_contact_hold_frames(int frames);

#endif
