/* test_sc_viewer_cine.c: the viewer's cine loop keeps the last frames in order and steps within
 * them; the calipers measure a known geometry in mm. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_scan_overlay.h"
#include "vw_cine.h"

static uint8_t g_img[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];

static sc_dlink_done frame(uint32_t no)
{
    sc_dlink_done d;
    memset(&d, 0, sizeof d);
    d.frame.frame_no = no;
    d.frame.line_count = 8u;
    d.frame.samples = 16u;
    for (uint32_t l = 0; l < 8u; l++) {
        memset(g_img + (size_t)l * SC_MAX_SCAN_SAMPLES, (int)(no * 8u + l), 16u);
    }
    d.image = g_img;
    return d;
}

static void cine_keeps_the_last_frames_in_order_and_steps_within_them(void **state)
{
    (void)state;
    vw_cine c;
    assert_int_equal(vw_cine_init(&c, 5u), 0);
    assert_null(vw_cine_get(&c, 0u));
    for (uint32_t no = 1; no <= 7u; no++) {
        const sc_dlink_done d = frame(no);
        vw_cine_push(&c, &d);
    }
    assert_int_equal(c.count, 5u);
    for (uint32_t back = 0; back < 5u; back++) {
        const sc_dlink_done *d = vw_cine_get(&c, back);
        assert_non_null(d);
        assert_int_equal(d->frame.frame_no, 7u - back); /* 7 newest .. 3 oldest */
        assert_int_equal(d->image[3u * SC_MAX_SCAN_SAMPLES + 5u], (uint8_t)((7u - back) * 8u + 3u));
    }
    assert_null(vw_cine_get(&c, 5u)); /* frames 1, 2 dropped */
    assert_int_equal(vw_cine_step(&c, 0u, -1), 0u);
    assert_int_equal(vw_cine_step(&c, 0u, 1), 1u);
    assert_int_equal(vw_cine_step(&c, 3u, 5), 4u);
    vw_cine_free(&c);
}

static void calipers_measure_the_known_geometry_in_mm(void **state)
{
    (void)state;
    sc_display_frame_info g;
    memset(&g, 0, sizeof g);
    g.lines = 128u;
    g.samples = 512u;
    g.depth_mm = 40.0f;
    g.width_mm = 30.0f;
    /* linear 30 x 40 mm on 400 x 500 px: 0.08 mm per px (the depth fits; 30 mm take 375 px) */
    assert_true(fabs(vw_caliper_mm(&g, 400u, 500u, 10.0, 100.0, 10.0, 350.0) - 20.0) < 1e-6);
    assert_true(fabs(vw_caliper_mm(&g, 400u, 500u, 0.0, 0.0, 30.0, 40.0) - 4.0) < 1e-6);
    /* the points of depths 10 and 30 mm on the fan's edge of a curvilinear probe: 20 mm */
    g.geometry_id = 1u;
    g.width_mm = 60.0f;
    g.radius_mm = 40.0f;
    double x0, y0, x1, y1;
    assert_int_equal(sc_overlay_edge_px(&g, 400u, 500u, 10.0, 1, &x0, &y0), 0);
    assert_int_equal(sc_overlay_edge_px(&g, 400u, 500u, 30.0, 1, &x1, &y1), 0);
    const double mm = vw_caliper_mm(&g, 400u, 500u, x0, y0, x1, y1);
    print_message("curvilinear caliper: %.4f mm\n", mm);
    assert_true(fabs(mm - 20.0) < 1e-3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cine_keeps_the_last_frames_in_order_and_steps_within_them),
        cmocka_unit_test(calipers_measure_the_known_geometry_in_mm),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
