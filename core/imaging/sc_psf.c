/* sc_psf.c: speckle from a rest-configuration scatterer field and the beam's PSF, see sc_psf.h. */
#include "sc_psf.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"

#define SC_PSF_C_MM_US   1.54f   /* speed of sound in soft tissue, mm/us */
#define SC_PSF_TB        0.8825f /* Gaussian time-bandwidth product of -6 dB widths, 4 ln2 / pi */
#define SC_PSF_FWHM_SIG  2.3548f /* FWHM / sigma of a Gaussian */
#define SC_PSF_DOF       7.1f    /* depth of field of a focused aperture, lambda F^2 units */
#define SC_PSF_DB_LOG2   3.0103f /* 10 log10(2) */
/* uniform in [-1, 1) from 16 bits; I and Q of variance 1/2 each (E|s|^2 = 1) need sqrt 1.5 */
#define SC_PSF_U16 (1.2247449f / 32768.0f)

sc_psf_def sc_psf_default_def(void)
{
    sc_psf_def d;
    d.fractional_bw = 0.5f;
    d.aperture_mm = 8.0f;
    d.slice_mm = 1.0f;
    d.seed = 1u;
    return d;
}

/* Gaussian taps exp(-x^2 / 2 s^2), x = -h..h, scaled to unit energy (sum of squares 1): a
 * uniform region's mean intensity is kept. */
static void gauss_taps(float sigma, uint32_t h, float *w)
{
    float e = 0.0f;
    for (uint32_t i = 0; i <= 2u * h; i++) {
        const float x = (float)i - (float)h;
        w[i] = expf(-0.5f * x * x / (sigma * sigma));
        e += w[i] * w[i];
    }
    const float s = 1.0f / sqrtf(e);
    for (uint32_t i = 0; i <= 2u * h; i++) {
        w[i] *= s;
    }
}

static uint32_t half_of(float sigma, uint32_t most)
{
    const float h = ceilf(2.0f * sigma); /* the Gaussian to 2 sigma: 95 % of its area */
    return h < 1.0f ? 1u : (h > (float)most ? most : (uint32_t)h);
}

int sc_psf_setup(sc_psf *p, const sc_psf_def *def, const sc_scan_def *scan,
                 const sc_scan_geom *geom, float focus_mm, float frequency_mhz,
                 float dynamic_range_db)
{
    if (p == NULL || def == NULL || scan == NULL || geom == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(def->fractional_bw) || !isfinite(def->aperture_mm) ||
        !isfinite(def->slice_mm) || !isfinite(focus_mm) || !isfinite(frequency_mhz) ||
        !isfinite(dynamic_range_db)) {
        return SC_ERR_NOT_FINITE;
    }
    if (def->fractional_bw < 0.2f || def->fractional_bw > 1.5f || def->aperture_mm < 1.0f ||
        def->aperture_mm > 60.0f || def->slice_mm < 0.1f || def->slice_mm > 10.0f ||
        !(focus_mm > 0.0f) || frequency_mhz < 1.0f || frequency_mhz > 30.0f ||
        dynamic_range_db < 10.0f || scan->lines_n > SC_MAX_SCAN_LINES ||
        scan->samples_n > SC_MAX_SCAN_SAMPLES || !(geom->sample_mm > 0.0f)) {
        return SC_ERR_RANGE;
    }
    p->def = *def;
    p->lines_n = scan->lines_n;
    p->samples_n = scan->samples_n;
    const float ds = geom->sample_mm;
    const int curved = scan->kind == SC_SCAN_GEOM_CURVILINEAR;
    /* axial */
    const float ax_fwhm = SC_PSF_C_MM_US * SC_PSF_TB / (2.0f * def->fractional_bw * frequency_mhz);
    const float ax_sig = ax_fwhm / SC_PSF_FWHM_SIG / ds;
    p->ax_half = half_of(ax_sig, SC_PSF_MAX_AX_HALF);
    memset(p->ax_w, 0, sizeof p->ax_w);
    gauss_taps(ax_sig, p->ax_half, p->ax_w);
    p->widths.axial_fwhm_mm = ax_fwhm;
    /* lateral, per depth band */
    const float lambda = SC_PSF_C_MM_US / frequency_mhz;
    const float fnum = focus_mm / def->aperture_mm;
    const float w_rx = lambda * fnum;
    const float z_r = 0.5f * SC_PSF_DOF * lambda * fnum * fnum;
    p->widths.lateral_fwhm_focus_mm = w_rx / sqrtf(2.0f);
    memset(p->lat_w, 0, sizeof p->lat_w);
    for (uint32_t b = 0; b <= SC_PSF_BANDS; b++) {
        p->band_k0[b] = (uint32_t)(((uint64_t)b * scan->samples_n) / SC_PSF_BANDS);
    }
    for (uint32_t b = 0; b < SC_PSF_BANDS; b++) {
        const float kc = 0.5f * (float)(p->band_k0[b] + p->band_k0[b + 1u]);
        const float z = kc * ds;
        const float u = (z - focus_mm) / z_r;
        const float w_tx = w_rx * sqrtf(1.0f + u * u);
        const float w = 1.0f / sqrtf(1.0f / (w_tx * w_tx) + 1.0f / (w_rx * w_rx));
        /* mm between lines at this depth */
        const float pitch = curved ? (scan->radius_mm + z) * geom->line_pitch : geom->line_pitch;
        const float sig = w / SC_PSF_FWHM_SIG / (pitch > 1e-6f ? pitch : 1e-6f);
        p->lat_half[b] = half_of(sig, SC_PSF_MAX_LAT_HALF);
        gauss_taps(sig, p->lat_half[b], p->lat_w[b]);
        p->widths.lateral_fwhm_mm[b] = w;
        p->widths.band_depth_mm[b] = z;
    }
    /* the taps per sample (0 beyond its band's half-width), for straight loops over a line */
    p->lat_max = 1u;
    for (uint32_t b = 0; b < SC_PSF_BANDS; b++) {
        p->lat_max = p->lat_half[b] > p->lat_max ? p->lat_half[b] : p->lat_max;
    }
    memset(p->lat_wk, 0, sizeof p->lat_wk);
    for (uint32_t b = 0; b < SC_PSF_BANDS; b++) {
        const uint32_t off = p->lat_max - p->lat_half[b];
        for (uint32_t j = 0; j <= 2u * p->lat_half[b]; j++) {
            for (uint32_t k = p->band_k0[b]; k < p->band_k0[b + 1u]; k++) {
                p->lat_wk[off + j][k] = p->lat_w[b][j];
            }
        }
    }
    /* grey <-> amplitude: grey 255 + (255 / R) 20 log10 A */
    for (uint32_t g = 0; g < 256u; g++) {
        p->amp[g] = powf(10.0f, ((float)g - 255.0f) * dynamic_range_db / (255.0f * 20.0f));
    }
    p->out_a = 255.0f * SC_PSF_DB_LOG2 / dynamic_range_db;
    p->out_b = 255.0f;
    /* lattice: one sample deep, one line wide (at the focus), the slice in elevation */
    const float pitch_f = curved ? (scan->radius_mm + focus_mm) * geom->line_pitch : geom->line_pitch;
    p->cell_mm[0] = pitch_f > 1e-3f ? pitch_f : 1e-3f;
    p->cell_mm[1] = def->slice_mm;
    p->cell_mm[2] = ds;
    p->cell_inv[0] = p->cell_inv[1] = p->cell_inv[2] = 1.0f;
    memset(p->sre, 0, sizeof p->sre);
    memset(p->sim, 0, sizeof p->sim);
    return SC_OK;
}

void sc_psf_frame_begin(sc_psf *p, const float spacing_mm[3])
{
    for (uint32_t d = 0; d < 3u; d++) {
        p->cell_inv[d] = spacing_mm[d] / p->cell_mm[d];
    }
}

static inline uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* A cell's 32 random bits: the lattice index spread by odd constants, then one multiply-xorshift
 * round (neighbouring cells come out uncorrelated; test_sc_psf checks the statistics). */
static inline uint32_t cell_hash(int32_t ix, int32_t iy, int32_t iz, uint32_t seed)
{
    uint32_t x = ((uint32_t)ix * 0x9e3779b1u) ^ ((uint32_t)iy * 0x85ebca77u) ^
                 ((uint32_t)iz * 0xc2b2ae3du) ^ seed;
    x ^= x >> 15;
    x *= 0x2c1b3c6du;
    x ^= x >> 12;
    return x;
}


/* floor for |x| < 2^31 without a library call (SSE2 has no floor instruction) */
static inline int32_t floor_i32(float x)
{
    const int32_t i = (int32_t)x;
    return i - ((float)i > x ? 1 : 0);
}

void sc_psf_span(sc_psf *p, uint32_t k0, uint32_t k1, const float a[3], const float b[3])
{
    const uint32_t seed = mix32(p->def.seed);
    const float ci0 = p->cell_inv[0], ci1 = p->cell_inv[1], ci2 = p->cell_inv[2];
    float *sre = p->sre + SC_PSF_MAX_AX_HALF, *sim = p->sim + SC_PSF_MAX_AX_HALF;
    k1 = k1 < p->samples_n ? k1 : p->samples_n;
    for (uint32_t k = k0; k < k1; k++) {
        const float s = (float)k;
        const float X = (a[0] + s * b[0]) * ci0, Y = (a[1] + s * b[1]) * ci1,
                    Z = (a[2] + s * b[2]) * ci2;
        const int32_t ix = floor_i32(X), iy = floor_i32(Y), iz = floor_i32(Z);
        const float f = Y - (float)iy;
        const uint32_t h0 = cell_hash(ix, iy, iz, seed), h1 = cell_hash(ix, iy + 1, iz, seed);
        /* linear along y at unit variance: 1 / sqrt(w0^2 + w1^2) = 1 / sqrt(0.5 + 2u),
         * u = (f - 1/2)^2 in [0, 1/4], by the quadratic through u = 0, 1/8, 1/4 (< 0.6 %) */
        const float w1 = f, w0 = 1.0f - f;
        const float u = (f - 0.5f) * (f - 0.5f);
        const float nrm = SC_PSF_U16 * (1.4142136f + u * (-2.4953f + u * 3.3539f));
        const float r0 = (float)((int32_t)(h0 & 0xffffu) - 32768),
                    q0 = (float)((int32_t)(h0 >> 16) - 32768);
        const float r1 = (float)((int32_t)(h1 & 0xffffu) - 32768),
                    q1 = (float)((int32_t)(h1 >> 16) - 32768);
        sre[k] = (w0 * r0 + w1 * r1) * nrm;
        sim[k] = (w0 * q0 + w1 * q1) * nrm;
    }
}

void sc_psf_line_in(sc_psf *p, uint32_t l, const uint8_t *grey)
{
    const uint32_t n = p->samples_n, h = p->ax_half, slot = l % SC_PSF_RING;
    float *sre = p->sre + SC_PSF_MAX_AX_HALF, *sim = p->sim + SC_PSF_MAX_AX_HALF;
    /* echo x scatterer in place (the pads beyond the line stay 0: no echo there) */
    for (uint32_t k = 0; k < n; k++) {
        const float A = p->amp[grey[k]] * (grey[k] != 0u ? 1.0f : 0.0f);
        sre[k] *= A;
        sim[k] *= A;
    }
    float *restrict ore = p->re[slot], *restrict oim = p->im[slot];
    for (uint32_t k = 0; k < n; k++) {
        ore[k] = 0.0f;
        oim[k] = 0.0f;
    }
    for (uint32_t j = 0; j <= 2u * h; j++) { /* tap by tap: straight loops over k */
        const float wj = p->ax_w[j];
        const float *restrict xr = sre + j - h, *restrict xq = sim + j - h;
        for (uint32_t k = 0; k < n; k++) {
            ore[k] += wj * xr[k];
            oim[k] += wj * xq[k];
        }
    }
    for (uint32_t k = 0; k < n; k++) { /* the next line's spans fill it again */
        sre[k] = 0.0f;
        sim[k] = 0.0f;
    }
    memcpy(p->tissue[slot], grey, n);
    memcpy(p->hooked[slot], grey, n);
}

void sc_psf_line_hooked(sc_psf *p, uint32_t l, const uint8_t *grey)
{
    memcpy(p->hooked[l % SC_PSF_RING], grey, p->samples_n);
}

int32_t sc_psf_line_ready(const sc_psf *p, uint32_t last_in, uint32_t next_out)
{
    if (next_out > last_in || next_out >= p->lines_n) {
        return -1;
    }
    if (last_in + 1u >= p->lines_n || next_out + SC_PSF_MAX_LAT_HALF <= last_in) {
        return (int32_t)next_out;
    }
    return -1;
}

/* log2 of x > 0: exponent and a quadratic in the mantissa (error < 0.005) */
static inline float fast_log2(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    const float e = (float)((int32_t)(u >> 23) - 127);
    u = (u & 0x007fffffu) | 0x3f800000u;
    float m;
    memcpy(&m, &u, sizeof m);
    return e + (-0.34484843f * m + 2.02466578f) * m - 1.67487759f;
}

void sc_psf_line_out(sc_psf *p, uint32_t m, uint8_t *out)
{
    const uint32_t slot = m % SC_PSF_RING, n = p->samples_n;
    const uint8_t *tis = p->tissue[slot], *hk = p->hooked[slot];
    const int32_t last = (int32_t)p->lines_n - 1;
    float *restrict r = p->sre, *restrict q = p->sim; /* scratch: the line going in is done */
    const uint32_t h = p->lat_max;
    for (uint32_t k = 0; k < n; k++) {
        r[k] = 0.0f;
        q[k] = 0.0f;
    }
    for (uint32_t j = 0; j <= 2u * h; j++) { /* tap by tap, each sample its depth's weight */
        int32_t ln = (int32_t)m + (int32_t)j - (int32_t)h;
        ln = ln < 0 ? 0 : (ln > last ? last : ln); /* the edge line repeated */
        const uint32_t s = (uint32_t)ln % SC_PSF_RING;
        const float *restrict wj = p->lat_wk[j];
        const float *restrict xr = p->re[s], *restrict xq = p->im[s];
        for (uint32_t k = 0; k < n; k++) {
            r[k] += wj[k] * xr[k];
            q[k] += wj[k] * xq[k];
        }
    }
    const float oa = p->out_a, ob = p->out_b + 0.5f;
    for (uint32_t k = 0; k < n; k++) { /* envelope, log compression: straight float */
        const float e2 = r[k] * r[k] + q[k] * q[k] + 1e-30f;
        const float g = oa * fast_log2(e2) + ob;
        r[k] = g < 0.0f ? 0.0f : (g > 255.0f ? 255.0f : g);
    }
    for (uint32_t k = 0; k < n; k++) {
        const uint8_t v = tis[k] == 0u ? 0u : (uint8_t)(int32_t)r[k];
        out[k] = hk[k] != tis[k] ? hk[k] : v;
    }
    for (uint32_t k = 0; k < n; k++) { /* the next line's spans fill them again */
        r[k] = 0.0f;
        q[k] = 0.0f;
    }
}
