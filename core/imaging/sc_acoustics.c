/* sc_acoustics.c: beam-dependent acoustics along a scan line, see sc_acoustics.h. */
#include "sc_acoustics.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "sc_err.h"

static sc_acoustic_props props(float atten, float z)
{
    const sc_acoustic_props p = {atten, z, 0.0f};
    return p;
}

sc_acoustics_def sc_acoustics_default_def(void)
{
    sc_acoustics_def d;
    d.label[SC_LABEL_OUTSIDE] = props(0.65f, 1.63f);
    d.label[SC_LABEL_SKIN] = props(0.8f, 1.60f);
    d.label[SC_LABEL_FAT] = props(0.6f, 1.38f);
    d.label[SC_LABEL_MUSCLE] = props(0.7f, 1.70f);
    d.label[SC_LABEL_VEIN] = props(0.15f, 1.61f);
    d.label[SC_LABEL_ARTERY] = props(0.15f, 1.61f);
    d.label[SC_LABEL_NERVE] = props(0.9f, 1.65f);
    d.label[SC_LABEL_THROMBUS] = props(0.5f, 1.66f);
    d.label[SC_LABEL_BONE] = props(20.0f, 7.8f);
    d.frequency_mhz = 7.5f;
    d.ref_atten_db_cm_mhz = 0.65f;
    return d;
}

static int in(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

static int check(const sc_acoustics_def *d, float sample_mm, float dr_db)
{
    if (!isfinite(d->frequency_mhz) || !isfinite(d->ref_atten_db_cm_mhz) || !isfinite(sample_mm) ||
        !isfinite(dr_db)) {
        return SC_ERR_NOT_FINITE;
    }
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        const sc_acoustic_props *p = &d->label[i];
        if (!isfinite(p->atten_db_cm_mhz) || !isfinite(p->impedance_mrayl) ||
            !isfinite(p->scatter_db)) {
            return SC_ERR_NOT_FINITE;
        }
        if (!in(p->atten_db_cm_mhz, 0.0f, 100.0f) || !in(p->impedance_mrayl, 0.1f, 20.0f) ||
            !in(p->scatter_db, -60.0f, 60.0f)) {
            return SC_ERR_RANGE;
        }
    }
    if (!in(d->frequency_mhz, 1.0f, 30.0f) || !in(d->ref_atten_db_cm_mhz, 0.0f, 10.0f) ||
        !(sample_mm > 0.0f) || !(dr_db > 0.0f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* A table value in Q16 grey levels, clamped to +-SC_ACOU_Q_LIMIT (a per-sample loss, echo or
 * offset that large leaves every sample it touches black or white either way). x * 65536 is
 * exact in float (a power of two); the rounding is to nearest, ties away from zero. */
static int32_t to_q(float x)
{
    const float lim = (float)SC_ACOU_Q_LIMIT;
    float v = x * 65536.0f;
    v = v > lim ? lim : (v < -lim ? -lim : v);
    return (int32_t)(v >= 0.0f ? v + 0.5f : v - 0.5f);
}

int sc_acoustics_init(sc_acoustics *a, const sc_acoustics_def *def, float sample_mm,
                      float dynamic_range_db)
{
    if (a == NULL || def == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = check(def, sample_mm, dynamic_range_db);
    if (rc != SC_OK) {
        return rc;
    }
    const float gl_per_db = 255.0f / dynamic_range_db;
    /* two-way path of one sample, in cm, times the frequency */
    const float path_cm_mhz = 2.0f * 0.1f * sample_mm * def->frequency_mhz;
    const float comp_gl = def->ref_atten_db_cm_mhz * path_cm_mhz * gl_per_db;
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        const sc_acoustic_props *p = &def->label[i];
        /* even: half of it before the sample's middle, half after, both exact */
        a->atten_q[i] = 2 * to_q(0.5f * (p->atten_db_cm_mhz * path_cm_mhz * gl_per_db - comp_gl));
        a->scatter_q[i] = to_q(p->scatter_db * gl_per_db);
        for (uint32_t j = 0; j < SC_LABEL_COUNT; j++) {
            if (i == SC_LABEL_OUTSIDE || j == SC_LABEL_OUTSIDE) {
                /* coupling gel, or the tissue continued beyond the volume: no interface */
                a->trans_q[i][j] = 0;
                a->echo_q[i][j] = 0;
                continue;
            }
            const float z1 = p->impedance_mrayl, z2 = def->label[j].impedance_mrayl;
            const float r = (z2 - z1) / (z2 + z1);
            const float refl = r * r; /* intensity reflection coefficient */
            /* the part 1 - R crosses the interface on the way down and again on the way up */
            a->trans_q[i][j] = to_q(-20.0f * log10f(1.0f - refl) * gl_per_db);
            /* the echo of the interface itself, 10 log10 R dB below white */
            const float echo = refl > 0.0f ? 255.0f + 10.0f * log10f(refl) * gl_per_db : 0.0f;
            a->echo_q[i][j] = to_q(echo > 0.0f ? echo : 0.0f);
        }
    }
    return SC_OK;
}

#define Q_ONE  65536
#define Q_HALF 32768
#define Q_255  (255 * Q_ONE)

/* One displayed sample: o the volume's grey, v its value in Q16 after the loss (o == 0 stays 0:
 * air above the skin). Rounded to nearest, halves up, saturated at 0 and 255. */
static inline uint8_t shade_q(uint32_t o, int64_t v)
{
    if (o == 0u || v <= 0) {
        return 0u;
    }
    return v >= Q_255 ? 255u : (uint8_t)((v + Q_HALF) >> 16);
}

void sc_acoustics_run_generic(uint8_t *restrict out, uint32_t len, int32_t base, int32_t step)
{
    int32_t t = base;
    for (uint32_t i = 0; i < len; i++) {
        const int32_t o = (int32_t)out[i];
        /* a bias keeps the shifted value non-negative (no implementation-defined shift); the
         * clamp after it is shade_q's: v <= 0 gives at most 0, v >= 255 in Q16 at least 255 */
        int32_t r = (int32_t)((uint32_t)(o * Q_ONE + t + Q_HALF + (1 << 30)) >> 16) - (1 << 14);
        r = r < 0 ? 0 : r;
        r = r > 255 ? 255 : r;
        out[i] = (uint8_t)(o == 0 ? 0 : r);
        t -= step;
    }
}

/* Length of the run of bytes equal to lab[k] from k (at least 1), 8 at a time. */
static uint32_t run_end(const uint8_t *lab, uint32_t k, uint32_t n)
{
    const uint8_t c = lab[k];
    const uint64_t pat = UINT64_C(0x0101010101010101) * c;
    uint32_t e = k + 1u;
    while (e + 8u <= n) {
        uint64_t w;
        memcpy(&w, lab + e, sizeof w);
        if ((w ^ pat) != 0u) {
            break;
        }
        e += 8u;
    }
    while (e < n && lab[e] == c) {
        e++;
    }
    return e;
}

void sc_acoustics_line(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n)
{
    sc_acoustics_line_k(a, lab, out, n, sc_acoustics_run_generic);
}

void sc_acoustics_line_k(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n,
                         sc_acoustics_run_fn run)
{
    int64_t loss = 0; /* two-way loss above the next sample, net of the TGC (Q16 grey levels) */
    uint32_t prev = SC_LABEL_OUTSIDE;
    uint32_t k = 0;
    while (k < n) {
        const uint32_t e = run_end(lab, k, n);
        const uint32_t l = lab[k] < SC_LABEL_COUNT ? lab[k] : (uint32_t)SC_LABEL_OUTSIDE;
        const int64_t step = a->atten_q[l], half = step / 2;
        /* the first sample: the interface's echo (after the loss above it), the loss across
         * the interface, then half this sample's own path (its echo comes from its middle) */
        int64_t echo = INT64_MIN;
        if (l != prev) {
            echo = (int64_t)a->echo_q[prev][l] - loss;
            loss += a->trans_q[prev][l];
            prev = l;
        }
        const int64_t base = (int64_t)a->scatter_q[l] - loss - half;
        {
            int64_t v = (int64_t)out[k] * Q_ONE + base;
            v = v > echo ? v : echo;
            out[k] = shade_q(out[k], v);
        }
        const uint32_t len = e - k - 1u; /* the rest of the run, no interface */
        if (len > 0u) {
            const int64_t b1 = base - step; /* the run's second sample */
            const int64_t b_end = b1 - (int64_t)(len - 1u) * step;
            const int64_t lim = INT64_C(1) << 29;
            if (b1 < lim && b1 > -lim && b_end < lim && b_end > -lim) {
                run(out + k + 1u, len, (int32_t)b1, (int32_t)step);
            } else {
                for (uint32_t i = 0; i < len; i++) {
                    out[k + 1u + i] =
                        shade_q(out[k + 1u + i], (int64_t)out[k + 1u + i] * Q_ONE + b1 -
                                                     (int64_t)i * step);
                }
            }
        }
        loss += (int64_t)(e - k) * step;
        k = e;
    }
}
