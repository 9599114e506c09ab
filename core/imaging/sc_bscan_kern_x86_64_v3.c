/* sc_bscan_kern_x86_64_v3.c: the span sampler for the x86-64-v3 level (AVX2), built with
 * -march=x86-64-v3 where the compiler takes it (SC_SIMD_X86_64_V3_BUILT); elsewhere this unit is
 * empty. Eight samples at a time: the positions stepped exactly in 32-bit lanes (the 32.32
 * position split at bit 22 into the part the sampler reads, voxel index and 10-bit weight, and
 * the 22 bits below, whose carry is added), the 2x2 neighbour pairs and the label gathered, the
 * same integer arithmetic as sc_bscan_sample_fx lane by lane: the same bytes. */
#if defined(SC_SIMD_X86_64_V3_BUILT)
#include <immintrin.h>
#include <string.h>

#include "sc_bscan_kern.h"

#define SC_LOW_BITS (32 - SC_W_BITS) /* 22: below the weight */
#define SC_LOW_MASK ((1 << SC_LOW_BITS) - 1)
/* The line sampler prefetches the 2x2 voxel rows of the sample this many ahead (its first lane;
 * a vector's 8 samples span about a voxel). A hint: no result changes. `bench_bscan contact
 * /tmp/cases neck-ijv-32 60 msds`, three alternated pairs, the rigid pose's imaging min 0.996-0.998
 * -> 0.960-0.970 ms, the walker's 1.78 -> 1.75 ms; 8 ahead the same, 32 half of it, 96 slower;
 * the label's line as well bought nothing. */
#ifndef SC_LINE_PREFETCH
#define SC_LINE_PREFETCH 16u
#endif

/* 8 lanes of one axis: hi = position >> 22 (index << 10 | weight), lo = the 22 bits below */
typedef struct lanes {
    __m256i hi, lo, dhi, dlo;
} lanes;

/* the 8 lanes' positions x + HALF + j d (j = 0..7) split at bit 22, in vector registers (a
 * scalar fill read back as a vector stalls on the store forwarding: a span is often short).
 * Lanes past the span may hold anything (their results are never used); the others are >= 0,
 * where the logical shift is the arithmetic one. */
static inline __m256i pack_lo32(__m256i a, __m256i b)
{
    const __m256i sel = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
    return _mm256_blend_epi32(_mm256_permutevar8x32_epi32(a, sel),
                              _mm256_permutevar8x32_epi32(b, sel), 0xf0);
}

static inline lanes lanes_init(int64_t x, int64_t d)
{
    const __m256i p0 =
        _mm256_add_epi64(_mm256_set1_epi64x(x + SC_W_HALF), _mm256_setr_epi64x(0, d, 2 * d, 3 * d));
    const __m256i p1 = _mm256_add_epi64(p0, _mm256_set1_epi64x(4 * d));
    const __m256i m = _mm256_set1_epi64x(SC_LOW_MASK);
    const int64_t d8 = 8 * d;
    lanes l;
    l.hi = pack_lo32(_mm256_srli_epi64(p0, SC_LOW_BITS), _mm256_srli_epi64(p1, SC_LOW_BITS));
    l.lo = pack_lo32(_mm256_and_si256(p0, m), _mm256_and_si256(p1, m));
    l.dhi = _mm256_set1_epi32((int32_t)(d8 >> SC_LOW_BITS)); /* floor: exact split */
    l.dlo = _mm256_set1_epi32((int32_t)(d8 & SC_LOW_MASK));
    return l;
}

static inline void lanes_step(lanes *l)
{
    const __m256i lo = _mm256_add_epi32(l->lo, l->dlo); /* < 2^23 */
    l->hi = _mm256_add_epi32(_mm256_add_epi32(l->hi, l->dhi), _mm256_srli_epi32(lo, SC_LOW_BITS));
    l->lo = _mm256_and_si256(lo, _mm256_set1_epi32(SC_LOW_MASK));
}

/* one level of the interpolation: (a * 1024 + t * (b - a) + 512) >> 10 */
static inline __m256i lerp(__m256i a, __m256i b, __m256i t)
{
    const __m256i s = _mm256_add_epi32(_mm256_slli_epi32(a, SC_W_BITS),
                                       _mm256_mullo_epi32(t, _mm256_sub_epi32(b, a)));
    return _mm256_srai_epi32(_mm256_add_epi32(s, _mm256_set1_epi32(SC_W_ONE / 2)), SC_W_BITS);
}

/* the first interpolation level from a gathered dword: byte `sh`/8 and the next one */
static inline __m256i pair_level(__m256i g, int sh, __m256i tx)
{
    const __m256i m = _mm256_set1_epi32(0xff);
    const __m256i a = _mm256_and_si256(_mm256_srli_epi32(g, sh), m);
    const __m256i b = _mm256_and_si256(_mm256_srli_epi32(g, sh + 8), m);
    return _mm256_add_epi32(_mm256_slli_epi32(a, SC_W_BITS),
                            _mm256_mullo_epi32(tx, _mm256_sub_epi32(b, a)));
}

/* 4 display values from 4 int64 sums: 0 below 1 << 26, 255 from 255 << 26, else sum >> 26 */
static inline __m256i display4(__m256i ifx4, __m256i la, const int64_t *lut, __m256i m64)
{
    /* lanes past the span read nothing (the table may end there) */
    const __m256i sum =
        _mm256_add_epi64(_mm256_mul_epi32(ifx4, la),
                         _mm256_maskload_epi64((const long long *)(const void *)lut, m64));
    __m256i v = _mm256_srli_epi64(sum, 26);
    v = _mm256_blendv_epi8(v, _mm256_setzero_si256(),
                           _mm256_cmpgt_epi64(_mm256_set1_epi64x((int64_t)1 << 26), sum));
    v = _mm256_blendv_epi8(v, _mm256_set1_epi64x(255),
                           _mm256_cmpgt_epi64(sum, _mm256_set1_epi64x(((int64_t)255 << 26) - 1)));
    return v;
}

/* the low byte of each of 8 dwords, to dst[0..8) */
static inline void store_bytes(uint8_t *dst, __m256i v)
{
    const __m256i pick =
        _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12,
                         -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m256i p = _mm256_shuffle_epi8(v, pick);
    const int32_t lo = _mm256_cvtsi256_si32(p);
    const int32_t hi = _mm256_extract_epi32(p, 4);
    memcpy(dst, &lo, 4);
    memcpy(dst + 4, &hi, 4);
}

/* The constants of the 8-sample step, set once per call. */
typedef struct samp8 {
    __m256i wmask, half, vsy, vsz, vsyz2, la, outside, three;
    const int *vox, *labp;
} samp8;

static inline samp8 samp8_init(const vol_regs v)
{
    samp8 c;
    c.wmask = _mm256_set1_epi32(SC_W_ONE - 1);
    c.half = _mm256_set1_epi32(SC_W_ONE / 2 - 1);
    c.vsy = _mm256_set1_epi32((int32_t)v.sy);
    c.vsz = _mm256_set1_epi32((int32_t)v.sz);
    c.vsyz2 = _mm256_set1_epi32((int32_t)(v.sy + v.sz) - 2);
    c.la = _mm256_set1_epi64x(v.la);
    c.outside = _mm256_set1_epi32(SC_LABEL_OUTSIDE);
    c.three = _mm256_set1_epi32(3);
    c.vox = (const int *)(const void *)v.vox;
    c.labp = (const int *)(const void *)v.lab;
    return c;
}

/* 8 samples at the position words px, py, pz (lanes m; the first r are stored): the trilinear
 * level through lut[0..8) to out[0..r), the nearest voxel's label to lab_out[0..r). Shared by
 * the span sampler (words from its 64-bit lanes) and the line sampler (words from memory). */
static inline void sample8(const samp8 *c, __m256i px, __m256i py, __m256i pz, __m256i m,
                           uint32_t r, const int64_t *lut, uint8_t *out, uint8_t *lab_out)
{
    const __m256i wmask = c->wmask, half = c->half, vsy = c->vsy, vsz = c->vsz, vsyz2 = c->vsyz2,
                  la = c->la, outside = c->outside, three = c->three;
    const int *vox = c->vox;
    const int *labp = c->labp;
    const __m256i tx = _mm256_and_si256(px, wmask);
    const __m256i ty = _mm256_and_si256(py, wmask);
    const __m256i tz = _mm256_and_si256(pz, wmask);
    const __m256i base = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_srli_epi32(px, SC_W_BITS),
                         _mm256_mullo_epi32(_mm256_srli_epi32(py, SC_W_BITS), vsy)),
        _mm256_mullo_epi32(_mm256_srli_epi32(pz, SC_W_BITS), vsz));
    /* 4 bytes from each row start; the last row from 2 before it (never past the end: the
     * +1 neighbour of the last row is the volume's last byte at most) */
    const __m256i z = _mm256_setzero_si256();
    const __m256i g00 = _mm256_mask_i32gather_epi32(z, vox, base, m, 1);
    const __m256i g10 = _mm256_mask_i32gather_epi32(z, vox, _mm256_add_epi32(base, vsy), m, 1);
    const __m256i g01 = _mm256_mask_i32gather_epi32(z, vox, _mm256_add_epi32(base, vsz), m, 1);
    const __m256i g11 = _mm256_mask_i32gather_epi32(z, vox, _mm256_add_epi32(base, vsyz2), m, 1);
    const __m256i c00 = pair_level(g00, 0, tx), c10 = pair_level(g10, 0, tx);
    const __m256i c01 = pair_level(g01, 0, tx), c11 = pair_level(g11, 16, tx);
    const __m256i c0 = lerp(c00, c10, ty), c1 = lerp(c01, c11, ty);
    const __m256i ifx = lerp(c0, c1, tz);
    __m256i label;
    if (labp != NULL) {
        /* nearest voxel: + 1 where the weight is >= 1/2 */
        const __m256i li =
            _mm256_add_epi32(_mm256_add_epi32(base, _mm256_srli_epi32(tx, SC_W_BITS - 1)),
                             _mm256_add_epi32(_mm256_and_si256(_mm256_cmpgt_epi32(ty, half), vsy),
                                              _mm256_and_si256(_mm256_cmpgt_epi32(tz, half), vsz)));
        /* the dword ending at the label (or starting at it near the array's start) */
        const __m256i at = _mm256_max_epi32(_mm256_sub_epi32(li, three), z);
        const __m256i g = _mm256_mask_i32gather_epi32(z, labp, at, m, 1);
        label =
            _mm256_and_si256(_mm256_srlv_epi32(g, _mm256_slli_epi32(_mm256_sub_epi32(li, at), 3)),
                             _mm256_set1_epi32(0xff));
    } else {
        label = _mm256_set1_epi32(SC_LABEL_MUSCLE);
    }
    const __m256i d_lo = display4(_mm256_cvtepu32_epi64(_mm256_castsi256_si128(ifx)), la, lut,
                                  _mm256_cvtepi32_epi64(_mm256_castsi256_si128(m)));
    const __m256i d_hi = display4(_mm256_cvtepu32_epi64(_mm256_extracti128_si256(ifx, 1)), la,
                                  lut + 4, _mm256_cvtepi32_epi64(_mm256_extracti128_si256(m, 1)));
    /* the low dwords of the 8 int64 into 8 dwords, in order */
    const __m256i sel = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
    const __m256i disp = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(d_lo, sel),
                                            _mm256_permutevar8x32_epi32(d_hi, sel), 0xf0);
    const __m256i shown = _mm256_andnot_si256(_mm256_cmpeq_epi32(label, outside), disp);
    if (r == 8u) {
        store_bytes(out, shown);
        store_bytes(lab_out, label);
    } else {
        uint8_t t[16];
        store_bytes(t, shown);
        store_bytes(t + 8, label);
        memcpy(out, t, r);
        memcpy(lab_out, t + 8, r);
    }
}

void sc_bscan_span_x86_64_v3(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t k0,
                             uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX, int64_t DY,
                             int64_t DZ, uint8_t *restrict out, uint8_t *restrict lab_out)
{
    if (k1 <= k0) {
        return;
    }
    lanes lx = lanes_init(X, DX), ly = lanes_init(Y, DY), lz = lanes_init(Z, DZ);
    const samp8 c = samp8_init(v);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (uint32_t k = k0; k < k1; k += 8u) {
        /* the lanes of this span: all 8, or the last few (the others gather and load nothing:
         * their positions may be anywhere) */
        const uint32_t r = k1 - k < 8u ? k1 - k : 8u;
        const __m256i m = _mm256_cmpgt_epi32(_mm256_set1_epi32((int32_t)r), lane);
        sample8(&c, lx.hi, ly.hi, lz.hi, m, r, lut_b_fx + k, out + k, lab_out + k);
        lanes_step(&lx);
        lanes_step(&ly);
        lanes_step(&lz);
    }
}

/* 8 position words of one axis from x + HALF + j d (j = 0..7), 64-bit lanes shifted and packed */
static inline __m256i words8(__m256i p0, __m256i p1)
{
    return pack_lo32(_mm256_srli_epi64(p0, SC_LOW_BITS), _mm256_srli_epi64(p1, SC_LOW_BITS));
}

void sc_bscan_words_x86_64_v3(uint32_t *restrict hx, uint32_t *restrict hy, uint32_t *restrict hz,
                              uint32_t k0, uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX,
                              int64_t DY, int64_t DZ)
{
    __m256i x0 = _mm256_add_epi64(_mm256_set1_epi64x(X + SC_W_HALF),
                                  _mm256_setr_epi64x(0, DX, 2 * DX, 3 * DX));
    __m256i y0 = _mm256_add_epi64(_mm256_set1_epi64x(Y + SC_W_HALF),
                                  _mm256_setr_epi64x(0, DY, 2 * DY, 3 * DY));
    __m256i z0 = _mm256_add_epi64(_mm256_set1_epi64x(Z + SC_W_HALF),
                                  _mm256_setr_epi64x(0, DZ, 2 * DZ, 3 * DZ));
    const __m256i dx4 = _mm256_set1_epi64x(4 * DX), dy4 = _mm256_set1_epi64x(4 * DY),
                  dz4 = _mm256_set1_epi64x(4 * DZ);
    for (uint32_t k = k0; k < k1; k += 8u) {
        const __m256i x1 = _mm256_add_epi64(x0, dx4), y1 = _mm256_add_epi64(y0, dy4),
                      z1 = _mm256_add_epi64(z0, dz4);
        _mm256_storeu_si256((__m256i *)(void *)(hx + k), words8(x0, x1));
        _mm256_storeu_si256((__m256i *)(void *)(hy + k), words8(y0, y1));
        _mm256_storeu_si256((__m256i *)(void *)(hz + k), words8(z0, z1));
        x0 = _mm256_add_epi64(x1, dx4);
        y0 = _mm256_add_epi64(y1, dy4);
        z0 = _mm256_add_epi64(z1, dz4);
    }
}

void sc_bscan_line_x86_64_v3(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t n,
                             const uint32_t *restrict hx, const uint32_t *restrict hy,
                             const uint32_t *restrict hz, uint8_t *restrict out,
                             uint8_t *restrict lab_out)
{
    const samp8 c = samp8_init(v);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (uint32_t k = 0; k < n; k += 8u) {
        const uint32_t r = n - k < 8u ? n - k : 8u;
        const __m256i m = _mm256_cmpgt_epi32(_mm256_set1_epi32((int32_t)r), lane);
        if (k + SC_LINE_PREFETCH < n) {
            const uint32_t kp = k + SC_LINE_PREFETCH;
            /* as an integer: a clamped word's rows may lie past the array (a hint reads none) */
            const uintptr_t b = (uintptr_t)v.vox + (uintptr_t)(hx[kp] >> SC_W_BITS) +
                                (uintptr_t)(hy[kp] >> SC_W_BITS) * v.sy +
                                (uintptr_t)(hz[kp] >> SC_W_BITS) * v.sz;
            __builtin_prefetch((const void *)b, 0, 3);
            __builtin_prefetch((const void *)(b + v.sy), 0, 3);
            __builtin_prefetch((const void *)(b + v.sz), 0, 3);
            __builtin_prefetch((const void *)(b + v.sy + v.sz), 0, 3);
        }
        const __m256i px = _mm256_loadu_si256((const __m256i *)(const void *)(hx + k));
        const __m256i py = _mm256_loadu_si256((const __m256i *)(const void *)(hy + k));
        const __m256i pz = _mm256_loadu_si256((const __m256i *)(const void *)(hz + k));
        sample8(&c, px, py, pz, m, r, lut_b_fx + k, out + k, lab_out + k);
    }
}
/* The acoustics pass's run kernel: 16 samples per iteration (sc_acoustics_run_generic's
 * arithmetic in 32-bit lanes; the arithmetic shift is the generic's biased one, the two
 * saturating packs its clamp to 0..255), the tail sample by sample as there. */
void sc_acoustics_run_x86_64_v3(uint8_t *restrict out, uint32_t len, int32_t base, int32_t step)
{
    uint32_t i = 0;
    if (len >= 16u) {
        const __m256i j8 = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        const __m256i half = _mm256_set1_epi32(1 << 15);
        /* base - j step + half, lanes 0..7, and the same 8 further on */
        __m256i t0 = _mm256_sub_epi32(_mm256_set1_epi32(base),
                                      _mm256_mullo_epi32(j8, _mm256_set1_epi32(step)));
        t0 = _mm256_add_epi32(t0, half);
        const __m256i d8 = _mm256_set1_epi32((int32_t)((uint32_t)step * 8u));
        for (; i + 16u <= len; i += 16u) {
            const __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(out + i));
            const __m256i t1 = _mm256_sub_epi32(t0, d8);
            const __m256i o0 = _mm256_cvtepu8_epi32(b);
            const __m256i o1 = _mm256_cvtepu8_epi32(_mm_srli_si128(b, 8));
            const __m256i r0 = _mm256_srai_epi32(_mm256_add_epi32(_mm256_slli_epi32(o0, 16), t0), 16);
            const __m256i r1 = _mm256_srai_epi32(_mm256_add_epi32(_mm256_slli_epi32(o1, 16), t1), 16);
            /* per 128-bit half: r0 0..3, r1 0..3 | r0 4..7, r1 4..7 -> in sample order */
            const __m256i p16 = _mm256_permute4x64_epi64(_mm256_packs_epi32(r0, r1), 0xd8);
            const __m128i p8 = _mm_packus_epi16(_mm256_castsi256_si128(p16),
                                                _mm256_extracti128_si256(p16, 1));
            const __m128i z = _mm_cmpeq_epi8(b, _mm_setzero_si128());
            _mm_storeu_si128((__m128i *)(void *)(out + i), _mm_andnot_si128(z, p8));
            t0 = _mm256_sub_epi32(t1, d8);
        }
    }
    if (i < len) {
        sc_acoustics_run_generic(out + i, len - i, (int32_t)(base - (int32_t)i * step), step);
    }
}

/* the label byte at each of 8 dword indices li (>= 0, inside the array): the dword ending at it
 * (or starting at it near the array's start) gathered and shifted */
static inline __m256i gather_labels(const int *labp, __m256i li)
{
    const __m256i z = _mm256_setzero_si256();
    const __m256i at = _mm256_max_epi32(_mm256_sub_epi32(li, _mm256_set1_epi32(3)), z);
    const __m256i g = _mm256_i32gather_epi32(labp, at, 1);
    return _mm256_and_si256(_mm256_srlv_epi32(g, _mm256_slli_epi32(_mm256_sub_epi32(li, at), 3)),
                            _mm256_set1_epi32(0xff));
}

/* the high dwords (integer parts of 32.32) of 8 int64 lanes, in order */
static inline __m256i pack_hi32(__m256i a, __m256i b)
{
    const __m256i sel = _mm256_setr_epi32(1, 3, 5, 7, 1, 3, 5, 7);
    return _mm256_blend_epi32(_mm256_permutevar8x32_epi32(a, sel),
                              _mm256_permutevar8x32_epi32(b, sel), 0xf0);
}

void sc_bscan_labels_nearest_x86_64_v3(const uint8_t *restrict lab, size_t sy, size_t sz,
                                       uint8_t *restrict out, uint32_t n, int64_t X, int64_t Y,
                                       int64_t Z, int64_t DX, int64_t DY, int64_t DZ)
{
    uint32_t k = 0;
    if (n >= 8u) {
        const int *labp = (const int *)(const void *)lab;
        const __m256i vsy = _mm256_set1_epi32((int32_t)sy), vsz = _mm256_set1_epi32((int32_t)sz);
        __m256i x0 =
            _mm256_add_epi64(_mm256_set1_epi64x(X), _mm256_setr_epi64x(0, DX, 2 * DX, 3 * DX));
        __m256i y0 =
            _mm256_add_epi64(_mm256_set1_epi64x(Y), _mm256_setr_epi64x(0, DY, 2 * DY, 3 * DY));
        __m256i z0 =
            _mm256_add_epi64(_mm256_set1_epi64x(Z), _mm256_setr_epi64x(0, DZ, 2 * DZ, 3 * DZ));
        const __m256i dx4 = _mm256_set1_epi64x(4 * DX), dy4 = _mm256_set1_epi64x(4 * DY),
                      dz4 = _mm256_set1_epi64x(4 * DZ);
        for (; k + 8u <= n; k += 8u) {
            const __m256i x1 = _mm256_add_epi64(x0, dx4), y1 = _mm256_add_epi64(y0, dy4),
                          z1 = _mm256_add_epi64(z0, dz4);
            const __m256i li = _mm256_add_epi32(
                _mm256_add_epi32(pack_hi32(x0, x1), _mm256_mullo_epi32(pack_hi32(y0, y1), vsy)),
                _mm256_mullo_epi32(pack_hi32(z0, z1), vsz));
            store_bytes(out + k, gather_labels(labp, li));
            x0 = _mm256_add_epi64(x1, dx4);
            y0 = _mm256_add_epi64(y1, dy4);
            z0 = _mm256_add_epi64(z1, dz4);
        }
    }
    if (k < n) {
        const int64_t kk = (int64_t)k;
        sc_bscan_labels_nearest(lab, sy, sz, out + k, n - k, X + kk * DX, Y + kk * DY, Z + kk * DZ,
                                DX, DY, DZ);
    }
}

void sc_bscan_margin_labels_x86_64_v3(const uint8_t *restrict lab, const uint32_t dim[3],
                                      const float f0[3], const float fd[3], uint32_t j0, uint32_t n,
                                      uint8_t *restrict out)
{
    const int *labp = (const int *)(const void *)lab;
    const __m256 lo = _mm256_set1_ps(-0.5f), half = _mm256_set1_ps(0.5f);
    const __m256 hx = _mm256_set1_ps((float)dim[0] - 0.5f),
                 hy = _mm256_set1_ps((float)dim[1] - 0.5f),
                 hz = _mm256_set1_ps((float)dim[2] - 0.5f);
    const __m256 ax = _mm256_set1_ps(f0[0]), ay = _mm256_set1_ps(f0[1]), az = _mm256_set1_ps(f0[2]);
    const __m256 bx = _mm256_set1_ps(fd[0]), by = _mm256_set1_ps(fd[1]), bz = _mm256_set1_ps(fd[2]);
    const __m256i d0 = _mm256_set1_epi32((int32_t)dim[0]), d1 = _mm256_set1_epi32((int32_t)dim[1]);
    const __m256i outside = _mm256_set1_epi32(SC_LABEL_OUTSIDE);
    const __m256 sign = _mm256_set1_ps(-0.0f);
    /* j0 + 4 i + 2 for the 8 lanes (below 2^24: exact in float) */
    __m256i jv = _mm256_add_epi32(_mm256_set1_epi32((int32_t)(j0 + 2u)),
                                  _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28));
    const __m256i j32 = _mm256_set1_epi32(32);
    for (uint32_t i = 0; i < n; i += 8u) {
        const __m256 s = _mm256_xor_ps(_mm256_cvtepi32_ps(jv), sign); /* -(float)j */
        const __m256 fx = _mm256_add_ps(ax, _mm256_mul_ps(s, bx));
        const __m256 fy = _mm256_add_ps(ay, _mm256_mul_ps(s, by));
        const __m256 fz = _mm256_add_ps(az, _mm256_mul_ps(s, bz));
        const __m256 in = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_and_ps(_mm256_cmp_ps(fx, lo, _CMP_GE_OQ), _mm256_cmp_ps(fx, hx, _CMP_LT_OQ)),
                _mm256_and_ps(_mm256_cmp_ps(fy, lo, _CMP_GE_OQ),
                              _mm256_cmp_ps(fy, hy, _CMP_LT_OQ))),
            _mm256_and_ps(_mm256_cmp_ps(fz, lo, _CMP_GE_OQ), _mm256_cmp_ps(fz, hz, _CMP_LT_OQ)));
        const __m256i m = _mm256_castps_si256(in);
        const __m256i x = _mm256_cvttps_epi32(_mm256_add_ps(fx, half));
        const __m256i y = _mm256_cvttps_epi32(_mm256_add_ps(fy, half));
        const __m256i z = _mm256_cvttps_epi32(_mm256_add_ps(fz, half));
        /* outside lanes: index 0 (their label is replaced) */
        const __m256i li = _mm256_and_si256(
            _mm256_add_epi32(
                x, _mm256_mullo_epi32(d0, _mm256_add_epi32(y, _mm256_mullo_epi32(d1, z)))),
            m);
        const __m256i label = _mm256_blendv_epi8(outside, gather_labels(labp, li), m);
        if (n - i >= 8u) {
            store_bytes(out + i, label);
        } else {
            uint8_t t[8];
            store_bytes(t, label);
            memcpy(out + i, t, n - i);
        }
        jv = _mm256_add_epi32(jv, j32);
    }
}
#else
typedef int sc_bscan_kern_x86_64_v3_unused; /* ISO C: a translation unit is not empty */
#endif
