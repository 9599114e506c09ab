/* bench_fem.c: time of one FEM frame (sc_fem_step, 20 CG iterations by default) on the
 * paper's mesh sizes, linear and corotated, on one core. Prints a table.
 *
 * Scene: the default 40 x 20 x 30 mm box, fat with a vein and an artery, bottom and sides
 * fixed, a probe pushing the top nodes under its footprint (external forces), so that the
 * solver works on a real deformation. Frames: 30 warm-up, then `frames` timed ones.
 * Times are thread CPU time (CLOCK_THREAD_CPUTIME_ID) so that other processes on a shared
 * machine do not count; cache interference still does: read p50 rather than max there, and
 * min_ms, the smallest mean over batches of 10 consecutive frames (the least disturbed
 * stretch: the figure to compare between builds on a noisy machine).
 * Usage: bench-fem [frames (200)] [cg iterations (20)] [all | corot | linear]
 *   all: every mesh size, both models (the table); corot / linear: only 32x16x16 with that
 *   model (the callgrind target for per-frame instruction counts of the corotated step). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_cpu.h"
#include "sc_err.h"
#include "sc_fem.h"
#include "sc_simd.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_mesh.h"

static sc_mesh g_mesh;
static sc_nodes g_nodes;
static sc_fem g_fem;
static double g_ms[100000];

/* Frames per batch of the min_ms column. */
#define BENCH_BATCH 10u

/* Thread CPU time: the machine may be shared; time spent descheduled is not the solver's. */
static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void label_scene(sc_mesh *m)
{
    for (uint32_t e = 0; e < m->tet_count; e++) {
        float c[3] = {0.0f, 0.0f, 0.0f};
        for (uint32_t v = 0; v < 4u; v++) {
            c[0] += 0.25f * m->rest_x[m->tet[e][v]];
            c[2] += 0.25f * m->rest_z[m->tet[e][v]];
        }
        uint8_t lab = c[2] > 20.0f ? SC_LABEL_MUSCLE : SC_LABEL_FAT;
        const float za = c[2] - 10.0f, xa = c[0] - 13.0f, xb = c[0] - 27.0f;
        if (xa * xa + za * za <= 9.0f) {
            lab = SC_LABEL_VEIN;
        } else if (xb * xb + za * za <= 9.0f) {
            lab = SC_LABEL_ARTERY;
        }
        m->tet_label[e] = lab;
    }
}

int main(int argc, char **argv)
{
    const uint32_t frames = argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 200u;
    const uint32_t iters = argc > 2 ? (uint32_t)strtoul(argv[2], NULL, 10) : 20u;
    const char *mode = argc > 3 ? argv[3] : "all";
    const int only_big = strcmp(mode, "all") != 0;
    const uint32_t only_corot = strcmp(mode, "corot") == 0 ? 1u : 0u;
    if (frames == 0u || frames > 100000u || iters == 0u || iters > SC_PHYS_ITERATIONS_MAX ||
        (only_big && !only_corot && strcmp(mode, "linear") != 0)) {
        fprintf(stderr,
                "usage: bench-fem [frames 1..100000] [cg iterations 1..%u] [all|corot|linear]\n",
                (unsigned)SC_PHYS_ITERATIONS_MAX);
        return 2;
    }
    if (sc_cpu_select_simd() != SC_OK) {
        fprintf(stderr, "bench-fem: SONOCOMP_SIMD not available here, using %s\n",
                sc_simd_name(sc_simd_selected()));
    }
    static const uint32_t sizes[4][3] = {{20, 10, 10}, {24, 12, 12}, {28, 14, 14}, {32, 16, 16}};
    static const double paper_ms[4] = {30.0, 60.0, 100.0, 150.0};
    sc_material_table mat;
    sc_material_table_default(&mat);
    printf("FEM frame time, one core, %u CG iterations, %u timed frames, kernels %s "
           "(sizeof(sc_fem) %zu B)\n",
           (unsigned)iters, (unsigned)frames, sc_simd_name(sc_simd_selected()), sizeof(sc_fem));
    printf("%-10s %6s %6s %-10s %8s %8s %8s %8s %8s %9s\n", "mesh", "nodes", "tets",
           "model", "mean_ms", "min_ms", "p50_ms", "p99_ms", "paper_ms", "res_ratio");
    for (uint32_t s = only_big ? 3u : 0u; s < 4u; s++) {
        if (sizes[s][0] > SC_MAX_MESH_NX || sizes[s][1] > SC_MAX_MESH_NY ||
            sizes[s][2] > SC_MAX_MESH_NZ) {
            continue;
        }
        for (uint32_t corot = 0; corot < 2u; corot++) {
            if (only_big && corot != only_corot) {
                continue;
            }
            sc_mesh_def d = sc_mesh_default_def();
            d.nx = sizes[s][0];
            d.ny = sizes[s][1];
            d.nz = sizes[s][2];
            int rc = sc_mesh_build(&g_mesh, &d);
            if (rc == SC_OK) {
                rc = sc_material_assign(&g_mesh, NULL, &mat, SC_LABEL_FAT);
            }
            label_scene(&g_mesh);
            sc_fem_def def = sc_fem_default_def();
            def.corotated = (uint8_t)corot;
            if (rc == SC_OK) {
                rc = sc_fem_init(&g_fem, &g_mesh, &mat, &def);
            }
            if (rc != SC_OK) {
                fprintf(stderr, "setup failed: %s\n", sc_err_str(rc));
                return 1;
            }
            sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
            for (uint32_t i = 0; i < g_mesh.nx * g_mesh.ny; i++) { /* top layer */
                const float x = g_mesh.rest_x[i], y = g_mesh.rest_y[i];
                if (x > 2.0f && x < 38.0f && y > 4.0f && y < 16.0f) {
                    g_nodes.fz[i] = 2.0e-4f; /* 0.2 mN per node, ~0.1 N total */
                }
            }
            for (uint32_t f = 0; f < 30u; f++) {
                sc_fem_step(&g_fem, &g_mesh, &g_nodes, SC_PHYS_DT_DEFAULT_S, iters);
            }
            double res = 0.0;
            for (uint32_t f = 0; f < frames; f++) {
                const double t0 = now_ms();
                sc_fem_step(&g_fem, &g_mesh, &g_nodes, SC_PHYS_DT_DEFAULT_S, iters);
                g_ms[f] = now_ms() - t0;
                res += (double)g_fem.stats.residual_ratio;
            }
            double sum = 0.0, batch = 0.0, min_batch = 0.0;
            for (uint32_t f = 0; f < frames; f++) {
                sum += g_ms[f];
                batch += g_ms[f];
                if (f % BENCH_BATCH == BENCH_BATCH - 1u || f + 1u == frames) {
                    const double mean = batch / (double)(f % BENCH_BATCH + 1u);
                    min_batch = (f < BENCH_BATCH || mean < min_batch) ? mean : min_batch;
                    batch = 0.0;
                }
            }
            qsort(g_ms, frames, sizeof g_ms[0], cmp_double);
            char mesh[32];
            snprintf(mesh, sizeof mesh, "%ux%ux%u", (unsigned)d.nx, (unsigned)d.ny, (unsigned)d.nz);
            printf("%-10s %6u %6u %-10s %8.2f %8.2f %8.2f %8.2f %8.0f %9.2e\n", mesh,
                   (unsigned)g_mesh.node_count, (unsigned)g_mesh.tet_count,
                   corot ? "corotated" : "linear", sum / frames,
                   min_batch, g_ms[frames / 2u], g_ms[(frames * 99u) / 100u], paper_ms[s],
                   res / frames);
            if (sc_fem_status(&g_fem) != SC_OK) {
                printf("  (unstable steps: %u)\n", (unsigned)g_fem.stats.unstable_steps);
            }
        }
    }
    return 0;
}
