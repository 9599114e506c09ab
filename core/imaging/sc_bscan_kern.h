/*
 * sc_bscan_kern.h: the B-scan's sampling loop (internal to sc_bscan.c), per instruction-set
 * variant (core/physics/sc_simd.h): the portable one (sc_bscan_kern.c, one sample at a time)
 * and the x86-64-v3 one (sc_bscan_kern_x86_64_v3.c, AVX2: eight samples at a time with
 * gathers). Integer arithmetic throughout, so every variant gives the same bytes: a variant is
 * a speed choice only (tests/unit/test_sc_bscan_kern.c compares them).
 */
#ifndef SC_BSCAN_KERN_H
#define SC_BSCAN_KERN_H

#include <stddef.h>
#include <stdint.h>

#include "sc_acoustics.h"
#include "sc_labels.h"

/* Trilinear weights: 10 bits, rounded to nearest (half a weight step added to the position). */
#define SC_W_BITS 10
#define SC_W_ONE  (1 << SC_W_BITS)
#define SC_W_HALF ((int64_t)1 << (31 - SC_W_BITS)) /* half a weight step in 32.32 */

/* The volume as the sampler sees it: values, labels (NULL: none), the y and z strides, the
 * display gain lut_a in 16.16. Passed by value so that the byte stores (which may alias
 * anything) do not force reloads. */
typedef struct vol_regs {
    const uint8_t *vox, *lab;
    size_t sy, sz;
    int64_t la;
} vol_regs;

/* One sample at 32.32 position (X, Y, Z), inside [0, xmax] (the caller clamps): trilinear with
 * 10-bit weights rounded to nearest (within 0.2 grey level of the exact value for neighbour
 * differences up to 128), nearest label, display table. The volume has at least 2 voxels along
 * every axis, so the +1 neighbours are 1, sy and sz away. */
static inline void sc_bscan_sample_fx(const vol_regs v, const int64_t *restrict lut_b_fx,
                                      uint32_t k, int64_t X, int64_t Y, int64_t Z,
                                      uint8_t *restrict out, uint8_t *restrict lab_out)
{
    X += SC_W_HALF;
    Y += SC_W_HALF;
    Z += SC_W_HALF;
    const int32_t tx = (int32_t)((X >> (32 - SC_W_BITS)) & (SC_W_ONE - 1));
    const int32_t ty = (int32_t)((Y >> (32 - SC_W_BITS)) & (SC_W_ONE - 1));
    const int32_t tz = (int32_t)((Z >> (32 - SC_W_BITS)) & (SC_W_ONE - 1));
    const size_t base = (size_t)(X >> 32) + v.sy * (size_t)(Y >> 32) + v.sz * (size_t)(Z >> 32);
    const uint8_t *r00 = v.vox + base, *r10 = r00 + v.sy, *r01 = r00 + v.sz, *r11 = r01 + v.sy;
    /* 18 bits after the first level, 28 bits inside the later ones: int32 is enough */
    const int32_t c00 = r00[0] * SC_W_ONE + tx * (r00[1] - r00[0]);
    const int32_t c10 = r10[0] * SC_W_ONE + tx * (r10[1] - r10[0]);
    const int32_t c01 = r01[0] * SC_W_ONE + tx * (r01[1] - r01[0]);
    const int32_t c11 = r11[0] * SC_W_ONE + tx * (r11[1] - r11[0]);
    const int32_t c0 = (c00 * SC_W_ONE + ty * (c10 - c00) + SC_W_ONE / 2) >> SC_W_BITS;
    const int32_t c1 = (c01 * SC_W_ONE + ty * (c11 - c01) + SC_W_ONE / 2) >> SC_W_BITS;
    const int32_t ifx = (c0 * SC_W_ONE + tz * (c1 - c0) + SC_W_ONE / 2) >> SC_W_BITS;
    uint8_t label = (uint8_t)SC_LABEL_MUSCLE; /* volumes without a label map */
    if (v.lab != NULL) {                      /* nearest voxel's label */
        label = v.lab[base + (size_t)(tx >> (SC_W_BITS - 1)) + (ty >= SC_W_ONE / 2 ? v.sy : 0u) +
                      (tz >= SC_W_ONE / 2 ? v.sz : 0u)];
    }
    lab_out[k] = label;
    /* display: out = (A * I + B[k]) >> 26 with I in 1/1024 grey, A = lut_a in 16.16 and
     * B = lut_b in 38.26 with the rounding half folded in */
    const int64_t sum = v.la * (int64_t)ifx + lut_b_fx[k];
    out[k] = (uint8_t)(label == (uint8_t)SC_LABEL_OUTSIDE || sum < ((int64_t)1 << 26)
                           ? 0
                           : (sum >= ((int64_t)255 << 26) ? 255 : (sum >> 26)));
}

/* The position word of one axis as the sampler reads it: (P + SC_W_HALF) >> (32 - SC_W_BITS) for
 * the 32.32 position P (in [0, xmax]): the voxel index << SC_W_BITS | the weight. The volume's
 * axes are below 2^22 voxels (SC_MAX_VOLUME_DIM), so it fits 32 bits. */
#define SC_POS_SHIFT (32 - SC_W_BITS)

/* One sample from its position words (hx, hy, hz): the same arithmetic as sc_bscan_sample_fx
 * on the position they come from, so the same bytes. */
static inline void sc_bscan_sample_h(const vol_regs v, const int64_t *restrict lut_b_fx,
                                     uint32_t k, uint32_t hx, uint32_t hy, uint32_t hz,
                                     uint8_t *restrict out, uint8_t *restrict lab_out)
{
    const int32_t tx = (int32_t)(hx & (SC_W_ONE - 1));
    const int32_t ty = (int32_t)(hy & (SC_W_ONE - 1));
    const int32_t tz = (int32_t)(hz & (SC_W_ONE - 1));
    const size_t base = (size_t)(hx >> SC_W_BITS) + v.sy * (size_t)(hy >> SC_W_BITS) +
                        v.sz * (size_t)(hz >> SC_W_BITS);
    const uint8_t *r00 = v.vox + base, *r10 = r00 + v.sy, *r01 = r00 + v.sz, *r11 = r01 + v.sy;
    const int32_t c00 = r00[0] * SC_W_ONE + tx * (r00[1] - r00[0]);
    const int32_t c10 = r10[0] * SC_W_ONE + tx * (r10[1] - r10[0]);
    const int32_t c01 = r01[0] * SC_W_ONE + tx * (r01[1] - r01[0]);
    const int32_t c11 = r11[0] * SC_W_ONE + tx * (r11[1] - r11[0]);
    const int32_t c0 = (c00 * SC_W_ONE + ty * (c10 - c00) + SC_W_ONE / 2) >> SC_W_BITS;
    const int32_t c1 = (c01 * SC_W_ONE + ty * (c11 - c01) + SC_W_ONE / 2) >> SC_W_BITS;
    const int32_t ifx = (c0 * SC_W_ONE + tz * (c1 - c0) + SC_W_ONE / 2) >> SC_W_BITS;
    uint8_t label = (uint8_t)SC_LABEL_MUSCLE;
    if (v.lab != NULL) {
        label = v.lab[base + (size_t)(tx >> (SC_W_BITS - 1)) + (ty >= SC_W_ONE / 2 ? v.sy : 0u) +
                      (tz >= SC_W_ONE / 2 ? v.sz : 0u)];
    }
    lab_out[k] = label;
    const int64_t sum = v.la * (int64_t)ifx + lut_b_fx[k];
    out[k] = (uint8_t)(label == (uint8_t)SC_LABEL_OUTSIDE || sum < ((int64_t)1 << 26)
                           ? 0
                           : (sum >= ((int64_t)255 << 26) ? 255 : (sum >> 26)));
}

/* Samples [0, n) of a whole line from their position words h[0][k], h[1][k], h[2][k] (the
 * caller steps each span's positions exactly as the span sampler does, so the same bytes; a
 * sample the caller does otherwise has any valid words, e.g. 0, and is overwritten after).
 * The arrays are readable up to n rounded up to 8. One call per line instead of one per span
 * (a mesh run is one tet crossed: about 5 samples). */
typedef void (*sc_bscan_line_fn)(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t n,
                                 const uint32_t *restrict hx, const uint32_t *restrict hy,
                                 const uint32_t *restrict hz, uint8_t *restrict out,
                                 uint8_t *restrict lab_out);

void sc_bscan_line_generic(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t n,
                           const uint32_t *restrict hx, const uint32_t *restrict hy,
                           const uint32_t *restrict hz, uint8_t *restrict out,
                           uint8_t *restrict lab_out);
#if defined(SC_SIMD_X86_64_V3_BUILT)
void sc_bscan_line_x86_64_v3(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t n,
                             const uint32_t *restrict hx, const uint32_t *restrict hy,
                             const uint32_t *restrict hz, uint8_t *restrict out,
                             uint8_t *restrict lab_out);
#endif

/* The selected variant's line sampler (sc_simd_selected()). */
sc_bscan_line_fn sc_bscan_line_selected(void);

/* The position words h[d][k] of samples [k0, k1) at 32.32 positions (X, Y, Z) + (k - k0)
 * (DX, DY, DZ), every one inside [0, xmax] of its axis: exactly the positions the span sampler
 * steps. A variant may write the words of up to 7 samples past k1 (the arrays are padded; a
 * later span overwrites them). */
typedef void (*sc_bscan_words_fn)(uint32_t *restrict hx, uint32_t *restrict hy,
                                  uint32_t *restrict hz, uint32_t k0, uint32_t k1, int64_t X,
                                  int64_t Y, int64_t Z, int64_t DX, int64_t DY, int64_t DZ);
void sc_bscan_words_generic(uint32_t *restrict hx, uint32_t *restrict hy, uint32_t *restrict hz,
                            uint32_t k0, uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX,
                            int64_t DY, int64_t DZ);
#if defined(SC_SIMD_X86_64_V3_BUILT)
void sc_bscan_words_x86_64_v3(uint32_t *restrict hx, uint32_t *restrict hy,
                              uint32_t *restrict hz, uint32_t k0, uint32_t k1, int64_t X,
                              int64_t Y, int64_t Z, int64_t DX, int64_t DY, int64_t DZ);
#endif
sc_bscan_words_fn sc_bscan_words_selected(void);

/* Samples [k0, k1) at 32.32 positions (X, Y, Z) + (k - k0) (DX, DY, DZ), every one inside
 * [0, xmax] of its axis (checked by the caller at both ends); out[k], lab_out[k] written. The
 * volume has fewer than 2^31 voxels (SC_MAX_VOLUME_VOXELS). */
typedef void (*sc_bscan_span_fn)(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t k0,
                                 uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX,
                                 int64_t DY, int64_t DZ, uint8_t *restrict out,
                                 uint8_t *restrict lab_out);

void sc_bscan_span_generic(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t k0,
                           uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX, int64_t DY,
                           int64_t DZ, uint8_t *restrict out, uint8_t *restrict lab_out);
#if defined(SC_SIMD_X86_64_V3_BUILT)
void sc_bscan_span_x86_64_v3(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t k0,
                             uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX,
                             int64_t DY, int64_t DZ, uint8_t *restrict out,
                             uint8_t *restrict lab_out);
#endif

/* The selected variant's span sampler (sc_simd_selected()). */
sc_bscan_span_fn sc_bscan_span_selected(void);

/* The labels at n positions (X, Y, Z) + k (DX, DY, DZ) in 32.32 voxel units, each the voxel
 * of the integer parts (the caller offsets by a half for the nearest voxel and keeps every
 * position inside the grid): the compression measure's rest labels of a mesh run. A unit of
 * its own so that the B-scan's frame loop, with every stage inlined, does not keep its
 * operands on the stack. */
void sc_bscan_labels_nearest(const uint8_t *restrict lab, size_t sy, size_t sz,
                             uint8_t *restrict out, uint32_t n, int64_t X, int64_t Y, int64_t Z,
                             int64_t DX, int64_t DY, int64_t DZ);
typedef void (*sc_bscan_nearest_fn)(const uint8_t *restrict lab, size_t sy, size_t sz,
                                    uint8_t *restrict out, uint32_t n, int64_t X, int64_t Y,
                                    int64_t Z, int64_t DX, int64_t DY, int64_t DZ);
#if defined(SC_SIMD_X86_64_V3_BUILT)
/* The same labels, 8 positions per iteration (64-bit lanes, the integer parts packed, the
 * labels gathered), the tail as the generic one. */
void sc_bscan_labels_nearest_x86_64_v3(const uint8_t *restrict lab, size_t sy, size_t sz,
                                       uint8_t *restrict out, uint32_t n, int64_t X, int64_t Y,
                                       int64_t Z, int64_t DX, int64_t DY, int64_t DZ);
#endif
/* The selected variant's rest-label kernel (sc_simd_selected()). */
sc_bscan_nearest_fn sc_bscan_nearest_selected(void);

/* The compression measure's rest reference above the probe face: out[i] = the nearest label at
 * the float position f0 + s fd (voxel-index units, multiplied then added: no contraction),
 * s = -(float)(j0 + 4 i + 2), i in [0, n), or SC_LABEL_OUTSIDE where that position is outside
 * [-1/2, dim - 1/2) on an axis (or not a number). The same test, rounding and index as
 * sc_bscan.c's label_at, sample by sample. lab holds dim[0] dim[1] dim[2] labels
 * (dim[d] <= SC_MAX_VOLUME_DIM). */
typedef void (*sc_bscan_margin_fn)(const uint8_t *restrict lab, const uint32_t dim[3],
                                   const float f0[3], const float fd[3], uint32_t j0, uint32_t n,
                                   uint8_t *restrict out);
void sc_bscan_margin_labels_generic(const uint8_t *restrict lab, const uint32_t dim[3],
                                    const float f0[3], const float fd[3], uint32_t j0, uint32_t n,
                                    uint8_t *restrict out);
#if defined(SC_SIMD_X86_64_V3_BUILT)
/* 8 positions per iteration in float lanes: the same products, sums, tests and truncations. */
void sc_bscan_margin_labels_x86_64_v3(const uint8_t *restrict lab, const uint32_t dim[3],
                                      const float f0[3], const float fd[3], uint32_t j0,
                                      uint32_t n, uint8_t *restrict out);
#endif
sc_bscan_margin_fn sc_bscan_margin_selected(void);

/* The blocks [*lo, *hi) of [0, blocks) whose margin positions (as sc_bscan_margin_labels, s =
 * -(4 i + 2)) may lie inside the grid: every block outside that range is more than a voxel
 * outside [-1/2, dim - 1/2) on some axis, so its label is SC_LABEL_OUTSIDE without looking
 * (the range is widened by a voxel and a block against the float roundings; far from the grid's
 * origin, beyond 2^16 voxels, or not a number: the whole range). Above a pressed face most of
 * the 60 mm margin is above the skin, outside the case volume. */
void sc_bscan_margin_near(const uint32_t dim[3], const float f0[3], const float fd[3],
                          uint32_t blocks, uint32_t *lo, uint32_t *hi);

/* The acoustics pass's run kernel (sc_acoustics.h): the portable one there, the x86-64-v3
 * one here (AVX2: 16 samples per iteration, the same integer arithmetic, the same bytes). */
void sc_acoustics_run_x86_64_v3(uint8_t *restrict out, uint32_t len, int32_t base, int32_t step);
sc_acoustics_run_fn sc_acoustics_run_selected(void);

#endif /* SC_BSCAN_KERN_H */
