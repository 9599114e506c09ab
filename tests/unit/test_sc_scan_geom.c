/* test_sc_scan_geom.c: pixel positions of linear and curvilinear probes, validation, and the
 * conservative line-range filter the B-scan mapper relies on. */
#include "sc_test.h"

#include <math.h>

#include "sc_err.h"
#include "sc_scan_geom.h"

static sc_scan_geom g_g;

static void linear_pixels_span_the_aperture_and_depth_at_pixel_centres(void **state)
{
    (void)state;
    sc_scan_def d = sc_scan_default_def();
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_OK);
    float p[3];
    const float pitch = 38.0f / 256.0f, dz = 60.0f / 512.0f;
    sc_scan_geom_pixel(&g_g, 0, 0, p);
    /* float32 positions of tens of mm: 1e-4 mm is 10 ulps */
    assert_true(fabsf(p[0] - (-19.0f + 0.5f * pitch)) < 1e-4f);
    assert_true(fabsf(p[1]) < 1e-9f);
    assert_true(fabsf(p[2] - 0.5f * dz) < 1e-4f);
    sc_scan_geom_pixel(&g_g, 255, 511, p);
    assert_true(fabsf(p[0] - (19.0f - 0.5f * pitch)) < 1e-4f);
    assert_true(fabsf(p[2] - (60.0f - 0.5f * dz)) < 1e-4f);
    assert_true(fabsf(g_g.sample_area_mm2[100] - pitch * dz) < 1e-7f);
}

static void curvilinear_pixels_lie_on_arcs_around_the_apex(void **state)
{
    (void)state;
    sc_scan_def d = sc_scan_curvilinear_default_def();
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_OK);
    const float dr = d.depth_mm / (float)d.samples_n;
    for (uint32_t l = 0; l < d.lines_n; l += 17u) {
        for (uint32_t k = 0; k < d.samples_n; k += 61u) {
            float p[3];
            sc_scan_geom_pixel(&g_g, l, k, p);
            const float r = hypotf(p[0], p[2] + d.radius_mm);
            assert_true(fabsf(r - (d.radius_mm + ((float)k + 0.5f) * dr)) < 1e-3f);
        }
    }
    /* the outer lines sit half a line pitch inside the sector's edges */
    float p[3];
    sc_scan_geom_pixel(&g_g, 0, 10, p);
    const float th = atan2f(p[0], p[2] + d.radius_mm) * 180.0f / 3.14159265f;
    assert_true(fabsf(th - (-30.0f + 0.5f * 60.0f / (float)d.lines_n)) < 1e-3f);
    /* pixel areas grow with the radius */
    assert_true(g_g.sample_area_mm2[500] > g_g.sample_area_mm2[0] * 1.5f);
}

static void invalid_geometries_are_refused_and_leave_the_old_one(void **state)
{
    (void)state;
    sc_scan_def ok = sc_scan_default_def();
    assert_int_equal(sc_scan_geom_init(&g_g, &ok), SC_OK);
    sc_scan_def d = ok;
    d.lines_n = SC_MAX_SCAN_LINES + 1u;
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    d = ok;
    d.samples_n = 1u;
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    d = ok;
    d.depth_mm = NAN;
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    d = ok;
    d.kind = 7u;
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    d = ok;
    d.image_to_probe.r[0] = 1.5f; /* not rigid */
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    d = sc_scan_curvilinear_default_def();
    d.sector_deg = 180.0f;
    assert_int_equal(sc_scan_geom_init(&g_g, &d), SC_ERR_IMG_GEOMETRY);
    assert_int_equal(sc_scan_geom_init(NULL, &ok), SC_ERR_INVALID_ARG);
    assert_int_equal(g_g.def.kind, SC_SCAN_GEOM_LINEAR);
    assert_int_equal(g_g.def.lines_n, ok.lines_n);
}

/* Every line that passes through a box must be inside the range the filter returns. */
static void line_range_never_misses_a_line_through_the_box(void **state)
{
    (void)state;
    const sc_scan_def defs[2] = {sc_scan_default_def(), sc_scan_curvilinear_default_def()};
    uint32_t seed = 12345u;
    for (int g = 0; g < 2; g++) {
        assert_int_equal(sc_scan_geom_init(&g_g, &defs[g]), SC_OK);
        for (int trial = 0; trial < 300; trial++) {
            seed = seed * 1664525u + 1013904223u;
            const float x0 = -40.0f + (float)(seed >> 8) / (float)(1u << 24) * 80.0f;
            seed = seed * 1664525u + 1013904223u;
            const float z0 = -10.0f + (float)(seed >> 8) / (float)(1u << 24) * 80.0f;
            const float xmin = x0, xmax = x0 + 0.3f + (float)(trial % 7) * 0.7f;
            const float zmin = z0, zmax = z0 + 0.3f + (float)(trial % 5) * 0.9f;
            int32_t lo = -1, hi = -1;
            const int any = sc_scan_geom_line_range(&g_g, xmin, xmax, zmin, zmax, &lo, &hi);
            for (uint32_t l = 0; l < defs[g].lines_n; l++) {
                int hits = 0;
                for (uint32_t k = 0; k < defs[g].samples_n && !hits; k++) {
                    float p[3];
                    sc_scan_geom_pixel(&g_g, l, k, p);
                    hits = p[0] >= xmin && p[0] <= xmax && p[2] >= zmin && p[2] <= zmax;
                }
                if (hits) {
                    assert_true(any);
                    assert_true((int32_t)l >= lo && (int32_t)l <= hi);
                }
            }
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_pixels_span_the_aperture_and_depth_at_pixel_centres),
        cmocka_unit_test(curvilinear_pixels_lie_on_arcs_around_the_apex),
        cmocka_unit_test(invalid_geometries_are_refused_and_leave_the_old_one),
        cmocka_unit_test(line_range_never_misses_a_line_through_the_box),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
