/* bench_scene.c: see bench_scene.h. */
#include "bench_machine.h"
#include "bench_scene.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_cpu.h"
#include "sc_err.h"
#include "sc_labels.h"
#include "sc_material.h"
#include "sc_pool_linux.h"

const char *const bench_method_name[BENCH_METHODS] = {"msds", "fem", "corot"};

const uint32_t bench_default_mesh[BENCH_DEFAULT_MESHES][3] = {
    {20, 10, 10}, {24, 12, 12}, {28, 14, 14}, {32, 16, 16}, {48, 24, 24}, {64, 32, 32}};

void bench_select_kernels(const char *prog)
{
    if (sc_cpu_select_simd() != SC_OK) {
        fprintf(stderr, "%s: SONOCOMP_SIMD not available here, using %s\n", prog,
                sc_simd_name(sc_simd_selected()));
    }
    printf("kernels: %s\n", sc_simd_name(sc_simd_selected()));
    bench_print_machine();
    bench_select_prefetch(prog);
}

static uint64_t clock_ns(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

uint64_t bench_now_ns(void)
{
    return clock_ns(CLOCK_MONOTONIC);
}

uint64_t bench_cpu_ns(void)
{
    return clock_ns(CLOCK_PROCESS_CPUTIME_ID);
}

uint64_t bench_thread_cpu_ns(void)
{
    return clock_ns(CLOCK_THREAD_CPUTIME_ID);
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

int bench_cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double bench_median_ms(uint64_t *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmp_u64);
    return (n % 2) ? (double)v[n / 2] / 1e6 : (double)(v[n / 2 - 1] + v[n / 2]) / 2e6;
}

double bench_median_d(double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], bench_cmp_d);
    return (n % 2) ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2.0;
}

int bench_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out, char **end)
{
    errno = 0;
    const unsigned long v = strtoul(s, end, 10);
    if (errno || *end == s || s[0] == '-' || s[0] == '+' || s[0] == ' ' || v < lo || v > hi) {
        return -1;
    }
    *out = (uint32_t)v;
    return 0;
}

int bench_parse_workers(const char *v, uint32_t max_workers, uint32_t *out, int max, int *n)
{
    *n = 0;
    const char *s = v;
    if (!*s) {
        return -1;
    }
    while (*s) {
        char *end = NULL;
        uint32_t u;
        if (*n == max || bench_parse_u32(s, 1u, max_workers, &u, &end)) {
            return -1;
        }
        out[(*n)++] = u;
        if (*end && *end != ',') {
            return -1;
        }
        s = *end == ',' ? end + 1 : end;
    }
    return 0;
}

int bench_parse_meshes(const char *v, uint32_t (*out)[3], int max, int *n)
{
    *n = 0;
    const char *s = v;
    if (!*s) {
        return -1;
    }
    while (*s) {
        if (*n == max) {
            return -1;
        }
        uint32_t *d = out[*n];
        const uint32_t maxd[3] = {SC_MAX_MESH_NX, SC_MAX_MESH_NY, SC_MAX_MESH_NZ};
        for (int k = 0; k < 3; k++) {
            char *end = NULL;
            if (bench_parse_u32(s, 2u, maxd[k], &d[k], &end) || (k < 2 && *end != 'x')) {
                return -1;
            }
            s = k < 2 ? end + 1 : end;
        }
        (*n)++;
        if (*s == ',') {
            s++;
        } else if (*s) {
            return -1;
        }
    }
    return 0;
}

void bench_opts_default(bench_opts *o, int frames, const int on[BENCH_METHODS])
{
    memset(o, 0, sizeof *o);
    o->frames = frames;
    o->repeats = 5;
    o->workers[0] = 1u;
    o->workers[1] = 2u;
    o->nworkers = 2;
    for (int i = 0; i < BENCH_DEFAULT_MESHES; i++) {
        memcpy(o->mesh[i], bench_default_mesh[i], sizeof bench_default_mesh[i]);
    }
    o->nmesh = BENCH_DEFAULT_MESHES;
    for (int m = 0; m < BENCH_METHODS; m++) {
        o->method_on[m] = on[m];
    }
}

int bench_opts_parse(bench_opts *o, const char *a, const char *v)
{
    char *end = NULL;
    uint32_t u;
    if (strcmp(a, "--frames") == 0) {
        if (bench_parse_u32(v, 1u, BENCH_MAX_FRAMES, &u, &end) || *end) {
            return -1;
        }
        o->frames = (int)u;
    } else if (strcmp(a, "--repeats") == 0) {
        if (bench_parse_u32(v, 1u, BENCH_MAX_REPEATS, &u, &end) || *end) {
            return -1;
        }
        o->repeats = (int)u;
    } else if (strcmp(a, "--workers") == 0) {
        if (bench_parse_workers(v, SC_POOL_LINUX_MAX_WORKERS, o->workers, BENCH_MAX_LIST,
                                &o->nworkers)) {
            return -1;
        }
    } else if (strcmp(a, "--meshes") == 0) {
        if (bench_parse_meshes(v, o->mesh, BENCH_MAX_LIST, &o->nmesh)) {
            return -1;
        }
    } else if (strcmp(a, "--methods") == 0) {
        int any = 0;
        for (int m = 0; m < BENCH_METHODS; m++) {
            o->method_on[m] = strstr(v, bench_method_name[m]) != NULL;
            any |= o->method_on[m];
        }
        if (!any) {
            return -1;
        }
    } else {
        return 0;
    }
    return 1;
}

int bench_scene_press(sc_tissue *t, sc_test_scene *sc, const uint32_t mesh[3], bench_method m,
                      const sc_pool_dev *pool, sc_pose *hold, sc_collider_grid *grid)
{
    sc_test_scene_params p = sc_test_scene_default_params();
    p.nx = mesh[0];
    p.ny = mesh[1];
    p.nz = mesh[2];
    sc_test_scene_build(sc, &p);
    sc_tissue_def d =
        sc_test_scene_tissue_def(sc, m == BENCH_MSDS ? SC_TISSUE_MSDS : SC_TISSUE_FEM);
    d.skin_enabled = 0u;
    d.fem.corotated = m == BENCH_COROT ? 1u : 0u;
    sc_material_table mat;
    sc_material_table_default(&mat);
    int rc = sc_tissue_build_begin(t, &d, &sc->vol, &mat, SC_LABEL_FAT);
    if (rc != SC_OK) {
        return rc;
    }
    sc_tissue_set_pool(t, pool);
    while ((rc = sc_tissue_build_step(t)) == SC_OK) {
    }
    if (rc != 1) {
        return rc;
    }
    for (int f = 0; f < 30; f++) {
        const sc_pose q = sc_test_scene_probe(sc, -0.5f + 3.5f * (float)(f + 1) / 30.0f);
        (void)sc_tissue_step(t, &q);
    }
    *hold = sc_test_scene_probe(sc, 3.0f);
    const sc_collider_grid g = {t->mesh.nx,
                                t->mesh.ny,
                                t->mesh.nz,
                                {t->mesh.origin_mm[0], t->mesh.origin_mm[1], t->mesh.origin_mm[2]},
                                {t->mesh.cell_mm[0], t->mesh.cell_mm[1], t->mesh.cell_mm[2]}};
    *grid = g;
    return SC_OK;
}
