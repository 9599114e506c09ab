/* sc_doppler.c: colour and pulsed-wave Doppler from a vessel flow model (see sc_doppler.h). */
#include "sc_doppler.h"

#include <math.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"

#define PI_F 3.14159265f
/* speed of sound in soft tissue, the scanner's convention (m/s -> mm/s) */
#define SOUND_MM_S 1540000.0f
/* colour appears where gain * echo weight of blood reaches this (weight 1 at the centreline,
 * 0.25 at the wall): at 0 dB all but the outer 3 % of the radius, at -12 dB nothing */
#define COLOUR_THRESHOLD 0.3f
/* spectral broadening: a floor of the scale plus a share of the speed (aperture) */
#define SPEC_BROAD_FLOOR 0.02f
#define SPEC_BROAD_SPEED 0.08f
#define SPEC_RANGE_DB 40.0f

sc_doppler_def sc_doppler_default_def(void)
{
    sc_doppler_def d;
    memset(&d, 0, sizeof d);
    d.enabled = 1u;
    d.box_u0 = 0.25f;
    d.box_u1 = 0.75f;
    d.box_v0 = 0.05f;
    d.box_v1 = 0.7f;
    d.steer_deg = 0.0f;
    d.prf_hz = 4000.0f;
    d.f0_mhz = 5.0f;
    d.wall_hz = 100.0f;
    d.gain_db = 0.0f;
    d.gate_u = 0.5f;
    d.gate_depth_mm = 20.0f;
    d.gate_len_mm = 2.0f;
    d.artery_peak_mm_s = 800.0f; /* common carotid PSV ~ 80-100 cm/s, EDV ~ 20-30 cm/s */
    d.artery_floor_mm_s = 200.0f;
    d.vein_mean_mm_s = 150.0f; /* internal jugular ~ 10-30 cm/s, phasic with respiration */
    d.vein_resp_fraction = 0.5f;
    d.heart_rate_bpm = 72.0f;
    d.resp_rate_bpm = 15.0f;
    d.artery_sign = 1.0f;
    d.vein_sign = -1.0f;
    return d;
}

static int in_range(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

int sc_doppler_def_validate(const sc_doppler_def *d)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const float f[] = {d->box_u0,  d->box_u1,           d->box_v0,           d->box_v1,
                       d->steer_deg, d->prf_hz,         d->f0_mhz,           d->wall_hz,
                       d->gain_db,  d->gate_u,           d->gate_depth_mm,    d->gate_len_mm,
                       d->artery_peak_mm_s, d->artery_floor_mm_s, d->vein_mean_mm_s,
                       d->vein_resp_fraction, d->heart_rate_bpm, d->resp_rate_bpm,
                       d->artery_sign, d->vein_sign};
    for (uint32_t i = 0; i < sizeof f / sizeof f[0]; i++) {
        if (!isfinite(f[i])) {
            return SC_ERR_NOT_FINITE;
        }
    }
    if (d->enabled > 1u || !in_range(d->box_u0, 0.0f, 1.0f) || !in_range(d->box_u1, 0.0f, 1.0f) ||
        !(d->box_u0 < d->box_u1) || !in_range(d->box_v0, 0.0f, 1.0f) ||
        !in_range(d->box_v1, 0.0f, 1.0f) || !(d->box_v0 < d->box_v1) ||
        !in_range(d->steer_deg, -30.0f, 30.0f) || !in_range(d->prf_hz, 100.0f, 20000.0f) ||
        !in_range(d->f0_mhz, 1.0f, 15.0f) || !in_range(d->wall_hz, 0.0f, 0.25f * d->prf_hz) ||
        !in_range(d->gain_db, -30.0f, 30.0f) || !in_range(d->gate_u, 0.0f, 1.0f) ||
        !in_range(d->gate_depth_mm, 0.0f, 300.0f) || !in_range(d->gate_len_mm, 0.5f, 20.0f) ||
        !in_range(d->artery_peak_mm_s, 0.0f, 3000.0f) ||
        !in_range(d->artery_floor_mm_s, 0.0f, d->artery_peak_mm_s) ||
        !in_range(d->vein_mean_mm_s, 0.0f, 1000.0f) ||
        !in_range(d->vein_resp_fraction, 0.0f, 1.0f) ||
        !in_range(d->heart_rate_bpm, 20.0f, 240.0f) || !in_range(d->resp_rate_bpm, 4.0f, 60.0f) ||
        !(d->artery_sign > 0.5f || d->artery_sign < -0.5f) ||
        !in_range(d->artery_sign, -1.0f, 1.0f) || !(d->vein_sign > 0.5f || d->vein_sign < -0.5f) ||
        !in_range(d->vein_sign, -1.0f, 1.0f)) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

int sc_doppler_set_def(sc_doppler *d, const sc_doppler_def *def)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = sc_doppler_def_validate(def);
    if (rc != SC_OK) {
        return rc;
    }
    d->def = *def;
    return SC_OK;
}

int sc_doppler_init(sc_doppler *d, const sc_doppler_def *def)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    memset(d, 0, sizeof *d);
    const int rc = sc_doppler_set_def(d, def);
    if (rc == SC_OK) {
        sc_doppler_advance(d, 0.0f);
    }
    return rc;
}

/* ---- vessel model ------------------------------------------------------------------------ */

static void fit_vessel(sc_doppler_vessel *ves, double n, const double s[3], const double ss[6])
{
    memset(ves, 0, sizeof *ves);
    if (n < 8.0) {
        return;
    }
    double m[3], c[3][3];
    for (uint32_t i = 0; i < 3u; i++) {
        m[i] = s[i] / n;
    }
    /* ss: xx, yy, zz, xy, xz, yz */
    c[0][0] = ss[0] / n - m[0] * m[0];
    c[1][1] = ss[1] / n - m[1] * m[1];
    c[2][2] = ss[2] / n - m[2] * m[2];
    c[0][1] = c[1][0] = ss[3] / n - m[0] * m[1];
    c[0][2] = c[2][0] = ss[4] / n - m[0] * m[2];
    c[1][2] = c[2][1] = ss[5] / n - m[1] * m[2];
    /* power iteration from the axis of largest variance (a fixed count: deterministic) */
    uint32_t best = 0;
    for (uint32_t i = 1; i < 3u; i++) {
        if (c[i][i] > c[best][best]) {
            best = i;
        }
    }
    double v[3] = {0.0, 0.0, 0.0};
    v[best] = 1.0;
    double lam = 0.0;
    for (uint32_t it = 0; it < 64u; it++) {
        double w[3];
        for (uint32_t i = 0; i < 3u; i++) {
            w[i] = c[i][0] * v[0] + c[i][1] * v[1] + c[i][2] * v[2];
        }
        const double nw = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (!(nw > 0.0)) {
            return;
        }
        lam = nw;
        for (uint32_t i = 0; i < 3u; i++) {
            v[i] = w[i] / nw;
        }
    }
    const double perp = c[0][0] + c[1][1] + c[2][2] - lam; /* mean r^2 across the axis */
    if (!(perp > 0.0)) {
        return;
    }
    uint32_t big = 0;
    for (uint32_t i = 1; i < 3u; i++) {
        if (fabs(v[i]) > fabs(v[big])) {
            big = i;
        }
    }
    const double sg = v[big] < 0.0 ? -1.0 : 1.0;
    for (uint32_t i = 0; i < 3u; i++) {
        ves->centre_mm[i] = (float)m[i];
        ves->axis[i] = (float)(sg * v[i]);
    }
    ves->radius_mm = (float)sqrt(2.0 * perp);
    ves->voxels = (uint32_t)n;
    ves->valid = 1u;
}

int sc_doppler_attach_volume(sc_doppler *d, const sc_volume *v)
{
    if (d == NULL || v == NULL || v->voxels == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    memset(d->vessel, 0, sizeof d->vessel);
    d->attached = 0u;
    for (uint32_t a = 0; a < 3u; a++) {
        if (v->dim[a] == 0u || !isfinite(v->spacing_mm[a]) || !(v->spacing_mm[a] > 0.0f) ||
            !isfinite(v->origin_mm[a])) {
            return SC_ERR_INVALID_ARG;
        }
        d->voxel_mm[a] = v->spacing_mm[a];
        d->origin_mm[a] = v->origin_mm[a];
    }
    if (v->labels == NULL) {
        d->attached = 1u;
        return SC_OK;
    }
    uint32_t st = 1u;
    for (;;) {
        const uint64_t cnt = (uint64_t)((v->dim[0] + st - 1u) / st) *
                             ((v->dim[1] + st - 1u) / st) * ((v->dim[2] + st - 1u) / st);
        if (cnt <= SC_DOPPLER_MAX_SCAN_VOXELS) {
            break;
        }
        st++;
    }
    static const uint8_t flowing[2] = {SC_LABEL_VEIN, SC_LABEL_ARTERY};
    double n[2] = {0.0, 0.0}, s[2][3], ss[2][6];
    memset(s, 0, sizeof s);
    memset(ss, 0, sizeof ss);
    for (uint32_t k = 0; k < v->dim[2]; k += st) {
        const double z = (double)v->origin_mm[2] + (double)k * (double)v->spacing_mm[2];
        for (uint32_t j = 0; j < v->dim[1]; j += st) {
            const double y = (double)v->origin_mm[1] + (double)j * (double)v->spacing_mm[1];
            const size_t row = (size_t)v->dim[0] * ((size_t)j + (size_t)v->dim[1] * k);
            for (uint32_t i = 0; i < v->dim[0]; i += st) {
                const uint8_t lab = v->labels[row + i];
                const int w = lab == flowing[0] ? 0 : (lab == flowing[1] ? 1 : -1);
                if (w < 0) {
                    continue;
                }
                const double x = (double)v->origin_mm[0] + (double)i * (double)v->spacing_mm[0];
                n[w] += 1.0;
                s[w][0] += x;
                s[w][1] += y;
                s[w][2] += z;
                ss[w][0] += x * x;
                ss[w][1] += y * y;
                ss[w][2] += z * z;
                ss[w][3] += x * y;
                ss[w][4] += x * z;
                ss[w][5] += y * z;
            }
        }
    }
    for (uint32_t w = 0; w < 2u; w++) {
        fit_vessel(&d->vessel[flowing[w]], n[w], s[w], ss[w]);
    }
    d->attached = 1u;
    return SC_OK;
}

/* ---- flow in time ------------------------------------------------------------------------ */

int sc_doppler_set_phase(sc_doppler *d, float cardiac_phase, float resp_phase)
{
    if (d == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(cardiac_phase) || !isfinite(resp_phase)) {
        return SC_ERR_NOT_FINITE;
    }
    d->cardiac_phase = cardiac_phase - floorf(cardiac_phase);
    d->resp_phase = resp_phase - floorf(resp_phase);
    d->phase_external = 1u;
    return SC_OK;
}

/* Arterial waveform, 0..1 of (peak - floor) over one cardiac cycle: a systolic upstroke and
 * fall in the first 35 %, a small dicrotic wave, then the diastolic floor. */
static float artery_wave(float ph)
{
    if (ph < 0.35f) {
        return sinf(PI_F * ph / 0.35f);
    }
    if (ph < 0.5f) {
        return 0.15f * sinf(PI_F * (ph - 0.35f) / 0.15f);
    }
    return 0.0f;
}

void sc_doppler_advance(sc_doppler *d, float dt_s)
{
    if (d == NULL || !isfinite(dt_s) || dt_s < 0.0f) {
        return;
    }
    if (!d->phase_external) {
        float c = d->cardiac_phase + d->def.heart_rate_bpm / 60.0f * dt_s;
        float r = d->resp_phase + d->def.resp_rate_bpm / 60.0f * dt_s;
        d->cardiac_phase = c - floorf(c);
        d->resp_phase = r - floorf(r);
    }
    d->phase_external = 0u;
    const sc_doppler_def *f = &d->def;
    d->v_artery_mm_s = f->artery_floor_mm_s +
                       (f->artery_peak_mm_s - f->artery_floor_mm_s) * artery_wave(d->cardiac_phase);
    d->v_vein_mm_s =
        f->vein_mean_mm_s * (1.0f + f->vein_resp_fraction * sinf(2.0f * PI_F * d->resp_phase));
}

int sc_doppler_velocity_at(const sc_doppler *d, uint8_t label, const float p_vox[3],
                           float out_mm_s[3])
{
    out_mm_s[0] = out_mm_s[1] = out_mm_s[2] = 0.0f;
    if (label != SC_LABEL_VEIN && label != SC_LABEL_ARTERY) {
        return 0;
    }
    const sc_doppler_vessel *ves = &d->vessel[label];
    if (!ves->valid) {
        return 0;
    }
    float rel[3];
    for (uint32_t a = 0; a < 3u; a++) {
        rel[a] = d->origin_mm[a] + p_vox[a] * d->voxel_mm[a] - ves->centre_mm[a];
    }
    const float along = rel[0] * ves->axis[0] + rel[1] * ves->axis[1] + rel[2] * ves->axis[2];
    const float r2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - along * along;
    float prof = 1.0f - r2 / (ves->radius_mm * ves->radius_mm);
    prof = prof < 0.0f ? 0.0f : prof;
    const float speed = label == SC_LABEL_ARTERY ? d->def.artery_sign * d->v_artery_mm_s * prof
                                                 : d->def.vein_sign * d->v_vein_mm_s * prof;
    for (uint32_t a = 0; a < 3u; a++) {
        out_mm_s[a] = speed * ves->axis[a];
    }
    return 1;
}

/* ---- frame ------------------------------------------------------------------------------- */

static uint16_t clamp_u16(float v, uint32_t hi)
{
    if (!(v > 0.0f)) {
        return 0u;
    }
    return v >= (float)hi ? (uint16_t)hi : (uint16_t)v;
}

int sc_doppler_frame_begin(sc_doppler *d, sc_bscan *b, const sc_display_dev *display,
                           uint32_t frame_no)
{
    if (d == NULL || b == NULL || display == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    sc_doppler_status *st = &d->status;
    st->frame_no = frame_no;
    st->colour_pixels = 0u;
    st->aliased_pixels = 0u;
    st->filtered_pixels = 0u;
    st->gate_velocity_mm_s = 0.0f;
    st->gate_peak_mm_s = 0.0f;
    st->gate_in_lumen = 0u;
    if (!d->def.enabled || !d->attached) {
        sc_bscan_set_line_hook(b, NULL, NULL);
        return SC_OK;
    }
    const sc_doppler_def *f = &d->def;
    const uint32_t lines = b->def.scan.lines_n, n = b->def.scan.samples_n;
    d->display = display;
    d->frame_no = frame_no;
    d->box_l0 = clamp_u16(f->box_u0 * (float)lines, lines);
    d->box_l1 = clamp_u16(ceilf(f->box_u1 * (float)lines), lines);
    d->box_k0 = clamp_u16(f->box_v0 * (float)n, n);
    d->box_k1 = clamp_u16(ceilf(f->box_v1 * (float)n), n);
    d->gate_line = clamp_u16(f->gate_u * (float)(lines - 1u) + 0.5f, lines - 1u);
    const float smm = b->geom.sample_mm;
    d->gate_k0 = clamp_u16((f->gate_depth_mm - 0.5f * f->gate_len_mm) / smm, n - 1u);
    d->gate_k1 = clamp_u16((f->gate_depth_mm + 0.5f * f->gate_len_mm) / smm, n);
    if (d->gate_k1 <= d->gate_k0) {
        d->gate_k1 = (uint16_t)(d->gate_k0 + 1u);
    }
    const float a = f->steer_deg * PI_F / 180.0f;
    d->steer_s = sinf(a);
    d->steer_c = cosf(a);
    d->nyq_mm_s = SOUND_MM_S * f->prf_hz / (4.0f * f->f0_mhz * 1e6f);
    d->wall_mm_s = SOUND_MM_S * f->wall_hz / (2.0f * f->f0_mhz * 1e6f);
    d->gain_lin = powf(10.0f, f->gain_db / 20.0f);
    memset(d->hist, 0, sizeof d->hist);
    sc_bscan_set_line_hook(b, sc_doppler_line_hook, d);
    return SC_OK;
}

static void count_display(sc_doppler *d, int rc)
{
    if (rc != SC_OK && rc != SC_ERR_NOT_SUPPORTED) {
        d->status.display_errors++;
    }
}

/* floorf without the libm call (the portable x86-64 build has no rounding instruction and
 * calls it for every colour sample): the same value for every finite x in int32's range (the
 * argument here is never -0: v + nyq with nyq > 0), libm's beyond. */
static inline float floor_f(float x)
{
    if (!(x > -2147483520.0f && x < 2147483520.0f)) {
        return floorf(x);
    }
    const float t = (float)(int32_t)x; /* toward zero, exact below 2^24; above, x is whole */
    return t > x ? t - 1.0f : t;
}

static float wrap_nyq(float v, float nyq)
{
    return v - 2.0f * nyq * floor_f((v + nyq) / (2.0f * nyq));
}

/* Velocity toward the probe of sample k, before aliasing; *w the echo weight of blood there
 * (1 centre .. 0.25 wall). Returns 0 outside a flowing lumen. */
static int sample_velocity(const sc_doppler *d, uint8_t label, const float p[3],
                           const float beam[3], float *v_toward, float *w)
{
    float vel[3];
    if (!sc_doppler_velocity_at(d, label, p, vel)) {
        return 0;
    }
    const sc_doppler_vessel *ves = &d->vessel[label];
    float rel[3];
    for (uint32_t a = 0; a < 3u; a++) {
        rel[a] = d->origin_mm[a] + p[a] * d->voxel_mm[a] - ves->centre_mm[a];
    }
    const float along = rel[0] * ves->axis[0] + rel[1] * ves->axis[1] + rel[2] * ves->axis[2];
    const float r2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - along * along;
    float prof = 1.0f - r2 / (ves->radius_mm * ves->radius_mm);
    prof = prof < 0.0f ? 0.0f : prof;
    *w = 0.25f + 0.75f * prof;
    *v_toward = -(vel[0] * beam[0] + vel[1] * beam[1] + vel[2] * beam[2]);
    return 1;
}

static void spectrum_add(sc_doppler *d, float v)
{
    const float nyq = d->nyq_mm_s, bins = (float)SC_DOPPLER_SPECTRUM_BINS;
    float x = (v + nyq) / (2.0f * nyq) * bins - 0.5f; /* bin units, unwrapped */
    float av = v < 0.0f ? -v : v;
    float hb = (SPEC_BROAD_FLOOR * 2.0f * nyq + SPEC_BROAD_SPEED * av) / (2.0f * nyq) * bins;
    hb = hb < 1.0f ? 1.0f : (hb > 0.25f * bins ? 0.25f * bins : hb);
    const int32_t j0 = (int32_t)ceilf(x - hb), j1 = (int32_t)floorf(x + hb);
    for (int32_t j = j0; j <= j1; j++) {
        const float dj = (float)j - x;
        const float wgt = 1.0f - (dj < 0.0f ? -dj : dj) / hb;
        int32_t idx = j % (int32_t)SC_DOPPLER_SPECTRUM_BINS; /* aliasing: wrap around */
        idx = idx < 0 ? idx + (int32_t)SC_DOPPLER_SPECTRUM_BINS : idx;
        d->hist[idx] += wgt;
    }
}

static uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

static void finish_frame(sc_doppler *d, uint32_t lines)
{
    const float nyq = d->nyq_mm_s, bins = (float)SC_DOPPLER_SPECTRUM_BINS;
    float hmax = 0.0f;
    uint32_t peak = 0u;
    for (uint32_t i = 0; i < SC_DOPPLER_SPECTRUM_BINS; i++) {
        const float vc = -nyq + ((float)i + 0.5f) * 2.0f * nyq / bins;
        if ((vc < 0.0f ? -vc : vc) < d->wall_mm_s) {
            d->hist[i] = 0.0f; /* the wall filter removes the slow end of the spectrum too */
        }
        if (d->hist[i] > hmax) {
            hmax = d->hist[i];
            peak = i;
        }
    }
    sc_doppler_status *st = &d->status;
    st->gate_peak_mm_s = hmax > 0.0f ? -nyq + ((float)peak + 0.5f) * 2.0f * nyq / bins : 0.0f;
    for (uint32_t i = 0; i < SC_DOPPLER_SPECTRUM_BINS; i++) {
        float out = 0.0f;
        if (hmax > 0.0f && d->hist[i] > 0.0f) {
            /* speckle of a real spectrum: a fixed pseudo-random factor per frame and bin */
            const float m = 0.6f + 0.8f * (float)(mix32(d->frame_no * 131u + i) >> 8) / 16777216.0f;
            const float db = 10.0f * log10f(d->hist[i] * m / hmax);
            out = 255.0f * (1.0f + db / SPEC_RANGE_DB);
        }
        d->spectrum[i] = out <= 0.0f ? 0u : (out >= 255.0f ? 255u : (uint8_t)(out + 0.5f));
    }
    const sc_display_doppler_info info = {
        .frame_no = d->frame_no,
        .box_line_lo = d->box_l0,
        .box_line_hi = d->box_l1,
        .box_sample_lo = d->box_k0,
        .box_sample_hi = d->box_k1,
        .nyquist_mm_s = nyq,
        .steer_deg = d->def.steer_deg,
        .gate_velocity_mm_s = st->gate_velocity_mm_s,
        .gate_line = d->gate_line,
        .gate_sample_lo = d->gate_k0,
        .gate_sample_hi = d->gate_k1,
        .spectrum_bins = (uint16_t)SC_DOPPLER_SPECTRUM_BINS,
        .spectrum = d->spectrum,
    };
    (void)lines;
    count_display(d, sc_display_doppler(d->display, &info));
}

_Static_assert(SC_LABEL_ARTERY == SC_LABEL_VEIN + 1, "the line hook indexes flows[] by label");

void sc_doppler_line_hook(void *ctx, const sc_bscan_line_view *v)
{
    sc_doppler *d = ctx;
    const uint32_t l = v->line;
    const int in_box = l >= d->box_l0 && l < d->box_l1 && d->box_k0 < d->box_k1;
    const int is_gate = l == d->gate_line;
    if (in_box || is_gate) {
        /* the colour beam: the line's direction steered in the image plane, to the volume */
        const float len = sqrtf(v->dir_x * v->dir_x + v->dir_z * v->dir_z);
        const float dx = v->dir_x / len, dz = v->dir_z / len;
        const float bi[3] = {dx * d->steer_c + dz * d->steer_s, 0.0f,
                             -dx * d->steer_s + dz * d->steer_c};
        const float *r = v->img2vol->r;
        const float beam[3] = {r[0] * bi[0] + r[2] * bi[2], r[3] * bi[0] + r[5] * bi[2],
                               r[6] * bi[0] + r[8] * bi[2]};
        const uint32_t k_lo = in_box ? d->box_k0 : d->gate_k0;
        const uint32_t k_hi_box = in_box ? d->box_k1 : 0u;
        const uint32_t k_hi = k_hi_box > d->gate_k1 || !is_gate ? k_hi_box : d->gate_k1;
        const uint32_t k_first = is_gate && d->gate_k0 < k_lo ? d->gate_k0 : k_lo;
        const uint32_t gate_mid = ((uint32_t)d->gate_k0 + d->gate_k1) / 2u;
        uint32_t ri = 0;
        const uint32_t k_end = k_hi < v->samples_n ? k_hi : v->samples_n;
        /* samples without flow (most of the box is tissue): no colour, nothing in the gate, the
         * position not needed; cleared up front and skipped 8 labels at a time (each sample
         * is still written once: the same colour line and gate as sample by sample) */
        if (in_box) {
            const uint32_t c1 = d->box_k1 < k_end ? d->box_k1 : k_end;
            if (c1 > d->box_k0) {
                memset(d->colour, 0, c1 - d->box_k0);
            }
        }
        const uint8_t flows[2] = {d->vessel[SC_LABEL_VEIN].valid != 0,
                                  d->vessel[SC_LABEL_ARTERY].valid != 0};
        if (is_gate && gate_mid >= k_first && gate_mid < k_end) {
            const uint8_t lg = v->labels[gate_mid];
            if ((lg != SC_LABEL_VEIN && lg != SC_LABEL_ARTERY) ||
                !flows[lg - (uint8_t)SC_LABEL_VEIN]) {
                d->status.gate_in_lumen = 0u;
                d->status.gate_velocity_mm_s = 0.0f;
            }
        }
        const uint64_t ones = UINT64_C(0x0101010101010101), highs = UINT64_C(0x8080808080808080);
        const uint64_t pv = ones * (uint64_t)SC_LABEL_VEIN, pa = ones * (uint64_t)SC_LABEL_ARTERY;
        for (uint32_t k = k_first; k < k_end; k++) {
            while (k + 8u <= k_end) { /* no vein or artery byte among the next 8: skip them */
                uint64_t w;
                memcpy(&w, v->labels + k, sizeof w);
                const uint64_t xv = w ^ pv, xa = w ^ pa;
                if ((((xv - ones) & ~xv) | ((xa - ones) & ~xa)) & highs) {
                    break;
                }
                k += 8u;
            }
            if (k >= k_end) {
                break;
            }
            const uint8_t lk = v->labels[k];
            if ((lk != SC_LABEL_VEIN && lk != SC_LABEL_ARTERY) ||
                !flows[lk - (uint8_t)SC_LABEL_VEIN]) {
                continue;
            }
            while (ri < v->run_count && v->runs[ri].k1 <= k) {
                ri++;
            }
            float p[3];
            const int in_run = ri < v->run_count && v->runs[ri].k0 <= k;
            for (uint32_t a = 0; a < 3u; a++) {
                p[a] = in_run ? v->runs[ri].a[a] + (float)k * v->runs[ri].b[a]
                              : v->f0[a] + (float)k * v->fd[a];
            }
            float vt = 0.0f, w = 0.0f;
            const int flow = sample_velocity(d, v->labels[k], p, beam, &vt, &w);
            if (in_box && k >= d->box_k0 && k < d->box_k1) {
                int8_t q = 0;
                if (flow) {
                    const float va = wrap_nyq(vt, d->nyq_mm_s);
                    const float ava = va < 0.0f ? -va : va;
                    if (ava < d->wall_mm_s || d->gain_lin * w < COLOUR_THRESHOLD) {
                        d->status.filtered_pixels++;
                    } else {
                        float x = va / d->nyq_mm_s * 127.0f;
                        x = x > 127.0f ? 127.0f : (x < -127.0f ? -127.0f : x);
                        int32_t qi = (int32_t)floor_f(x + 0.5f);
                        qi = qi == 0 ? (va > 0.0f ? 1 : -1) : qi;
                        q = (int8_t)qi;
                        d->status.colour_pixels++;
                        if ((vt < 0.0f ? -vt : vt) > d->nyq_mm_s) {
                            d->status.aliased_pixels++;
                        }
                    }
                }
                d->colour[k - d->box_k0] = q;
            }
            if (is_gate && k >= d->gate_k0 && k < d->gate_k1) {
                if (flow) {
                    spectrum_add(d, vt);
                }
                if (k == gate_mid) {
                    d->status.gate_in_lumen = (uint8_t)flow;
                    d->status.gate_velocity_mm_s = flow ? vt : 0.0f;
                }
            }
        }
        if (in_box) {
            count_display(d, sc_display_colour_line(d->display, d->frame_no, (uint16_t)l,
                                                    d->box_k0, d->colour,
                                                    (uint16_t)(d->box_k1 - d->box_k0)));
        }
    }
    if (l + 1u == v->lines_n) {
        finish_frame(d, v->lines_n);
    }
}

void sc_doppler_colour_rgb(int8_t value, uint8_t rgb[3])
{
    if (value == 0) {
        rgb[0] = rgb[1] = rgb[2] = 0u;
        return;
    }
    /* dark red -> red -> yellow toward the probe; dark blue -> blue -> cyan away */
    const int32_t m = value < 0 ? -(int32_t)value : (int32_t)value; /* 1..128 */
    const uint8_t main = (uint8_t)(m >= 64 ? 255 : 95 + (m * 160) / 64);
    const uint8_t side = (uint8_t)(m > 80 ? ((m - 80) * 255) / 48 : 0);
    if (value > 0) {
        rgb[0] = main;
        rgb[1] = side;
        rgb[2] = 0u;
    } else {
        rgb[0] = 0u;
        rgb[1] = side;
        rgb[2] = main;
    }
}

const sc_doppler_status *sc_doppler_status_get(const sc_doppler *d)
{
    return &d->status;
}
