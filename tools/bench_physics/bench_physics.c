/* bench_physics.c: soft-tissue cost per frame for the mesh sizes of the paper's Table I.
 *
 * Scene: the clinical block of tests/support/sc_test_tissue_scene.h (40 x 20 x 30 mm, fat,
 * muscle, vein, artery) with the probe held 3 mm (10%) into the skin, so that contacts exist
 * every frame. Per mesh size and method: `frames` frames after a warm-up; wall time of
 * sc_tissue_step (solver + collision, skin off) and of the collision detection alone; one
 * thread, the best kernel variant for this CPU (core/physics/sc_simd.h). Then the MSDS at 32x16x16
 * with the volume term off and on (sc_msds.h) for every kernel variant this CPU runs.
 * Times are thread CPU time (CLOCK_THREAD_CPUTIME_ID), so that on a shared machine the time
 * the thread spends descheduled is not counted (cache interference still is: compare p50
 * and best with the mean).
 * Usage: bench-physics [frames]   (default 200)
 *        bench-physics frames stable (the stable MSDS and the FEMs at 32x16x16 only)
 *        bench-physics frames msds   (the MSDS solver alone, see msds_only)
 *        bench-physics frames stages [NXxNYxNZ] (per stage, see stages; default 32x16x16)
 *        bench-physics frames cg [NXxNYxNZ] (the CG alone, see cg_only; default 64x32x32) */
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_machine.h"
#include "bench_pages.h"
#include "sc_err.h"
#include "sc_cpu.h"
#include "sc_grid_kern.h"
#include "sc_labels.h"
#include "sc_simd.h"
#include "sc_stats.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

static sc_tissue g_t;
static sc_pose g_pose; /* the probe pose of the last run_cfg */

/* the explicit MSDS's former default volume term with Algorithm 1's springs (sc_msds.h) */
#define PAPER_VOLUME_RATIO 6.0f

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static double ms(uint64_t ns)
{
    return (double)ns / 1e6;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

typedef struct result {
    double mean_ms, p50_ms, p99_ms, best_ms, coll_ms;
    uint32_t contacts, mpr;
} result;

/* Solver configurations of the table. */
typedef enum config {
    CFG_MSDS_STABLE = 0,   /* default: implicit integrator, derived springs */
    CFG_MSDS_EXPLICIT = 1, /* the paper's explicit Euler, Algorithm 1's springs, ratio 6 */
    CFG_FEM_LINEAR = 2,
    CFG_FEM_COROTATED = 3,
} config;

static int run_cfg(uint32_t nx, uint32_t ny, uint32_t nz, config c, float volume_ratio,
                   int frames, result *out);

static int run(uint32_t nx, uint32_t ny, uint32_t nz, sc_tissue_method m, float volume_ratio,
               int frames, result *out)
{
    /* the explicit MSDS (sc_msds_step, the kernel variants) or the linear FEM */
    return run_cfg(nx, ny, nz, m == SC_TISSUE_MSDS ? CFG_MSDS_EXPLICIT : CFG_FEM_LINEAR,
                   volume_ratio, frames, out);
}

static int run_cfg(uint32_t nx, uint32_t ny, uint32_t nz, config c, float volume_ratio,
                   int frames, result *out)
{
    const sc_tissue_method m =
        (c == CFG_MSDS_STABLE || c == CFG_MSDS_EXPLICIT) ? SC_TISSUE_MSDS : SC_TISSUE_FEM;
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = nx;
    p.ny = ny;
    p.nz = nz;
    static sc_test_scene scene;
    sc_test_scene_build(&scene, &p);
    sc_tissue_def d = sc_tissue_default_def();
    d.mesh = scene.mesh;
    d.collider = sc_test_scene_collider(&scene);
    d.skin_enabled = 0u;
    d.method = m;
    d.msds.volume_stiffness_ratio = volume_ratio;
    if (c == CFG_MSDS_EXPLICIT) {
        d.msds.integrator = (uint8_t)SC_MSDS_EXPLICIT;
        d.msds.springs = (uint8_t)SC_MSDS_SPRINGS_PAPER;
    }
    d.fem.corotated = c == CFG_FEM_COROTATED ? 1u : 0u;
    sc_material_table mat;
    sc_material_table_default(&mat);
    int rc = sc_tissue_init(&g_t, &d, &scene.vol, &mat, SC_LABEL_FAT);
    if (rc != 0) {
        return rc;
    }
    const sc_pose pose = sc_test_scene_probe(&scene, 3.0f);
    g_pose = pose;
    for (int f = 0; f < 30; f++) { /* press in and settle */
        const sc_pose q = sc_test_scene_probe(&scene, -0.5f + 3.5f * (float)(f + 1) / 30.0f);
        (void)sc_tissue_step(&g_t, &q);
    }
    sc_stats st;
    sc_stats_reset(&st);
    uint64_t coll = 0;
    const sc_collider_grid g = {
        g_t.mesh.nx,
        g_t.mesh.ny,
        g_t.mesh.nz,
        {g_t.mesh.origin_mm[0], g_t.mesh.origin_mm[1], g_t.mesh.origin_mm[2]},
        {g_t.mesh.cell_mm[0], g_t.mesh.cell_mm[1], g_t.mesh.cell_mm[2]}};
    static sc_contact_set cs;
    for (int f = 0; f < frames; f++) {
        const uint64_t t0 = now_ns();
        rc = sc_tissue_step(&g_t, &pose);
        const uint64_t t1 = now_ns();
        sc_stats_add(&st, t1 - t0);
        sc_collider_detect(&g_t.collider, &g, g_t.nodes.x, g_t.nodes.y, g_t.nodes.z,
                           g_t.mesh.node_fixed, g_t.stats.max_disp_mm, &cs);
        coll += now_ns() - t1;
        if (rc != 0) {
            return rc;
        }
    }
    out->mean_ms = ms(sc_stats_mean_ns(&st));
    out->p50_ms = ms(sc_stats_percentile_ns(&st, 500));
    out->p99_ms = ms(sc_stats_percentile_ns(&st, 990));
    out->best_ms = ms(st.best_ns);
    out->coll_ms = ms(coll / (uint64_t)frames);
    out->contacts = cs.count;
    out->mpr = cs.mpr_calls;
    return 0;
}

/* The MSDS solver alone (sc_msds_step: 20 substeps, no collision, no contact handling) at
 * 32x16x16 after the press of run(): min over 5 batches of frames / 5 frames, springs only
 * and default. For instruction counts: valgrind --tool=callgrind
 * --toggle-collect=sc_msds_step bench-physics 10 msds (Ir / 10 = per frame, both runs). */
static int msds_only(int frames, int which)
{
    const float ratios[2] = {0.0f, PAPER_VOLUME_RATIO};
    const int batch = frames >= 5 ? frames / 5 : 1;
    for (int r = 0; r < 2; r++) {
        if (which >= 0 && which != r) {
            continue;
        }
        result a;
        if (run(32u, 16u, 16u, SC_TISSUE_MSDS, ratios[r], 1, &a) != 0) {
            return 1;
        }
        uint64_t best = UINT64_MAX;
        for (int b = 0; b < 5; b++) {
            const uint64_t t0 = now_ns();
            for (int f = 0; f < batch; f++) {
                sc_msds_step(&g_t.msds, &g_t.nodes);
            }
            const uint64_t t = (now_ns() - t0) / (uint64_t)batch;
            best = t < best ? t : best;
        }
        printf("sc_msds_step 32x16x16, volume ratio %.1f%s: %.3f ms per frame (min of 5 "
               "batches of %d)\n",
               (double)ratios[r], r ? " (default)" : " (springs only)", ms(best), batch);
    }
    return 0;
}

static uint64_t umin(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

/* The 32x16x16 tissue frame per stage, minimum over `frames` frames each (the machine is
 * shared: the least disturbed frame): the whole frame (sc_tissue_step, skin off), the
 * collision detection, and for the implicit methods the step's start and assembly
 * (sc_grid_begin and the method's element or spring and cell passes, timed again on the
 * frame's state); the CG with the rest of the frame is the frame minus those. */
static int stages(int frames, uint32_t nx, uint32_t ny, uint32_t nz)
{
    const config cs[4] = {CFG_MSDS_STABLE, CFG_MSDS_EXPLICIT, CFG_FEM_LINEAR, CFG_FEM_COROTATED};
    static const char *const names[4] = {"MSDS stable", "MSDS explicit", "FEM linear",
                                         "FEM corotated"};
    printf("%ux%ux%u per stage, ms, minimum over %d frames (kernels %s); stable MSDS and FEM: "
           "%u CG iterations; explicit MSDS: %u substeps of %.3f s (Algorithm 1 springs, volume "
           "ratio 6)\n",
           (unsigned)nx, (unsigned)ny, (unsigned)nz, frames, sc_simd_name(sc_simd_selected()), (unsigned)SC_PHYS_CG_ITERATIONS_DEFAULT,
           (unsigned)SC_PHYS_ITERATIONS_DEFAULT, (double)SC_PHYS_DT_DEFAULT_S);
    printf("%-14s | %8s | %9s | %8s | %8s | %10s | %6s\n", "method", "frame", "collision", "start",
           "assembly", "solve+rest", "lumen");
    for (int c = 0; c < 4; c++) {
        result a;
        const float ratio =
            cs[c] == CFG_MSDS_EXPLICIT ? PAPER_VOLUME_RATIO : sc_msds_default_def().volume_stiffness_ratio;
        if (run_cfg(nx, ny, nz, cs[c], ratio, 1, &a) != 0) {
            return 1;
        }
        const sc_pose pose = g_pose;
        uint64_t best[5] = {UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT64_MAX};
        uint64_t best_springs = UINT64_MAX, best_cells = UINT64_MAX; /* the MSDS's, apart */
        const sc_collider_grid gr = {
            g_t.mesh.nx,
            g_t.mesh.ny,
            g_t.mesh.nz,
            {g_t.mesh.origin_mm[0], g_t.mesh.origin_mm[1], g_t.mesh.origin_mm[2]},
            {g_t.mesh.cell_mm[0], g_t.mesh.cell_mm[1], g_t.mesh.cell_mm[2]}};
        static sc_contact_set ccs;
        const sc_grid_kern *k = sc_grid_kern_selected();
        sc_grid *g = &g_t.fem.grid;
        const float dt = g_t.msds.def.dt_s * (float)g_t.msds.def.iterations;
        for (int f = 0; f < frames; f++) {
            const uint64_t t0 = now_ns();
            if (sc_tissue_step(&g_t, &pose) != 0) {
                return 1;
            }
            const uint64_t t1 = now_ns();
            sc_collider_detect(&g_t.collider, &gr, g_t.nodes.x, g_t.nodes.y, g_t.nodes.z,
                               g_t.mesh.node_fixed, g_t.stats.max_disp_mm, &ccs);
            const uint64_t t2 = now_ns();
            uint64_t t3 = t2, t4 = t2;
            if (cs[c] != CFG_MSDS_EXPLICIT) {
                const int msds = cs[c] == CFG_MSDS_STABLE;
                const float beta = msds ? g_t.msds.gamma_per_k_s : g_t.fem.def.rayleigh_beta_s;
                const float alpha = msds ? g_t.msds.def.drag_per_s : 0.0f;
                const float ck = dt * beta + dt * dt;
                sc_grid_begin(g, &g_t.mesh, &g_t.nodes, dt, beta, alpha, g_t.kinematic);
                t3 = now_ns();
                if (msds) {
                    /* the step's assembly (msds_assemble: one pass on the large meshes), then
                     * its two parts apart, for the split printed after the row */
                    sc_grid_clear(g, SC_GRID_CLEAR_DIAG);
                    k->msds_assemble(g, &g_t.msds, dt, ck, 1);
                    t4 = now_ns();
                    sc_grid_clear(g, SC_GRID_CLEAR_DIAG);
                    const uint64_t ts = now_ns();
                    k->msds_springs(g, &g_t.msds, dt, ck);
                    const uint64_t tc = now_ns();
                    k->msds_cells(g, &g_t.msds, dt, ck);
                    const uint64_t te = now_ns();
                    best_springs = umin(best_springs, tc - ts);
                    best_cells = umin(best_cells, te - tc);
                } else {
                    sc_grid_fem_in in = g_t.fem.element;
                    in.lamv = &g_t.fem.lamv[0][0];
                    in.muv = &g_t.fem.muv[0][0];
                    in.corotated = cs[c] == CFG_FEM_COROTATED;
                    if (in.corotated) {
                        sc_grid_clear(g, SC_GRID_CLEAR_DIAG | SC_GRID_CLEAR_BLOCKS);
                        (void)k->fem_cells(g, &in, dt, ck);
                    } else {
                        /* the linear step: volume check and the r0 mat-vec on the rest K */
                        (void)k->fem_below(g, &in);
                        k->matvec(g, 0.0f, 1.0f);
                    }
                    t4 = now_ns();
                }
            }
#if SC_PHYS_LUMEN
            /* the lumen pass (inside the frame): volumes, law, boundary forces, and their
             * clearing */
            const uint64_t t5 = now_ns();
            sc_lumen_apply(&g_t.lumen, &g_t.mesh, &g_t.nodes);
            sc_lumen_clear(&g_t.lumen, &g_t.mesh, &g_t.nodes);
            best[4] = umin(best[4], now_ns() - t5);
#else
            best[4] = 0u;
#endif
            best[0] = umin(best[0], t1 - t0);
            best[1] = umin(best[1], t2 - t1);
            best[2] = umin(best[2], t3 - t2);
            best[3] = umin(best[3], t4 - t3);
        }
        const double rest = ms(best[0]) - ms(best[1]) - ms(best[2]) - ms(best[3]) - ms(best[4]);
        printf("%-14s | %8.3f | %9.3f | %8.3f | %8.3f | %10.3f | %6.3f", names[c], ms(best[0]),
               ms(best[1]), ms(best[2]), ms(best[3]), rest, ms(best[4]));
        if (best_cells != UINT64_MAX) {
            printf("   (apart: springs %.3f, cells %.3f)", ms(best_springs), ms(best_cells));
        }
        printf("\n");
    }
#if SC_PHYS_LUMEN
    printf("lumen: %u vessels, %u boundary faces loaded in the last frame\n",
           (unsigned)g_t.lumen.count, (unsigned)g_t.lumen.faces);
#endif
    return 0;
}

/* The CG alone on one mesh (stable MSDS scene, the press's state), one thread: the mat-vec and
 * the whole CG of the default iterations, min over `frames` calls each. */
static int cg_only(int frames, uint32_t nx, uint32_t ny, uint32_t nz)
{
    result a;
    if (run_cfg(nx, ny, nz, CFG_MSDS_STABLE, sc_msds_default_def().volume_stiffness_ratio, 3,
                &a) != 0) {
        return 1;
    }
    const sc_grid_kern *k = sc_grid_kern_selected();
    sc_grid *g = &g_t.fem.grid;
    const float ck = 1e-3f;
    uint64_t best[2] = {UINT64_MAX, UINT64_MAX};
    for (int f = 0; f < frames; f++) {
        sc_grid_cg_out out;
        uint64_t t0 = now_ns();
        k->matvec(g, 1.0f, ck);
        best[0] = umin(best[0], now_ns() - t0);
        t0 = now_ns();
        k->cg(g, 1.0f, ck, SC_PHYS_CG_ITERATIONS_DEFAULT, &out);
        best[1] = umin(best[1], now_ns() - t0);
    }
    /* The product's floor from memory: its 60 rows read once over the nodes, one multiply and
     * one add per value into 16 independent sums (no neighbour loads, no blocks), run right
     * after a product, as the CG's next one is. docs/performance.md, twenty-second pass. */
    uint64_t stream = UINT64_MAX;
    volatile float one = 1.0f; /* a multiplier the compiler cannot fold away */
    const float scale = one;
    float sink = 0.0f;
    for (int f = 0; f < frames; f++) {
        k->matvec(g, 1.0f, ck);
        typedef float v16 __attribute__((vector_size(64)));
        v16 acc = {0.0f};
        const v16 sc = acc + scale;
        const uint64_t t0 = now_ns();
        for (uint32_t r = 0; r < SC_GRID_MAT_ROWS; r++) {
            const float *row = &g->d[0][0] + (size_t)r * SC_GRID_ROW + SC_GRID_HEAD;
            for (uint32_t t = 0; t < g->node_end; t += 16u) {
                v16 x;
                memcpy(&x, row + t, sizeof x);
                acc += x * sc;
            }
        }
        stream = umin(stream, now_ns() - t0);
        for (uint32_t l = 0; l < 16u; l++) {
            sink += acc[l];
        }
    }
    const double matrix_mb = (double)g->node_count * 60.0 * 4.0 / 1e6;
    printf("%ux%ux%u, %u nodes (matrix %.1f MB), kernels %s, one thread, min of %d: mat-vec "
           "%.3f ms (%.1f GB/s of matrix), CG of %u iterations %.3f ms; the 60 rows streamed "
           "alone %.3f ms (%.1f GB/s; sum %g)\n",
           (unsigned)nx, (unsigned)ny, (unsigned)nz, (unsigned)g->node_count, matrix_mb,
           sc_simd_name(sc_simd_selected()), frames, ms(best[0]),
           matrix_mb / 1e3 / (ms(best[0]) / 1e3), (unsigned)SC_PHYS_CG_ITERATIONS_DEFAULT,
           ms(best[1]), ms(stream), matrix_mb / 1e3 / (ms(stream) / 1e3), (double)sink);
    return 0;
}

int main(int argc, char **argv)
{
    const int frames = argc > 1 ? atoi(argv[1]) : 200;
    const char *pages = bench_pages(&g_t, sizeof g_t);
    if (sc_cpu_select_simd() != SC_OK) {
        fprintf(stderr, "bench-physics: SONOCOMP_SIMD not available here, using %s\n",
                sc_simd_name(sc_simd_selected()));
    }
    printf("kernels: %s\n", sc_simd_name(sc_simd_selected()));
    bench_print_machine();
    bench_select_prefetch("bench-physics");
    printf("pages: %s\n", pages);
    if (argc > 2 && strcmp(argv[2], "stable") == 0) {
        /* the stable MSDS and the FEMs at 32x16x16 only (the targets' measure) */
        const config cs[3] = {CFG_MSDS_STABLE, CFG_FEM_LINEAR, CFG_FEM_COROTATED};
        static const char *const names[3] = {"MSDS stable", "FEM linear", "FEM corotated"};
        for (int i = 0; i < 3; i++) {
            result a;
            if (run_cfg(32u, 16u, 16u, cs[i], sc_msds_default_def().volume_stiffness_ratio, frames,
                        &a) != 0) {
                return 1;
            }
            printf("32x16x16 %-14s tissue frame mean %6.2f  p50 %6.2f  best %6.2f ms\n", names[i],
                   a.mean_ms, a.p50_ms, a.best_ms);
        }
        return 0;
    }
    const int cg = argc > 2 && strcmp(argv[2], "cg") == 0;
    if (cg || (argc > 2 && strcmp(argv[2], "stages") == 0)) {
        unsigned nx = cg ? 64u : 32u, ny = cg ? 32u : 16u, nz = cg ? 32u : 16u;
        if (argc > 3 && (sscanf(argv[3], "%ux%ux%u", &nx, &ny, &nz) != 3 || nx < 2u ||
                         ny < 2u || nz < 2u)) {
            fprintf(stderr, "bench-physics: mesh '%s' is not NXxNYxNZ\n", argv[3]);
            return 2;
        }
        return cg ? cg_only(frames, nx, ny, nz) : stages(frames, nx, ny, nz);
    }
    if (argc > 2 && strcmp(argv[2], "msds") == 0) {
        const int which = argc > 3 ? (strcmp(argv[3], "springs") == 0 ? 0 : 1) : -1;
        return msds_only(frames, which);
    }
    static const uint32_t sizes[4][3] = {{20, 10, 10}, {24, 12, 12}, {28, 14, 14}, {32, 16, 16}};
    static const double paper_msds[4] = {10, 17, 27, 40}, paper_fem[4] = {30, 60, 100, 150},
                        paper_coll[4] = {0.1, 0.2, 0.2, 0.3};
    printf("soft tissue, ms per frame (20 iterations or CG iterations, 0.2 s simulated), one "
           "thread, %d frames, probe 3 mm in contact; paper Table I in brackets\n"
           "MSDS stable: implicit integrator + derived springs (default); MSDS explicit: the "
           "paper's Euler + Algorithm 1's springs + volume ratio 6; targets at 32x16x16: stable "
           "MSDS <= 2 ms, corotated FEM <= 6 ms\n",
           frames);
    printf("%-10s %6s %7s | %-16s | %-22s | %-22s | %-16s | %-26s\n", "mesh", "nodes", "tets",
           "MSDS stable", "MSDS explicit [paper]", "FEM linear [paper]", "FEM corotated",
           "collision ms (contacts) [paper]");
    for (int s = 0; s < 4; s++) {
        result a, e, b, c;
        int rc = run_cfg(sizes[s][0], sizes[s][1], sizes[s][2], CFG_MSDS_STABLE,
                         sc_msds_default_def().volume_stiffness_ratio, frames, &a);
        rc |= run_cfg(sizes[s][0], sizes[s][1], sizes[s][2], CFG_MSDS_EXPLICIT,
                      PAPER_VOLUME_RATIO, frames, &e);
        rc |= run_cfg(sizes[s][0], sizes[s][1], sizes[s][2], CFG_FEM_LINEAR,
                      PAPER_VOLUME_RATIO, frames, &b);
        rc |= run_cfg(sizes[s][0], sizes[s][1], sizes[s][2], CFG_FEM_COROTATED,
                      PAPER_VOLUME_RATIO, frames, &c);
        if (rc != 0) {
            fprintf(stderr, "run failed: %d\n", rc);
            return 1;
        }
        char name[32];
        snprintf(name, sizeof name, "%ux%ux%u", sizes[s][0], sizes[s][1], sizes[s][2]);
        printf("%-10s %6u %7u | %6.2f / %6.2f | %6.2f / %6.2f [%4.0f] | %6.2f / %6.2f [%4.0f] | "
               "%6.2f / %6.2f | %6.3f (%4u, %4u MPR) [%.1f]\n",
               name, g_t.mesh.node_count, g_t.mesh.tet_count, a.mean_ms, a.p99_ms, e.mean_ms,
               e.p99_ms, paper_msds[s], b.mean_ms, b.p99_ms, paper_fem[s], c.mean_ms, c.p99_ms,
               a.coll_ms, a.contacts, a.mpr, paper_coll[s]);
    }
    /* the MSDS at the largest size per kernel variant: the solver alone (sc_msds_step, 20
     * substeps, after the press of run(); the target's measure, as the paper's MSDS column
     * has no collision) and the whole tissue frame as above; Algorithm 1's springs alone (the
     * paper's MSDS, volume term off) and the default (springs + volume term) */
    printf("explicit MSDS 32x16x16 by kernel variant, ms per frame over %d frames: solver mean / "
           "median / best; tissue frame mean / p50 (a histogram bin's upper bound) / best\n",
           frames);
    printf("%-10s | %-24s | %-24s | %-27s\n", "kernels", "solver springs only", "solver ratio 6",
           "tissue frame");
    const sc_simd chosen = sc_simd_selected();
    for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
        if (!sc_simd_built((sc_simd)v) || v > (int)sc_cpu_best_simd()) {
            continue;
        }
        (void)sc_simd_select((sc_simd)v);
        double sm[2], sp[2], sb[2];
        const float ratios[2] = {0.0f, PAPER_VOLUME_RATIO};
        result a1;
        for (int r = 0; r < 2; r++) {
            if (run(32u, 16u, 16u, SC_TISSUE_MSDS, ratios[r], r == 1 ? frames : 1, &a1) != 0) {
                fprintf(stderr, "run failed\n");
                return 1;
            }
            static uint64_t t_ns[100000];
            const int nf = frames < 100000 ? frames : 100000;
            uint64_t sum = 0;
            for (int f = 0; f < nf; f++) {
                const uint64_t t0 = now_ns();
                sc_msds_step(&g_t.msds, &g_t.nodes);
                t_ns[f] = now_ns() - t0;
                sum += t_ns[f];
            }
            qsort(t_ns, (size_t)nf, sizeof t_ns[0], cmp_u64);
            sm[r] = ms(sum / (uint64_t)nf);
            sp[r] = ms(t_ns[nf / 2]);
            sb[r] = ms(t_ns[0]);
        }
        printf("%-10s | %6.2f / %6.2f / %6.2f | %6.2f / %6.2f / %6.2f | %7.2f / %7.2f / %7.2f\n",
               sc_simd_name((sc_simd)v), sm[0], sp[0], sb[0], sm[1], sp[1], sb[1], a1.mean_ms,
               a1.p50_ms, a1.best_ms);
    }
    (void)sc_simd_select(chosen);
    printf("sizeof(sc_tissue) = %zu bytes (sc_msds %zu, sc_fem %zu, sc_springs %zu)\n",
           sizeof(sc_tissue), sizeof(sc_msds), sizeof(sc_fem), sizeof(sc_springs));
    return 0;
}
