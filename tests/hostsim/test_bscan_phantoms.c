/* test_bscan_phantoms.c: the B-scan of each phantom case has no black "no data" band.
 *
 * The phantoms (tools/casebuild/sc_phantom.c) are 46 mm deep below the skin and 48 mm wide;
 * the default linear image is 60 mm deep and a press carries it deeper still, a tilt or a
 * curvilinear fan beside the volume. Beyond the case volume the image continues as tissue
 * (sc_bscan.h), so in every contact frame every depth row has signal: no row of the image is
 * all zero. Rigid imaging (no mesh): the rows beyond the volume are the same with the mesh, which
 * never leaves the volume.
 */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_labels.h"
#include "sc_phantom.h"
#include "sc_scan_geom.h"

static sc_bscan g_b;
static sc_hs_display g_disp;

/* Probe face centre at (x, y, z) of the volume frame, beam along +z, tilted about y. */
static sc_xform probe_at(float x, float y, float z, float tilt_deg)
{
    const float a = tilt_deg * 3.14159265f / 180.0f;
    const float c = cosf(a), s = sinf(a);
    const sc_xform t = {.r = {c, 0.0f, s, 0.0f, 1.0f, 0.0f, -s, 0.0f, c}, .t_mm = {x, y, z}};
    return t;
}

/* Image one frame; returns the number of depth rows (sample indices) that are zero on every
 * line, and the fraction of zero pixels in *zero_frac. */
static uint32_t zero_rows(const sc_volume *v, const sc_scan_def *scan, const sc_xform *probe,
                          float *zero_frac)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan = *scan;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, v, probe, 1, &dev, 1u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
    const uint32_t lines = scan->lines_n, n = scan->samples_n;
    uint32_t rows = 0, zeros = 0;
    for (uint32_t k = 0; k < n; k++) {
        uint32_t lit = 0;
        for (uint32_t l = 0; l < lines; l++) {
            const uint8_t px = g_disp.last[(size_t)l * n + k];
            lit += px != 0u;
            zeros += px == 0u;
        }
        rows += lit == 0u;
    }
    *zero_frac = (float)zeros / (float)(lines * n);
    return rows;
}

static void every_contact_frame_of_every_phantom_has_signal_in_every_row(void **state)
{
    (void)state;
    for (int kind = 0; kind < (int)SC_PHANTOM_KIND_COUNT; kind++) {
        sc_phantom_def pd = sc_phantom_default_def();
        pd.kind = (sc_phantom_kind)kind;
        pd.spacing_mm = 0.5f; /* the test's speed; the geometry is the same at 0.25 mm */
        sc_phantom ph;
        assert_int_equal(sc_phantom_generate(&pd, &ph), SC_OK);
        const sc_volume *v = &ph.def.volume;
        const float depth_below_skin_mm =
            v->origin_mm[2] + (float)(v->dim[2] - 1u) * v->spacing_mm[2];
        assert_true(depth_below_skin_mm < 50.0f); /* shallower than the 60 mm image */
        /* the host simulator's contact point: the top centre of the mesh box */
        const sc_mesh_def *m = &ph.def.mesh;
        const float cx = m->origin_mm[0] + 0.5f * m->size_mm[0];
        const float cy = m->origin_mm[1] + 0.5f * m->size_mm[1];
        const float cz = m->origin_mm[2];
        const sc_scan_def lin = sc_scan_default_def();
        const sc_scan_def curv = sc_scan_curvilinear_default_def();
        struct {
            const char *what;
            const sc_scan_def *scan;
            sc_xform probe;
        } frames[] = {
            {"rest", &lin, probe_at(cx, cy, cz, 0.0f)},
            {"press 16 mm", &lin, probe_at(cx, cy, cz + 16.0f, 0.0f)},
            {"tilt 20 deg, 8 mm", &lin, probe_at(cx, cy, cz + 8.0f, 20.0f)},
            {"beside the volume", &lin, probe_at(cx + 20.0f, cy, cz + 4.0f, 0.0f)},
            {"curvilinear, 80 mm", &curv, probe_at(cx, cy, cz + 4.0f, 0.0f)},
        };
        for (size_t f = 0; f < sizeof frames / sizeof frames[0]; f++) {
            float zf;
            const uint32_t rows = zero_rows(v, frames[f].scan, &frames[f].probe, &zf);
            print_message("%s, %s: %u all-zero rows, %.1f %% zero pixels\n",
                          sc_phantom_kind_name(pd.kind), frames[f].what, rows, 100.0 * zf);
            assert_int_equal(rows, 0);
        }
        sc_phantom_free(&ph);
    }
}

/* Speckle size as a trainee sees it: the default linear image (256 x 512, 38 x 60 mm) of the
 * neck phantom at its real 0.25 mm voxels, rigid at rest; the normalised autocorrelation of the
 * speckle (grey level less its 4 x 4 mm local mean) over pixel pairs that both lie in soft
 * tissue (fat or muscle at rest, 4-30 mm deep, at least 1 mm along the beam from another label:
 * the fascia's bright lines are anatomy), axial (along a line) and lateral (across lines); its
 * full width at half maximum in mm.
 * A 7-12 MHz linear probe's speckle is about 0.2-0.5 mm axial and 0.3-0.8 mm lateral (the
 * pulse's length and the beam's width at the focus: Szabo, "Diagnostic ultrasound imaging",
 * ch. 7 and 8). */
static float g_res[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];

/* The speckle: each pixel less the mean of its soft-tissue neighbours within +-hl lines and
 * +-hk samples (the tissue's slow brightness changes: fat against muscle, lobules, TGC). */
static void speckle_residual(const uint8_t *img, const uint8_t *ok, uint32_t lines, uint32_t n,
                             uint32_t hl, uint32_t hk)
{
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < n; k++) {
            const size_t i = (size_t)l * n + k;
            g_res[i] = 0.0f;
            if (!ok[i]) {
                continue;
            }
            double sum = 0.0, c = 0.0;
            for (uint32_t ll = l > hl ? l - hl : 0u; ll <= l + hl && ll < lines; ll++) {
                for (uint32_t kk = k > hk ? k - hk : 0u; kk <= k + hk && kk < n; kk++) {
                    const size_t j = (size_t)ll * n + kk;
                    if (ok[j]) {
                        sum += img[j];
                        c += 1.0;
                    }
                }
            }
            g_res[i] = (float)(img[i] - sum / c);
        }
    }
}

static double acf_fwhm_mm(const uint8_t *img, const uint8_t *ok, uint32_t lines, uint32_t n,
                          int axial, double step_mm)
{
    (void)img;
    const double mean = 0.0;
    double prev = 1.0;
    for (uint32_t lag = 1; lag < 40u; lag++) {
        double num = 0.0, den = 0.0;
        for (uint32_t l = 0; l < lines; l++) {
            for (uint32_t k = 0; k < n; k++) {
                const uint32_t l2 = axial ? l : l + lag, k2 = axial ? k + lag : k;
                if (l2 >= lines || k2 >= n) {
                    continue;
                }
                const size_t i = (size_t)l * n + k, j = (size_t)l2 * n + k2;
                if (!ok[i] || !ok[j]) {
                    continue;
                }
                const double a = g_res[i] - mean, c = g_res[j] - mean;
                num += a * c;
                den += 0.5 * (a * a + c * c);
            }
        }
        const double r = den > 0.0 ? num / den : 0.0;
        if (r <= 0.5) {
            /* half maximum between lag-1 and lag, linearly; the width is twice that lag */
            const double f = (prev - 0.5) / (prev - r);
            return 2.0 * ((double)lag - 1.0 + f) * step_mm;
        }
        prev = r;
    }
    return 2.0 * 40.0 * step_mm;
}

static void speckle_size_of_the_neck_phantom_is_measured_and_fine(void **state)
{
    (void)state;
    sc_phantom_def pd = sc_phantom_default_def(); /* 0.25 mm voxels */
    sc_phantom ph;
    assert_int_equal(sc_phantom_generate(&pd, &ph), SC_OK);
    const sc_volume *v = &ph.def.volume;
    const sc_mesh_def *m = &ph.def.mesh;
    const sc_xform probe = probe_at(m->origin_mm[0] + 0.5f * m->size_mm[0],
                                    m->origin_mm[1] + 0.5f * m->size_mm[1], 0.0f, 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, v, &probe, 1, &dev, 1u), SC_OK);
    const uint32_t lines = d.scan.lines_n, n = d.scan.samples_n;
    static uint8_t ok[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    uint32_t used = 0;
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < n; k++) {
            float p[3];
            sc_scan_geom_pixel(&g_b.geom, l, k, p);
            const float w[3] = {p[0] + probe.t_mm[0], p[1] + probe.t_mm[1], p[2] + probe.t_mm[2]};
            int32_t ix[3];
            int in = 1;
            for (uint32_t a = 0; a < 3u; a++) {
                ix[a] = (int32_t)lrintf((w[a] - v->origin_mm[a]) / v->spacing_mm[a]);
                in = in && ix[a] >= 0 && ix[a] < (int32_t)v->dim[a];
            }
            uint8_t lab = SC_LABEL_OUTSIDE;
            if (in) {
                lab = v->labels[(size_t)ix[0] +
                                (size_t)v->dim[0] * ((size_t)ix[1] + (size_t)v->dim[1] * ix[2])];
            }
            const size_t i = (size_t)l * n + k;
            ok[i] = lab; /* labels first, the mask below */
        }
    }
    /* soft tissue at least 1 mm from another label along the beam: the fascia's bright lines
     * (interfaces across the beam, laterally long) are anatomy, not speckle */
    static uint8_t lab_img[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    memcpy(lab_img, ok, (size_t)lines * n);
    const uint32_t margin = (uint32_t)(1.0f / g_b.geom.sample_mm) + 1u;
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < n; k++) {
            const size_t i = (size_t)l * n + k;
            const uint8_t lab = lab_img[i];
            const float depth = ((float)k + 0.5f) * g_b.geom.sample_mm;
            int same = k >= margin && k + margin < n;
            for (uint32_t dk = 1; same && dk <= margin; dk++) {
                same = lab_img[i - dk] == lab && lab_img[i + dk] == lab;
            }
            ok[i] = (uint8_t)((lab == SC_LABEL_MUSCLE || lab == SC_LABEL_FAT) && same &&
                              depth > 4.0f && depth < 30.0f && g_disp.last[i] > 0u);
            used += ok[i];
        }
    }
    /* 2 mm either way: well above a speckle cell, below the tissue's structure */
    speckle_residual(g_disp.last, ok, lines, n, (uint32_t)(2.0f / (d.scan.width_mm / (float)lines)),
                     (uint32_t)(2.0f / g_b.geom.sample_mm));
    const double ax = acf_fwhm_mm(g_disp.last, ok, lines, n, 1, g_b.geom.sample_mm);
    const double lat = acf_fwhm_mm(g_disp.last, ok, lines, n, 0, d.scan.width_mm / (float)lines);
    print_message("speckle FWHM (autocorrelation, %u soft-tissue pixels): axial %.2f mm, lateral "
                  "%.2f mm\n",
                  used, ax, lat);
    assert_true(used > 10000u);
    /* fine-grained: a resolution cell of a 7-12 MHz linear probe (measured 0.41 / 0.44 mm;
     * the phantom of before, box-blurred 0.75 mm both ways, gave 0.70 / 0.72 mm) */
    assert_true(ax > 0.1 && ax <= 0.5);
    assert_true(lat > 0.1 && lat <= 0.6);
    sc_phantom_free(&ph);
}

/* Shadow under the neck phantom's vertebra with and without the engine's acoustics: per scan
 * line (linear probe, untilted, so a line is a column of the volume) the depth of the first bone
 * voxel from the label map; the mean 2..6 mm below it on lines that meet bone, against the mean
 * at the same depths on lines that do not. Returns that ratio. */
static float vertebra_shadow_ratio(const sc_phantom *ph, int acoustics)
{
    const sc_volume *v = &ph->def.volume;
    const sc_mesh_def *m = &ph->def.mesh;
    const float cx = m->origin_mm[0] + 0.5f * m->size_mm[0];
    const float cy = m->origin_mm[1] + 0.5f * m->size_mm[1];
    const sc_xform probe = probe_at(cx, cy, m->origin_mm[2], 0.0f);
    sc_bscan_def d = sc_bscan_default_def();
    d.acoustics = (uint32_t)acoustics;
    d.scan.depth_mm = 45.0f; /* inside the volume: the shadow is the model's, not the edge's */
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, v, &probe, 1, &dev, 1u), SC_OK);
    const uint32_t lines = d.scan.lines_n, n = d.scan.samples_n;
    const float pitch = d.scan.width_mm / (float)lines, dr = d.scan.depth_mm / (float)n;
    const uint32_t j = (uint32_t)lrintf((cy - v->origin_mm[1]) / v->spacing_mm[1]);
    double s_sh = 0.0, s_bs = 0.0;
    uint32_t n_sh = 0, n_bs = 0;
    float top_sum = 0.0f;
    uint32_t top_n = 0;
    float bone_top[SC_MAX_SCAN_LINES];
    for (uint32_t l = 0; l < lines; l++) {
        const float x = cx - 0.5f * d.scan.width_mm + ((float)l + 0.5f) * pitch;
        const uint32_t i = (uint32_t)lrintf((x - v->origin_mm[0]) / v->spacing_mm[0]);
        bone_top[l] = -1.0f;
        for (uint32_t k = 0; k < v->dim[2]; k++) {
            const size_t o = i + (size_t)v->dim[0] * (j + (size_t)v->dim[1] * k);
            if (v->labels[o] == SC_LABEL_BONE) {
                bone_top[l] = v->origin_mm[2] + (float)k * v->spacing_mm[2] - m->origin_mm[2];
                top_sum += bone_top[l];
                top_n++;
                break;
            }
        }
    }
    assert_true(top_n > 10u && top_n < lines - 10u); /* bone under part of the image */
    const float mean_top = top_sum / (float)top_n;
    for (uint32_t l = 0; l < lines; l++) {
        for (uint32_t k = 0; k < n; k++) {
            const float z = ((float)k + 0.5f) * dr;
            const uint8_t px = g_disp.last[(size_t)l * n + k];
            if (bone_top[l] >= 0.0f && z >= bone_top[l] + 2.0f && z <= bone_top[l] + 6.0f) {
                s_sh += px;
                n_sh++;
            } else if (bone_top[l] < 0.0f && z >= mean_top + 2.0f && z <= mean_top + 6.0f) {
                s_bs += px;
                n_bs++;
            }
        }
    }
    print_message("bone under %u of %u lines, top %.1f mm; %u shadow, %u beside samples\n", top_n,
                  lines, (double)mean_top, n_sh, n_bs);
    assert_true(n_sh > 100u && n_bs > 100u);
    const float r = (float)((s_sh / n_sh) / (s_bs / n_bs));
    print_message("%s: shadow %.1f, beside %.1f (%.3f)\n",
                  acoustics ? "engine acoustics" : "volume only", s_sh / n_sh, s_bs / n_bs,
                  (double)r);
    return r;
}

/* The neck phantom built for the engine's acoustics has no shadow in its voxels and asks the
 * engine for it (the case flag); with the engine's acoustics on, the vertebra shadows. */
static void engine_acoustics_phantom_gets_its_shadow_from_the_engine(void **state)
{
    (void)state;
    sc_phantom_def pd = sc_phantom_default_def();
    pd.spacing_mm = 0.5f;
    pd.engine_acoustics = 1;
    sc_phantom ph;
    assert_int_equal(sc_phantom_generate(&pd, &ph), SC_OK);
    assert_int_equal(ph.def.imaging_flags, SC_CASE_IMAGING_ENGINE_ACOUSTICS);
    assert_true(vertebra_shadow_ratio(&ph, 0) > 0.6f); /* not in the voxels */
    assert_true(vertebra_shadow_ratio(&ph, 1) <= 0.3f);
    sc_phantom_free(&ph);
    /* the default phantom keeps its baked shadow and does not ask for the engine's */
    pd.engine_acoustics = 0;
    assert_int_equal(sc_phantom_generate(&pd, &ph), SC_OK);
    assert_int_equal(ph.def.imaging_flags, 0u);
    assert_true(vertebra_shadow_ratio(&ph, 0) <= 0.3f);
    sc_phantom_free(&ph);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_contact_frame_of_every_phantom_has_signal_in_every_row),
        cmocka_unit_test(engine_acoustics_phantom_gets_its_shadow_from_the_engine),
        cmocka_unit_test(speckle_size_of_the_neck_phantom_is_measured_and_fine),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
