/* sc_bscan_kern.c: the portable span sampler and the variant choice (sc_bscan_kern.h). */
#include "sc_bscan_kern.h"

#include "sc_simd.h"

void sc_bscan_span_generic(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t k0,
                           uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX, int64_t DY,
                           int64_t DZ, uint8_t *restrict out, uint8_t *restrict lab_out)
{
    for (uint32_t k = k0; k < k1; k++) {
        sc_bscan_sample_fx(v, lut_b_fx, k, X, Y, Z, out, lab_out);
        X += DX;
        Y += DY;
        Z += DZ;
    }
}

void sc_bscan_line_generic(const vol_regs v, const int64_t *restrict lut_b_fx, uint32_t n,
                           const uint32_t *restrict hx, const uint32_t *restrict hy,
                           const uint32_t *restrict hz, uint8_t *restrict out,
                           uint8_t *restrict lab_out)
{
    for (uint32_t k = 0; k < n; k++) {
        sc_bscan_sample_h(v, lut_b_fx, k, hx[k], hy[k], hz[k], out, lab_out);
    }
}

sc_bscan_line_fn sc_bscan_line_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) {
        return sc_bscan_line_x86_64_v3;
    }
#endif
    return sc_bscan_line_generic;
}

void sc_bscan_words_generic(uint32_t *restrict hx, uint32_t *restrict hy, uint32_t *restrict hz,
                            uint32_t k0, uint32_t k1, int64_t X, int64_t Y, int64_t Z, int64_t DX,
                            int64_t DY, int64_t DZ)
{
    X += SC_W_HALF;
    Y += SC_W_HALF;
    Z += SC_W_HALF;
    for (uint32_t k = k0; k < k1; k++) {
        hx[k] = (uint32_t)((uint64_t)X >> SC_POS_SHIFT);
        hy[k] = (uint32_t)((uint64_t)Y >> SC_POS_SHIFT);
        hz[k] = (uint32_t)((uint64_t)Z >> SC_POS_SHIFT);
        X += DX;
        Y += DY;
        Z += DZ;
    }
}

sc_bscan_words_fn sc_bscan_words_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) {
        return sc_bscan_words_x86_64_v3;
    }
#endif
    return sc_bscan_words_generic;
}

sc_bscan_span_fn sc_bscan_span_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) { /* v3 or v4: both have AVX2 */
        return sc_bscan_span_x86_64_v3;
    }
#endif
    return sc_bscan_span_generic;
}

sc_acoustics_run_fn sc_acoustics_run_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) {
        return sc_acoustics_run_x86_64_v3;
    }
#endif
    return sc_acoustics_run_generic;
}

void sc_bscan_labels_nearest(const uint8_t *restrict lab, size_t sy, size_t sz,
                             uint8_t *restrict out, uint32_t n, int64_t X, int64_t Y, int64_t Z,
                             int64_t DX, int64_t DY, int64_t DZ)
{
    for (uint32_t k = 0; k < n; k++) {
        out[k] = lab[(size_t)(X >> 32) + sy * (size_t)(Y >> 32) + sz * (size_t)(Z >> 32)];
        X += DX;
        Y += DY;
        Z += DZ;
    }
}

sc_bscan_nearest_fn sc_bscan_nearest_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) {
        return sc_bscan_labels_nearest_x86_64_v3;
    }
#endif
    return sc_bscan_labels_nearest;
}

void sc_bscan_margin_labels_generic(const uint8_t *restrict lab, const uint32_t dim[3],
                                    const float f0[3], const float fd[3], uint32_t j0, uint32_t n,
                                    uint8_t *restrict out)
{
    const float hx = (float)dim[0] - 0.5f, hy = (float)dim[1] - 0.5f, hz = (float)dim[2] - 0.5f;
    for (uint32_t i = 0; i < n; i++) {
        const float s = -(float)(j0 + 4u * i + 2u);
        const float fx = f0[0] + s * fd[0], fy = f0[1] + s * fd[1], fz = f0[2] + s * fd[2];
        if (!(fx >= -0.5f && fx < hx && fy >= -0.5f && fy < hy && fz >= -0.5f && fz < hz)) {
            out[i] = (uint8_t)SC_LABEL_OUTSIDE;
            continue;
        }
        const uint32_t x = (uint32_t)(fx + 0.5f), y = (uint32_t)(fy + 0.5f),
                       z = (uint32_t)(fz + 0.5f);
        out[i] = lab[(size_t)x + (size_t)dim[0] * ((size_t)y + (size_t)dim[1] * z)];
    }
}

sc_bscan_margin_fn sc_bscan_margin_selected(void)
{
#if defined(SC_SIMD_X86_64_V3_BUILT)
    if (sc_simd_selected() != SC_SIMD_GENERIC) {
        return sc_bscan_margin_labels_x86_64_v3;
    }
#endif
    return sc_bscan_margin_labels_generic;
}

void sc_bscan_margin_near(const uint32_t dim[3], const float f0[3], const float fd[3],
                          uint32_t blocks, uint32_t *lo, uint32_t *hi)
{
    *lo = 0u;
    *hi = blocks;
    const float big = 65536.0f, tmax = 4.0f * (float)blocks + 2.0f;
    float tl = 0.0f, th = tmax; /* t = 4 i + 2 */
    for (uint32_t d = 0; d < 3u; d++) {
        const float a = f0[d], b = fd[d];
        const float ab = a < 0.0f ? -a : a, bb = b < 0.0f ? -b : b;
        if (!(ab < big && bb * tmax < big)) {
            return; /* far out or not a number: label every block */
        }
        /* near: -3/2 <= a - t b <= dim + 1/2 */
        const float pl = -1.5f, ph = (float)dim[d] + 0.5f;
        if (b > 0.0f || b < 0.0f) {
            const float t1 = (a - pl) / b, t2 = (a - ph) / b;
            const float t_lo = t1 < t2 ? t1 : t2, t_hi = t1 < t2 ? t2 : t1;
            tl = t_lo > tl ? t_lo : tl;
            th = t_hi < th ? t_hi : th;
        } else if (!(a >= pl && a <= ph)) {
            th = -1.0f; /* parallel to this axis's faces and outside them */
        }
    }
    if (!(th >= tl)) {
        *hi = 0u; /* nowhere near */
        return;
    }
    /* blocks (t - 2) / 4, one more each side */
    const float il = (tl - 2.0f) / 4.0f - 1.0f, ih = (th - 2.0f) / 4.0f + 2.0f;
    *lo = il <= 0.0f ? 0u : (il >= (float)blocks ? blocks : (uint32_t)il);
    *hi = ih <= 0.0f ? 0u : (ih >= (float)blocks ? blocks : (uint32_t)ih);
    if (*hi < *lo) {
        *hi = *lo;
    }
}
