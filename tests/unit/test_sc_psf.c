/* test_sc_psf.c: speckle from the rest-configuration scatterer field and the beam's PSF.
 *
 * A uniform volume (one grey everywhere, no texture of its own) is imaged with the speckle pass
 * on. The displayed grey is turned back into the envelope (the inverse of the log compression,
 * 100 dB displayed so nothing clips) and measured in a window at the focus and one far below
 * it: fully developed speckle has mean / std of the envelope 1.91 (Rayleigh); the intensity's
 * autocovariance has the amplitude PSF's FWHM (a Gaussian PSF of FWHM W: |R|^2 of FWHM W),
 * axially from the pulse, laterally from the aperture and focus (narrower at the focus than far
 * from it). A probe tilted in plane keeps its speckle long across its own beam (the pass works
 * in image axes). The field lives in the rest configuration: a 0.1 mm step out of plane keeps
 * the speckle, two slice thicknesses decorrelate it. A line hook's drawing survives the pass.
 */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_psf.h"

#define PH_SP_MM 0.5f
#define PH_NX    121u /* x -30 .. 30 */
#define PH_NY    21u  /* y -5 .. 5 */
#define PH_NZ    101u /* z -5 .. 45 */
#define PH_GREY  200u
#define RANGE_DB 100.0f
#define LINES    256u
#define SAMPLES  512u
#define WIDTH_MM 38.0f
#define DEPTH_MM 40.0f

static uint8_t g_vox[PH_NX * PH_NY * PH_NZ];
static sc_volume g_vol;
static sc_bscan g_b;
static sc_hs_display g_disp;
static float g_env[LINES * SAMPLES];
static float g_env2[LINES * SAMPLES];

static void volume_setup(void)
{
    memset(g_vox, PH_GREY, sizeof g_vox);
    g_vol.dim[0] = PH_NX;
    g_vol.dim[1] = PH_NY;
    g_vol.dim[2] = PH_NZ;
    g_vol.spacing_mm[0] = g_vol.spacing_mm[1] = g_vol.spacing_mm[2] = PH_SP_MM;
    g_vol.origin_mm[0] = -30.0f;
    g_vol.origin_mm[1] = -5.0f;
    g_vol.origin_mm[2] = -5.0f;
    g_vol.voxels = g_vox;
    g_vol.labels = NULL;
}

static sc_bscan_def psf_def(void)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.lines_n = LINES;
    d.scan.samples_n = SAMPLES;
    d.scan.width_mm = WIDTH_MM;
    d.scan.depth_mm = DEPTH_MM;
    d.dynamic_range_db = RANGE_DB;
    d.volume_range_db = RANGE_DB;
    d.focus_mm = 20.0f;
    d.psf = 1u;
    return d;
}

/* Image with the probe turned by tilt_deg about y (in plane) and moved dy_mm out of plane;
 * the envelope into env. */
static void image(const sc_bscan_def *d, float tilt_deg, float dy_mm, float *env)
{
    assert_int_equal(sc_bscan_init(&g_b, d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    sc_xform probe = sc_xform_identity();
    const float a = tilt_deg * 3.14159265f / 180.0f;
    probe.r[0] = cosf(a);
    probe.r[2] = sinf(a);
    probe.r[6] = -sinf(a);
    probe.r[8] = cosf(a);
    probe.t_mm[1] = dy_mm;
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol, &probe, 1, &dev, 1u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
    for (uint32_t i = 0; i < LINES * SAMPLES; i++) {
        const float g = (float)g_disp.last[i];
        env[i] = powf(10.0f, (g - 255.0f) * RANGE_DB / (255.0f * 20.0f));
    }
}

typedef struct window {
    uint32_t l0, l1, k0, k1;
} window;

static window depth_window(float z0_mm, float z1_mm)
{
    const float ds = DEPTH_MM / (float)SAMPLES;
    window w = {24u, LINES - 24u, (uint32_t)(z0_mm / ds), (uint32_t)(z1_mm / ds)};
    return w;
}

static void mean_std(const float *env, window w, float *mean, float *sd)
{
    double s = 0.0, s2 = 0.0;
    uint32_t n = 0;
    for (uint32_t l = w.l0; l < w.l1; l++) {
        for (uint32_t k = w.k0; k < w.k1; k++) {
            const double v = env[l * SAMPLES + k];
            s += v;
            s2 += v * v;
            n++;
        }
    }
    *mean = (float)(s / n);
    *sd = (float)sqrt(s2 / n - (s / n) * (s / n));
}

/* FWHM (in steps) of the intensity autocovariance along lines (axis 1) or samples (axis 0). */
static float acov_fwhm(const float *env, window w, int lateral)
{
    double mean = 0.0;
    uint32_t n = 0;
    for (uint32_t l = w.l0; l < w.l1; l++) {
        for (uint32_t k = w.k0; k < w.k1; k++) {
            const double v = env[l * SAMPLES + k];
            mean += v * v;
            n++;
        }
    }
    mean /= n;
    double c[16];
    for (uint32_t lag = 0; lag < 16u; lag++) {
        double s = 0.0;
        uint32_t m = 0;
        for (uint32_t l = w.l0; l < w.l1; l++) {
            for (uint32_t k = w.k0; k < w.k1; k++) {
                const uint32_t l2 = lateral ? l + lag : l, k2 = lateral ? k : k + lag;
                const double a = (double)env[l * SAMPLES + k] * env[l * SAMPLES + k] - mean;
                const double b = (double)env[l2 * SAMPLES + k2] * env[l2 * SAMPLES + k2] - mean;
                s += a * b;
                m++;
            }
        }
        c[lag] = s / m;
    }
    for (uint32_t lag = 1; lag < 16u; lag++) {
        const double r0 = c[lag - 1u] / c[0], r1 = c[lag] / c[0];
        if (r1 <= 0.5) {
            return (float)(2.0 * ((double)(lag - 1u) + (r0 - 0.5) / (r0 - r1)));
        }
    }
    return 32.0f;
}

static float band_width_mm(const sc_psf_widths *wd, float z_mm)
{
    uint32_t best = 0;
    for (uint32_t b = 1; b < SC_PSF_BANDS; b++) {
        if (fabsf(wd->band_depth_mm[b] - z_mm) < fabsf(wd->band_depth_mm[best] - z_mm)) {
            best = b;
        }
    }
    return wd->lateral_fwhm_mm[best];
}

static void speckle_is_rayleigh_with_the_psf_s_cell_narrowest_at_focus(void **state)
{
    (void)state;
    volume_setup();
    const sc_bscan_def d = psf_def();
    image(&d, 0.0f, 0.0f, g_env);
    const sc_psf_widths *wd = &g_b.psf.widths;
    const float ds = DEPTH_MM / (float)SAMPLES, pitch = WIDTH_MM / (float)LINES;
    const window wf = depth_window(17.0f, 23.0f), wdeep = depth_window(33.0f, 39.0f);
    float mean, sd;
    mean_std(g_env, wf, &mean, &sd);
    print_message("speckle SNR at the focus: %.3f (Rayleigh 1.91)\n", (double)(mean / sd));
    assert_float_equal(mean / sd, 1.91f, 0.15f);
    mean_std(g_env, wdeep, &mean, &sd);
    print_message("speckle SNR deep: %.3f\n", (double)(mean / sd));
    assert_float_equal(mean / sd, 1.91f, 0.15f);

    const float ax = acov_fwhm(g_env, wf, 0) * ds, lat_f = acov_fwhm(g_env, wf, 1) * pitch,
                lat_d = acov_fwhm(g_env, wdeep, 1) * pitch;
    const float psf_lat_f = band_width_mm(wd, 20.0f), psf_lat_d = band_width_mm(wd, 36.0f);
    print_message("FWHM mm: axial %.3f (PSF %.3f); lateral at focus %.3f (PSF %.3f), deep %.3f "
                  "(PSF %.3f)\n",
                  (double)ax, (double)wd->axial_fwhm_mm, (double)lat_f, (double)psf_lat_f,
                  (double)lat_d, (double)psf_lat_d);
    /* the speckle cell is the PSF's (within the sampling: a sample and a line wide cells) */
    assert_float_equal(ax, wd->axial_fwhm_mm, 0.35f * wd->axial_fwhm_mm);
    assert_float_equal(lat_f, psf_lat_f, 0.3f * psf_lat_f);
    assert_float_equal(lat_d, psf_lat_d, 0.3f * psf_lat_d);
    assert_true(lat_f < 0.85f * lat_d); /* narrowest at the focus */
    assert_true(ax < 0.8f * lat_f);     /* long across the beam */
    /* a uniform region keeps its mean intensity: the log image's mean lies the Rayleigh log
     * bias (2.51 dB) below the voxel's grey */
    double gsum = 0.0;
    uint32_t gn = 0;
    for (uint32_t l = wf.l0; l < wf.l1; l++) {
        for (uint32_t k = wf.k0; k < wf.k1; k++) {
            gsum += g_disp.last[l * SAMPLES + k];
            gn++;
        }
    }
    assert_float_equal(gsum / gn, (double)PH_GREY - 2.5068 * 255.0 / RANGE_DB, 2.0);
}

static void tilted_probe_keeps_speckle_long_across_its_beam(void **state)
{
    (void)state;
    volume_setup();
    const sc_bscan_def d = psf_def();
    image(&d, 30.0f, 0.0f, g_env);
    const float ds = DEPTH_MM / (float)SAMPLES, pitch = WIDTH_MM / (float)LINES;
    const window wf = depth_window(17.0f, 23.0f);
    const float ax = acov_fwhm(g_env, wf, 0) * ds, lat = acov_fwhm(g_env, wf, 1) * pitch;
    print_message("tilted 30 deg: axial %.3f mm, lateral %.3f mm\n", (double)ax, (double)lat);
    assert_true(ax < 0.8f * lat);
    float mean, sd;
    mean_std(g_env, wf, &mean, &sd);
    assert_float_equal(mean / sd, 1.91f, 0.15f);
}

static float correlation(const float *a, const float *b, window w)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    uint32_t n = 0;
    for (uint32_t l = w.l0; l < w.l1; l++) {
        for (uint32_t k = w.k0; k < w.k1; k++) {
            const double x = a[l * SAMPLES + k], y = b[l * SAMPLES + k];
            sa += x;
            sb += y;
            saa += x * x;
            sbb += y * y;
            sab += x * y;
            n++;
        }
    }
    const double ca = saa / n - (sa / n) * (sa / n), cb = sbb / n - (sb / n) * (sb / n);
    return (float)((sab / n - (sa / n) * (sb / n)) / sqrt(ca * cb));
}

static void speckle_is_fixed_in_tissue_and_decorrelates_out_of_plane(void **state)
{
    (void)state;
    volume_setup();
    const sc_bscan_def d = psf_def();
    const window wf = depth_window(10.0f, 30.0f);
    image(&d, 0.0f, 0.0f, g_env);
    image(&d, 0.0f, 0.0f, g_env2);
    assert_float_equal(correlation(g_env, g_env2, wf), 1.0f, 1e-6f); /* deterministic */
    image(&d, 0.0f, 0.1f, g_env2);
    const float near = correlation(g_env, g_env2, wf);
    image(&d, 0.0f, 2.0f * d.psf_def.slice_mm, g_env2);
    const float far = correlation(g_env, g_env2, wf);
    print_message("correlation out of plane: 0.1 mm %.3f, two slices %.3f\n", (double)near,
                  (double)far);
    assert_true(near > 0.8f);
    assert_true(far < 0.2f);
}

/* A hook drawing into every 10th sample: the pass leaves its drawing as it drew it. */
static void hook_draw(void *ctx, const sc_bscan_line_view *v)
{
    (void)ctx;
    for (uint32_t k = 0; k < v->samples_n; k += 10u) {
        v->out[k] = 7u;
    }
}

static void line_hook_drawing_survives_the_pass(void **state)
{
    (void)state;
    volume_setup();
    const sc_bscan_def d = psf_def();
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_bscan_set_line_hook(&g_b, hook_draw, NULL);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    const sc_xform probe = sc_xform_identity();
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol, &probe, 1, &dev, 1u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
    uint32_t drawn = 0, other7 = 0;
    for (uint32_t l = 0; l < LINES; l++) {
        for (uint32_t k = 0; k < SAMPLES; k++) {
            const uint8_t g = g_disp.last[l * SAMPLES + k];
            if (k % 10u == 0u) {
                drawn += g == 7u;
            } else {
                other7 += g == 7u;
            }
        }
    }
    assert_int_equal(drawn, LINES * ((SAMPLES + 9u) / 10u));
    assert_true(other7 < 20u);
}

static void bad_psf_settings_are_rejected(void **state)
{
    (void)state;
    sc_bscan_def d = psf_def();
    d.psf_def.fractional_bw = 0.0f;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_ERR_RANGE);
    d = psf_def();
    d.psf_def.aperture_mm = NAN;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_ERR_NOT_FINITE);
    d = psf_def();
    d.psf = 2u;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_ERR_RANGE);
}

/* The field lives in the rest configuration: tissue slid 4 line pitches sideways under the probe
 * (a mesh over the image, every node moved) carries its speckle along: the deformed image's line
 * l is the rest image's line l - 4, and no longer its own line l. */
static sc_mesh g_mesh;
static sc_nodes g_nodes;

static float shifted_correlation(const float *a, const float *b, window w, uint32_t shift)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    uint32_t n = 0;
    for (uint32_t l = w.l0; l < w.l1; l++) {
        for (uint32_t k = w.k0; k < w.k1; k++) {
            const double x = a[l * SAMPLES + k], y = b[(l - shift) * SAMPLES + k];
            sa += x;
            sb += y;
            saa += x * x;
            sbb += y * y;
            sab += x * y;
            n++;
        }
    }
    const double ca = saa / n - (sa / n) * (sa / n), cb = sbb / n - (sb / n) * (sb / n);
    return (float)((sab / n - (sa / n) * (sb / n)) / sqrt(ca * cb));
}

static void image_mesh(const sc_bscan_def *d, float *env)
{
    assert_int_equal(sc_bscan_init(&g_b, d), SC_OK);
    assert_int_equal(sc_bscan_attach_mesh(&g_b, &g_mesh), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    const sc_xform probe = sc_xform_identity();
    assert_int_equal(sc_bscan_frame(&g_b, &g_mesh, &g_nodes, &g_vol, &probe, 1, &dev, 1u), SC_OK);
    for (uint32_t i = 0; i < LINES * SAMPLES; i++) {
        const float g = (float)g_disp.last[i];
        env[i] = powf(10.0f, (g - 255.0f) * RANGE_DB / (255.0f * 20.0f));
    }
}

static void speckle_moves_with_the_tissue(void **state)
{
    (void)state;
    volume_setup();
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = 12u;
    md.ny = 3u;
    md.nz = 10u;
    md.origin_mm[0] = -28.0f;
    md.origin_mm[1] = -4.0f;
    md.origin_mm[2] = -2.0f;
    md.size_mm[0] = 56.0f;
    md.size_mm[1] = 8.0f;
    md.size_mm[2] = 44.0f;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    const sc_bscan_def d = psf_def();
    image_mesh(&d, g_env);
    const float dx = 4.0f * WIDTH_MM / (float)LINES;
    for (uint32_t i = 0; i < g_mesh.node_count; i++) {
        g_nodes.x[i] += dx;
    }
    image_mesh(&d, g_env2);
    const window w = depth_window(5.0f, 35.0f);
    const float moved = shifted_correlation(g_env2, g_env, w, 4u);
    const float still = shifted_correlation(g_env2, g_env, w, 0u);
    print_message("tissue slid 4 lines: correlation with the rest image moved along %.3f, in "
                  "place %.3f\n",
                  (double)moved, (double)still);
    assert_true(moved > 0.9f);
    assert_true(still < 0.3f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(speckle_is_rayleigh_with_the_psf_s_cell_narrowest_at_focus),
        cmocka_unit_test(tilted_probe_keeps_speckle_long_across_its_beam),
        cmocka_unit_test(speckle_is_fixed_in_tissue_and_decorrelates_out_of_plane),
        cmocka_unit_test(line_hook_drawing_survives_the_pass),
        cmocka_unit_test(speckle_moves_with_the_tissue),
        cmocka_unit_test(bad_psf_settings_are_rejected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
