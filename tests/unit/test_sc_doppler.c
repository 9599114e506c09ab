/* test_sc_doppler.c: colour and pulsed-wave Doppler from the vessel flow model (sc_doppler.h).
 *
 * A generated volume holds a straight artery (and in one variant a vein, or a thrombus instead
 * of the artery) lying in the image plane along x at 15 mm depth; the B-scan runs rigid (no mesh)
 * or, for the compressed vein, through the deformed mesh of tools/bench_bscan/bscan_scene.h.
 * Colour arrives through the host simulator's display (the colour ops), as a sink receives it.
 */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "../../tools/bench_bscan/bscan_scene.h"
#include "sc_bscan.h"
#include "sc_doppler.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_mesh.h"

#define VSP  0.5f
#define VNX  100u /* x -10 .. 40 */
#define VNY  40u  /* y -10 .. 10 */
#define VNZ  100u /* z -5 .. 45 */
#define ART_Z 15.0f
#define ART_R 3.0f
#define VEIN_Z 28.0f
#define VEIN_R 4.0f

static uint8_t g_vox[VNX * VNY * VNZ], g_lab[VNX * VNY * VNZ];
static sc_volume g_vol;
static sc_bscan g_b;
static sc_doppler g_d;
static sc_hs_display g_disp;

/* kind 0: artery only; 1: artery and vein; 2: the artery's lumen is thrombus */
static void make_volume(int kind)
{
    g_vol.dim[0] = VNX;
    g_vol.dim[1] = VNY;
    g_vol.dim[2] = VNZ;
    for (uint32_t a = 0; a < 3u; a++) {
        g_vol.spacing_mm[a] = VSP;
    }
    g_vol.origin_mm[0] = -10.0f;
    g_vol.origin_mm[1] = -10.0f;
    g_vol.origin_mm[2] = -5.0f;
    g_vol.voxels = g_vox;
    g_vol.labels = g_lab;
    for (uint32_t k = 0; k < VNZ; k++) {
        for (uint32_t j = 0; j < VNY; j++) {
            for (uint32_t i = 0; i < VNX; i++) {
                const size_t idx = i + VNX * (j + (size_t)VNY * k);
                const float y = -10.0f + (float)j * VSP, z = -5.0f + (float)k * VSP;
                uint8_t lab = SC_LABEL_MUSCLE;
                if (z < 0.0f) {
                    lab = SC_LABEL_OUTSIDE;
                } else if (hypotf(y, z - ART_Z) < ART_R) {
                    lab = kind == 2 ? SC_LABEL_THROMBUS : SC_LABEL_ARTERY;
                } else if (kind == 1 && hypotf(y, z - VEIN_Z) < VEIN_R) {
                    lab = SC_LABEL_VEIN;
                }
                g_lab[idx] = lab;
                g_vox[idx] = lab == SC_LABEL_MUSCLE ? 120u : (lab == SC_LABEL_OUTSIDE ? 0u : 20u);
            }
        }
    }
}

static sc_bscan_def scan_def(void)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan.depth_mm = 40.0f;
    return d;
}

/* Systolic peak (cardiac phase 0.175 is the top of the systolic wave), mid-expiration. */
static sc_doppler_def dop_def(float steer_deg, float prf_hz)
{
    sc_doppler_def d = sc_doppler_default_def();
    d.box_u0 = 0.0f;
    d.box_u1 = 1.0f;
    d.box_v0 = 0.0f;
    d.box_v1 = 1.0f;
    d.steer_deg = steer_deg;
    d.prf_hz = prf_hz;
    d.wall_hz = 50.0f;
    d.gate_u = 0.5f;
    d.gate_depth_mm = ART_Z;
    d.gate_len_mm = 1.0f;
    return d;
}

static void render(const sc_doppler_def *dd, const sc_mesh *mesh, const sc_nodes *nodes,
                   const sc_volume *vol, const sc_xform *probe, uint32_t fno)
{
    const sc_bscan_def bd = scan_def();
    assert_int_equal(sc_bscan_init(&g_b, &bd), SC_OK);
    if (mesh != NULL) {
        assert_int_equal(sc_bscan_attach_mesh(&g_b, mesh), SC_OK);
    }
    assert_int_equal(sc_doppler_init(&g_d, dd), SC_OK);
    assert_int_equal(sc_doppler_attach_volume(&g_d, vol), SC_OK);
    assert_int_equal(sc_doppler_set_phase(&g_d, 0.175f, 0.0f), SC_OK);
    sc_doppler_advance(&g_d, 0.0f);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_doppler_frame_begin(&g_d, &g_b, &dev, fno), SC_OK);
    assert_int_equal(sc_bscan_frame(&g_b, mesh, nodes, vol, probe, 1, &dev, fno), SC_OK);
    assert_int_equal(g_disp.protocol_errors, 0);
    assert_int_equal(g_disp.frames_complete, 1);
    assert_int_equal(g_disp.doppler_records, 1);
    assert_int_equal(g_d.status.display_errors, 0);
}

static sc_xform probe_at(float x, float y)
{
    sc_xform t = sc_xform_identity();
    t.t_mm[0] = x;
    t.t_mm[1] = y;
    return t;
}

/* Count coloured pixels by sign; check each lies in a flowing lumen of the (rigid) volume. */
typedef struct colour_count {
    uint32_t pos, neg, outside_lumen;
} colour_count;

static colour_count count_colour(const sc_xform *probe)
{
    colour_count c = {0, 0, 0};
    const sc_bscan_def bd = scan_def();
    for (uint32_t l = 0; l < bd.scan.lines_n; l++) {
        for (uint32_t k = 0; k < bd.scan.samples_n; k++) {
            const int8_t v = g_disp.colour[(size_t)l * SC_MAX_SCAN_SAMPLES + k];
            if (v == 0) {
                continue;
            }
            c.pos += v > 0;
            c.neg += v < 0;
            /* the pixel's position: linear probe, identity rotation */
            const float x = g_b.geom.start_x_mm[l] + (float)k * g_b.geom.step_x_mm[l];
            const float z = g_b.geom.start_z_mm[l] + (float)k * g_b.geom.step_z_mm[l];
            const float p[3] = {x + probe->t_mm[0], probe->t_mm[1], z + probe->t_mm[2]};
            const int i = (int)floorf((p[0] - g_vol.origin_mm[0]) / VSP + 0.5f);
            const int j = (int)floorf((p[1] - g_vol.origin_mm[1]) / VSP + 0.5f);
            const int kk = (int)floorf((p[2] - g_vol.origin_mm[2]) / VSP + 0.5f);
            const uint8_t lab = g_lab[(size_t)i + VNX * ((size_t)j + (size_t)VNY * (size_t)kk)];
            c.outside_lumen += lab != SC_LABEL_ARTERY && lab != SC_LABEL_VEIN;
        }
    }
    return c;
}

static void vessel_model_fits_the_tube(void **state)
{
    (void)state;
    make_volume(1);
    const sc_doppler_def dd = sc_doppler_default_def();
    assert_int_equal(sc_doppler_init(&g_d, &dd), SC_OK);
    assert_int_equal(sc_doppler_attach_volume(&g_d, &g_vol), SC_OK);
    const sc_doppler_vessel *a = &g_d.vessel[SC_LABEL_ARTERY], *v = &g_d.vessel[SC_LABEL_VEIN];
    assert_true(a->valid && v->valid);
    assert_true(fabsf(a->axis[0] - 1.0f) < 1e-3f); /* along +x */
    assert_true(fabsf(a->centre_mm[2] - ART_Z) < 0.1f && fabsf(a->centre_mm[1]) < 0.1f);
    assert_true(fabsf(a->radius_mm - ART_R) < 0.25f);
    assert_true(fabsf(v->radius_mm - VEIN_R) < 0.25f);
    assert_int_equal(g_d.vessel[SC_LABEL_THROMBUS].valid, 0);
}

static void colour_only_inside_flowing_lumens(void **state)
{
    (void)state;
    make_volume(1);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    const sc_doppler_def dd = dop_def(20.0f, 6000.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    const colour_count c = count_colour(&probe);
    assert_int_equal(c.outside_lumen, 0);
    /* the lumens' in-plane area: (2 * 3 + 2 * 4) mm x 38 mm, in pixels of 0.148 x 0.078 mm */
    const float px_mm2 = (38.0f / 256.0f) * (40.0f / 512.0f);
    const float lumen_px = (2.0f * ART_R + 2.0f * VEIN_R) * 38.0f / px_mm2;
    assert_true((float)(c.pos + c.neg) > 0.8f * lumen_px);
    assert_int_equal(c.pos + c.neg, g_d.status.colour_pixels);
    /* artery (+x) and vein (-x) flow opposite ways: both colours appear */
    assert_true(c.pos > 1000u && c.neg > 1000u);
}

static void unsteered_beam_across_the_flow_shows_no_colour(void **state)
{
    (void)state;
    make_volume(0);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    const sc_doppler_def dd = dop_def(0.0f, 6000.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    /* cos 90 degrees: the wall filter removes everything */
    assert_int_equal(g_d.status.colour_pixels, 0);
    assert_true(g_d.status.filtered_pixels > 1000u);
}

static void colour_flips_with_the_sign_of_the_beam_angle(void **state)
{
    (void)state;
    make_volume(0);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    sc_doppler_def dd = dop_def(20.0f, 6000.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    const colour_count plus = count_colour(&probe);
    dd.steer_deg = -20.0f;
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    const colour_count minus = count_colour(&probe);
    /* flow along +x, beam steered toward +x: away from the probe (blue); steered the other way:
     * toward it (red) */
    assert_true(plus.neg > 1000u);
    assert_int_equal(plus.pos, 0);
    assert_true(minus.pos > 1000u);
    assert_int_equal(minus.neg, 0);
    assert_true(plus.neg > minus.pos - minus.pos / 50u && plus.neg < minus.pos + minus.pos / 50u);
    assert_int_equal(g_d.status.aliased_pixels, 0);
}

static void colour_aliases_above_the_scale(void **state)
{
    (void)state;
    make_volume(0);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    /* peak along the beam 800 sin 20 = 274 mm/s; PRF 1500 Hz at 5 MHz: Nyquist 115 mm/s */
    sc_doppler_def dd = dop_def(20.0f, 1500.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    const colour_count c = count_colour(&probe);
    print_message("aliased %u of %u (red %u, blue %u)\n", g_d.status.aliased_pixels,
                  g_d.status.colour_pixels, c.pos, c.neg);
    assert_true(g_d.status.aliased_pixels > 1000u);
    assert_true(c.pos > 500u); /* wrapped over to the other colour */
    assert_true(c.neg > 500u);
    assert_int_equal(c.outside_lumen, 0);
    /* the same flow with a scale above it does not alias */
    dd.prf_hz = 6000.0f;
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    assert_int_equal(g_d.status.aliased_pixels, 0);
}

static void thrombus_shows_no_colour(void **state)
{
    (void)state;
    make_volume(2);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    const sc_doppler_def dd = dop_def(20.0f, 6000.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    assert_int_equal(g_d.status.colour_pixels, 0);
    assert_int_equal(g_d.status.gate_in_lumen, 0);
    for (uint32_t i = 0; i < SC_DOPPLER_SPECTRUM_BINS; i++) {
        assert_int_equal(g_disp.spectrum[i], 0);
    }
}

static void spectrum_peaks_at_the_model_velocity(void **state)
{
    (void)state;
    make_volume(0);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    const sc_doppler_def dd = dop_def(-20.0f, 6000.0f);
    render(&dd, NULL, NULL, &g_vol, &probe, 1u);
    /* the gate (1 mm at the centreline) sees 800 mm/s at 70 degrees: 800 sin 20 toward */
    const float expect = 800.0f * sinf(20.0f * 3.14159265f / 180.0f);
    const float nyq = 1540000.0f * 6000.0f / (4.0f * 5e6f);
    const float bin = 2.0f * nyq / (float)SC_DOPPLER_SPECTRUM_BINS;
    print_message("gate %.1f mm/s, spectrum peak %.1f, expected %.1f\n",
                  (double)g_d.status.gate_velocity_mm_s, (double)g_d.status.gate_peak_mm_s,
                  (double)expect);
    assert_int_equal(g_d.status.gate_in_lumen, 1);
    assert_true(fabsf(g_d.status.gate_velocity_mm_s - expect) < 0.01f * expect);
    assert_true(fabsf(g_d.status.gate_peak_mm_s - expect) < 0.03f * expect + bin);
    /* the display record carries the same spectrum: its brightest bin at that velocity */
    assert_int_equal(g_disp.doppler.spectrum_bins, SC_DOPPLER_SPECTRUM_BINS);
    uint32_t best = 0;
    for (uint32_t i = 1; i < SC_DOPPLER_SPECTRUM_BINS; i++) {
        if (g_disp.spectrum[i] > g_disp.spectrum[best]) {
            best = i;
        }
    }
    const float v_best = -nyq + ((float)best + 0.5f) * bin;
    assert_true(fabsf(v_best - expect) < 0.1f * expect);
    assert_true(fabsf(g_disp.doppler.nyquist_mm_s - nyq) < 0.01f);
    /* nothing on the other side of zero */
    const uint32_t zero_bin = SC_DOPPLER_SPECTRUM_BINS / 2u;
    for (uint32_t i = 0; i + 4u < zero_bin; i++) {
        assert_int_equal(g_disp.spectrum[i], 0);
    }
}

static void artery_velocity_pulses_with_the_cardiac_phase(void **state)
{
    (void)state;
    sc_doppler_def dd = sc_doppler_default_def();
    assert_int_equal(sc_doppler_init(&g_d, &dd), SC_OK);
    assert_int_equal(sc_doppler_set_phase(&g_d, 0.175f, 0.0f), SC_OK);
    sc_doppler_advance(&g_d, 0.0f);
    assert_true(fabsf(g_d.v_artery_mm_s - dd.artery_peak_mm_s) < 1.0f);
    assert_int_equal(sc_doppler_set_phase(&g_d, 0.8f, 0.25f), SC_OK);
    sc_doppler_advance(&g_d, 0.0f);
    assert_true(fabsf(g_d.v_artery_mm_s - dd.artery_floor_mm_s) < 1.0f);
    assert_true(fabsf(g_d.v_vein_mm_s - dd.vein_mean_mm_s * 1.5f) < 1.0f);
    /* own clock: one second at 60 bpm is one cycle */
    dd.heart_rate_bpm = 60.0f;
    assert_int_equal(sc_doppler_init(&g_d, &dd), SC_OK);
    for (int i = 0; i < 30; i++) {
        sc_doppler_advance(&g_d, 1.0f / 60.0f);
    }
    assert_true(fabsf(g_d.cardiac_phase - 0.5f) < 1e-3f);
    assert_int_equal(sc_doppler_set_phase(&g_d, NAN, 0.0f), SC_ERR_NOT_FINITE);
}

static void bad_settings_are_refused_and_the_previous_stay(void **state)
{
    (void)state;
    sc_doppler_def dd = sc_doppler_default_def();
    assert_int_equal(sc_doppler_init(&g_d, &dd), SC_OK);
    sc_doppler_def bad = dd;
    bad.steer_deg = 45.0f;
    assert_int_equal(sc_doppler_set_def(&g_d, &bad), SC_ERR_RANGE);
    bad = dd;
    bad.prf_hz = NAN;
    assert_int_equal(sc_doppler_set_def(&g_d, &bad), SC_ERR_NOT_FINITE);
    bad = dd;
    bad.box_u0 = 0.8f; /* u0 > u1 */
    assert_int_equal(sc_doppler_set_def(&g_d, &bad), SC_ERR_RANGE);
    bad = dd;
    bad.wall_hz = dd.prf_hz; /* above prf / 4 */
    assert_int_equal(sc_doppler_set_def(&g_d, &bad), SC_ERR_RANGE);
    assert_int_equal(sc_doppler_set_def(&g_d, NULL), SC_ERR_INVALID_ARG);
    assert_true(memcmp(&g_d.def, &dd, sizeof dd) == 0);
}

/* The deformed configuration decides: a vein squeezed shut loses its colour, the artery keeps
 * it. Scene of bscan_scene.h (vessels along y), the probe rolled 20 degrees about x so that the
 * beam has a component along the flow. */
static scn_volume g_scn;
static sc_mesh g_mesh;
static sc_nodes g_nodes;

static uint32_t count_sign(int sign)
{
    uint32_t n = 0;
    for (size_t i = 0; i < sizeof g_disp.colour; i++) {
        n += sign > 0 ? g_disp.colour[i] > 0 : g_disp.colour[i] < 0;
    }
    return n;
}

static void squeezed_vein_loses_its_colour(void **state)
{
    (void)state;
    scn_make_volume(&g_scn);
    sc_mesh_def md = sc_mesh_default_def();
    md.nx = 32;
    md.ny = 16;
    md.nz = 16;
    assert_int_equal(sc_mesh_build(&g_mesh, &md), SC_OK);
    sc_nodes_reset_to_rest(&g_nodes, &g_mesh);
    const float a = 20.0f * 3.14159265f / 180.0f, c = cosf(a), s = sinf(a);
    const sc_xform probe = {.r = {1.0f, 0.0f, 0.0f, 0.0f, c, -s, 0.0f, s, c},
                            .t_mm = {20.0f, 10.0f, 0.0f}};
    sc_doppler_def dd = sc_doppler_default_def();
    dd.box_u0 = 0.0f;
    dd.box_u1 = 1.0f;
    dd.box_v0 = 0.0f;
    dd.box_v1 = 1.0f;
    dd.prf_hz = 8000.0f;
    render(&dd, &g_mesh, &g_nodes, &g_scn.v, &probe, 3u);
    /* vein (sign -1) and artery (+1) flow opposite ways along +y */
    const uint32_t vein_rest = count_sign(-1), art_rest = count_sign(+1);
    assert_true(vein_rest > 1000u && art_rest > 500u);
    scn_deform(&g_mesh, &g_nodes, SCN_DEFORM_SQUASH_VEIN, 0.95f);
    render(&dd, &g_mesh, &g_nodes, &g_scn.v, &probe, 4u);
    const uint32_t vein_sq = count_sign(-1), art_sq = count_sign(+1);
    print_message("vein colour px %u -> %u, artery %u -> %u\n", vein_rest, vein_sq, art_rest,
                  art_sq);
    assert_true(vein_sq < vein_rest / 5u);
    assert_true(art_sq > art_rest - art_rest / 5u);
}

static void colour_and_spectrum_are_deterministic(void **state)
{
    (void)state;
    make_volume(1);
    const sc_xform probe = probe_at(15.0f, 0.0f);
    const sc_doppler_def dd = dop_def(15.0f, 2500.0f);
    uint64_t h[2];
    for (int r = 0; r < 2; r++) {
        render(&dd, NULL, NULL, &g_vol, &probe, 9u);
        h[r] = sc_hs_hash64(g_disp.colour, sizeof g_disp.colour,
                            sc_hs_hash64(g_disp.spectrum, sizeof g_disp.spectrum, 1u));
        assert_true(g_disp.colour_lines > 0u);
    }
    assert_true(h[0] == h[1]);
}

static void colour_map_is_red_toward_blue_away(void **state)
{
    (void)state;
    uint8_t rgb[3];
    sc_doppler_colour_rgb(0, rgb);
    assert_true(rgb[0] == 0u && rgb[1] == 0u && rgb[2] == 0u);
    sc_doppler_colour_rgb(60, rgb);
    assert_true(rgb[0] > 200u && rgb[2] == 0u);
    sc_doppler_colour_rgb(-60, rgb);
    assert_true(rgb[2] > 200u && rgb[0] == 0u);
    sc_doppler_colour_rgb(127, rgb);
    assert_true(rgb[0] == 255u && rgb[1] > 200u); /* fast toward: yellow */
    sc_doppler_colour_rgb(-127, rgb);
    assert_true(rgb[2] == 255u && rgb[1] > 200u); /* fast away: cyan */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(vessel_model_fits_the_tube),
        cmocka_unit_test(colour_only_inside_flowing_lumens),
        cmocka_unit_test(unsteered_beam_across_the_flow_shows_no_colour),
        cmocka_unit_test(colour_flips_with_the_sign_of_the_beam_angle),
        cmocka_unit_test(colour_aliases_above_the_scale),
        cmocka_unit_test(thrombus_shows_no_colour),
        cmocka_unit_test(spectrum_peaks_at_the_model_velocity),
        cmocka_unit_test(artery_velocity_pulses_with_the_cardiac_phase),
        cmocka_unit_test(bad_settings_are_refused_and_the_previous_stay),
        cmocka_unit_test(squeezed_vein_loses_its_colour),
        cmocka_unit_test(colour_and_spectrum_are_deterministic),
        cmocka_unit_test(colour_map_is_red_toward_blue_away),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
