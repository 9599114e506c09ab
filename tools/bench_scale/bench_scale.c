/* bench_scale.c: the soft tissue's cost per frame against mesh size and worker count.
 *
 * Scene: the clinical block of tests/support/sc_test_tissue_scene.h (40 x 20 x 30 mm, fat,
 * muscle, vein, artery), the probe pressed 3 mm in and held (contacts every frame), skin off,
 * as bench-physics. Per mesh, method and worker count: `repeats` runs of `frames` frames after
 * a 30-frame press; per run the median frame (wall clock, CLOCK_MONOTONIC: with workers the
 * frame is spread over threads); printed: the median over runs and the spread (min .. max of the
 * runs' medians), the collision detection's median alone, the speed-up over one worker and the
 * share of a 60 Hz frame left, and the process CPU time of a frame (all threads, the least
 * disturbed run's median: on a shared machine the one-worker figure that does not count the
 * time the thread waited for a CPU; with workers it includes their spinning). Workers:
 * platform/linux/sc_pool_linux.h, pinned from CPU 0. Meshes: the paper's Table I (20x10x10,
 * 24x12x12, 28x14x14, 32x16x16) and 48x24x24, 64x32x32. Methods: the stable MSDS (default), the FEM
 * linear and corotated (the paper's explicit MSDS is bench-physics'). Every run's frame state hash
 * is checked against the one-worker run of the same mesh and method: a mismatch is reported (and
 * the exit status is 1).
 *
 * Usage: bench-scale [--frames N] [--repeats R] [--workers 1,2] [--meshes 20x10x10,...]
 *                    [--methods msds,fem,corot] [--csv FILE]
 * Defaults: 40 frames, 5 repeats, workers 1,2, all six meshes, all three methods.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_collider.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_pool_linux.h"
#include "sc_test_tissue_scene.h"
#include "sc_tissue.h"

#define MAX_LIST    16
#define MAX_FRAMES  1000
#define MAX_REPEATS 50

static sc_tissue g_t;
static sc_test_scene g_scene;

typedef enum method { M_MSDS = 0, M_FEM, M_COROT, M_COUNT } method;
static const char *const k_method_name[M_COUNT] = {"msds", "fem", "corot"};

typedef struct opts {
    int frames, repeats;
    uint32_t workers[MAX_LIST];
    int nworkers;
    uint32_t mesh[MAX_LIST][3];
    int nmesh;
    int method_on[M_COUNT];
    const char *csv;
} opts;

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static uint64_t cpu_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static double median_ms(uint64_t *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmp_u64);
    return (n % 2) ? (double)v[n / 2] / 1e6 : (double)(v[n / 2 - 1] + v[n / 2]) / 2e6;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int usage(void)
{
    fprintf(stderr, "usage: bench-scale [--frames N] [--repeats R] [--workers 1,2] "
                    "[--meshes 20x10x10,...] [--methods msds,fem,corot] [--csv FILE]\n");
    return 2;
}

static int parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out, char **end)
{
    errno = 0;
    const unsigned long v = strtoul(s, end, 10);
    if (errno || *end == s || s[0] == '-' || v < lo || v > hi) {
        return -1;
    }
    *out = (uint32_t)v;
    return 0;
}

static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 40;
    o->repeats = 5;
    o->workers[0] = 1u;
    o->workers[1] = 2u;
    o->nworkers = 2;
    static const uint32_t def_mesh[6][3] = {{20, 10, 10}, {24, 12, 12}, {28, 14, 14},
                                            {32, 16, 16}, {48, 24, 24}, {64, 32, 32}};
    for (int i = 0; i < 6; i++) {
        memcpy(o->mesh[i], def_mesh[i], sizeof def_mesh[i]);
    }
    o->nmesh = 6;
    for (int m = 0; m < M_COUNT; m++) {
        o->method_on[m] = 1;
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc) {
            return usage();
        }
        const char *v = argv[++i];
        char *end = NULL;
        uint32_t u;
        if (strcmp(a, "--frames") == 0) {
            if (parse_u32(v, 1u, MAX_FRAMES, &u, &end) || *end) {
                return usage();
            }
            o->frames = (int)u;
        } else if (strcmp(a, "--repeats") == 0) {
            if (parse_u32(v, 1u, MAX_REPEATS, &u, &end) || *end) {
                return usage();
            }
            o->repeats = (int)u;
        } else if (strcmp(a, "--workers") == 0) {
            o->nworkers = 0;
            const char *s = v;
            while (*s) {
                if (o->nworkers == MAX_LIST ||
                    parse_u32(s, 1u, SC_POOL_LINUX_MAX_WORKERS, &u, &end)) {
                    return usage();
                }
                o->workers[o->nworkers++] = u;
                s = *end == ',' ? end + 1 : end;
                if (*end && *end != ',') {
                    return usage();
                }
            }
        } else if (strcmp(a, "--meshes") == 0) {
            o->nmesh = 0;
            const char *s = v;
            while (*s) {
                if (o->nmesh == MAX_LIST) {
                    return usage();
                }
                uint32_t *d = o->mesh[o->nmesh];
                const uint32_t maxd[3] = {SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ};
                for (int k = 0; k < 3; k++) {
                    if (parse_u32(s, 2u, maxd[k], &d[k], &end) || (k < 2 && *end != 'x')) {
                        return usage();
                    }
                    s = k < 2 ? end + 1 : end;
                }
                o->nmesh++;
                if (*s == ',') {
                    s++;
                } else if (*s) {
                    return usage();
                }
            }
        } else if (strcmp(a, "--methods") == 0) {
            for (int m = 0; m < M_COUNT; m++) {
                o->method_on[m] = strstr(v, k_method_name[m]) != NULL;
            }
        } else if (strcmp(a, "--csv") == 0) {
            o->csv = v;
        } else {
            return usage();
        }
    }
    return 0;
}

typedef struct run_out {
    double med_ms, min_ms, max_ms, coll_ms, cpu_ms;
    uint64_t hash;
    uint32_t nodes, tets, contacts;
} run_out;

/* build, press, then `repeats` runs of `frames` frames; the pool may be NULL */
static int bench_one(const uint32_t mesh[3], method m, const sc_pool_dev *pool, const opts *o,
                     run_out *out, FILE *csv, uint32_t workers)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = mesh[0];
    p.ny = mesh[1];
    p.nz = mesh[2];
    sc_test_scene_build(&g_scene, &p);
    sc_tissue_def d =
        sc_test_scene_tissue_def(&g_scene, m == M_MSDS ? SC_TISSUE_MSDS : SC_TISSUE_FEM);
    d.skin_enabled = 0u;
    d.fem.corotated = m == M_COROT ? 1u : 0u;
    sc_material_table mat;
    sc_material_table_default(&mat);
    int rc = sc_tissue_build_begin(&g_t, &d, &g_scene.vol, &mat, SC_LABEL_FAT);
    if (rc != SC_OK) {
        return rc;
    }
    sc_tissue_set_pool(&g_t, pool);
    while ((rc = sc_tissue_build_step(&g_t)) == SC_OK) {
    }
    if (rc != 1) {
        return rc;
    }
    for (int f = 0; f < 30; f++) {
        const sc_pose q = sc_test_scene_probe(&g_scene, -0.5f + 3.5f * (float)(f + 1) / 30.0f);
        (void)sc_tissue_step(&g_t, &q);
    }
    const sc_pose pose = sc_test_scene_probe(&g_scene, 3.0f);
    const sc_collider_grid g = {
        g_t.mesh.nx,
        g_t.mesh.ny,
        g_t.mesh.nz,
        {g_t.mesh.origin_mm[0], g_t.mesh.origin_mm[1], g_t.mesh.origin_mm[2]},
        {g_t.mesh.cell_mm[0], g_t.mesh.cell_mm[1], g_t.mesh.cell_mm[2]}};
    static sc_contact_set cs;
    static uint64_t fr[MAX_FRAMES], co[MAX_FRAMES], cp[MAX_FRAMES];
    double meds[MAX_REPEATS], colls[MAX_REPEATS], cpus[MAX_REPEATS];
    for (int r = 0; r < o->repeats; r++) {
        for (int f = 0; f < o->frames; f++) {
            const uint64_t c0 = cpu_ns();
            const uint64_t t0 = now_ns();
            rc = sc_tissue_step(&g_t, &pose);
            const uint64_t t1 = now_ns();
            cp[f] = cpu_ns() - c0;
            sc_collider_detect(&g_t.collider, &g, g_t.nodes.x, g_t.nodes.y, g_t.nodes.z,
                               g_t.mesh.node_fixed, g_t.stats.max_disp_mm, &cs);
            co[f] = now_ns() - t1;
            fr[f] = t1 - t0;
            if (rc != SC_OK) {
                return rc;
            }
        }
        meds[r] = median_ms(fr, o->frames);
        colls[r] = median_ms(co, o->frames);
        cpus[r] = median_ms(cp, o->frames);
        if (csv) {
            fprintf(csv, "%ux%ux%u,%u,%u,%s,%u,%d,%.4f,%.4f,%.4f\n", mesh[0], mesh[1], mesh[2],
                    g_t.mesh.node_count, g_t.mesh.tet_count, k_method_name[m], (unsigned)workers, r,
                    meds[r], colls[r], cpus[r]);
        }
    }
    qsort(meds, (size_t)o->repeats, sizeof meds[0], cmp_d);
    qsort(colls, (size_t)o->repeats, sizeof colls[0], cmp_d);
    qsort(cpus, (size_t)o->repeats, sizeof cpus[0], cmp_d);
    out->cpu_ms = cpus[0]; /* the least disturbed run */
    out->med_ms = meds[o->repeats / 2];
    out->min_ms = meds[0];
    out->max_ms = meds[o->repeats - 1];
    out->coll_ms = colls[o->repeats / 2];
    out->hash = sc_tissue_state_hash(&g_t);
    out->nodes = g_t.mesh.node_count;
    out->tets = g_t.mesh.tet_count;
    out->contacts = cs.count;
    return 0;
}

int main(int argc, char **argv)
{
    opts o;
    const int prc = parse_args(argc, argv, &o);
    if (prc != 0) {
        return prc;
    }
    FILE *csv = NULL;
    if (o.csv) {
        csv = fopen(o.csv, "w");
        if (!csv) {
            fprintf(stderr, "bench-scale: %s: %s\n", o.csv, strerror(errno));
            return 1;
        }
        fprintf(csv, "mesh,nodes,tets,method,workers,run,median_frame_ms,median_collision_ms,"
                     "median_frame_cpu_ms\n");
    }
    printf("bench-scale: %d runs x %d frames per row, wall clock; median (min..max of the runs' "
           "medians)\n",
           o.repeats, o.frames);
    printf("%-9s %6s %7s %-6s %3s %9s %19s %8s %8s %7s %9s %6s\n", "mesh", "nodes", "tets",
           "method", "w", "frame ms", "spread", "coll ms", "speedup", "60Hz", "cpu ms", "hash");
    int status = 0;
    for (int mi = 0; mi < o.nmesh; mi++) {
        for (int m = 0; m < M_COUNT; m++) {
            if (!o.method_on[m]) {
                continue;
            }
            double one = 0.0;
            uint64_t ref_hash = 0u;
            for (int wi = 0; wi < o.nworkers; wi++) {
                const uint32_t w = o.workers[wi];
                static sc_pool_linux lp;
                sc_pool_dev dev = {0};
                if (w > 1u && sc_pool_linux_start(&lp, w, 0, 200u, &dev) != 0) {
                    fprintf(stderr, "bench-scale: cannot start %u workers\n", (unsigned)w);
                    return 1;
                }
                run_out r;
                const int rc =
                    bench_one(o.mesh[mi], (method)m, w > 1u ? &dev : NULL, &o, &r, csv, w);
                if (w > 1u) {
                    sc_pool_linux_stop(&lp);
                }
                if (rc != 0) {
                    fprintf(stderr, "bench-scale: %ux%ux%u %s: %s\n", o.mesh[mi][0], o.mesh[mi][1],
                            o.mesh[mi][2], k_method_name[m], sc_err_name(rc));
                    status = 1;
                    break;
                }
                if (wi == 0) {
                    one = r.med_ms;
                    ref_hash = r.hash;
                }
                const int same = r.hash == ref_hash;
                status |= !same;
                printf(
                    "%2ux%2ux%2u  %6u %7u %-6s %3u %9.3f %8.3f..%8.3f %8.3f %7.2fx %6.0f%% %9.3f "
                    "%s\n",
                    o.mesh[mi][0], o.mesh[mi][1], o.mesh[mi][2], r.nodes, r.tets, k_method_name[m],
                    (unsigned)w, r.med_ms, r.min_ms, r.max_ms, r.coll_ms, one / r.med_ms,
                    100.0 * (1.0 - r.med_ms / (1000.0 / 60.0)), r.cpu_ms,
                    same ? "same" : "DIFFERS");
                fflush(stdout);
            }
        }
    }
    if (csv) {
        fclose(csv);
    }
    return status;
}
