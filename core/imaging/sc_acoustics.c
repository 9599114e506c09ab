/* sc_acoustics.c: beam-dependent acoustics along a scan line, see sc_acoustics.h. */
#include "sc_acoustics.h"

#include <math.h>
#include <stddef.h>

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
        a->atten_gl[i] = p->atten_db_cm_mhz * path_cm_mhz * gl_per_db - comp_gl;
        a->scatter_gl[i] = p->scatter_db * gl_per_db;
        for (uint32_t j = 0; j < SC_LABEL_COUNT; j++) {
            if (i == SC_LABEL_OUTSIDE || j == SC_LABEL_OUTSIDE) {
                /* coupling gel, or the tissue continued beyond the volume: no interface */
                a->trans_gl[i][j] = 0.0f;
                a->echo_gl[i][j] = 0.0f;
                continue;
            }
            const float z1 = p->impedance_mrayl, z2 = def->label[j].impedance_mrayl;
            const float r = (z2 - z1) / (z2 + z1);
            const float refl = r * r; /* intensity reflection coefficient */
            /* the part 1 - R crosses the interface on the way down and again on the way up */
            a->trans_gl[i][j] = -20.0f * log10f(1.0f - refl) * gl_per_db;
            /* the echo of the interface itself, 10 log10 R dB below white */
            const float echo = refl > 0.0f ? 255.0f + 10.0f * log10f(refl) * gl_per_db : 0.0f;
            a->echo_gl[i][j] = echo > 0.0f ? echo : 0.0f;
        }
    }
    return SC_OK;
}

void sc_acoustics_line(const sc_acoustics *a, const uint8_t *lab, uint8_t *out, uint32_t n)
{
    float loss_gl = 0.0f; /* two-way loss above this sample, net of the TGC */
    uint32_t prev = SC_LABEL_OUTSIDE;
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t l = lab[k] < SC_LABEL_COUNT ? lab[k] : (uint32_t)SC_LABEL_OUTSIDE;
        float echo = 0.0f; /* the interface's echo, after the loss above the interface */
        if (l != prev) {
            echo = a->echo_gl[prev][l] - loss_gl;
            loss_gl += a->trans_gl[prev][l];
            prev = l;
        }
        /* the loss of half this sample's own path (its echo comes from its middle) */
        const float half = 0.5f * a->atten_gl[l];
        loss_gl += half;
        if (out[k] != 0u) {
            float v = (float)out[k] + a->scatter_gl[l] - loss_gl;
            v = v > echo ? v : echo;
            out[k] = (uint8_t)(v <= 0.0f ? 0.0f : (v >= 255.0f ? 255.0f : v + 0.5f));
        }
        loss_gl += half;
    }
}
