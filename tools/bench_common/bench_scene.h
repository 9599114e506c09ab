/* bench_scene.h: what bench-scale and bench-paper share: the scene (the clinical block of
 * tests/support/sc_test_tissue_scene.h, skin off, the probe pressed from 0.5 mm above the skin to
 * 3 mm in over 30 frames and held), the clocks, medians and the command-line lists
 * (--frames, --repeats, --workers 1,2, --meshes 20x10x10,...). Tools only (not the engine). */
#ifndef BENCH_SCENE_H
#define BENCH_SCENE_H

#include <stdint.h>

#include "sc_collider.h"
#include "sc_hal_pool.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

/* the solver methods of both tables (bench-paper adds Bullet after them) */
typedef enum bench_method { BENCH_MSDS = 0, BENCH_FEM, BENCH_COROT, BENCH_METHODS } bench_method;
extern const char *const bench_method_name[BENCH_METHODS];

/* the options both programs take: --frames N (1 .. BENCH_MAX_FRAMES), --repeats R
 * (1 .. BENCH_MAX_REPEATS), --workers 1,2 and --meshes 20x10x10,... (up to BENCH_MAX_LIST each),
 * --methods msds,fem,corot (at least one) */
#define BENCH_MAX_LIST    16
#define BENCH_MAX_FRAMES  1000
#define BENCH_MAX_REPEATS 50
typedef struct bench_opts {
    int frames, repeats;
    uint32_t workers[BENCH_MAX_LIST];
    int nworkers;
    uint32_t mesh[BENCH_MAX_LIST][3];
    int nmesh;
    int method_on[BENCH_METHODS];
} bench_opts;

/* defaults: `frames` frames, 5 repeats, workers 1,2, the six meshes, the methods of on[] */
void bench_opts_default(bench_opts *o, int frames, const int on[BENCH_METHODS]);
/* option a with value v: 1 taken, 0 not one of these, -1 a bad value */
int bench_opts_parse(bench_opts *o, const char *a, const char *v);

/* the six meshes: the paper's Table I and 48x24x24, 64x32x32 */
#define BENCH_DEFAULT_MESHES 6
extern const uint32_t bench_default_mesh[BENCH_DEFAULT_MESHES][3];

/* Select the kernel variant as sonocomp does (platform/linux/sc_cpu.h: the best this CPU runs,
 * or SONOCOMP_SIMD) and print it ("kernels: NAME"); prog names the program in a refusal. */
void bench_select_kernels(const char *prog);

/* clocks, ns: CLOCK_MONOTONIC, the process's and the calling thread's CPU time */
uint64_t bench_now_ns(void);
uint64_t bench_cpu_ns(void);
uint64_t bench_thread_cpu_ns(void);

/* medians (sort v): of n nanosecond samples in ms, of n doubles */
double bench_median_ms(uint64_t *v, int n);
double bench_median_d(double *v, int n);
/* qsort comparator of doubles */
int bench_cmp_d(const void *a, const void *b);

/* a decimal in lo .. hi (no sign, no space); *end after it; 0 or -1 */
int bench_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out, char **end);
/* "1,2,4": up to max worker counts of 1 .. max_workers into out, *n of them; 0 or -1 */
int bench_parse_workers(const char *v, uint32_t max_workers, uint32_t *out, int max, int *n);
/* "20x10x10,48x24x24": up to max meshes within SC_MAX_MESH_NX/NY/NZ, *n of them; 0 or -1 */
int bench_parse_meshes(const char *v, uint32_t (*out)[3], int max, int *n);

/* Build the scene for mesh (into sc) and the tissue t with method m on pool (may be NULL),
 * press over 30 frames; *hold the probe pose held from then on (3 mm in), *grid the collider's
 * grid of the mesh. SC_OK or the tissue's error. */
int bench_scene_press(sc_tissue *t, sc_test_scene *sc, const uint32_t mesh[3], bench_method m,
                      const sc_pool_dev *pool, sc_pose *hold, sc_collider_grid *grid);

#endif /* BENCH_SCENE_H */
