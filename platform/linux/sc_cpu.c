/* sc_cpu.c: the host CPU's kernel variant; see sc_cpu.h. */
#include "sc_cpu.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_err.h"
#include "sc_grid.h"
#include "sc_grid_kern.h"

#if defined(__x86_64__) && defined(__clang__) && __clang_major__ < 16
/* Clang before 16 knows no level names: the features the kernels' code generation uses (the
 * vector ISA and FMA, BMI for the scalar glue); Clang checks the OS's vector state for AVX
 * and AVX-512 as GCC does */
#define SC_CPU_HAS_V3()                                                                            \
    (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&                           \
     __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2"))
#define SC_CPU_HAS_V4()                                                                            \
    (SC_CPU_HAS_V3() && __builtin_cpu_supports("avx512f") &&                                     \
     __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&                  \
     __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
#elif defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
/* the level names test every feature of the level, and, for AVX and AVX-512, that the OS
 * saves the vector state (GCC and Clang check xgetbv) */
#define SC_CPU_HAS_V3() __builtin_cpu_supports("x86-64-v3")
#define SC_CPU_HAS_V4() __builtin_cpu_supports("x86-64-v4")
#endif

sc_simd sc_cpu_best_simd(void)
{
#ifdef SC_CPU_HAS_V4
    if (sc_simd_built(SC_SIMD_X86_64_V4) && SC_CPU_HAS_V4()) {
        return SC_SIMD_X86_64_V4;
    }
    if (sc_simd_built(SC_SIMD_X86_64_V3) && SC_CPU_HAS_V3()) {
        return SC_SIMD_X86_64_V3;
    }
#endif
    return SC_SIMD_GENERIC;
}

int sc_cpu_select_simd(void)
{
    const sc_simd best = sc_cpu_best_simd();
    const char *want = getenv("SONOCOMP_SIMD");
    if (want == NULL || want[0] == '\0') {
        return sc_simd_select(best);
    }
    for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
        /* a level up to the best one (the levels are nested) */
        if (strcmp(want, sc_simd_name((sc_simd)v)) == 0 && v <= (int)best) {
            return sc_simd_select((sc_simd)v);
        }
    }
    (void)sc_simd_select(best);
    return SC_ERR_INVALID_ARG;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

#if SC_GRID_COARSE
/* A box grid's matrix rows, masses and p filled with a stiffness pattern (a diagonally dominant
 * K, normal floats throughout: no denormal slows either run). */
static void fill_box(sc_grid *g)
{
    const uint32_t h = SC_GRID_HEAD, nn = g->node_count;
    float *rows = &g->d[0][0];
    for (uint32_t k = 0; k < SC_GRID_MAT_ROWS; k++) {
        float *row = rows + (size_t)k * SC_GRID_ROW + h;
        /* d: xx yy zz 6, the rest 0.1; e, f: the axis entries (0, 4, 8 of 9) -1, the rest 0.05 */
        const int diag = k < 6u ? (k == 0u || k == 3u || k == 5u) : ((k - 6u) % 9u) % 4u == 0u;
        const float v = k < 6u ? (diag ? 6.0f : 0.1f) : (diag ? -1.0f : 0.05f);
        for (uint32_t t = 0; t < nn; t++) {
            row[t] = v;
        }
    }
    for (uint32_t t = 0; t < nn; t++) {
        g->mass[h + t] = 1.0e-3f;
        g->p[0][h + t] = 1.0f + (float)(t % 7u) * 0.125f;
        g->p[1][h + t] = 0.5f - (float)(t % 5u) * 0.0625f;
        g->p[2][h + t] = -0.25f + (float)(t % 3u) * 0.25f;
    }
}

/* the fastest of `n` mat-vecs with prefetch p selected */
static double time_matvec(sc_grid *g, sc_simd_prefetch p, int n)
{
    const sc_grid_kern *k = sc_grid_kern_selected();
    (void)sc_simd_select_prefetch(p);
    double best = 1e30;
    for (int i = 0; i < n; i++) {
        const double t0 = now_ms();
        k->matvec(g, 1.0f, 1.0e-2f);
        const double dt = now_ms() - t0;
        best = dt < best ? dt : best;
    }
    return best;
}
#endif

int sc_cpu_select_prefetch(int measure, sc_cpu_prefetch *out)
{
    sc_cpu_prefetch r;
    memset(&r, 0, sizeof r);
    r.chosen = SC_SIMD_PREFETCH_MESH;
    int rc = SC_OK;
    const char *want = getenv("SONOCOMP_PREFETCH");
    if (want != NULL && want[0] != '\0') {
        int found = 0;
        for (int p = 0; p < (int)SC_SIMD_PREFETCH_COUNT; p++) {
            if (strcmp(want, sc_simd_prefetch_name((sc_simd_prefetch)p)) == 0) {
                r.chosen = (sc_simd_prefetch)p;
                found = 1;
            }
        }
        rc = found ? SC_OK : SC_ERR_INVALID_ARG;
        r.forced = found;
        measure = 0;
    }
#if SC_GRID_COARSE
    if (measure) {
        sc_grid *g = calloc(1, sizeof *g);
        if (g == NULL) {
            rc = SC_ERR_NO_SPACE;
        } else {
            r.nx = SC_MAX_MESH_NX < 64u ? SC_MAX_MESH_NX : 64u;
            r.ny = SC_MAX_MESH_NY < 32u ? SC_MAX_MESH_NY : 32u;
            r.nz = SC_MAX_MESH_NZ < 32u ? SC_MAX_MESH_NZ : 32u;
            const float origin[3] = {0.0f, 0.0f, 0.0f}, cell[3] = {1.0f, 1.0f, 1.0f};
            if (sc_grid_init_box(g, r.nx, r.ny, r.nz, origin, cell) == SC_OK) {
                fill_box(g);
                g->prefetch = 1u; /* the mesh rule's value at 64x32x32 (ON and OFF override it) */
                (void)time_matvec(g, SC_SIMD_PREFETCH_OFF, 2); /* pages and caches warm */
                r.on_ms = r.off_ms = 1e30;
                for (int round = 0; round < 6; round++) {
                    const double on = time_matvec(g, SC_SIMD_PREFETCH_ON, 2);
                    const double off = time_matvec(g, SC_SIMD_PREFETCH_OFF, 2);
                    r.on_ms = on < r.on_ms ? on : r.on_ms;
                    r.off_ms = off < r.off_ms ? off : r.off_ms;
                }
                r.measured = 1;
                /* a prefetch that pays at 64x32x32 stays with the mesh rule (on above 8,192
                 * nodes), not on every mesh: the L2-resident meshes lost by it on the EPYCs */
                if (r.off_ms < r.on_ms * (1.0 - SC_CPU_PREFETCH_MARGIN)) {
                    r.chosen = SC_SIMD_PREFETCH_OFF;
                }
            }
            free(g);
        }
    }
#else
    (void)measure;
#endif
    (void)sc_simd_select_prefetch(r.chosen);
    if (out != NULL) {
        *out = r;
    }
    return rc;
}

void sc_cpu_prefetch_describe(const sc_cpu_prefetch *p, char *buf, unsigned size)
{
    if (buf == NULL || size == 0u) {
        return;
    }
    if (p == NULL) {
        buf[0] = '\0';
        return;
    }
    if (p->measured) {
        snprintf(buf, size,
                 "mat-vec prefetch %s (measured on %ux%ux%u: %.3f ms without, %.3f ms with)",
                 sc_simd_prefetch_name(p->chosen), p->nx, p->ny, p->nz, p->off_ms, p->on_ms);
    } else {
        snprintf(buf, size, "mat-vec prefetch %s (not measured%s)",
                 sc_simd_prefetch_name(p->chosen),
                 p->forced ? ": SONOCOMP_PREFETCH" : "");
    }
}
