/*
 * sc_vec.h: W-lane float vectors for the implicit solvers' hot loops (sc_grid_kern.inc).
 *
 * The kernels are written once against the vf_ / vm_ helpers below and compiled once per
 * instruction-set variant (sc_simd.h), each unit defining SC_VEC_W before including this file:
 * 4 lanes for the portable variant (SSE2 on x86-64, NEON on aarch64), 8 for x86-64-v3 / -v4
 * (measured: 8 lanes are as fast as 16 on AVX-512 here, at half the register pressure).
 * Targets without a 128-bit SIMD unit (the Cortex-M7) and a build with -DSC_VEC_SCALAR take
 * one plain float per "vector". Every lane does the same IEEE operations in the same order
 * whatever the width (no operation mixes lanes; -ffp-contract=off keeps a * b + c unfused), so
 * all widths give bit-identical results (tests/unit/test_sc_simd.c compares them).
 *
 * Memory: loads and stores go through memcpy (any alignment, no aliasing assumptions), so a
 * vector may start at any float of an array. Never allocates.
 */
#ifndef SC_VEC_H
#define SC_VEC_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#if !defined(SC_VEC_W)
#error "define SC_VEC_W (lanes) before including sc_vec.h"
#endif

#if defined(__GNUC__) && !defined(SC_VEC_SCALAR) &&                                                \
    (defined(__SSE2__) || defined(__ARM_NEON) || defined(__aarch64__))
#define SC_VEC_LANES SC_VEC_W
#if defined(__AVX__) && SC_VEC_W == 8
#include <immintrin.h>
#endif
typedef float vf __attribute__((vector_size(4 * SC_VEC_W)));
typedef int32_t vm __attribute__((vector_size(4 * SC_VEC_W))); /* lane mask: 0 or -1 */

static inline vf vf_ld(const float *p)
{
    vf v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline void vf_st(float *p, vf v)
{
    memcpy(p, &v, sizeof v);
}
static inline vm vm_ld(const int32_t *p)
{
    vm v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline vf vf_splat(float x)
{
    vf v;
    for (uint32_t l = 0; l < SC_VEC_LANES; l++) {
        v[l] = x;
    }
    return v;
}
/* a where m, else b. Eight AVX lanes: one blend on the mask's sign bits (every mask is 0 or -1,
 * so the same lanes as the bit select); the bit select took three logic ops (xor, and, xor), 702
 * of the 8-lane MSDS volume kernel's ~2,800 instructions per vector of cells. AVX-512's 16
 * lanes make the bit select one ternary-logic op, SSE2's 4 lanes have no blend. */
static inline vf vf_sel(vm m, vf a, vf b)
{
#if defined(__AVX__) && SC_VEC_W == 8
    return (vf)_mm256_blendv_ps((__m256)b, (__m256)a, (__m256)m);
#else
    return (vf)((m & (vm)a) | (~m & (vm)b));
#endif
}
static inline vf vf_sqrt(vf v)
{
    vf r;
    for (uint32_t l = 0; l < SC_VEC_LANES; l++) {
        r[l] = sqrtf(v[l]);
    }
    return r;
}
static inline vm vf_lt(vf a, vf b)
{
    return (vm)(a < b);
}
static inline vm vf_gt(vf a, vf b)
{
    return (vm)(a > b);
}
static inline vm vm_and_not(vm a, vm b)
{
    return a & ~b;
}
static inline int vm_any(vm m)
{
    int32_t any = 0;
    for (uint32_t l = 0; l < SC_VEC_LANES; l++) {
        any |= m[l];
    }
    return any != 0;
}
static inline int vm_lane(vm m, uint32_t l)
{
    return m[l] != 0;
}
static inline float vf_lane(vf v, uint32_t l)
{
    return v[l];
}
#else
#define SC_VEC_LANES 1u
typedef float vf;
typedef int32_t vm;

static inline vf vf_ld(const float *p)
{
    return *p;
}
static inline void vf_st(float *p, vf v)
{
    *p = v;
}
static inline vm vm_ld(const int32_t *p)
{
    return *p;
}
static inline vf vf_splat(float x)
{
    return x;
}
static inline vf vf_sel(vm m, vf a, vf b)
{
    return m != 0 ? a : b;
}
static inline vf vf_sqrt(vf v)
{
    return sqrtf(v);
}
static inline vm vf_lt(vf a, vf b)
{
    return a < b ? -1 : 0;
}
static inline vm vf_gt(vf a, vf b)
{
    return a > b ? -1 : 0;
}
static inline vm vm_and_not(vm a, vm b)
{
    return a & ~b;
}
static inline int vm_any(vm m)
{
    return m != 0;
}
static inline int vm_lane(vm m, uint32_t l)
{
    (void)l;
    return m != 0;
}
static inline float vf_lane(vf v, uint32_t l)
{
    (void)l;
    return v;
}
#endif

/* p[k] += v over the lanes (read-modify-write of one vector). */
static inline void vf_add_to(float *p, vf v)
{
    vf_st(p, vf_ld(p) + v);
}

#endif /* SC_VEC_H */
