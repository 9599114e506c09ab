/* test_sc_scanconv.c: scan geometry from the engine to the screen, checked on a phantom with
 * known point targets.
 *
 * A uniform volume holds small bright spheres at known positions in the probe frame. The real
 * B-scan synthesis images it (rigidly, no mesh), the host display records the frame with its
 * geometry record, and the scan converter that every sink uses (PNG, KMS/fbdev, viewer) draws
 * it. Each target must land on the scan line and sample its depth and angle give, and on the
 * raster pixel the physical layout gives (the fan's arc of radius R at the top, 1 pixel = s mm
 * in both directions). With the probe-face radius missing from the frame record the converter
 * draws a pointed fan from the skin and the targets land mm away: this test fails then.
 */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_bscan.h"
#include "sc_err.h"
#include "sc_hs_display.h"
#include "sc_scanconv.h"

#define PH_SP_MM 0.5f
#define PH_NX    181u /* x -45 .. 45 */
#define PH_NY    13u  /* y -3 .. 3 */
#define PH_NZ    141u /* z -5 .. 65 */
#define PH_VOX   (PH_NX * PH_NY * PH_NZ)
#define PH_BG    90u
#define PH_TGT_R 0.8f /* target sphere radius, mm */
#define RAST_W   480u
#define RAST_H   400u

typedef struct target {
    float x_mm, z_mm; /* probe/volume frame, y = 0 */
} target;

static uint8_t g_vox[PH_VOX];
static sc_volume g_vol;
static sc_bscan g_b;
static sc_hs_display g_disp;
static uint8_t g_raster[RAST_W * RAST_H];

static void make_phantom(const target *t, size_t n)
{
    memset(g_vox, PH_BG, sizeof(g_vox));
    for (uint32_t k = 0; k < PH_NZ; k++) {
        for (uint32_t j = 0; j < PH_NY; j++) {
            for (uint32_t i = 0; i < PH_NX; i++) {
                const float x = -45.0f + (float)i * PH_SP_MM, y = -3.0f + (float)j * PH_SP_MM,
                            z = -5.0f + (float)k * PH_SP_MM;
                for (size_t q = 0; q < n; q++) {
                    const float dx = x - t[q].x_mm, dz = z - t[q].z_mm;
                    if (dx * dx + y * y + dz * dz <= PH_TGT_R * PH_TGT_R) {
                        g_vox[((size_t)k * PH_NY + j) * PH_NX + i] = 255u;
                    }
                }
            }
        }
    }
    g_vol.dim[0] = PH_NX;
    g_vol.dim[1] = PH_NY;
    g_vol.dim[2] = PH_NZ;
    g_vol.spacing_mm[0] = g_vol.spacing_mm[1] = g_vol.spacing_mm[2] = PH_SP_MM;
    g_vol.origin_mm[0] = -45.0f;
    g_vol.origin_mm[1] = -3.0f;
    g_vol.origin_mm[2] = -5.0f;
    g_vol.voxels = g_vox;
    g_vol.labels = NULL;
}

/* Image the phantom with the probe face centred at the volume origin, beam along +z. */
static void image(const sc_scan_def *scan)
{
    sc_bscan_def d = sc_bscan_default_def();
    d.scan = *scan;
    assert_int_equal(sc_bscan_init(&g_b, &d), SC_OK);
    sc_hs_display_init(&g_disp);
    const sc_display_dev dev = sc_hs_display_dev(&g_disp);
    const sc_xform probe = sc_xform_identity();
    assert_int_equal(sc_bscan_frame(&g_b, NULL, NULL, &g_vol, &probe, 1, &dev, 1u), SC_OK);
    assert_int_equal(g_disp.frames_complete, 1);
}

/* Centroid of the pixels brighter than the background within a window around (cx, cy). */
static void bright_centroid(const uint8_t *img, uint32_t w, uint32_t h, float cx, float cy,
                            float win, float *ox, float *oy)
{
    double sx = 0.0, sy = 0.0, sw = 0.0;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            if (fabsf((float)x + 0.5f - cx) > win || fabsf((float)y + 0.5f - cy) > win) {
                continue;
            }
            const int v = img[(size_t)y * w + x];
            if (v > (int)PH_BG + 40) {
                const double wt = v - (int)PH_BG;
                sx += wt * ((double)x + 0.5);
                sy += wt * ((double)y + 0.5);
                sw += wt;
            }
        }
    }
    assert_true(sw > 0.0);
    *ox = (float)(sx / sw);
    *oy = (float)(sy / sw);
}

/* Curvilinear: radius R, sector S, depth D. A target at depth d along angle th from the apex
 * lies at (R + d) (sin th, cos th) - (0, R) in the probe frame. */
static void curvilinear_targets_land_on_their_line_sample_and_pixel(void **state)
{
    (void)state;
    sc_scan_def s = sc_scan_curvilinear_default_def();
    s.lines_n = 128u;
    s.samples_n = 400u;
    s.radius_mm = 40.0f;
    s.sector_deg = 60.0f;
    s.depth_mm = 50.0f;
    const float deg = 3.14159265f / 180.0f;
    const float tgt_th[3] = {0.0f, 15.0f * deg, -22.0f * deg};
    const float tgt_d[3] = {8.0f, 30.0f, 42.0f};
    target t[3];
    for (int q = 0; q < 3; q++) {
        t[q].x_mm = (s.radius_mm + tgt_d[q]) * sinf(tgt_th[q]);
        t[q].z_mm = (s.radius_mm + tgt_d[q]) * cosf(tgt_th[q]) - s.radius_mm;
    }
    make_phantom(t, 3);
    image(&s);

    /* the frame record carries the probe-face radius to every sink */
    assert_int_equal(g_disp.last_info.geometry_id, SC_SCAN_GEOM_CURVILINEAR);
    assert_float_equal(g_disp.last_info.radius_mm, 40.0f, 1e-6f);
    assert_float_equal(g_disp.last_info.width_mm, 60.0f, 1e-6f);

    /* line and sample of each target in the line-major image */
    const float pitch = 60.0f * deg / 128.0f, dr = 50.0f / 400.0f;
    for (int q = 0; q < 3; q++) {
        const float l_exp = (tgt_th[q] + 30.0f * deg) / pitch - 0.5f;
        const float k_exp = tgt_d[q] / dr - 0.5f;
        float l, k;
        bright_centroid(g_disp.last, s.samples_n, s.lines_n, k_exp + 0.5f, l_exp + 0.5f, 20.0f, &k,
                        &l);
        assert_float_equal(l - 0.5f, l_exp, 0.6f);
        assert_float_equal(k - 0.5f, k_exp, 1.5f);
    }

    /* the raster: the fan of radii R .. R + D over +-30 deg fits the raster, same scale in x
     * and z, centred; its top is the chord of the face arc's ends, R cos(30) from the apex */
    sc_scanconv c;
    assert_int_equal(sc_scanconv_init(&c, RAST_W, RAST_H), 0);
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, s.samples_n, g_raster);
    const float r1 = 90.0f, half = 30.0f * deg;
    const float fan_w = 2.0f * r1 * sinf(half), top = 40.0f * cosf(half), fan_h = r1 - top;
    const float mm_px = fmaxf(fan_w / (float)RAST_W, fan_h / (float)RAST_H);
    for (int q = 0; q < 3; q++) {
        const float px = 0.5f * (float)RAST_W + t[q].x_mm / mm_px;
        const float py = (t[q].z_mm + 40.0f - top) / mm_px;
        float x, y;
        bright_centroid(g_raster, RAST_W, RAST_H, px, py, 12.0f, &x, &y);
        assert_float_equal(x, px, 1.5f);
        assert_float_equal(y, py, 1.5f);
    }
    /* the probe face is the arc at the top: on the centre column the image starts (R -
     * R cos 30) below the raster's top edge, at the edges of the fan on the top row */
    const uint32_t cx = RAST_W / 2u;
    uint32_t first = 0;
    while (first < RAST_H && g_raster[(size_t)first * RAST_W + cx] == 0u) {
        first++;
    }
    assert_float_equal((float)first, (40.0f - top) / mm_px, 1.5f);
    sc_scanconv_free(&c);
}

/* Linear: lines across the width, samples down the depth, same scale both ways. */
static void linear_targets_land_on_their_pixel(void **state)
{
    (void)state;
    sc_scan_def s = sc_scan_default_def();
    s.lines_n = 128u;
    s.samples_n = 400u;
    s.width_mm = 38.0f;
    s.depth_mm = 40.0f;
    const target t[2] = {{-12.0f, 6.0f}, {9.0f, 31.0f}};
    make_phantom(t, 2);
    image(&s);
    assert_int_equal(g_disp.last_info.geometry_id, SC_SCAN_GEOM_LINEAR);
    assert_float_equal(g_disp.last_info.radius_mm, 0.0f, 0.0f);
    sc_scanconv c;
    assert_int_equal(sc_scanconv_init(&c, RAST_W, RAST_H), 0);
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, s.samples_n, g_raster);
    const float mm_px = fmaxf(38.0f / (float)RAST_W, 40.0f / (float)RAST_H);
    for (int q = 0; q < 2; q++) {
        const float px = 0.5f * (float)RAST_W + t[q].x_mm / mm_px, py = t[q].z_mm / mm_px;
        float x, y;
        bright_centroid(g_raster, RAST_W, RAST_H, px, py, 12.0f, &x, &y);
        assert_float_equal(x, px, 1.5f);
        assert_float_equal(y, py, 1.5f);
    }
    sc_scanconv_free(&c);
}

/* Fit mode (the PNG sinks): a 38 x 39 mm linear image in a 480 x 640 canvas was drawn 480 x 492
 * with 148 black rows below it; fitted, the raster is the image's box: every row and column
 * holds image (the background 90), at the canvas's scale, the targets on their pixels. A
 * curvilinear fan's box: image on the bottom row's centre and, at the face arc's ends, on the top rows. */
static void fit_raster_is_the_image_box_with_no_black_band(void **state)
{
    (void)state;
    sc_scan_def s = sc_scan_default_def();
    s.lines_n = 128u;
    s.samples_n = 400u;
    s.width_mm = 38.0f;
    s.depth_mm = 39.0f;
    const target t[2] = {{-12.0f, 6.0f}, {9.0f, 36.0f}};
    make_phantom(t, 2);
    image(&s);
    static uint8_t big[480u * 640u];
    sc_scanconv c;
    assert_int_equal(sc_scanconv_init(&c, 480u, 640u), 0);
    /* the fixed canvas: black rows below the image */
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, s.samples_n, big);
    assert_int_equal(big[(size_t)639u * 480u + 240u], 0u);
    sc_scanconv_set_fit(&c, 1);
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, s.samples_n, big);
    const float mm_px = fmaxf(38.0f / 480.0f, 39.0f / 640.0f);
    assert_int_equal(c.width, 480u);
    assert_int_equal(c.height, (uint32_t)(39.0f / mm_px + 1e-3f));
    uint32_t w = 0, h = 0;
    sc_scanconv_fit_size(&g_disp.last_info, 480u, 640u, &w, &h);
    assert_int_equal(w, c.width);
    assert_int_equal(h, c.height);
    for (uint32_t y = 0; y < c.height; y++) {
        for (uint32_t x = 0; x < c.width; x++) {
            assert_true(big[(size_t)y * c.width + x] != 0u);
        }
    }
    for (int q = 0; q < 2; q++) {
        const float px = 0.5f * (float)c.width + t[q].x_mm / mm_px, py = t[q].z_mm / mm_px;
        float x, y;
        bright_centroid(big, c.width, c.height, px, py, 12.0f, &x, &y);
        assert_float_equal(x, px, 1.5f);
        assert_float_equal(y, py, 1.5f);
    }
    /* back to the canvas */
    sc_scanconv_set_fit(&c, 0);
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, s.samples_n, big);
    assert_int_equal(c.height, 640u);

    sc_scan_def cs = sc_scan_curvilinear_default_def();
    cs.lines_n = 128u;
    cs.samples_n = 400u;
    cs.radius_mm = 40.0f;
    cs.sector_deg = 60.0f;
    cs.depth_mm = 50.0f;
    make_phantom(t, 0);
    image(&cs);
    sc_scanconv_set_fit(&c, 1);
    sc_scanconv_render(&c, &g_disp.last_info, g_disp.last, cs.samples_n, big);
    assert_int_equal(c.width, 480u);
    assert_true(c.height < 640u);
    const uint32_t last = c.height - 1u;
    assert_true(big[(size_t)last * c.width + c.width / 2u] != 0u);
    /* the face arc's ends touch the top rows */
    uint32_t top_hits = 0;
    for (uint32_t i = 0; i < 2u * c.width; i++) {
        top_hits += big[i] != 0u;
    }
    assert_true(top_hits > 0u);
    sc_scanconv_free(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(curvilinear_targets_land_on_their_line_sample_and_pixel),
        cmocka_unit_test(linear_targets_land_on_their_pixel),
        cmocka_unit_test(fit_raster_is_the_image_box_with_no_black_band),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
