/* test_sc_bscan_kern.c: the B-scan's span sampler gives the same bytes in every variant
 * (sc_bscan_kern.h): random spans (every direction, lengths with and without a remainder of 8,
 * positions up to both ends of every axis) through a random volume with and without labels,
 * generic against each variant this build and CPU have. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan_kern.h"
#include "sc_cpu.h"
#include "sc_err.h"
#include "sc_simd.h"

enum { NX = 37, NY = 29, NZ = 23, N = 600 };

static uint8_t g_vox[NX * NY * NZ];
static uint8_t g_lab[NX * NY * NZ];
static int64_t g_lut[N];
static uint32_t g_rng = 12345u;

static uint32_t rnd(void)
{
    g_rng = g_rng * 1664525u + 1013904223u;
    return g_rng >> 8;
}

/* a position in [0, xm] of 32.32 */
static int64_t pos(int64_t xm)
{
    const uint32_t r = rnd() % 16u;
    if (r == 0u) {
        return 0;
    }
    if (r == 1u) {
        return xm;
    }
    return (int64_t)(((uint64_t)rnd() << 24 | rnd()) % (uint64_t)(xm + 1));
}

static void fill(void)
{
    for (uint32_t i = 0; i < NX * NY * NZ; i++) {
        g_vox[i] = (uint8_t)rnd();
        g_lab[i] = (uint8_t)(rnd() % (uint32_t)SC_LABEL_COUNT);
    }
    for (uint32_t k = 0; k < N; k++) {
        /* the display table's range: gain, TGC and range of sc_bscan_def */
        g_lut[k] = ((int64_t)(rnd() % 600000u) - 300000) * 65536;
    }
}

/* spans of random length and direction, every sample inside [0, xmax] */
static uint32_t compare(sc_bscan_span_fn f, int with_labels, int64_t la)
{
    const int64_t xm[3] = {((int64_t)(NX - 1) << 32) - 1 - SC_W_HALF,
                           ((int64_t)(NY - 1) << 32) - 1 - SC_W_HALF,
                           ((int64_t)(NZ - 1) << 32) - 1 - SC_W_HALF};
    const vol_regs v = {g_vox, with_labels ? g_lab : NULL, NX, (size_t)NX * NY, la};
    uint32_t spans = 0;
    for (uint32_t it = 0; it < 3000u; it++) {
        const uint32_t len = 1u + rnd() % (it % 3u == 0u ? 20u : 400u);
        const uint32_t k0 = rnd() % (N - len);
        int64_t p0[3], p1[3], d[3];
        for (int a = 0; a < 3; a++) {
            p0[a] = pos(xm[a]);
            p1[a] = rnd() % 8u == 0u ? p0[a] : pos(xm[a]);
            d[a] = len > 1u ? (p1[a] - p0[a]) / (int64_t)(len - 1u) : 0;
        }
        uint8_t o1[N], l1[N], o2[N], l2[N];
        memset(o1, 0xa5, sizeof o1);
        memset(l1, 0xa5, sizeof l1);
        memset(o2, 0xa5, sizeof o2);
        memset(l2, 0xa5, sizeof l2);
        sc_bscan_span_generic(v, g_lut, k0, k0 + len, p0[0], p0[1], p0[2], d[0], d[1], d[2], o1,
                              l1);
        f(v, g_lut, k0, k0 + len, p0[0], p0[1], p0[2], d[0], d[1], d[2], o2, l2);
        assert_memory_equal(o1, o2, sizeof o1);
        assert_memory_equal(l1, l2, sizeof l1);
        spans++;
    }
    return spans;
}

static void test_variants_agree(void **state)
{
    (void)state;
    fill();
    const sc_simd keep = sc_simd_selected();
    const sc_simd best = sc_cpu_best_simd();
    uint32_t tried = 0;
    for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
        if (!sc_simd_built((sc_simd)s) || s > (int)best) {
            continue;
        }
        assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
        const sc_bscan_span_fn f = sc_bscan_span_selected();
        assert_non_null(f);
        /* lut_a 1 (volume shown unchanged) and 12 (120 dB over 10) */
        assert_int_equal(compare(f, 1, 65536), 3000u);
        assert_int_equal(compare(f, 0, 65536), 3000u);
        assert_int_equal(compare(f, 1, 12 * 65536), 3000u);
        tried++;
    }
    (void)sc_simd_select(keep);
    print_message("span sampler variants compared with the generic one: %u\n", tried);
    assert_true(tried >= 1u);
}

/* The line sampler from position words (one call per line) against the span sampler on the
 * same spans, and every variant's words and line sampler against the generic ones: random lines
 * made of random spans (lengths 1..40, every direction, up to both ends of every axis). */
static uint32_t g_h[3][N + 8];
static uint32_t g_hv[3][N + 8];

static void test_line_sampler_equals_span_sampler(void **state)
{
    (void)state;
    fill();
    const int64_t xm[3] = {((int64_t)(NX - 1) << 32) - 1 - SC_W_HALF,
                           ((int64_t)(NY - 1) << 32) - 1 - SC_W_HALF,
                           ((int64_t)(NZ - 1) << 32) - 1 - SC_W_HALF};
    const sc_simd keep = sc_simd_selected();
    const sc_simd best = sc_cpu_best_simd();
    uint32_t lines = 0;
    for (uint32_t it = 0; it < 600u; it++) {
        const vol_regs v = {g_vox, it % 3u == 0u ? NULL : g_lab, NX, (size_t)NX * NY,
                            it % 2u == 0u ? 65536 : 12 * 65536};
        const uint32_t n = 1u + rnd() % N;
        uint8_t o1[N], l1[N], o2[N], l2[N];
        /* the reference: span by span */
        uint32_t k = 0;
        memset(g_h, 0, sizeof g_h);
        while (k < n) {
            uint32_t len = 1u + rnd() % 40u;
            len = len > n - k ? n - k : len;
            int64_t p0[3], p1[3], d[3];
            for (int a = 0; a < 3; a++) {
                p0[a] = pos(xm[a]);
                p1[a] = pos(xm[a]);
                d[a] = len > 1u ? (p1[a] - p0[a]) / (int64_t)(len - 1u) : 0;
            }
            sc_bscan_span_generic(v, g_lut, k, k + len, p0[0], p0[1], p0[2], d[0], d[1], d[2], o1,
                                  l1);
            sc_bscan_words_generic(g_h[0], g_h[1], g_h[2], k, k + len, p0[0], p0[1], p0[2], d[0],
                                   d[1], d[2]);
            for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
                if (!sc_simd_built((sc_simd)s) || s > (int)best) {
                    continue;
                }
                assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
                memset(g_hv, 0xa5, sizeof g_hv);
                sc_bscan_words_selected()(g_hv[0], g_hv[1], g_hv[2], k, k + len, p0[0], p0[1],
                                          p0[2], d[0], d[1], d[2]);
                for (int a = 0; a < 3; a++) {
                    assert_memory_equal(&g_h[a][k], &g_hv[a][k], len * sizeof(uint32_t));
                }
            }
            k += len;
        }
        for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
            if (!sc_simd_built((sc_simd)s) || s > (int)best) {
                continue;
            }
            assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
            memset(o2, 0x5a, sizeof o2);
            memset(l2, 0x5a, sizeof l2);
            sc_bscan_line_selected()(v, g_lut, n, g_h[0], g_h[1], g_h[2], o2, l2);
            assert_memory_equal(o1, o2, n);
            assert_memory_equal(l1, l2, n);
        }
        lines++;
    }
    (void)sc_simd_select(keep);
    assert_int_equal(lines, 600u);
}

/* The generic sampler against the formula: a voxel centre gives the voxel, the midpoint of two
 * gives their mean rounded, the label is the nearest voxel's. */
static void test_generic_values(void **state)
{
    (void)state;
    fill();
    const vol_regs v = {g_vox, g_lab, NX, (size_t)NX * NY, 65536};
    /* out = (lut_a I + B) >> 26 with I = value * 1024 and lut_a = 1: B = 1/2 grey rounds */
    const int64_t lut[2] = {(int64_t)1 << 25, (int64_t)1 << 25};
    uint8_t o[2], l[2];
    const uint32_t i = 5, j = 7, k = 9;
    const size_t at = i + (size_t)NX * (j + (size_t)NY * k);
    sc_bscan_span_generic(v, lut, 0, 1, (int64_t)i << 32, (int64_t)j << 32, (int64_t)k << 32, 0,
                          0, 0, o, l);
    assert_int_equal(l[0], g_lab[at]);
    if (g_lab[at] != SC_LABEL_OUTSIDE) {
        assert_int_equal(o[0], g_vox[at]);
    }
    /* halfway between voxels i and i + 1 along x: their mean, rounded half up; the label
     * of the voxel at or past the middle (i + 1) */
    sc_bscan_span_generic(v, lut, 0, 1, ((int64_t)i << 32) + ((int64_t)1 << 31), (int64_t)j << 32,
                          (int64_t)k << 32, 0, 0, 0, o, l);
    assert_int_equal(l[0], g_lab[at + 1u]);
    if (g_lab[at + 1u] != SC_LABEL_OUTSIDE) {
        assert_int_equal(o[0], (g_vox[at] + g_vox[at + 1u] + 1) / 2);
    }
}

/* The acoustics pass's run kernel (sc_acoustics.h): every variant against the generic one on
 * random runs (lengths 0..600, with and without a remainder of 16; zero samples among them;
 * base and step up to the +-2^29 the caller keeps), and the generic one against the formula
 * in 64-bit arithmetic. */
static uint8_t g_run_in[N], g_run_g[N], g_run_v[N];

static uint8_t shade_ref(uint32_t o, int64_t v)
{
    if (o == 0u || v <= 0) {
        return 0u;
    }
    return v >= ((int64_t)255 << 16) ? 255u : (uint8_t)((v + 32768) >> 16);
}

static void test_acoustics_run_variants_agree(void **state)
{
    (void)state;
    const sc_simd keep = sc_simd_selected();
    const sc_simd best = sc_cpu_best_simd();
    uint32_t tried = 0, differ = 0;
    for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
        if (!sc_simd_built((sc_simd)s) || s > (int)best) {
            continue;
        }
        assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
        const sc_acoustics_run_fn f = sc_acoustics_run_selected();
        assert_non_null(f);
        for (uint32_t it = 0; it < 2000u; it++) {
            const uint32_t len = it % 7u == 0u ? 16u * (rnd() % 38u) : rnd() % (N + 1u);
            /* a step up to 2^28 / len (one in 8: up to 16 grey levels per sample) */
            const int32_t lim = (int32_t)1 << 29;
            const int32_t smax = len > 1u ? (int32_t)((uint32_t)lim / len) : lim;
            const int32_t sm = rnd() % 8u == 0u ? smax : (smax < (1 << 20) ? smax : (1 << 20));
            const int32_t step = (int32_t)(rnd() % (uint32_t)(2 * sm + 1)) - sm;
            /* base such that base and base - (len - 1) step are both within +-2^29 */
            const int64_t span = (int64_t)(len > 0u ? len - 1u : 0u) * step;
            const int64_t lo = span > 0 ? -lim + span : -lim, hi = span > 0 ? lim : lim + span;
            const int64_t wide = rnd() % 4u == 0u ? hi - lo : ((int64_t)600 << 16);
            const int64_t mid = rnd() % 2u == 0u ? (lo + hi) / 2 : (int64_t)(rnd() % (256u << 16));
            int64_t base = mid - wide / 2 + (int64_t)(((uint64_t)rnd() << 8) % (uint64_t)(wide + 1));
            base = base < lo ? lo : (base > hi ? hi : base);
            for (uint32_t i = 0; i < len; i++) {
                const uint32_t r = rnd();
                g_run_in[i] = (uint8_t)(r % 5u == 0u ? 0u : (r >> 4) & 255u);
            }
            memcpy(g_run_g, g_run_in, len);
            memcpy(g_run_v, g_run_in, len);
            sc_acoustics_run_generic(g_run_g, len, (int32_t)base, step);
            f(g_run_v, len, (int32_t)base, step);
            for (uint32_t i = 0; i < len; i++) {
                const uint8_t want =
                    shade_ref(g_run_in[i], ((int64_t)g_run_in[i] << 16) + base - (int64_t)i * step);
                assert_int_equal(g_run_g[i], want);
                differ += g_run_in[i] != want;
            }
            assert_memory_equal(g_run_v, g_run_g, len);
        }
        tried++;
    }
    (void)sc_simd_select(keep);
    print_message("acoustics run kernel variants compared with the generic one: %u\n", tried);
    assert_true(tried >= 1u);
    assert_true(differ > 1000u); /* the runs changed samples */
}

/* The rest labels of a clear run (32.32 positions, integer parts): every variant against the
 * generic kernel on random runs inside the grid (lengths 1..300, every direction). */
static void test_nearest_variants_agree(void **state)
{
    (void)state;
    fill();
    const sc_simd keep = sc_simd_selected();
    const sc_simd best = sc_cpu_best_simd();
    const int64_t xm[3] = {((int64_t)NX << 32) - 1, ((int64_t)NY << 32) - 1,
                           ((int64_t)NZ << 32) - 1};
    uint32_t tried = 0;
    for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
        if (!sc_simd_built((sc_simd)s) || s > (int)best) {
            continue;
        }
        assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
        const sc_bscan_nearest_fn f = sc_bscan_nearest_selected();
        assert_non_null(f);
        uint32_t varied = 0;
        for (uint32_t it = 0; it < 3000u; it++) {
            const uint32_t len = 1u + rnd() % (it % 3u == 0u ? 20u : 300u);
            int64_t p0[3], d[3];
            for (int a = 0; a < 3; a++) {
                p0[a] = pos(xm[a]);
                const int64_t p1 = rnd() % 8u == 0u ? p0[a] : pos(xm[a]);
                d[a] = len > 1u ? (p1 - p0[a]) / (int64_t)(len - 1u) : 0;
            }
            uint8_t o1[N], o2[N];
            memset(o1, 0xa5, sizeof o1);
            memset(o2, 0xa5, sizeof o2);
            sc_bscan_labels_nearest(g_lab, NX, (size_t)NX * NY, o1, len, p0[0], p0[1], p0[2], d[0],
                                    d[1], d[2]);
            f(g_lab, NX, (size_t)NX * NY, o2, len, p0[0], p0[1], p0[2], d[0], d[1], d[2]);
            assert_memory_equal(o1, o2, sizeof o1);
            for (uint32_t k = 1; k < len; k++) {
                if (o1[k] != o1[0]) {
                    varied++;
                    break;
                }
            }
        }
        assert_true(varied > 1000u); /* runs crossing several labels */
        tried++;
    }
    (void)sc_simd_select(keep);
    print_message("rest-label kernel variants compared with the generic one: %u\n", tried);
    assert_true(tried >= 1u);
}

/* The rest reference above the face: the generic kernel against label_at's formula written out
 * here, and every variant against the generic one, on random lines through, beside and far
 * outside the grid (and a direction that is not a number). */
static float frnd(float lo, float hi)
{
    return lo + (hi - lo) * (float)(rnd() & 0xffffu) / 65535.0f;
}

static void test_margin_variants_agree(void **state)
{
    (void)state;
    fill();
    const uint32_t dim[3] = {NX, NY, NZ};
    const sc_simd keep = sc_simd_selected();
    const sc_simd best = sc_cpu_best_simd();
    uint32_t tried = 0, inside = 0, outside = 0;
    for (int s = 0; s < (int)SC_SIMD_COUNT; s++) {
        if (!sc_simd_built((sc_simd)s) || s > (int)best) {
            continue;
        }
        assert_int_equal(sc_simd_select((sc_simd)s), SC_OK);
        const sc_bscan_margin_fn f = sc_bscan_margin_selected();
        assert_non_null(f);
        for (uint32_t it = 0; it < 3000u; it++) {
            const uint32_t n = rnd() % 80u, j0 = 4u * (rnd() % 64u);
            float f0[3], fd[3];
            for (int a = 0; a < 3; a++) {
                f0[a] = frnd(-4.0f, (float)dim[a] + 4.0f);
                fd[a] = frnd(-0.3f, 0.3f);
                if (rnd() % 16u == 0u) {
                    f0[a] = (float)(rnd() % dim[a]) - 0.5f; /* on the lower boundary */
                    fd[a] = 0.0f;
                }
            }
            if (it == 7u) {
                fd[1] = NAN; /* not a number: outside */
            }
            uint8_t o1[N], o2[N];
            memset(o1, 0xa5, sizeof o1);
            memset(o2, 0xa5, sizeof o2);
            sc_bscan_margin_labels_generic(g_lab, dim, f0, fd, j0, n, o1);
            f(g_lab, dim, f0, fd, j0, n, o2);
            assert_memory_equal(o1, o2, sizeof o1);
            for (uint32_t i = 0; i < n; i++) {
                const float t = -(float)(j0 + 4u * i + 2u);
                const float p[3] = {f0[0] + t * fd[0], f0[1] + t * fd[1], f0[2] + t * fd[2]};
                uint8_t want = (uint8_t)SC_LABEL_OUTSIDE;
                if (p[0] >= -0.5f && p[0] < (float)NX - 0.5f && p[1] >= -0.5f &&
                    p[1] < (float)NY - 0.5f && p[2] >= -0.5f && p[2] < (float)NZ - 0.5f) {
                    const uint32_t x = (uint32_t)(p[0] + 0.5f), y = (uint32_t)(p[1] + 0.5f),
                                   z = (uint32_t)(p[2] + 0.5f);
                    want = g_lab[x + NX * (y + NY * z)];
                    inside++;
                } else {
                    outside++;
                }
                assert_int_equal(o1[i], want);
            }
        }
        tried++;
    }
    (void)sc_simd_select(keep);
    print_message("margin label variants compared with the generic one: %u (%u in, %u out)\n",
                  tried, inside, outside);
    assert_true(tried >= 1u);
    /* per variant compared (one where only the generic kernel is built, e.g. aarch64) */
    assert_true(inside > 4000u * tried && outside > 4000u * tried);
}

/* The margin's near range: every block outside it is labelled SC_LABEL_OUTSIDE by the generic
 * kernel (so skipping it changes no count), on random lines through, beside and far outside the
 * grid; and the range does cut most blocks of lines that leave the grid. */
static void test_margin_near_range_only_skips_outside_blocks(void **state)
{
    (void)state;
    fill();
    const uint32_t dim[3] = {NX, NY, NZ};
    uint32_t skipped = 0, labelled = 0, inside = 0;
    static uint8_t o[1200];
    for (uint32_t it = 0; it < 20000u; it++) {
        const uint32_t blocks = rnd() % 1200u;
        float f0[3], fd[3];
        for (int a = 0; a < 3; a++) {
            f0[a] = frnd(-30.0f, (float)dim[a] + 30.0f);
            fd[a] = it % 5u == 0u ? frnd(-2.0f, 2.0f) : frnd(-0.3f, 0.3f);
            if (rnd() % 16u == 0u) {
                f0[a] = (float)(rnd() % dim[a]) - 0.5f;
                fd[a] = 0.0f;
            }
            if (rnd() % 64u == 0u) {
                f0[a] = frnd(-1.0e6f, 1.0e6f); /* far out: the whole range */
            }
        }
        if (it == 11u) {
            fd[2] = NAN;
        }
        uint32_t lo = 0, hi = 0;
        sc_bscan_margin_near(dim, f0, fd, blocks, &lo, &hi);
        assert_true(lo <= hi && hi <= blocks);
        sc_bscan_margin_labels_generic(g_lab, dim, f0, fd, 0u, blocks, o);
        for (uint32_t i = 0; i < blocks; i++) {
            if (i < lo || i >= hi) {
                assert_int_equal(o[i], SC_LABEL_OUTSIDE);
                skipped++;
            } else {
                labelled++;
            }
        }
        /* a block whose label is not OUTSIDE is inside the grid: in the range */
        for (uint32_t i = 0; i < blocks; i++) {
            inside += o[i] != (uint8_t)SC_LABEL_OUTSIDE;
        }
    }
    print_message("margin blocks: %u skipped, %u labelled (%u inside)\n", skipped, labelled,
                  inside);
    assert_true(skipped > 4u * labelled); /* most of these lines leave the small grid */
    assert_true(inside > 10000u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_variants_agree),
        cmocka_unit_test(test_line_sampler_equals_span_sampler),
        cmocka_unit_test(test_generic_values),
        cmocka_unit_test(test_acoustics_run_variants_agree),
        cmocka_unit_test(test_nearest_variants_agree),
        cmocka_unit_test(test_margin_variants_agree),
        cmocka_unit_test(test_margin_near_range_only_skips_outside_blocks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
